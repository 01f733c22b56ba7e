"""Scaling of ``partlab batch`` on a local Dask cluster: clips per minute with 1 and 2 workers.

Renders ``--clips`` synthetic scenes (scenarios and seeds varied: single, pair_cross, pillar,
distractors, crowd), then for each of ``--repeats`` rounds runs the batch (``--tracker``, the
shipped bundle, seed 0) into a fresh folder with 1 worker and with 2 workers, each on a fresh
local cluster, and prints per worker count:

- clips per minute (mean and standard deviation over the rounds), from submitting the first clip
  to the last result (the cluster's start is timed apart);
- the speed-up of 2 workers over 1 (ratio of the means, and its spread from the rounds' ratios);
- the overhead per task: wall time x workers minus the tasks' own tracking seconds, per clip
  (scheduling, moving tables between processes, writing the CSVs, idle workers at the end);
- the round trip of an empty task (the scheduler's own latency).

    python benchmarks/batch_scaling.py                      # 20 clips of 60 frames, 2 rounds
    python benchmarks/batch_scaling.py --clips 8 --frames 40 --repeats 1

The machine is shared: run it with ``nice`` and read the ratios; the absolute rates are
pessimistic when other work runs, and a speed-up of 2 workers needs 2 otherwise idle cores.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from partlab.cli import main as partlab  # noqa: E402
from partlab.engine import batch, cluster  # noqa: E402

SCENARIOS = ("single", "pair_cross", "pillar", "distractors", "crowd")


def make_clips(folder: Path, n: int, frames: int, size: str) -> list[batch.ClipJob]:
    for k in range(n):
        out = folder / f"clip{k:02d}"
        if not (out / "clip.mp4").is_file():
            partlab(["synth", str(out), "--scenario", SCENARIOS[k % len(SCENARIOS)], "--seed", str(k),
                     "--frames", str(frames), "--size", size])
    return batch.discover(folder)


def one_round(jobs, workers: int, settings: batch.Settings, out: Path) -> dict:
    t0 = time.perf_counter()
    with cluster.client(workers=workers, dashboard=None) as c:
        c.wait_for_workers(workers)
        started = time.perf_counter() - t0
        t1 = time.perf_counter()
        c.submit(int, 0, pure=False).result()
        empty = time.perf_counter() - t1
        report = batch.run_batch(c, jobs, settings, batch.FolderSink(out))
    if report.failed:
        raise SystemExit(f"clips failed: {report.failed}")
    busy = sum(d["seconds"] for d in report.done)
    wall = report.seconds
    return dict(workers=workers, start_s=started, wall_s=wall, clips_per_min=60.0 * len(jobs) / wall,
                overhead_s=(wall * workers - busy) / len(jobs), empty_task_ms=1000.0 * empty,
                task_s=busy / len(jobs))


def _mean_sd(values) -> str:
    values = list(values)
    sd = statistics.stdev(values) if len(values) > 1 else 0.0
    return f"{statistics.mean(values):7.2f} +- {sd:5.2f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--clips", type=int, default=20)
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--tracker", default="body")
    ap.add_argument("--keep", metavar="DIR", help="render the clips here (and reuse them) instead of a temp dir")
    args = ap.parse_args()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    print(f"# batch_scaling: {args.clips} clips x {args.frames} frames {args.size}, tracker {args.tracker}, "
          f"model default, seed 0, {args.repeats} round(s); commit {commit}, {time.strftime('%Y-%m-%d')}, "
          f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    with tempfile.TemporaryDirectory() as tmp:
        clips_dir = Path(args.keep) if args.keep else Path(tmp) / "clips"
        clips_dir.mkdir(parents=True, exist_ok=True)
        jobs = make_clips(clips_dir, args.clips, args.frames, args.size)
        settings = batch.Settings(args.tracker, "default", 0)
        rows = []
        for r in range(args.repeats):
            for workers in (1, 2):
                row = one_round(jobs, workers, settings, Path(tmp) / f"out-{r}-{workers}")
                row["round"] = r
                rows.append(row)
                print(f"round {r} workers {workers}: {row['clips_per_min']:.2f} clips/min, wall {row['wall_s']:.1f} s, "
                      f"cluster start {row['start_s']:.1f} s, load {os.getloadavg()[0]:.1f}", flush=True)
    print("\nworkers | clips/min       | task s (tracking) | overhead s/task | empty task ms | cluster start s")
    for workers in (1, 2):
        rs = [r for r in rows if r["workers"] == workers]
        print(f"{workers:7d} | {_mean_sd(r['clips_per_min'] for r in rs)} | {_mean_sd(r['task_s'] for r in rs)} "
              f"| {_mean_sd(r['overhead_s'] for r in rs)} | {_mean_sd(r['empty_task_ms'] for r in rs)} "
              f"| {_mean_sd(r['start_s'] for r in rs)}")
    one = [r["clips_per_min"] for r in rows if r["workers"] == 1]
    two = [r["clips_per_min"] for r in rows if r["workers"] == 2]
    ratios = [b / a for a, b in zip(one, two)]
    print(f"\nspeed-up 2 vs 1 workers: {statistics.mean(two) / statistics.mean(one):.2f}x "
          f"(per round {', '.join(f'{x:.2f}' for x in ratios)})")


if __name__ == "__main__":
    main()
