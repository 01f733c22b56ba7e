"""How long ``partlab track`` takes on a 5-frame clip, against ``python -c pass``, and where the
import time goes (``python -X importtime``).

Renders a 5-frame synthetic clip (``partlab synth --frames 5``) in a scratch folder, then runs, in
turn and ``--repeat`` times each: ``python -c pass``, ``partlab --help``, ``partlab track CLIP``
(people found automatically) and ``partlab track CLIP --init init.csv``. Prints the median and
spread of each wall time, their ratio to ``python -c pass`` (the machine is shared, so the ratio
says more than the seconds), the CPU seconds (user + system: less shaken by other work on a
shared machine than the wall time), and the import time of ``partlab track`` by top-level package.
``--against DIR`` runs the same cases from another checkout too (e.g. ``git worktree add
../old HEAD~3``), interleaved with this one's, so a busy machine slows both alike.

    python benchmarks/startup.py [--repeat 5] [--against ../old]
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable


def wall(cmd: list[str], env: dict) -> tuple[float, float]:
    """Wall and CPU (user + system) seconds of one run of ``cmd``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    # run from the checkout itself: ``python -m`` puts the working directory before PYTHONPATH
    subprocess.run(cmd, env=env, cwd=env["PYTHONPATH"], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    elapsed = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return elapsed, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def imports(cmd: list[str], env: dict) -> dict[str, float]:
    """Seconds of import (self time) by top-level package, from ``-X importtime``."""
    err = subprocess.run([PY, "-X", "importtime", *cmd[1:]], env=env, check=True, capture_output=True,
                         text=True).stderr
    by = defaultdict(float)
    for m in re.finditer(r"import time:\s+(\d+) \|\s+\d+ \|\s*(\S+)", err):
        by[m.group(2).split(".")[0]] += int(m.group(1)) / 1e6
    return dict(sorted(by.items(), key=lambda kv: -kv[1]))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--against", type=Path, help="another checkout to time side by side with this one")
    a = ap.parse_args()
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    tmp = Path(tempfile.mkdtemp(prefix="partlab-startup-"))
    subprocess.run([PY, "-m", "partlab", "synth", str(tmp / "s"), "--frames", "5", "--seed", "1"], env=env,
                   check=True, stdout=subprocess.DEVNULL)
    clip = str(tmp / "s" / "clip.mp4")
    cases = {
        "python -c pass": [PY, "-c", "pass"],
        "partlab --help": [PY, "-m", "partlab", "--help"],
        "partlab track (5 frames)": [PY, "-m", "partlab", "track", clip, "-o", str(tmp / "t.csv"), "--no-progress"],
        "partlab track --init (5 frames)": [PY, "-m", "partlab", "track", clip, "--init", str(tmp / "s" / "init.csv"),
                                            "-o", str(tmp / "t.csv"), "--no-progress"],
    }
    envs = {"": env}
    if a.against is not None:
        envs[f" [{a.against}]"] = dict(os.environ, PYTHONPATH=str(a.against.resolve()))
    runs = {(name + tag): (cmd, e) for name, cmd in cases.items() for tag, e in envs.items()}
    for cmd, e in runs.values():  # warm the file cache and numba's on-disk cache
        wall(cmd, e)
    times = {name: [] for name in runs}
    for _ in range(a.repeat):  # interleaved, so that a busy moment hits every case alike
        for name, (cmd, e) in runs.items():
            times[name].append(wall(cmd, e))
    base = statistics.median(t for t, _ in times["python -c pass"])
    for name, xs in times.items():
        m, cpu = statistics.median(t for t, _ in xs), statistics.median(c for _, c in xs)
        print(f"{name:34s} median {m:.2f} s (min {min(t for t, _ in xs):.2f}, max {max(t for t, _ in xs):.2f}), "
              f"{m / base:.1f}x python -c pass; CPU {cpu:.2f} s")
    by = imports(cases["partlab track --init (5 frames)"], env)
    total = sum(by.values())
    print(f"import time of partlab track --init: {total:.2f} s; " +
          ", ".join(f"{k} {v:.2f}" for k, v in list(by.items())[:8]))
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=ROOT).stdout.strip()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, commit {commit}")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
