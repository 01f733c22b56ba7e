"""How long ``partlab track`` takes on a 5-frame clip, against ``python -c pass``, and where the
import time goes (``python -X importtime``).

Renders a 5-frame synthetic clip (``partlab synth --frames 5``) in a scratch folder, then runs, in
turn and ``--repeat`` times each: ``python -c pass``, ``partlab --help``, ``partlab track CLIP``
(people found automatically) and ``partlab track CLIP --init init.csv``. Prints the median and
spread of each wall time, their ratio to ``python -c pass`` (the machine is shared, so the ratio
says more than the seconds), and the import time of ``partlab track`` by top-level package.

    python benchmarks/startup.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable


def wall(cmd: list[str], env: dict) -> float:
    t = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t


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
    for cmd in cases.values():  # warm the file cache and numba's on-disk cache
        wall(cmd, env)
    times = {name: [] for name in cases}
    for _ in range(a.repeat):  # interleaved, so that a busy moment hits every case alike
        for name, cmd in cases.items():
            times[name].append(wall(cmd, env))
    base = statistics.median(times["python -c pass"])
    for name, xs in times.items():
        m = statistics.median(xs)
        print(f"{name:34s} median {m:.2f} s (min {min(xs):.2f}, max {max(xs):.2f}), {m / base:.1f}x python -c pass")
    by = imports(cases["partlab track --init (5 frames)"], env)
    total = sum(by.values())
    print(f"import time of partlab track --init: {total:.2f} s; " +
          ", ".join(f"{k} {v:.2f}" for k, v in list(by.items())[:8]))
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=ROOT).stdout.strip()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, commit {commit}")


if __name__ == "__main__":
    main()
