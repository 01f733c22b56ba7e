"""Seed 002 sec. 5.2 ablation on the synthetic suite: per-part tracking rates at frame 105.

    PYTHONPATH=. python benchmarks/failure_ablation.py [--scenes distractors,bend,...] [--seed 0]
                                                      [--fast] [--out /tmp/ablation.csv]

For every test scene (``labelling.synth``, seeds not used by the default bundle) the
body tracker runs from the truth's first boxes

* ``none``     : the default bundle's parameters, no failure detector (no adjustment);
* ``default``  : the default bundle's parameters and failure detector (adjustment);
* ``retrained``: a bundle trained here on the truth of *other* clips (other seeds, all
  walking scenarios including ``distractors`` and ``bend``, which the default bundle
  never saw), parameters and detector.

A part is tracked right at frame 105 (after its track's first frame) when at least
half of its box lies on the true box and its centre is inside it (seed 002 sec. 5.2-5.3,
DESIGN.md). The rate is over people x scenes. ``--fast`` trains the retrained bundle
from perturbed truth only (no tracker runs on the training clips).
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
sys.path.insert(0, str(ROOT / "scripts"))

TEST_SCENES = ("distractors", "bend", "single", "pair_cross", "crowd", "pillar")
RETRAIN_SCENES = (("distractors", 201), ("distractors", 202), ("bend", 203), ("bend", 204),
                  ("single", 205), ("pair_cross", 206), ("crowd", 207), ("pillar", 208))
AT = 105
PARTS = ("head", "torso", "hipleg")


def rates_at(tracks: pd.DataFrame, truth: pd.DataFrame, at: int = AT) -> dict[str, tuple[int, int]]:
    """Per part ``(right, total)`` at ``at`` frames after each truth track's first frame."""
    from models.labels import POSITIVE, label_states

    first = truth.groupby("track_id")["frame"].min()
    out = {}
    for part in PARTS:
        right = total = 0
        for tid, f0 in first.items():
            t = truth[(truth.track_id == tid) & (truth.part == part) & (truth.frame == f0 + at)]
            if t.empty:
                continue
            total += 1
            r = tracks[(tracks.track_id == tid) & (tracks.part == part) & (tracks.frame == f0 + at)]
            if r.empty:
                continue
            box = lambda d: np.array([d.x.iloc[0] + d.w.iloc[0] / 2, d.y.iloc[0] + d.h.iloc[0] / 2,  # noqa: E731
                                      d.w.iloc[0], d.h.iloc[0]])
            right += int(label_states(box(r), box(t)) == POSITIVE)
        out[part] = (right, total)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(TEST_SCENES))
    ap.add_argument("--seed", type=int, default=0, help="seed of the test scenes")
    ap.add_argument("--fast", action="store_true", help="retrain from perturbed truth only")
    ap.add_argument("--out", default=None, help="write the per-scene table as CSV")
    args = ap.parse_args(argv)

    from labelling.synth import make_scene
    from models.bundle import default_bundle
    from models.runner import body_tracker_runner, run_body_tracker
    from models.training import first_boxes, train_bundle
    from train_default_bundle import scene_clips

    t0 = time.time()
    default = default_bundle()
    print(f"retraining on {len(RETRAIN_SCENES)} other clips ({'perturbed truth only' if args.fast else 'with tracker runs'})...")
    clips, names, _ = scene_clips(RETRAIN_SCENES)
    retrained = train_bundle(clips, seed=1, tracker_runner=None if args.fast else body_tracker_runner, names=names)
    print(f"  done in {time.time() - t0:.0f} s")
    conditions = {
        "none": (default.body_params, None),
        "default": (default.body_params, default.failure_detector),
        "retrained": (retrained.body_params, retrained.failure_detector),
    }
    rows = []
    for name in args.scenes.split(","):
        scene = make_scene(name, seed=args.seed)
        init = first_boxes(scene.truth)
        frames = lambda: ((i, scene.frames[i]) for i in range(len(scene.frames)))  # noqa: E731
        for cond, (params, detector) in conditions.items():
            t1 = time.time()
            tracks = run_body_tracker(frames, scene.fps, init, seed=args.seed, params=params,
                                      occluders=scene.occluders, failure_detector=detector)
            for part, (right, total) in rates_at(tracks, scene.truth).items():
                rows.append(dict(scene=name, condition=cond, part=part, right=right, total=total))
            print(f"  {name:12} {cond:9} {time.time() - t1:5.1f} s  " +
                  "  ".join(f"{r['part']} {r['right']}/{r['total']}" for r in rows[-3:]))
    table = pd.DataFrame(rows)
    if args.out:
        table.to_csv(args.out, index=False)
    print(f"\nper-part rate at frame {AT} (right / people), seed {args.seed}:")
    groups = {"distractors+bend": table.scene.isin(["distractors", "bend"]), "all scenes": table.scene.notna()}
    lines = ["| scenes | condition | head | torso | hip-leg |", "|---|---|---|---|---|"]
    for gname, mask in groups.items():
        for cond in conditions:
            sub = table[mask & (table.condition == cond)]
            cells = []
            for part in PARTS:
                s = sub[sub.part == part]
                r, n = int(s.right.sum()), int(s.total.sum())
                cells.append(f"{r / n:.2f} ({r}/{n})" if n else "-")
            lines.append(f"| {gname} | {cond} | " + " | ".join(cells) + " |")
    print("\n".join(lines))
    print(f"\ntotal {time.time() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
