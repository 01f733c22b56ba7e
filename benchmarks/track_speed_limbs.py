"""Speed of the limb tracker with 1 and 4 people (drawn seated figures clapping).

Rows for the speed table of issue 4; named so as not to clash with the body
developer's ``benchmarks/track_speed.py``. Reports frames per second and the cost
per tracked target, on frames of the given size. A script, not a test:

    PYTHONPATH=. python benchmarks/track_speed_limbs.py [--frames 60] [--width 320] [--height 240]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout's partlab, not an installed one

from partlab.tracking.limbs.tracker import LimbTracker  # noqa: E402
from partlab.tracking.params import LimbParams  # noqa: E402
from partlab.tracking.run import run_single_view  # noqa: E402

SKIN = (105, 145, 195)


def seated_people(n_people: int, n_frames: int, width: int, height: int):
    """Frames and the frame-0 init table of ``n_people`` seated people clapping out of phase."""
    import pandas as pd

    frames, init = [], []
    cols = np.linspace(0, width, n_people + 1)
    for t in range(n_frames):
        f = np.full((height, width, 3), (90, 110, 70), np.uint8)
        for k in range(n_people):
            cx = int((cols[k] + cols[k + 1]) / 2)
            scale = (cols[k + 1] - cols[k]) / 160
            r_head, r_hand = max(int(11 * scale), 4), max(int(6 * scale), 3)
            hy, ay = int(height * 0.25), int(height * 0.65)
            cv2.rectangle(f, (cx - int(25 * scale), hy + r_head), (cx + int(25 * scale), height), (140, 60, 40), -1)
            phase = (t + 9 * k) % 40
            off = int((30 - 1.2 * min(phase, 20) if phase < 20 else 6 + 1.2 * (phase - 20)) * scale)
            off = max(off, int(6 * scale))
            for (x, y), r, part in (((cx, hy), r_head, "head"), ((cx + off, ay), r_hand, "left_hand"),
                                    ((cx - off, ay), r_hand, "right_hand")):
                cv2.circle(f, (x, y), r, SKIN, -1)
                if t == 0:
                    init.append((0, k + 1, part, x - r, y - r, 2 * r, 2 * r))
        frames.append(f)
    return frames, pd.DataFrame(init, columns=["frame", "track_id", "part", "x", "y", "w", "h"])


def limb_speed_rows(people=(1, 4), n_frames: int = 60, width: int = 320, height: int = 240) -> list[dict]:
    """One row per people count: targets, fps, ms per frame and per target of ``LimbTracker``
    (a foreground of ones, no face detector) on :func:`seated_people`; ``benchmarks/track_speed.py``
    prints these as its limb rows."""
    rows = []
    for n in people:
        frames, init = seated_people(n, n_frames, width, height)
        tracker = LimbTracker(LimbParams(), np.random.default_rng(0), init=init, face_detector=False)
        fg = np.full(frames[0].shape[:2], 255, np.uint8)

        class _Everywhere:  # the foreground: every pixel
            def apply(self, _frame, fg=fg):
                return fg

        t0 = time.perf_counter()
        run_single_view(tracker, frames, _Everywhere())
        dt = (time.perf_counter() - t0) / len(frames)
        rows.append({"people": n, "targets": 3 * n, "fps": 1 / dt, "ms/frame": 1000 * dt,
                     "ms/target": 1000 * dt / (3 * n)})
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    args = ap.parse_args()
    print(f"limb tracker speed, {args.width}x{args.height}, {args.frames} frames, "
          f"{LimbParams().dynamics.particles} particles per target")
    print(f"{'people':>6} {'targets':>7} {'fps':>8} {'ms/frame':>9} {'ms/target':>9}")
    for r in limb_speed_rows((1, 4), args.frames, args.width, args.height):
        print(f"{r['people']:>6} {r['targets']:>7} {r['fps']:>8.1f} {r['ms/frame']:>9.1f} {r['ms/target']:>9.2f}")


if __name__ == "__main__":
    main()
