"""Tracking rates of the body tracker (seed 002 sec. 5.3's measure), printed as tables.

The measures are :mod:`partlab.tracking.measures`: a box is right when at least half of it lies
on the true box and its centre is inside it; the rate at frame i counts the people tracked right
i frames after their initialisation; the mean rate averages that curve over frames 1 on.

    python benchmarks/track_accuracy.py                       # synthetic suite + PETS09-S2L1
    python benchmarks/track_accuracy.py --skip-pets --scenarios single,pillar
    python benchmarks/track_accuracy.py --skip-synth --pets-video V.avi --pets-truth gt.csv
    python benchmarks/track_accuracy.py --skip-synth --skip-pets --limbs-seeds 0,1,2,3   # limbs table only

The limbs table (issue 4) comes from ``benchmarks/track_accuracy_limbs.py``: head, left and right
hand rates of the limb tracker at frame 105 on the synthetic desk and walker (``single``) scenes
over ``--limbs-seeds``, and the identity swaps of the hands after the clap.

Synthetic scenes come from ``partlab.labelling.synth.make_scene`` (started from their ``init``);
PETS09-S2L1 (``../shared/data/pets09_s2l1_vtest``; PETS 2009, University of Reading, truth by
A. Milan via OpenTraj) is tracked from each person's first truth box, and with automatic
detection (no init) where each truth box counts as found when some tracked person box is
correct for it.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from partlab.tracking import measures  # noqa: E402
from partlab.tracking.body.tracker import BodyTracker  # noqa: E402
from partlab.tracking.core.background import BackgroundModel  # noqa: E402
from partlab.tracking.params import BodyParams  # noqa: E402
from partlab.tracking.run import run_single_view  # noqa: E402

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"  # ../shared/data beside the repository
PETS = DATA / "pets09_s2l1_vtest"
SUITE = ("single", "pillar", "distractors", "pair_cross", "crowd", "bend", "desk")
AT = 105


def rates(tracks: pd.DataFrame, truth: pd.DataFrame, part: str, at: int = AT):
    """(rate at ``at`` frames after start, averaged rate, people at ``at``) for one part
    (:mod:`partlab.tracking.measures`; a truth box without a tracked box counts as a miss)."""
    judged = measures.with_offsets(measures.judge(truth[truth.part == part], tracks[tracks.part == part]), truth)
    curve = measures.rate_curve(judged)
    return measures.rate_at(curve, at), measures.averaged_rate(curve), int((judged.offset == at).sum())


def run_tracker(frames, init, whole=False, occluders=(), seed=0, params=None, fps=25.0):
    """The body tracker through the one run loop: (tracks, seconds per frame)."""
    params = params or BodyParams()
    tracker = BodyTracker(params, np.random.default_rng(seed), init=init, occluders=occluders, whole=whole, fps=fps)
    t0 = time.perf_counter()
    tracks = run_single_view(tracker, frames, BackgroundModel(params))
    return tracks, (time.perf_counter() - t0) / max(len(frames), 1)


def synth_suite(names, seed, n_frames):
    from partlab.labelling.synth import make_scene

    rows = []
    for name in names:
        scene = make_scene(name, seed=seed, n_frames=n_frames, width=720, height=480)
        truth = scene.truth
        init = scene.init
        frames = list(enumerate(scene.frames))
        for mode in ("body", "whole"):
            tracks, spf = run_tracker(frames, init, whole=mode == "whole", occluders=scene.occluders, seed=seed,
                                      fps=scene.fps)
            row = {"scene": name, "tracker": mode, "ms/frame": 1000 * spf}
            parts = ("person",) if mode == "whole" else ("head", "torso", "hipleg", "person")
            for part in parts:
                r_at, r_mean, n = rates(tracks, truth, part)
                row[f"{part}@{AT}"] = r_at
                row[f"{part} mean"] = r_mean
            row["people"] = n
            rows.append(row)
    df = pd.DataFrame(rows)
    print(f"\nSynthetic scenes (720x480, {n_frames} frames, seed {seed}); rate at frame {AT} after start / mean:")
    print(df.to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    for mode in ("body", "whole"):
        sub = df[df.tracker == mode]
        print(f"suite mean person rate, {mode}: at {AT} {sub[f'person@{AT}'].mean():.3f}, "
              f"mean {sub['person mean'].mean():.3f}")


#: the fire-assembly-point sign and its post in PETS09-S2L1 view 1 (x, y, w, h; read off frame 0)
PETS_OCCLUDERS = ((413, 203, 31, 40), (425, 150, 12, 242))


def pets(video: Path, truth_csv: Path, stop: int | None):
    from partlab.labelling.video import VideoClip

    gt = pd.read_csv(truth_csv)
    if stop:
        gt = gt[gt.frame < stop]
    gt = gt.assign(part="person")
    first = gt.sort_values("frame").groupby("track_id").head(1)
    init = first[["frame", "track_id", "part", "x", "y", "w", "h"]]
    clip = VideoClip(video)
    frames = list(clip.frames(0, stop))
    print(f"\nPETS09-S2L1 ({video.name}, {len(frames)} frames, {gt.track_id.nunique()} people):")
    rows = []
    for mode, occluders in (("body", ()), ("whole", ()), ("body", PETS_OCCLUDERS)):
        tracks, spf = run_tracker(frames, init, whole=mode == "whole", occluders=occluders, fps=clip.fps)
        r_at, r_mean, n = rates(tracks, gt, "person")
        start = "first truth box" + (", sign post as occluder" if occluders else "")
        rows.append({"tracker": mode, "start": start, f"person@{AT}": r_at, "person mean": r_mean,
                     f"people@{AT}": n, "ms/frame": 1000 * spf})
    tracks, spf = run_tracker(frames, None, fps=clip.fps)
    found, precise = detection_rates(tracks[tracks.part == "person"], gt)
    from partlab.labelling.evaluation import evaluate  # MOT metrics of the person boxes

    rep = evaluate(gt, tracks[tracks.part == "person"], hota=False)
    mot = rep.mot.loc["person"]
    print("automatic detection, MOT metrics of person boxes (partlab.labelling.evaluation): "
          + ", ".join(f"{k} {mot[k]:.3f}" for k in mot.index if k in ("mota", "motp", "idf1", "num_switches")))
    rows.append({"tracker": "body", "start": "automatic", f"person@{AT}": float("nan"), "person mean": found,
                 f"people@{AT}": 0, "ms/frame": 1000 * spf})
    print(pd.DataFrame(rows).to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    print(f"automatic detection: {found:.2f} of truth boxes have a correct tracked person box; "
          f"{precise:.2f} of tracked person boxes are correct for some truth box; "
          f"{tracks.track_id.nunique()} tracks started for {gt.track_id.nunique()} people")


def detection_rates(tracks: pd.DataFrame, gt: pd.DataFrame) -> tuple[float, float]:
    found = 0
    good = 0
    for frame, t in gt.groupby("frame"):
        k = tracks[tracks.frame == frame]
        if k.empty:
            continue
        tb = t[["x", "y", "w", "h"]].to_numpy()
        kb = k[["x", "y", "w", "h"]].to_numpy()
        ok = np.zeros((len(kb), len(tb)), bool)
        for j in range(len(tb)):
            ok[:, j] = measures.right_box(kb, np.repeat(tb[j:j + 1], len(kb), axis=0))
        found += int(ok.any(axis=0).sum())
        good += int(ok.any(axis=1).sum())
    return found / max(len(gt), 1), good / max(len(tracks), 1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenarios", default=",".join(SUITE))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--frames", type=int, default=150, help="frames per synthetic scene")
    ap.add_argument("--pets-video", type=Path, default=PETS / "vtest.avi")
    ap.add_argument("--pets-truth", type=Path, default=PETS / "gt.csv")
    ap.add_argument("--pets-frames", type=int, default=None, help="only the first N frames of PETS")
    ap.add_argument("--skip-synth", action="store_true")
    ap.add_argument("--skip-pets", action="store_true")
    ap.add_argument("--limbs-seeds", default="0,1,2", help="seeds of the limbs table (720x480)")
    ap.add_argument("--skip-limbs", action="store_true")
    a = ap.parse_args()
    if not a.skip_synth:
        synth_suite([s for s in a.scenarios.split(",") if s], a.seed, a.frames)
    if not a.skip_pets:
        if a.pets_video.exists() and a.pets_truth.exists():
            pets(a.pets_video, a.pets_truth, a.pets_frames)
        else:
            print(f"PETS09-S2L1 not found at {a.pets_video}; skipped")
    if not a.skip_limbs:
        limbs_suite([int(v) for v in a.limbs_seeds.split(",") if v], a.frames)


def limbs_suite(seeds: list[int], n_frames: int) -> None:
    """The limb tracker's table (issue 4), from ``track_accuracy_limbs.limbs_table``."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from track_accuracy_limbs import limbs_table

    _, summary = limbs_table(("desk", "single"), seeds, n_frames, 720, 480, AT)
    print(f"\nLimb tracker (synthetic 720x480, {n_frames} frames, seeds {seeds}, from --init); rate at frame "
          f"{AT} / mean, hand swaps after the clap:")
    print(summary.reset_index().to_string(index=False, float_format=lambda v: f"{v:.2f}"))


if __name__ == "__main__":
    main()
