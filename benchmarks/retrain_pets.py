"""Learning that pays on the clip at hand (issue 13, item 6): correct the first stretch of a clip,
train, track the rest with the new bundle, and count the edits there against the bundle training
started from.

PETS09-S2L1: the truth's person boxes of frames ``[0, --split)`` stand for a user's corrections
(person boxes only, as the truth holds); ``partlab.models.training.train_bundle`` learns from them
(with the body tracker, starting from ``--from``: the shipped bundle by default), and frames
``[--split, 795)`` are tracked with the start bundle and with the trained one, over ``--seeds``:

* ``init``: from the truth's boxes at frame ``--split`` and each later person's first box (the
  ``--init`` workflow: one box drawn per person);
* ``auto``: no boxes at all (people found by the tracker itself, from frame ``--split`` on).

Edits per 100 truth boxes of frames ``[--split, 795)`` (``partlab.labelling.evaluation.count_edits``;
the init boxes count as drawn), person rate, MOTA and IDF1 as in ``benchmarks/annotation_effort.py``;
mean ± standard deviation over seeds and the paired difference (trained - start) per seed.
Nothing of frames ``[--split, 795)`` is seen by training.

``--synth 100,101``: the same on scenes of the randomized synthetic suite (scenario ``random`` at
those seeds, person rows of the truth only): train on the first half, track the second.

    nice python benchmarks/retrain_pets.py                       # PETS, seeds 1-4, init and auto
    nice python benchmarks/retrain_pets.py --skip-pets --modes init --seeds 1,2 --synth 104
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT.parent))
sys.path.insert(0, str(ROOT))

from annotation_effort import PETS, first_boxes, measure, read_truth  # noqa: E402

from partlab.models.bundle import default_bundle, save_bundle  # noqa: E402
from partlab.models.runner import body_tracker_runner  # noqa: E402
from partlab.models.training import NothingLearnt, train_bundle  # noqa: E402
from partlab.tracking.frame import MemoryTake  # noqa: E402
from partlab.tracking.run import track  # noqa: E402


def train_on(factory, fps: float, truth: pd.DataFrame, start, seed: int, name: str):
    """The bundle trained from ``truth`` (person rows) on ``factory``'s frames, or None when
    training learnt nothing (then the start is what a user keeps)."""
    t0 = time.time()
    try:
        bundle = train_bundle([(factory, fps, truth)], seed=seed, tracker_runner=body_tracker_runner, names=[name],
                              start=start, progress=lambda m: print(f"    train: {m}", flush=True))
    except NothingLearnt as exc:
        print(f"  training learnt nothing: {exc}")
        return None
    s = bundle.summary
    print(f"  trained in {time.time() - t0:.0f} s; learnt: {s['learnt'] or s['nothing_learnt']}")
    print(f"  person fits: {s.get('person')}")
    return None if s["nothing_learnt"] else bundle


def compare(name: str, take, truth: pd.DataFrame, split: int, models: dict, seeds, modes) -> pd.DataFrame:
    """Every model x mode x seed on frames ``[split, end)``."""
    test = truth[truth["frame"] >= split].reset_index(drop=True)
    init = first_boxes(test)
    rows = []
    for mode in modes:
        for label, model in models.items():
            for seed in seeds:
                t0 = time.process_time()
                props = track(take, "body", init=init if mode == "init" else None, model=model, seed=seed,
                              start=split).tracks
                if TRACKS:
                    TRACKS[0].mkdir(parents=True, exist_ok=True)
                    props.to_csv(TRACKS[0] / f"{name}_{mode}_{label}_seed{seed}.csv", index=False)
                cpu = (time.process_time() - t0) / max(take.frame_count - split, 1)
                row = {"clip": name, "mode": mode, "model": label, "seed": seed, "cpu ms/frame": 1000 * cpu,
                       **measure(test, props, init["track_id"].nunique() if mode == "init" else 0)}
                rows.append(row)
                print(f"  {name} {mode:4s} {label:8s} seed {seed}: " + ", ".join(
                    f"{k} {v:.3f}" if isinstance(v, float) else f"{k} {v}" for k, v in row.items()
                    if k not in ("clip", "mode", "model", "seed")), flush=True)
    return pd.DataFrame(rows)


def summarise(df: pd.DataFrame) -> None:
    cols = ["edits/100", "rate", "mota", "idf1", "tracks", "cpu ms/frame"]
    g = df.groupby(["clip", "mode", "model"], sort=False)[cols]
    mean, std = g.mean(), g.std(ddof=1).fillna(0.0)
    out = pd.DataFrame(index=mean.index)
    for c in cols:
        out[c] = [f"{m:.3f} ± {s:.3f}" for m, s in zip(mean[c], std[c])]
    out["seeds"] = g.size()
    print("\nmean ± standard deviation over seeds")
    print(out.reset_index().to_string(index=False))
    print("\npaired by seed: trained - start")
    for (clip, mode), d in df.groupby(["clip", "mode"], sort=False):
        p = d.pivot(index="seed", columns="model", values="edits/100")
        if {"start", "trained"} <= set(p.columns):
            diff = (p["trained"] - p["start"]).dropna()
            print(f"  {clip} {mode}: edits/100 {diff.mean():+.2f} ± {diff.std(ddof=1) if len(diff) > 1 else 0:.2f} "
                  f"(per seed {', '.join(f'{v:+.2f}' for v in diff)}; lower on {int((diff < 0).sum())}/{len(diff)})")


LOAD: list[Path] = []  # --load
MODELS: list[str] = ["start", "trained"]  # --models
TRACKS: list[Path] = []  # --tracks


def pets(split: int, start, seeds, modes, train_seed: int, out: Path | None) -> pd.DataFrame:
    from partlab.labelling.take import open_take
    from partlab.labelling.video import VideoClip

    truth = read_truth(PETS)
    train = truth[truth["frame"] < split].reset_index(drop=True)
    clip = VideoClip(PETS / "vtest.avi")
    print(f"PETS09-S2L1: training on frames 0-{split - 1} ({len(train)} person boxes, "
          f"{train.track_id.nunique()} people)", flush=True)
    if MODELS == ["start"]:
        trained = None
    elif LOAD:
        from partlab.models.bundle import load_bundle

        trained = load_bundle(LOAD[0])
        print(f"  loaded {LOAD[0]}: learnt {trained.summary['learnt']}")
    else:
        trained = train_on(lambda: clip.frames(0, split), clip.fps, train, start, train_seed, "vtest.avi")
        if trained is not None and out is not None:
            save_bundle(trained, out)
            print(f"  saved {out}")
    if not seeds:
        return pd.DataFrame()
    models = {"start": start, **({"trained": trained} if trained is not None else {})}
    models = {k: v for k, v in models.items() if k in MODELS}
    return compare("PETS", open_take(PETS / "vtest.avi"), truth, split, models, seeds, modes)


def synth(scenes: list[int], start, seeds, modes, train_seed: int, frames: int) -> pd.DataFrame:
    from partlab.labelling.synth import make_scene
    from partlab.labelling.synth.scene import random_size
    from partlab.models.training import iterate_frames

    out = []
    for seed in scenes:
        w, h = random_size(seed)
        scene = make_scene("random", seed=seed, n_frames=frames, width=w, height=h)
        truth = scene.truth[scene.truth["part"] == "person"][["frame", "track_id", "part", "x", "y", "w", "h"]]
        # as an annotator would: each person from the frame it was started on (wholly in view)
        begin = scene.init.groupby("track_id")["frame"].min()
        truth = truth[truth["frame"] >= truth["track_id"].map(begin)].reset_index(drop=True)
        split = frames // 2
        train = truth[truth["frame"] < split]
        print(f"synthetic random seed {seed}: {w}x{h}, {truth.track_id.nunique()} people; training on frames "
              f"0-{split - 1}", flush=True)
        trained = train_on(iterate_frames(scene.frames[:split]), scene.fps, train, start, train_seed, f"synth{seed}")
        models = {"start": start, **({"trained": trained} if trained is not None else {})}
        out.append(compare(f"synth{seed}", MemoryTake(scene.frames, scene.fps), truth, split, models, seeds, modes))
    return pd.concat(out, ignore_index=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", default="1,2,3,4", help="tracker seeds of the comparison")
    ap.add_argument("--split", type=int, default=200, help="train on frames before this, track from it")
    ap.add_argument("--from", dest="start", default="default", help="'default' (the shipped bundle) or 'none'")
    ap.add_argument("--modes", default="init,auto")
    ap.add_argument("--train-seed", type=int, default=0)
    ap.add_argument("--bundle", type=Path, help="also save the trained PETS bundle here")
    ap.add_argument("--load", type=Path, help="compare with this PETS bundle instead of training one (e.g. one "
                                              "saved by --bundle, to run seeds in parallel)")
    ap.add_argument("--models", default="start,trained", help="which to track with ('start' alone: no training; "
                                                              "to run the start's seeds while training runs)")
    ap.add_argument("--synth", default="", help="also run these scenes of the randomized synthetic suite "
                                                "(scenario random at these seeds, e.g. 100,101)")
    ap.add_argument("--synth-frames", type=int, default=200)
    ap.add_argument("--skip-pets", action="store_true")
    ap.add_argument("--csv", type=Path)
    ap.add_argument("--tracks", type=Path, help="also save every run's tracks here (CLIP_MODE_MODEL_seedN.csv)")
    a = ap.parse_args()
    seeds = [int(s) for s in a.seeds.split(",") if s]  # none: only train (and save with --bundle)
    LOAD[:] = [a.load] if a.load else []
    MODELS[:] = [m for m in a.models.split(",") if m]
    TRACKS[:] = [a.tracks] if a.tracks else []
    modes = [m for m in a.modes.split(",") if m]
    start = default_bundle() if a.start == "default" else None
    tables = []
    if not a.skip_pets:
        out = a.bundle or Path(tempfile.mkdtemp(prefix="retrain_pets_")) / "bundle"
        tables.append(pets(a.split, start, seeds, modes, a.train_seed, out))
    if a.synth:
        scenes = [int(v) for v in a.synth.split(",") if v]
        tables.append(synth(scenes, start, seeds, modes, a.train_seed, a.synth_frames))
    df = pd.concat(tables, ignore_index=True)
    if df.empty:
        return
    if a.csv:
        df.to_csv(a.csv, index=False)
    summarise(df)


if __name__ == "__main__":
    main()
