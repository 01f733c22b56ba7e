"""How long the Correct page's track mode takes to re-propose one 25-frame stretch at 768x576.

When a user moves a keyframe, the in-between boxes of that track and part up to its neighbouring
keyframes are re-proposed by keyframe-guided tracking (:func:`partlab.tracking.keyframes.track_stretch`,
forward from one keyframe, backward from the other, inside the track's region only). This script
times one such stretch on PETS09-S2L1 (``../shared/data/pets09_s2l1_vtest``, 768x576; never copied
into the repository): decoding its 26 frames, tracking in the region, and the same tracking on the
whole frame, for several people, stretches and seeds. It also prints how often the proposed person
box is right (IoU >= 0.5 with the truth) on the in-between frames, against the straight line.

    python benchmarks/keyframe_stretch.py [--seeds 0,1,2] [--stretches 6]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
_PETS_UNDER = [p / "shared" / "data" / "pets09_s2l1_vtest" for p in (ROOT.parent, ROOT.parent.parent)]
PETS = next((p for p in _PETS_UNDER if p.is_dir()), _PETS_UNDER[0])
SPAN = 25


def iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ix = np.clip(np.minimum(a[:, 0] + a[:, 2], b[:, 0] + b[:, 2]) - np.maximum(a[:, 0], b[:, 0]), 0, None)
    iy = np.clip(np.minimum(a[:, 1] + a[:, 3], b[:, 1] + b[:, 3]) - np.maximum(a[:, 1], b[:, 1]), 0, None)
    inter = ix * iy
    return inter / (a[:, 2] * a[:, 3] + b[:, 2] * b[:, 3] - inter)


def stretches(gt: pd.DataFrame, n: int) -> list[tuple[int, int]]:
    """``(track_id, start)`` of people present in every frame of ``start..start + SPAN``."""
    out = []
    for tid, g in gt[gt.part == "person"].groupby("track_id"):
        frames = set(g.frame)
        for start in range(0, int(g.frame.max()) - SPAN, 100):
            if all(f in frames for f in range(start, start + SPAN + 1)):
                out.append((int(tid), start))
                break
    return out[:n]


def right(rows: pd.DataFrame, truth: pd.DataFrame) -> float:
    t = truth.set_index("frame").loc[rows.frame, ["x", "y", "w", "h"]].to_numpy(float)
    return float((iou(rows[["x", "y", "w", "h"]].to_numpy(float), t) >= 0.5).mean())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--stretches", type=int, default=6)
    a = ap.parse_args()
    from benchmarks.correct_page import commit, pets_boxes
    from partlab.labelling.video import VideoClip
    from partlab.tracking.frame import MemoryTake
    from partlab.tracking.keyframes import stretch_region, track_between, track_stretch

    gt = pets_boxes(PETS / "gt.csv")
    video = VideoClip(PETS / "vtest.avi")
    seeds = [int(s) for s in a.seeds.split(",")]
    todo = stretches(gt, a.stretches)
    warm = gt[(gt.track_id == todo[0][0]) & gt.frame.isin([todo[0][1], todo[0][1] + SPAN])]
    frames0 = [video.read(i) for i in range(todo[0][1], todo[0][1] + SPAN + 1)]
    track_stretch(frames0, warm, todo[0][0], todo[0][1], todo[0][1] + SPAN)  # compiled kernels loaded
    decode, crop, full, ok = [], [], [], {"line": [], "region": [], "frame": []}
    print(f"PETS09-S2L1 768x576, {len(todo)} stretches of {SPAN} frames x seeds {seeds} (body tracker)")
    for tid, start in todo:
        end = start + SPAN
        keys = gt[(gt.track_id == tid) & gt.frame.isin([start, end])]
        truth = gt[(gt.track_id == tid) & (gt.part == "person") & (gt.frame > start) & (gt.frame < end)]
        x0, y0, x1, y1 = stretch_region(keys, video.width, video.height)
        t = time.perf_counter()
        frames = [video.read(i) for i in range(start, end + 1)]
        decode.append(time.perf_counter() - t)
        k = keys[keys.part == "person"].set_index("frame")
        lin = pd.DataFrame({"frame": truth.frame.to_numpy()})
        w = (lin.frame.to_numpy() - start) / SPAN
        for c in "xywh":
            lin[c] = (1 - w) * k.loc[start, c] + w * k.loc[end, c]
        ok["line"].append(right(lin, truth))
        for seed in seeds:
            t = time.perf_counter()
            rows = track_stretch(frames, keys, tid, start, end, seed=seed)
            crop.append(time.perf_counter() - t)
            t = time.perf_counter()
            whole = track_between(MemoryTake(frames), keys, tid, start, end, seed=seed, frames=frames)
            full.append(time.perf_counter() - t)
            for name, got in (("region", rows), ("frame", whole)):
                mine = got[(got.part == "person") & (got.frame > start) & (got.frame < end)]
                ok[name].append(right(mine, truth))
        print(f"  #{tid} frames {start}-{end}: region {x1 - x0}x{y1 - y0} of 768x576")

    def line(name, xs):
        return (f"{name}: median {statistics.median(xs):.2f} s (min {min(xs):.2f}, max {max(xs):.2f}, "
                f"n={len(xs)})")

    print(line("decode 26 frames", decode))
    print(line("track in the region (fwd + bwd, blend)", crop))
    print(line("track on the whole frame", full))
    print(f"whole frame / region: {statistics.median(full) / statistics.median(crop):.2f}x")
    for name, xs in ok.items():
        print(f"person box right (IoU >= 0.5) on in-between frames, {name}: {100 * np.mean(xs):.1f}% "
              f"(spread over stretches and seeds {100 * min(xs):.0f}-{100 * max(xs):.0f}%)")
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, commit {commit()}")


if __name__ == "__main__":
    main()
