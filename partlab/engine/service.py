"""partlab's own local Dask cluster for the app's jobs, as a process of its own.

Started detached by :func:`partlab.engine.jobs.scheduler_address` (``python -m
partlab.engine.service --workers N --address-file DATA/engine.json``) so that restarting the web
server leaves it, and the jobs on it, running. It writes the scheduler's address and its pid to
the address file and runs until it is killed (``kill PID``; the file names it).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import signal
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m partlab.engine.service")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--address-file", required=True)
    ap.add_argument("--dashboard", default=":0", help="dashboard address (':0' any free port)")
    args = ap.parse_args(argv)
    from distributed import LocalCluster

    from partlab.engine.cluster import ONE_CORE_ENV

    cluster = LocalCluster(n_workers=max(1, args.workers), threads_per_worker=1, processes=True,
                           dashboard_address=args.dashboard, silence_logs=logging.ERROR, env=ONE_CORE_ENV)
    path = Path(args.address_file)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps({"address": cluster.scheduler_address, "pid": os.getpid(),
                               "dashboard": cluster.dashboard_link, "workers": args.workers}), encoding="utf-8")
    os.replace(tmp, path)
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    try:
        while not stop:
            time.sleep(0.5)
    finally:
        cluster.close()
        path.unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
