"""What partlab's proposals cost an annotator: edits per 100 truth boxes (issue 13), with the
person rate (Zhao & Lee sec. 5.3's right-box rule, over every truth box), MOTA and IDF1.

Edits (``partlab.labelling.evaluation.count_edits``): per frame, max(truth boxes, proposals) minus
proposals on a truth box at IoU >= 0.5 (a wrong box is moved once, a missing one drawn, a spurious
one deleted), plus every box the annotator drew first (keyframes, init boxes). Compared methods:

* ``interp K``: linear interpolation between keyframes every K frames of each track (and its last
  frame), what CVAT's track mode does;
* ``body init``: the body tracker from each person's first truth box (``--init``);
* ``body keys K``: keyframe-guided tracking (``--keyframes``) with keyframes every K frames;
* ``body auto``: the body tracker finding people itself;

on PETS09-S2L1 (person boxes of every walker), OTB Human3 and Crossing (one walker each), and
a randomized synthetic suite (``partlab.labelling.synth`` scenario ``random``: proportions,
clothing and skin colours, lighting, camera height and tilt, resolution, 1-12 people; truth
person boxes). Tracker rows are over ``--seeds`` (mean and standard deviation); ms/frame is
the tracker's wall time per frame (pessimistic on a shared machine), cpu ms/frame its CPU time
(all threads of the process; steadier under load, and what to compare with HOG+SORT's).

    nice python benchmarks/annotation_effort.py                      # everything, seeds 1-4
    nice python benchmarks/annotation_effort.py --skip-synth --skip-otb --pets-frames 300
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

from partlab.labelling.evaluation import count_edits, evaluate, interpolate_keyframes, keyframes_of  # noqa: E402
from partlab.tracking.frame import MemoryTake  # noqa: E402
from partlab.tracking.run import track  # noqa: E402

# ../shared/data beside the repository (or beside the folder of worktrees holding it)
DATA = next((p / "shared" / "data" for p in (ROOT.parent, ROOT.parent.parent) if (p / "shared" / "data").is_dir()),
            ROOT.parent / "shared" / "data")
PETS = DATA / "pets09_s2l1_vtest"
OTB = {"human3": DATA / "otb_human3_strcf", "crossing": DATA / "otb_crossing_eco"}


def read_truth(folder: Path, stop: int | None = None) -> pd.DataFrame:
    gt = pd.read_csv(folder / "gt.csv")
    if stop:
        gt = gt[gt.frame < stop]
    return gt.assign(part="person")[["frame", "track_id", "part", "x", "y", "w", "h"]].reset_index(drop=True)


def load_frames(folder: Path, stop: int | None = None) -> tuple[list[np.ndarray], float]:
    """Decoded frames of a shared clip (the PETS video or an OTB image folder)."""
    import cv2

    video = folder / "vtest.avi"
    if video.exists():
        from partlab.labelling.video import VideoClip

        clip = VideoClip(video)
        return [f for _, f in clip.frames(0, stop)], clip.fps
    files = sorted((folder / "img").glob("*.jpg"))[:stop]
    return [cv2.imread(str(f)) for f in files], 25.0


def measure(truth: pd.DataFrame, proposals: pd.DataFrame, keyframes: int, matching: str = "auto") -> dict:
    """Person rate over truth boxes, MOTA, IDF1 and edits/100 of person ``proposals``; ``matching``
    as :func:`partlab.labelling.evaluation.evaluate`'s ("id" for runs whose ids are the truth's)."""
    props = proposals[proposals["part"] == "person"]
    edits = count_edits(truth, props, "person", keyframes=keyframes)
    row = {"edits/100": edits.per_100, "moved": edits.moved, "drawn": edits.drawn, "deleted": edits.deleted}
    if props.empty:
        return {**row, "rate": 0.0, "mota": float("nan"), "idf1": 0.0, "tracks": 0}
    rep = evaluate(truth, props, hota=False, matching=matching)
    c, r = rep.counts["person"], rep.rates["person"]
    row["rate"] = float((r * c).sum() / max(c.sum(), 1))
    row["mota"] = float(rep.mot.loc["person", "mota"])
    row["idf1"] = float(rep.mot.loc["person", "idf1"])
    row["tracks"] = int(props["track_id"].nunique())
    return row


def first_boxes(truth: pd.DataFrame) -> pd.DataFrame:
    return truth.sort_values("frame").groupby("track_id").head(1).reset_index(drop=True)


def methods(truth: pd.DataFrame, auto: bool, keys: tuple[int, ...], init: pd.DataFrame | None = None):
    """(name, kind, init/keyframes table) of what is compared on one clip."""
    out = [(f"interp {k}", "interp", keyframes_of(truth, k)) for k in (10, 25)]
    out.append(("body init", "init", first_boxes(truth) if init is None else init))
    for k in keys:
        out.append((f"body keys {k}", "keys", keyframes_of(truth, k)))
    if auto:
        out.append(("body auto", "auto", None))
    return out


def run_method(take, truth: pd.DataFrame, kind: str, table, seed: int) -> tuple[pd.DataFrame, float, int]:
    """(proposals, seconds per frame, keyframe boxes) of one method; the CPU seconds per frame (all
    threads of this process, steadier than wall time on a shared machine) go to ``CPU[-1]``."""
    n_keys = table["track_id"].nunique() if kind == "init" else None
    t0, c0 = time.perf_counter(), time.process_time()
    CPU.append(0.0)
    if kind == "interp":
        props = interpolate_keyframes(table)
        return props, 0.0, len(table)
    if kind == "init":
        props = track(take, "body", init=table, seed=seed, model=MODEL[0] if MODEL else None).tracks
        n = n_keys  # one box drawn per track (part rows of a synthetic init count as one person box)
    elif kind == "keys":
        from partlab.tracking.keyframes import track_with_keyframes

        props = track_with_keyframes(take, table, seed=seed, model=MODEL[0] if MODEL else None).tracks
        n = len(table)
    elif kind == "hog_sort":
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from hog_sort import hog_sort

        props = hog_sort(take)
        n = 0
    else:
        props = track(take, "body", seed=seed, model=MODEL[0] if MODEL else None).tracks
        n = 0
    CPU[-1] = (time.process_time() - c0) / max(take.frame_count, 1)
    return props, (time.perf_counter() - t0) / max(take.frame_count, 1), n


CPU: list[float] = []
PART_RATES = ("head", "torso", "hipleg")
ONLY: list[str] = []  # --methods
SAVE: list[Path] = []  # --save-proposals
MODEL: list = []  # --set: the body parameters with those changes


def clip_table(name: str, take, truth: pd.DataFrame, seeds, auto: bool, keys, hog: bool = False,
               init: pd.DataFrame | None = None, part_truth: pd.DataFrame | None = None) -> pd.DataFrame:
    """Every method on one clip; ``part_truth`` (synthetic scenes): also the head, torso and hip-leg
    rates at frame 105 after initialisation of the ``body init`` runs."""
    rows = []
    ms = methods(truth, auto, keys, init)
    if ONLY:
        ms = [m for m in ms if any(m[0].startswith(o) for o in ONLY)]
    if hog:
        ms.append(("HOG+SORT", "hog_sort", None))
    for label, kind, table in ms:
        for seed in (seeds if kind not in ("interp", "hog_sort") else seeds[:1]):
            props, spf, n = run_method(take, truth, kind, table, seed)
            if SAVE and kind != "interp":
                SAVE[0].mkdir(parents=True, exist_ok=True)
                props.to_csv(SAVE[0] / f"{name}_{label.replace(' ', '_')}_seed{seed}.csv", index=False)
            rows.append({"clip": name, "method": label, "seed": seed, "ms/frame": 1000 * spf,
                         "cpu ms/frame": 1000 * CPU[-1],
                         **measure(truth, props, n, "auto" if kind in ("auto", "hog_sort") else "id")})
            if part_truth is not None and kind == "init":
                rep = evaluate(part_truth, props, hota=False, matching="id")
                for part in PART_RATES:
                    rows[-1][f"{part}@105"] = rep.rate_at(part)
                    rows[-1][f"{part}@105 n"] = int(rep.counts[part].get(105, 0)) if part in rep.counts else 0
            print(f"  {name:10s} {label:14s} seed {seed}: " + ", ".join(
                f"{k} {v:.3f}" if isinstance(v, float) else f"{k} {v}" for k, v in rows[-1].items()
                if k not in ("clip", "method", "seed")), flush=True)
    return pd.DataFrame(rows)


def summarise(df: pd.DataFrame) -> pd.DataFrame:
    cols = ["rate", "mota", "idf1", "edits/100", "ms/frame", "cpu ms/frame", "tracks"]
    g = df.groupby(["clip", "method"], sort=False)[cols]
    mean, std = g.mean(), g.std(ddof=1).fillna(0.0)
    out = pd.DataFrame(index=mean.index)
    for c in cols:
        out[c] = [f"{m:.3f} ± {s:.3f}" if c != "tracks" else f"{m:.1f} ± {s:.1f}"
                  for m, s in zip(mean[c], std[c])]
    out["seeds"] = g.size()
    return out.reset_index()


def random_scene(seed: int, frames: int, cache: Path | None = None):
    """Scenario ``random`` at ``seed`` in its suite size (rendered once into ``cache`` when given:
    rendering costs more than tracking)."""
    import pickle

    from partlab.labelling.synth import make_scene
    from partlab.labelling.synth.scene import random_size

    path = None if cache is None else cache / f"random{seed}_{frames}.pkl"
    if path is not None and path.exists():
        with open(path, "rb") as f:  # our own cache of our own scenes
            return pickle.load(f)
    w, h = random_size(seed)
    scene = make_scene("random", seed=seed, n_frames=frames, width=w, height=h)
    if path is not None:
        cache.mkdir(parents=True, exist_ok=True)
        with open(path, "wb") as f:
            pickle.dump(scene, f)
    return scene


def synth_suite(n_scenes: int, seeds, keys, frames: int, first: int = 100, cache: Path | None = None) -> pd.DataFrame:
    """The randomized suite: scene ``s`` is scenario ``random`` at seed ``first + s``."""
    out = []
    for s in range(n_scenes):
        seed = first + s
        scene = random_scene(seed, frames, cache)
        # the truth from each track's init frame on (people walking in: once wholly in view, as an
        # annotator would start them); the slivers before are not counted
        start = scene.init.groupby("track_id")["frame"].min()
        tr = scene.truth[scene.truth["frame"] >= scene.truth["track_id"].map(start)]
        truth = tr[tr["part"] == "person"][["frame", "track_id", "part", "x", "y", "w", "h"]].reset_index(drop=True)
        take = MemoryTake(scene.frames, scene.fps)
        h, w = scene.frames.shape[1:3]
        print(f"synthetic random seed {seed}: {w}x{h}, {truth.track_id.nunique()} people", flush=True)
        out.append(clip_table(f"synth{seed}", take, truth, seeds, auto=True, keys=keys, init=scene.init,
                              part_truth=tr))
    df = pd.concat(out, ignore_index=True)
    return df


def parameter_changes(settings: list[str]):
    """``BodyParams`` with the ``GROUP.FIELD=VALUE`` changes of ``--set`` (values read as JSON)."""
    import json

    from partlab.tracking.params import BodyParams

    changes = {}
    for item in settings:
        key, sep, value = item.partition("=")
        if not sep:
            raise SystemExit(f"--set {item!r}: expected GROUP.FIELD=VALUE")
        try:
            value = json.loads(value)
            changes[key.strip()] = tuple(value) if isinstance(value, list) else value  # pairs, boxes
        except json.JSONDecodeError:
            changes[key.strip()] = value
    return BodyParams().updated(changes)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", default="1,2,3,4", help="tracker seeds")
    ap.add_argument("--keys", default="", help="keyframe spacings of keyframe-guided tracking, e.g. 25")
    ap.add_argument("--pets-frames", type=int, default=None, help="only the first N frames of PETS")
    ap.add_argument("--synth-scenes", type=int, default=6, help="scenes of the randomized suite")
    ap.add_argument("--synth-frames", type=int, default=150)
    ap.add_argument("--synth-first", type=int, default=100, help="seed of the suite's first scene")
    ap.add_argument("--scene-cache", type=Path, help="keep rendered synthetic scenes here (pickles) for reruns")
    ap.add_argument("--hog", action="store_true", help="also run the HOG+SORT baseline on PETS")
    ap.add_argument("--skip-pets", action="store_true")
    ap.add_argument("--skip-otb", action="store_true")
    ap.add_argument("--skip-synth", action="store_true")
    ap.add_argument("--csv", type=Path, help="write every run's row here")
    ap.add_argument("--save-proposals", type=Path, help="write every tracker run's tracks CSV into this folder")
    ap.add_argument("--methods", default="",
                    help="only these methods (comma-separated prefixes, e.g. 'body keys,body auto')")
    ap.add_argument("--set", action="append", default=[], metavar="GROUP.FIELD=VALUE",
                    help="run the body tracker with this parameter changed (repeatable; the value is read "
                         "as JSON, e.g. --set detector.duplicate_iou=0.4 --set occlusion.bridge=false)")
    a = ap.parse_args()
    if a.set:
        MODEL[:] = [parameter_changes(a.set)]
    seeds = [int(s) for s in a.seeds.split(",") if s]
    ONLY[:] = [m.strip() for m in a.methods.split(",") if m.strip()]
    SAVE[:] = [a.save_proposals] if a.save_proposals else []
    keys = tuple(int(k) for k in a.keys.split(",") if k)
    tables = []
    if not a.skip_pets:
        truth = read_truth(PETS, a.pets_frames)
        frames, fps = load_frames(PETS, a.pets_frames)
        print(f"PETS09-S2L1: {len(frames)} frames, {truth.track_id.nunique()} people, {len(truth)} boxes", flush=True)
        tables.append(clip_table("PETS", MemoryTake(frames, fps), truth, seeds, auto=True, keys=keys, hog=a.hog))
        del frames
    if not a.skip_otb:
        for name, folder in OTB.items():
            truth = read_truth(folder)
            frames, fps = load_frames(folder)
            print(f"OTB {name}: {len(frames)} frames", flush=True)
            tables.append(clip_table(name, MemoryTake(frames, fps), truth, seeds, auto=False, keys=keys))
    if not a.skip_synth:
        tables.append(synth_suite(a.synth_scenes, seeds, keys, a.synth_frames, a.synth_first, a.scene_cache))
    df = pd.concat(tables, ignore_index=True)
    if a.csv:
        df.to_csv(a.csv, index=False)
    print("\nmean ± standard deviation over seeds (interpolation is deterministic)")
    print(summarise(df).to_string(index=False))
    synth = df[df["clip"].str.startswith("synth")]
    if len(synth):
        print("\nrandomized synthetic suite, mean over scenes and seeds:")
        print(synth.groupby("method", sort=False)[["rate", "mota", "idf1", "edits/100"]].mean().to_string(
            float_format=lambda v: f"{v:.3f}"))
        init = synth[synth["method"] == "body init"]
        if init.empty:  # --methods without "body init": no parts at frame 105 to report
            return
        print("\nrandomized suite, body init: rate at frame 105 after initialisation, pooled over scenes "
              "(people seen 105 frames after their start) and seeds")
        for part in PART_RATES:
            n = init[f"{part}@105 n"].fillna(0)
            r = (init[f"{part}@105"].fillna(0) * n).sum() / max(n.sum(), 1)
            per_seed = [(g[f"{part}@105"].fillna(0) * g[f"{part}@105 n"]).sum() / max(g[f"{part}@105 n"].sum(), 1)
                        for _, g in init.groupby("seed")]
            print(f"  {part}: {r:.3f} over {int(n.sum())} person-runs (per seed {np.mean(per_seed):.3f} ± "
                  f"{np.std(per_seed, ddof=1) if len(per_seed) > 1 else 0:.3f})")


if __name__ == "__main__":
    main()
