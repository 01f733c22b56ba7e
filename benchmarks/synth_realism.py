"""Render every synthetic scenario and measure it: speed, sizes, and camera noise vs a real clip.

    PYTHONPATH=. python benchmarks/synth_realism.py [--real ../shared/data/pets09_s2l1_vtest/vtest.avi]

Per scenario: render time of a 150-frame 720x480 clip (frames + mp4 + CSVs), person heights
and widths from the truth, and on the decoded clip the frame-to-frame brightness spread
(std of the mean grey level / its mean) and the median temporal pixel std. With ``--real``
the same two camera numbers are printed for a real clip's first frames, for comparison.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout's partlab, not an installed one

from partlab.labelling.synth import SCENARIOS, render_scenario  # noqa: E402
from partlab.tracking.tracks import read_tracks_csv  # noqa: E402


def camera_stats(path: Path, n: int = 60) -> tuple[float, float]:
    cap = cv2.VideoCapture(str(path))
    frames = []
    for _ in range(n):
        ok, f = cap.read()
        if not ok:
            break
        frames.append(f.astype(np.float32))
    cap.release()
    x = np.stack(frames)
    level = x.mean(axis=(1, 2, 3))
    return float(level.std() / level.mean()), float(np.median(x.std(axis=0).mean(axis=-1)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--real", type=Path, help="a real clip to compare the camera noise with")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    print(f"{'scenario':12s} {'render s':>8s} {'height px':>10s} {'width px':>9s} {'flicker':>8s} {'noise':>6s}")
    for name in SCENARIOS:
        with tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            out = render_scenario(name, d, seed=args.seed)
            dt = time.perf_counter() - t0
            truth = read_tracks_csv(out / "truth.csv")
            person = truth[(truth.part == "person") & (truth.occluded < 0.01)]
            flicker, noise = camera_stats(out / "clip.mp4")
        print(f"{name:12s} {dt:8.2f} {person.h.min():4.0f}-{person.h.max():<5.0f} "
              f"{person.w.min():3.0f}-{person.w.max():<5.0f} {100 * flicker:7.2f}% {noise:6.2f}")
    if args.real:
        flicker, noise = camera_stats(args.real)
        print(f"{args.real.name:12s} {'':8s} {'':10s} {'':9s} {100 * flicker:7.2f}% {noise:6.2f}")


if __name__ == "__main__":
    main()
