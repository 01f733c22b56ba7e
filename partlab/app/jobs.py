"""Background jobs (tracking, training, comparison runs) with progress read back on rerun.

Two engines behind one job list. With ``PARTLAB_JOBS=engine`` (what ``partlab app`` sets unless
told otherwise) tracking and training are Dask tasks on workers outside the server process
(:mod:`partlab.engine.jobs`): their state is a row of the store's ``jobs`` table, so they keep
running when the server restarts, the restarted server shows them with their progress, and
:func:`cancel` stops them. Otherwise (the library's default, and always for comparison runs,
whose result is a table the page reads back) a job runs in a worker thread of the server
process; pages poll :func:`jobs` on each rerun (a fragment refreshes itself every second while
something runs). Thread workers default to one (``PARTLAB_WORKERS``): tracking is CPU-bound and
the machine is shared.

Thread jobs live in the server process, so stopping the app stops them (what they had already
stored stays). So that this is not silent, every thread job's state is also appended to a journal,
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
    status: str = "queued"  # queued, running, done, failed, cancelled
    done: int = 0
    total: int = 0
    error: str = ""
    result: Any = None
    created: float = field(default_factory=time.time)
    finished: float | None = None
    engine: bool = False  # a Dask job (a row of the store's jobs table), not a thread of this process
    cancel_requested: bool = False

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
             "done": job.done, "total": job.total, "error": job.error, "time": time.time(),
             "meta": job.meta}
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
        if job.cancel_requested:
            raise _Cancelled(job.id)
        job.done, job.total = int(done), int(total)
        if time.time() - journalled[0] >= JOURNAL_EVERY:
            journalled[0] = time.time()
            _journal(job)

    def run() -> None:
        job.status = "running"
        _journal(job)
        try:
            if job.cancel_requested:
                raise _Cancelled(job.id)
            job.result = fn(progress)
            job.status = "done"
        except _Cancelled:
            job.status = "cancelled"
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


class _Cancelled(Exception):
    pass


def engine_enabled() -> bool:
    """Whether tracking and training go to Dask workers (``PARTLAB_JOBS=engine``)."""
    return os.environ.get("PARTLAB_JOBS", "threads") == "engine"


def submit_engine(kind: str, label: str, task: Callable[..., Any], meta: dict, **kwargs) -> Job:
    """Run ``task(progress, **kwargs)`` (a function of :mod:`partlab.engine.tasks`) on a Dask worker."""
    from partlab.engine import jobs as engine

    job_id = engine.submit(kind, label, task, store_url=kwargs.get("url"), meta=meta, **kwargs)
    return get(job_id) or Job(id=job_id, kind=kind, label=label, meta=meta, engine=True)


def _engine_jobs() -> list[Job]:
    if not engine_enabled():
        return []
    from partlab.engine import jobs as engine

    out = []
    for r in engine.list_jobs():
        out.append(Job(id=r["id"], kind=r["kind"], label=r["label"], meta=dict(r["meta"] or {}), status=r["status"],
                       done=r["done"], total=r["total"], error=r["error"], result=r["result"],
                       created=r["created"].timestamp(),
                       finished=r["finished"].timestamp() if r["finished"] else None, engine=True,
                       cancel_requested=bool(r["cancel"])))
    return out


def get(job_id: str) -> Job | None:
    if job_id in _JOBS:
        return _JOBS[job_id]
    return next((j for j in _engine_jobs() if j.id == job_id), None)


def jobs(kind: str | None = None, **meta) -> list[Job]:
    """Jobs of both engines, newest first, filtered by kind and by equal meta values (e.g. ``clip_id=3``)."""
    with _LOCK:
        out = list(_JOBS.values())
    out += _engine_jobs()
    out = [j for j in out if (kind is None or j.kind == kind) and all(j.meta.get(k) == v for k, v in meta.items())]
    return sorted(out, key=lambda j: j.created, reverse=True)


def cancel(job_id: str) -> None:
    """Stop a job: a Dask job at its next progress report (or before it starts), a thread job at
    its next progress report."""
    job = _JOBS.get(job_id)
    if job is not None:
        job.cancel_requested = True
        return
    from partlab.engine import jobs as engine

    engine.cancel(job_id)


def active(kind: str | None = None, **meta) -> list[Job]:
    return [j for j in jobs(kind, **meta) if j.active]


def ended_since(watched: set[str], running: list[Job], ignore: set[str] = frozenset()) -> bool:
    """Whether a job in ``watched`` (ids seen running before) and not in ``ignore`` is no longer
    among ``running``; ``watched`` becomes the ids of ``running`` (the sidebar's job list reruns
    the page once then; ``ignore``: jobs a page's own panel reruns it for)."""
    now = {j.id for j in running}
    ended = bool(watched - now - set(ignore))
    watched.clear()
    watched.update(now)
    return ended


def wait(job_id: str, timeout: float = 60.0) -> Job:
    """Block until a job ends (tests and scripts)."""
    end = time.time() + timeout
    if job_id not in _JOBS:
        from partlab.engine import jobs as engine

        engine.wait(job_id, timeout)
        return get(job_id)
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
    if engine_enabled():
        from partlab.engine import jobs as engine

        gone += engine.clear_finished()
    return len(done) + gone
