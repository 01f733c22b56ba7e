"""Background jobs (tracking, training, comparison runs) with progress read back on rerun.

A job runs in a worker thread of the Streamlit server process, so it keeps running
while the user browses other pages or closes the tab; pages poll :func:`jobs` on each
rerun (a fragment refreshes itself every second while something runs). The registry
is process-wide: every browser session sees every job. Workers default to one
(``PARTLAB_WORKERS``): tracking is CPU-bound and the machine is shared.

Jobs live in the server process, so stopping the app stops them (what they had already
stored stays). So that this is not silent, every job's state is also appended to a journal,
``jobs.jsonl`` in the data directory; :func:`interrupted` lists the jobs a previous server
process left queued or running, which the app shows until they are cleared.
"""

from __future__ import annotations

import json
import os
import threading
import time
import traceback
import uuid
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


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
_JOURNAL_LOCK = threading.Lock()
#: progress is journalled at most this often (seconds); state changes always
JOURNAL_EVERY = 5.0


def journal_path() -> Path:
    from partlab.labelling.config import data_dir

    return data_dir() / "jobs.jsonl"


def _journal(job: Job) -> None:
    """Append the job's state to the journal; never lets a journal problem fail the job."""
    entry = {"id": job.id, "pid": os.getpid(), "kind": job.kind, "label": job.label, "status": job.status,
             "done": job.done, "total": job.total, "error": job.error, "time": time.time()}
    try:
        with _JOURNAL_LOCK, open(journal_path(), "a", encoding="utf-8") as f:
            f.write(json.dumps(entry) + "\n")
    except OSError:
        pass


def _read_journal() -> dict[str, dict]:
    """The last entry of every job in the journal (unreadable lines are skipped)."""
    last: dict[str, dict] = {}
    try:
        with _JOURNAL_LOCK, open(journal_path(), encoding="utf-8") as f:
            for line in f:
                try:
                    entry = json.loads(line)
                    last[str(entry["id"])] = entry
                except (ValueError, KeyError, TypeError):
                    continue
    except OSError:
        return {}
    return last


def interrupted() -> list[dict]:
    """Jobs an earlier server process left queued or running (it stopped before they ended),
    newest first: ``id, kind, label, status, done, total, time``."""
    out = [e for e in _read_journal().values()
           if e.get("status") in ("queued", "running") and e.get("pid") != os.getpid() and e["id"] not in _JOBS]
    return sorted(out, key=lambda e: e.get("time", 0), reverse=True)


def _rewrite_journal(keep) -> None:
    """Rewrite the journal with the last entries of the jobs ``keep(entry)`` accepts."""
    entries = [e for e in _read_journal().values() if keep(e)]
    try:
        with _JOURNAL_LOCK:
            tmp = journal_path().with_suffix(".tmp")
            tmp.write_text("".join(json.dumps(e) + "\n" for e in entries), encoding="utf-8")
            os.replace(tmp, journal_path())
    except OSError:
        pass


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

    journalled = [0.0]

    def progress(done: int, total: int) -> None:
        job.done, job.total = int(done), int(total)
        if time.time() - journalled[0] >= JOURNAL_EVERY:
            journalled[0] = time.time()
            _journal(job)

    def run() -> None:
        job.status = "running"
        _journal(job)
        try:
            job.result = fn(progress)
            job.status = "done"
        except Exception as exc:  # shown to the user on the page, with the trace in the log
            job.error = f"{type(exc).__name__}: {exc}"
            job.status = "failed"
            traceback.print_exc()
        finally:
            job.finished = time.time()
            _journal(job)

    with _LOCK:
        _JOBS[job.id] = job
    _journal(job)
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
    """Forget the jobs that have ended, and those an earlier server process left unfinished
    (the job list's "clear" button); returns how many."""
    with _LOCK:
        done = [k for k, j in _JOBS.items() if not j.active]
        for k in done:
            del _JOBS[k]
        live = {k for k, j in _JOBS.items() if j.active}
    gone = len(interrupted())
    _rewrite_journal(lambda e: e["id"] in live)
    return len(done) + gone
