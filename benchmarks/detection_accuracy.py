"""Automatic detection (no ``--init``): how many tracks the body tracker starts per true person,
and the MOT metrics of its person boxes, on the synthetic suite and PETS09-S2L1.

    PYTHONPATH=. python benchmarks/detection_accuracy.py [--scenes single,pair_cross,...]
                                                          [--seeds 0,1,2,3] [--skip-pets]
                                                          [--pets-frames 300] [--pets-seeds 0,1,2,3]

Per scene and seed: ``tracks`` started, ``people`` in the truth, MOTA, IDF1, identity switches,
false positives and misses of the ``person`` boxes (motmetrics through
``partlab.labelling.evaluation.mot_metrics``, IoU >= 0.5). A walker present in the first frame is
learnt into the background model and leaves a "ghost" where it stood; a tracker that starts
tracks on ghosts shows more tracks than people and false positives.
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

from partlab.labelling.evaluation import mot_metrics  # noqa: E402
from partlab.tracking.body.tracker import BodyTracker  # noqa: E402
from partlab.tracking.core.background import BackgroundModel  # noqa: E402
from partlab.tracking.params import BodyParams  # noqa: E402
from partlab.tracking.run import run_single_view  # noqa: E402

SCENES = ("single", "pair_cross", "crowd", "distractors", "bend", "pillar")
DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"  # ../shared/data beside the repository
PETS = DATA / "pets09_s2l1_vtest"


def track_auto(frames, occluders=(), seed: int = 0, fps: float = 25.0,
               params: BodyParams | None = None) -> pd.DataFrame:
    """Person boxes of the body tracker started automatically (no init)."""
    params = params or BodyParams()
    tracker = BodyTracker(params, np.random.default_rng(seed), occluders=occluders, fps=fps)
    tracks = run_single_view(tracker, frames, BackgroundModel(params))
    return tracks[tracks.part == "person"]


def scores(truth: pd.DataFrame, tracks: pd.DataFrame) -> dict:
    truth = truth[truth.part == "person"]
    m = mot_metrics(truth, tracks.assign(part="person")).loc["person"]
    return {"tracks": tracks.track_id.nunique(), "people": truth.track_id.nunique(), "mota": m["mota"],
            "idf1": m["idf1"], "switches": int(m["num_switches"]), "fp": int(m["num_false_positives"]),
            "misses": int(m["num_misses"])}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--seeds", default="0,1,2,3")
    ap.add_argument("--skip-pets", action="store_true")
    ap.add_argument("--pets-frames", type=int, default=0, help="first N frames of PETS (0: all)")
    ap.add_argument("--pets-seeds", default="0,1,2,3", help="tracker seeds for PETS (single runs vary)")
    args = ap.parse_args(argv)
    from partlab.labelling.synth import make_scene

    rows = []
    t0 = time.time()
    for name in args.scenes.split(","):
        for seed in (int(s) for s in args.seeds.split(",")):
            scene = make_scene(name, seed=seed)
            tracks = track_auto(scene.frames, scene.occluders, seed=seed, fps=scene.fps)
            rows.append({"scene": name, "seed": seed, **scores(scene.truth, tracks)})
            print(rows[-1], flush=True)
    df = pd.DataFrame(rows)
    if len(df):
        per = df.groupby("scene", sort=False).agg(
            tracks=("tracks", "sum"), people=("people", "sum"), mota=("mota", "mean"), idf1=("idf1", "mean"),
            switches=("switches", "sum"), fp=("fp", "sum"), misses=("misses", "sum"))
        print(f"\nSynthetic scenes, automatic detection, seeds {args.seeds} (sums of counts, means of MOTA/IDF1):")
        print(per.to_string(float_format=lambda v: f"{v:.2f}"))
        print(f"all: {per.tracks.sum()} tracks for {per.people.sum()} people, MOTA {df.mota.mean():.3f}, "
              f"IDF1 {df.idf1.mean():.3f}")
    if not args.skip_pets and (PETS / "vtest.avi").exists():
        from partlab.labelling.video import VideoClip

        clip = VideoClip(PETS / "vtest.avi")
        stop = args.pets_frames or clip.frame_count
        frames = [f for _, f in clip.frames(0, stop)]
        fps = clip.fps
        clip.close()
        gt = pd.read_csv(PETS / "gt.csv").assign(part="person")
        gt = gt[gt.frame < stop]
        runs = []
        for seed in (int(v) for v in args.pets_seeds.split(",")):
            runs.append({"seed": seed, **scores(gt, track_auto(frames, seed=seed, fps=fps))})
            print(runs[-1], flush=True)
        pets = pd.DataFrame(runs)
        print(f"\nPETS09-S2L1, first {stop} frames, automatic detection, seeds {args.pets_seeds} (means):")
        print(pets.drop(columns="seed").mean().to_frame().T.to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    print(f"({time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
