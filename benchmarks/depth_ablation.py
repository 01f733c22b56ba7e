"""Xu, Deng & Jia's ablation (Table 2) on synthetic fast-hand depth scenes, plus 3D posture errors,
stereo against rendered depth, and speed at 320x240.

Scenes: :func:`partlab.labelling.synth.depth_scene.make_depth_scene`, ``desk_depth`` on even seeds
and ``standing_depth`` on odd ones, 150 frames at 320x240 (the parameters were set by hand while
looking at seeds 0-3, so those four are not unseen). Variants (Table 2's rows):

- ``color_ms``: colour PF + mean shift, no depth at all;
- ``color_is``: colour PF + depth importance sampling (no mean shift);
- ``all``: colour PF + mean shift + depth importance sampling (the full tracker);
- ``stereo``: the full tracker on depth from the rendered stereo pair (``StereoRig``: rectify,
  SGBM, reprojectImageTo3D) instead of the z-buffer.

A hand is right when Zhao & Lee's rule holds (half of the box on the true box and its centre inside;
:func:`partlab.labelling.evaluation.box_correct`). Printed: the rate at frame 105 over seeds, the
fraction of frames right over the clip (mean and standard deviation over seeds), the fraction of
frames with both hands right, 3D errors (mm) of the head, hands, shoulders and elbows, and the
tracker's frames per second (its ``step`` only; stereo matching timed apart) on one OpenCV thread,
from CPU time (``time.process_time``), so that other work on a shared machine does not count.

    PYTHONPATH=. nice python benchmarks/depth_ablation.py [--seeds 10] [--frames 150]

On a shared machine, split the seeds over processes and summarise their rows afterwards:

    ... depth_ablation.py --first-seed 0 --seeds 4 --csv a.csv &   ... --first-seed 4 --seeds 3 --csv b.csv &
    ... depth_ablation.py --summarise a.csv b.csv ...
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout's partlab, not an installed one

from partlab.labelling.evaluation import box_correct  # noqa: E402
from partlab.labelling.stereo import StereoRig  # noqa: E402
from partlab.labelling.synth.depth_scene import make_depth_scene  # noqa: E402
from partlab.tracking.depth.params import DepthParams  # noqa: E402
from partlab.tracking.frame import FrameSet  # noqa: E402
from partlab.tracking.protocol import TrackContext  # noqa: E402
from partlab.tracking.run import build_tracker  # noqa: E402

VARIANTS = ("color_ms", "color_is", "all", "stereo")
HANDS = ("left_hand", "right_hand")
POINTS = ("head", "left_hand", "right_hand", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow")
AT = 105


# webcam-like sizes for --random-size (the paper's is 320x240)
RANDOM_SIZES = ((256, 192), (320, 240), (400, 300), (480, 360))


def random_size(seed: int) -> tuple[int, int]:
    return RANDOM_SIZES[int(np.random.default_rng([seed, 99]).integers(len(RANDOM_SIZES)))]


def run_variant(scene, depth, variant: str, seed: int):
    cam = scene.cameras["cam0"]
    params = DepthParams.ablation("all" if variant == "stereo" else variant)
    tracker = build_tracker("limbs-depth", model=params, seed=seed,
                            context=TrackContext(init=scene.init, cameras={"cam0": cam}))
    rows, spent = [], 0.0
    for i in range(len(scene.frames)):
        fs = FrameSet.single(i, scene.frames[i], depth[i], camera=cam)
        t = time.process_time()
        rows.extend(tracker.step(fs, {}))
        spent += time.process_time() - t
    return tracker.table(rows), len(scene.frames) / spent


def score(tracks: pd.DataFrame, truth: pd.DataFrame, n: int) -> dict:
    """Hands right per truth row (a hand wholly outside the frame has none, so is not scored there;
    a frame counts for "both" when every hand it has a row for is right), and the same over the
    rows whose hand is at least half in view (``occluded`` < 0.5: hidden or outside the frame)."""
    out = {}
    m = truth.merge(tracks, on=["frame", "part"], how="left", suffixes=("_t", ""))
    for suffix, rows in (("", m), (" half", m[m["occluded_t"] < 0.5])):  # the truth's occluded
        wrong = np.zeros(n, bool)
        seen = np.zeros(n, bool)
        for part in HANDS:
            q = rows[rows["part"] == part].sort_values("frame")
            ok = box_correct(q[["x", "y", "w", "h"]].to_numpy(float), q[["x_t", "y_t", "w_t", "h_t"]].to_numpy(float))
            f = q["frame"].to_numpy()
            if not suffix:
                out[f"{part}@{AT}"] = float(ok[f == AT].all()) if (AT < n and (f == AT).any()) else np.nan
            out[f"{part} clip{suffix}"] = float(ok.mean()) if len(ok) else np.nan
            wrong[f[~ok]] = True
            seen[f] = True
        out[f"both clip{suffix}"] = float((~wrong[seen]).mean()) if seen.any() else np.nan
        out[f"scored{suffix}"] = float(seen.mean())
    for part in POINTS:
        q = m[m["part"] == part]
        e = np.linalg.norm(q[["X", "Y", "Z"]].to_numpy(float) - q[["X_t", "Y_t", "Z_t"]].to_numpy(float), axis=1)
        out[f"{part} mm"] = float(np.nanmean(e)) if np.isfinite(e).any() else np.nan
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--frames", type=int, default=150)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--random-size", action="store_true",
                    help="render each seed at a size drawn from RANDOM_SIZES (by the seed) instead of --width/--height")
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS)
    ap.add_argument("--csv", help="also write the per-seed rows to this CSV (rewritten after every seed)")
    ap.add_argument("--summarise", nargs="+", metavar="CSV", help="only print the summary of these rows")
    args = ap.parse_args()
    if args.summarise:
        summarise(pd.concat([pd.read_csv(f) for f in args.summarise], ignore_index=True), args)
        return
    cv2.setNumThreads(1)  # the paper's figure is one 2.8 GHz core
    results = []
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        name = "desk_depth" if seed % 2 == 0 else "standing_depth"
        width, height = random_size(seed) if args.random_size else (args.width, args.height)
        scene = make_depth_scene(name, seed, args.frames, width, height)
        if "stereo" in args.variants:
            rig = StereoRig(scene.cameras["cam0"], scene.cameras["cam0_right"])
            t = time.process_time()
            stereo = np.stack([rig.depth(left, right) for left, right in zip(scene.frames, scene.right)])
            stereo_fps = len(stereo) / (time.process_time() - t)
            person = (scene.labels > 0) & (scene.labels != 9)
            err = np.abs(stereo - scene.depth)[person]
        for variant in args.variants:
            tracks, fps = run_variant(scene, stereo if variant == "stereo" else scene.depth, variant, seed)
            row = {"seed": seed, "scene": name, "variant": variant, "size": f"{width}x{height}", "fps": fps,
                   **score(tracks, scene.truth, args.frames)}
            if variant == "stereo":
                row.update({"stereo fps": stereo_fps, "stereo valid": float(np.isfinite(err).mean()),
                            "stereo median mm": float(np.nanmedian(err))})
            results.append(row)
            print(f"seed {seed} {name:15s} {width}x{height} {variant:9s} hands clip "
                  f"{row['left_hand clip']:.2f}/{row['right_hand clip']:.2f}"
                  f" both {row['both clip']:.2f} (half in view {row['both clip half']:.2f})"
                  f"  elbows {row['left_elbow mm']:.0f}/{row['right_elbow mm']:.0f} mm"
                  f"  shoulders {row['left_shoulder mm']:.0f}/{row['right_shoulder mm']:.0f} mm  {fps:.1f} fps",
                  flush=True)
        if args.csv:
            pd.DataFrame(results).to_csv(args.csv, index=False)
    df = pd.DataFrame(results)
    summarise(df, args)


def summarise(df: pd.DataFrame, args) -> None:
    seeds = sorted(df["seed"].unique())
    sizes = ", ".join(sorted(set(df["size"]))) if "size" in df else f"{args.width}x{args.height}"
    print(f"\nTable 2 (hands right; seeds {seeds[0]}..{seeds[-1]} ({len(seeds)}), {args.frames} frames, "
          f"{sizes}): mean (sd over seeds)")
    cols = [f"left_hand@{AT}", f"right_hand@{AT}", "left_hand clip", "right_hand clip", "both clip",
            "both clip half", "scored half"]
    for variant in [v for v in VARIANTS if v in set(df["variant"])]:
        d = df[df["variant"] == variant]
        cells = "  ".join(f"{c} {d[c].mean():.3f} ({d[c].std():.3f})" for c in cols)
        print(f"  {variant:9s} {cells}")
    print("\n3D errors, mm: mean over frames, then mean (sd) over seeds")
    for variant in [v for v in ("all", "stereo", "color_ms") if v in set(df["variant"])]:
        d = df[df["variant"] == variant]
        print(f"  {variant:9s} " + "  ".join(f"{p} {d[p + ' mm'].mean():.0f} ({d[p + ' mm'].std():.0f})"
                                             for p in POINTS))
    d = df[df["variant"] == "stereo"].set_index("seed")
    a = df[df["variant"] == "all"].set_index("seed")
    both = d.index.intersection(a.index)
    if len(both):
        for col in ("both clip", "both clip half"):
            diff = (d.loc[both, col] - a.loc[both, col]).to_numpy()
            print(f"\nstereo - rendered, {col}: mean {diff.mean():+.3f}, per seed {np.round(diff, 3).tolist()}")
        print(f"stereo depth on the person: valid {d['stereo valid'].mean():.3f}, median error "
              f"{d['stereo median mm'].mean():.1f} mm; matching {d['stereo fps'].mean():.1f} frames/s")
    print(f"\nframes/s of the tracker at {args.width}x{args.height} (one OpenCV thread), mean (sd) over seeds:")
    for variant in [v for v in VARIANTS if v in set(df["variant"])]:
        f = df[df["variant"] == variant]["fps"]
        print(f"  {variant:9s} {f.mean():.1f} ({f.std():.1f})")


if __name__ == "__main__":
    main()
