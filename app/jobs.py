"""Background jobs (tracking, training, comparison runs) with progress read back on rerun.

A job runs in a worker thread of the Streamlit server process, so it keeps running
while the user browses other pages or closes the tab; pages poll :func:`jobs` on each
rerun (a fragment refreshes itself every second while something runs). The registry
is process-wide: every browser session sees every job. Workers default to one
(``PARTLAB_WORKERS``): tracking is CPU-bound and the machine is shared.
"""

from __future__ import annotations

import os
import threading
import time
import traceback
import uuid
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Callable


@dataclass
class Job:
    id: str
    kind: str
    label: str
    meta: dict = field(default_factory=dict)
    status: str = "queued"  # queued, running, done, failed
    done: int = 0
    total: int = 0
    error: str = ""
    result: Any = None
    created: float = field(default_factory=time.time)
    finished: float | None = None

    @property
    def fraction(self) -> float:
        if self.status == "done":
            return 1.0
        return min(self.done / self.total, 1.0) if self.total else 0.0

    @property
    def active(self) -> bool:
        return self.status in ("queued", "running")


_JOBS: dict[str, Job] = {}
_LOCK = threading.Lock()
_EXECUTOR: ThreadPoolExecutor | None = None


def _executor() -> ThreadPoolExecutor:
    global _EXECUTOR
    with _LOCK:
        if _EXECUTOR is None:
            workers = max(1, int(os.environ.get("PARTLAB_WORKERS", "1")))
            _EXECUTOR = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="partlab-job")
        return _EXECUTOR


def submit(kind: str, label: str, fn: Callable[[Callable[[int, int], None]], Any], **meta) -> Job:
    """Run ``fn(progress)`` in the background; ``progress(done, total)`` updates the job."""
    job = Job(id=uuid.uuid4().hex[:12], kind=kind, label=label, meta=meta)

    def progress(done: int, total: int) -> None:
        job.done, job.total = int(done), int(total)

    def run() -> None:
        job.status = "running"
        try:
            job.result = fn(progress)
            job.status = "done"
        except Exception as exc:  # shown to the user on the page, with the trace in the log
            job.error = f"{type(exc).__name__}: {exc}"
            job.status = "failed"
            traceback.print_exc()
        finally:
            job.finished = time.time()

    with _LOCK:
        _JOBS[job.id] = job
    _executor().submit(run)
    return job


def get(job_id: str) -> Job | None:
    return _JOBS.get(job_id)


def jobs(kind: str | None = None, **meta) -> list[Job]:
    """Jobs, newest first, filtered by kind and by equal meta values (e.g. ``clip_id=3``)."""
    with _LOCK:
        out = [j for j in _JOBS.values()
               if (kind is None or j.kind == kind) and all(j.meta.get(k) == v for k, v in meta.items())]
    return sorted(out, key=lambda j: j.created, reverse=True)


def active(kind: str | None = None, **meta) -> list[Job]:
    return [j for j in jobs(kind, **meta) if j.active]


def wait(job_id: str, timeout: float = 60.0) -> Job:
    """Block until a job ends (tests and scripts)."""
    end = time.time() + timeout
    job = _JOBS[job_id]
    while job.active:
        if time.time() > end:
            raise TimeoutError(f"job {job.label!r} still {job.status} after {timeout} s")
        time.sleep(0.05)
    return job


def clear_finished() -> int:
    """Forget the jobs that have ended (the job list's "clear" button); returns how many."""
    with _LOCK:
        done = [k for k, j in _JOBS.items() if not j.active]
        for k in done:
            del _JOBS[k]
    return len(done)
