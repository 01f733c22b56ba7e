"""Speed of the body tracker against decoding and against OpenCV's TrackerMIL, as ratios.

For a 720x480 synthetic clip with 1, 4 and 8 walkers (500 particles per part, the
entropy adaptation pinned) and for PETS09-S2L1 (768x576), prints per frame:
decode-only ms, background-model ms, body-tracker ms (the run loop without the background model),
their ratio to decode, and OpenCV's ``TrackerMIL`` on the same person boxes (ms per
frame for all people, measured on the first ``--mil-frames`` frames).

    python benchmarks/track_speed.py
    python benchmarks/track_speed.py --walkers 1,4 --frames 60 --skip-pets

Then the limb tracker's rows (issue 4) with 1 and 4 people, from
``benchmarks/track_speed_limbs.py`` (``--skip-limbs`` to leave them out).

Numbers depend on the machine and its load: read the ratios. The walkers come from
``partlab.labelling.synth`` (a benchmark-only scenario with N walkers at spread depths).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from partlab.labelling.video import VideoClip, write_video  # noqa: E402
from partlab.tracking.body.tracker import BodyTracker  # noqa: E402
from partlab.tracking.core.background import BackgroundModel  # noqa: E402
from partlab.tracking.params import BodyParams  # noqa: E402
from partlab.tracking.run import run_single_view  # noqa: E402

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"  # ../shared/data beside the repository
PETS = DATA / "pets09_s2l1_vtest"


class _Timed:
    """A background model that adds the time of every ``apply`` to ``seconds``."""

    def __init__(self, model):
        self.model, self.seconds = model, 0.0

    def apply(self, frame):
        t0 = time.perf_counter()
        mask = self.model.apply(frame)
        self.seconds += time.perf_counter() - t0
        return mask


def walkers_scene(n: int, n_frames: int, seed: int = 0):
    """A synthetic 720x480 scene with ``n`` walkers crossing at depths 6.5..11 m."""
    import partlab.labelling.synth.scene as scene
    from partlab.labelling.synth.appearance import sample_appearances
    from partlab.labelling.synth.motion import walk
    from partlab.labelling.synth.scenarios import BUILDERS, Actor, Script

    def build(rng, camera, frames, fps):
        apps = sample_appearances(rng, min(n, 7))  # synth has 7 distinct outfits; repeat beyond
        apps = [apps[k % len(apps)] for k in range(n)]
        actors = []
        for k, app in enumerate(apps):
            z = 6.5 + 4.5 * k / max(n - 1, 1)
            a, b = (-0.85, 0.85) if k % 2 == 0 else (0.85, -0.85)
            start = a + 0.1 * (k // 2) * np.sign(b)
            actors.append(Actor(app, walk(camera, frames, [(0.0, start, z), (1.0, b, z)], app.height_m)))
        return Script(actors)

    name = f"bench_walkers_{n}"
    BUILDERS[name] = build
    if name not in scene.SCENARIOS:
        scene.SCENARIOS = scene.SCENARIOS + (name,)
    return scene.make_scene(name, seed=seed, n_frames=n_frames, width=720, height=480)


def decode_ms(path: Path, stop: int | None = None) -> float:
    clip = VideoClip(path)
    t0 = time.perf_counter()
    n = sum(1 for _ in clip.frames(0, stop))
    return 1000 * (time.perf_counter() - t0) / max(n, 1)


def body_ms(frames, init: pd.DataFrame, particles: int, whole: bool = False) -> tuple[float, float, int]:
    """(background ms/frame, tracker ms/frame, mean tracked people), timed on a second run over
    the clip: the first loads every compiled kernel (numba) it uses."""
    params = BodyParams().updated({"particles.initial": particles, "particles.min": particles,
                                   "particles.max": particles})
    for _ in range(2):
        tracker = BodyTracker(params, np.random.default_rng(0), init=init, whole=whole)
        bg = _Timed(BackgroundModel(params))
        people = []

        def count(_done, _total, tracker=tracker, people=people):
            people.append(len(tracker.people))

        t0 = time.perf_counter()
        run_single_view(tracker, frames, bg, progress=count)  # the one run loop
        t_all = time.perf_counter() - t0
    n = len(frames)
    return 1000 * bg.seconds / n, 1000 * (t_all - bg.seconds) / n, sum(people) / n


def repeated(n: int, decode, body) -> tuple[float, float, float, float]:
    """Decode and track ``n`` times, alternating (the machine's load changes): the median decode
    ms, background ms and tracker ms; the tracker ms is the run whose ratio to its own decode
    is the median ratio."""
    runs = []
    for _ in range(max(n, 1)):
        dec = decode()
        runs.append((dec, *body()))
    runs.sort(key=lambda r: r[2] / r[0])
    dec, bg, tr, people = runs[len(runs) // 2]
    return dec, bg, tr, people


def mil_ms(frames, init: pd.DataFrame, n_frames: int) -> float:
    """OpenCV TrackerMIL on every person box of ``init`` (started at frame 0 of ``frames``)."""
    boxes = init[(init.part == "person")]
    trackers = []
    for r in boxes.itertuples():
        t = cv2.TrackerMIL.create()
        t.init(frames[0], (int(r.x), int(r.y), max(int(r.w), 2), max(int(r.h), 2)))
        trackers.append(t)
    if not trackers:
        return float("nan")
    t0 = time.perf_counter()
    n = 0
    for frame in frames[1:n_frames + 1]:
        for t in trackers:
            t.update(frame)
        n += 1
    return 1000 * (time.perf_counter() - t0) / max(n, 1)


def row(label, size, people, dec, bg, tr, mil):
    return {"clip": label, "size": size, "people": people, "decode ms": dec, "background ms": bg,
            "tracker ms": tr, "tracker/decode": tr / dec, "MIL ms": mil, "MIL/decode": mil / dec,
            "MIL/tracker": mil / tr}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--walkers", default="1,4,8")
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--particles", type=int, default=500)
    ap.add_argument("--mil-frames", type=int, default=20)
    ap.add_argument("--pets-video", type=Path, default=PETS / "vtest.avi")
    ap.add_argument("--pets-truth", type=Path, default=PETS / "gt.csv")
    ap.add_argument("--pets-frames", type=int, default=200)
    ap.add_argument("--skip-pets", action="store_true")
    ap.add_argument("--repeat", type=int, default=3, help="runs per clip; the run with the median "
                    "tracker/decode ratio is shown")
    ap.add_argument("--skip-limbs", action="store_true")
    a = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in [int(v) for v in a.walkers.split(",") if v]:
            scene = walkers_scene(n, a.frames)
            path = write_video(Path(tmp) / f"walkers{n}.mp4", scene.frames, scene.fps)
            frames = [f for _, f in VideoClip(path).frames()]
            init = scene.init[scene.init.part.isin(["person", "head", "torso", "hipleg"])]
            dec, bg, tr, people = repeated(a.repeat, lambda path=path: decode_ms(path),
                                           lambda frames=frames, init=init: body_ms(frames, init, a.particles))
            mil = mil_ms(frames, init, a.mil_frames)
            rows.append(row(f"synthetic, {n} walker(s)", "720x480", people, dec, bg, tr, mil))
    if not a.skip_pets and a.pets_video.exists():
        gt = pd.read_csv(a.pets_truth)
        gt = gt[gt.frame < a.pets_frames].assign(part="person")
        init = gt.sort_values("frame").groupby("track_id").head(1)[["frame", "track_id", "part", "x", "y", "w", "h"]]
        frames = [f for _, f in VideoClip(a.pets_video).frames(0, a.pets_frames)]
        dec, bg, tr, people = repeated(a.repeat, lambda: decode_ms(a.pets_video, a.pets_frames),
                                       lambda: body_ms(frames, init, a.particles))
        mil = mil_ms(frames, init[init.frame == 0], a.mil_frames) * people / max((init.frame == 0).sum(), 1)
        rows.append(row(f"PETS09-S2L1 ({a.pets_frames} frames)", "768x576", people, dec, bg, tr, mil))
    df = pd.DataFrame(rows)
    print(f"\nBody tracker (3 parts x {a.particles} particles per person) vs decode and TrackerMIL, ms per frame:")
    print(df.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    print("people = mean number tracked per frame; PETS MIL ms is scaled from the people present at frame 0 "
          "to that mean.")
    if not a.skip_limbs:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from track_speed_limbs import limb_speed_rows

        from partlab.tracking.params import LimbParams
        print(f"\nLimb tracker (head and hands, {LimbParams().dynamics.particles} particles per target; seated people "
              "clapping, 640x480, "
              f"{a.frames} frames; step only, a foreground of ones):")
        print(pd.DataFrame(limb_speed_rows((1, 4), a.frames, 640, 480)).to_string(
            index=False, float_format=lambda v: f"{v:.1f}"))


if __name__ == "__main__":
    main()
