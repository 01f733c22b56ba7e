"""The limb tracker found automatically on real footage: PETS09-S2L1 (issue 13, items 5 and 7).

For each tracker seed, runs ``--tracker body``, ``limbs`` and ``all`` without ``--init`` on the
clip (``../shared/data/pets09_s2l1_vtest``, the same run loop as ``partlab track``) and prints per
tracker:

- its time: CPU seconds of this process (``time.process_time``: on a shared, loaded machine the
  wall clock measures the other jobs) and the wall clock, and both as ratios to the body tracker
  of the same seed (issue 13 asks limbs and all for at most 2x the body tracker);
- its track ids against the truth's people in the frames run;
- the share of reported heads whose centre lies in the top third of a truth person box of the
  same frame (``all``: every head written, and the limb tracker's own), and of hands inside one
  (the truth has person boxes only, so a head or hand off every person is on a wall, the grass or
  a car).

The means and standard deviations over the seeds close the table. A script, not a test:

    PYTHONPATH=. python benchmarks/limbs_pets.py [--seeds 1 2 3 4] [--stop 795] [--trackers body limbs all]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from partlab.labelling.take import open_take  # noqa: E402
from partlab.tracking.run import track  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
# ../shared/data beside the repository (or beside the folder of worktrees holding it)
DATA = next((p / "shared" / "data" for p in (ROOT.parent, ROOT.parent.parent) if (p / "shared" / "data").is_dir()),
            ROOT.parent / "shared" / "data") / "pets09_s2l1_vtest"


def on_truth(rows: pd.DataFrame, truth: pd.DataFrame, top: float) -> np.ndarray:
    """``(len(rows),) bool``: whose box centre lies inside a truth box of the same frame, within
    its top ``top`` fraction of height."""
    rows = rows.reset_index(drop=True)
    if rows.empty:
        return np.zeros(0, bool)
    m = rows[["frame", "x", "y", "w", "h"]].reset_index().merge(truth, on="frame", suffixes=("", "_t"))
    cx, cy = m["x"] + m["w"] / 2, m["y"] + m["h"] / 2
    hit = (cx >= m["x_t"]) & (cx <= m["x_t"] + m["w_t"]) & (cy >= m["y_t"]) & (cy <= m["y_t"] + top * m["h_t"])
    out = np.zeros(len(rows), bool)
    out[m.loc[hit.to_numpy(), "index"].to_numpy()] = True
    return out


def measure(tracks: pd.DataFrame, truth: pd.DataFrame) -> dict:
    """Track ids, heads in the top third of a truth person and hands inside one."""
    heads = tracks[tracks["part"] == "head"]
    hands = tracks[tracks["part"].isin(["left_hand", "right_hand"])]
    limb_heads = heads[heads["source"] == "limbs"] if "source" in heads else heads.iloc[:0]
    share = lambda rows, top: float(on_truth(rows, truth, top).mean()) if len(rows) else float("nan")  # noqa: E731
    return {"tracks": int(tracks["track_id"].nunique()), "heads": len(heads),
            "heads_top3": share(heads, 1 / 3), "limb_heads": len(limb_heads),
            "limb_heads_top3": share(limb_heads, 1 / 3), "hands": len(hands), "hands_in": share(hands, 1.0)}


def run(name: str, seed: int, stop: int | None) -> tuple[pd.DataFrame, float, float]:
    take = open_take(DATA / "vtest.avi")
    t0, c0 = time.perf_counter(), time.process_time()
    result = track(take, name, seed=seed, stop=stop)
    return result.tracks, time.process_time() - c0, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3, 4])
    ap.add_argument("--stop", type=int, default=None, help="last frame + 1 (default: the whole clip)")
    ap.add_argument("--trackers", nargs="+", default=["body", "limbs", "all"])
    args = ap.parse_args()
    truth = pd.read_csv(DATA / "gt.csv")
    if args.stop is not None:
        truth = truth[truth["frame"] < args.stop]
    truth = truth[["frame", "x", "y", "w", "h"]]
    people = pd.read_csv(DATA / "gt.csv").pipe(lambda g: g[g["frame"] < (args.stop or 10**9)])["track_id"].nunique()
    for name in args.trackers:  # compile the numba kernels and load the cascade before timing
        run(name, 0, 3)
    rows = []
    for seed in args.seeds:
        base = None
        for name in args.trackers:
            tracks, cpu, wall = run(name, seed, args.stop)
            base = (cpu, wall) if name == "body" else base
            r = {"seed": seed, "tracker": name, "cpu_s": cpu, "wall_s": wall,
                 "cpu_x_body": cpu / base[0] if base else float("nan"),
                 "wall_x_body": wall / base[1] if base else float("nan"), **measure(tracks, truth)}
            rows.append(r)
            print(" ".join(f"{k}={v:.3f}" if isinstance(v, float) else f"{k}={v}" for k, v in r.items()), flush=True)
    df = pd.DataFrame(rows)
    frames = args.stop or "all"
    print(f"\nPETS09-S2L1, frames 0..{frames}, no --init, truth people {people}, seeds {args.seeds}")
    pd.set_option("display.width", 200)
    cols = ["cpu_s", "cpu_x_body", "wall_x_body", "tracks", "heads_top3", "limb_heads_top3", "hands_in"]
    summary = df.groupby("tracker", sort=False)[cols].agg(["mean", "std"])
    print(summary.to_string(float_format="%.3f"))


if __name__ == "__main__":
    main()
