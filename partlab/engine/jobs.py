"""Jobs that outlive the web server: the app's track and train work, run by Dask workers.

A job is a row of the store's ``jobs`` table (schema revision 3) and a Dask task whose key is the
job's id. :func:`submit` writes the row (queued) and hands the task to the scheduler with
``fire_and_forget``, so the task runs to its end even when the server that submitted it stops.
The task (:func:`run_job`, on a worker) marks the row running, calls the work function with a
``progress(done, total)`` callback that writes the row at most every :data:`PROGRESS_EVERY`
seconds and raises :class:`Cancelled` once the row's ``cancel`` flag is set, and records the
result, the error or the cancellation. Any server process reads the rows (:func:`list_jobs`),
so a restarted server shows the job with its progress, and its "Cancel" button sets the flag
(:func:`cancel`; a job still queued is also withdrawn from the scheduler).

The scheduler is ``PARTLAB_SCHEDULER`` (``tcp://HOST:8786``) when set, else partlab's own local
cluster: a detached process (:mod:`partlab.engine.service`) started on first use, which a server
restart does not stop; its address is kept in ``engine.json`` in the data directory.
"""

from __future__ import annotations

import importlib
import json
import os
import socket
import subprocess
import sys
import time
import traceback
import uuid
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from sqlalchemy import delete, select

#: progress is written to the database at most this often (seconds); state changes always
PROGRESS_EVERY = 0.25
STATES = ("queued", "running", "done", "failed", "cancelled")
ACTIVE = ("queued", "running")


class Cancelled(Exception):
    """Raised inside a job's work by its progress callback once the job was cancelled."""


def _now() -> datetime:
    return datetime.now(UTC)


def _store(url: str | None):
    from partlab.labelling.store import Store

    return Store(url)


# ------------------------------------------------------------------------------- the scheduler
def service_file() -> Path:
    from partlab.labelling.config import data_dir

    return data_dir() / "engine.json"


def _reachable(address: str, timeout: float = 1.0) -> bool:
    host_port = address.split("://", 1)[-1]
    host, _, port = host_port.rpartition(":")
    try:
        with socket.create_connection((host or "127.0.0.1", int(port)), timeout=timeout):
            return True
    except (OSError, ValueError):
        return False


def running_service() -> dict | None:
    """The local service's address file (``address``, ``pid``, ...) when its scheduler answers;
    None when none was started or it has stopped."""
    try:
        known = json.loads(service_file().read_text(encoding="utf-8"))
        return known if _reachable(known["address"]) else None
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def scheduler_address(workers: int | None = None, wait: float = 120.0) -> str:
    """The scheduler jobs go to: ``PARTLAB_SCHEDULER``, or the local service (started if needed)."""
    given = os.environ.get("PARTLAB_SCHEDULER")
    if given:
        return given
    known = running_service()
    if known is not None:
        return known["address"]
    path = service_file()
    workers = workers or int(os.environ.get("PARTLAB_WORKERS", "0") or 0) or (os.cpu_count() or 1)
    path.unlink(missing_ok=True)
    log = path.with_suffix(".log")
    with open(log, "ab") as out:
        subprocess.Popen([sys.executable, "-m", "partlab.engine.service", "--workers", str(workers),
                          "--address-file", str(path)], stdout=out, stderr=out, stdin=subprocess.DEVNULL,
                         start_new_session=True, env=dict(os.environ))
    end = time.time() + wait
    while time.time() < end:
        try:
            return json.loads(path.read_text(encoding="utf-8"))["address"]
        except (OSError, ValueError, KeyError):
            time.sleep(0.2)
    raise RuntimeError(f"partlab's local Dask cluster did not start within {wait:.0f} s (see {log})")


_CLIENTS: dict[str, Any] = {}


def client(address: str | None = None):
    """A Dask client connected to the jobs' scheduler (one per address per process)."""
    from distributed import Client

    address = address or scheduler_address()
    c = _CLIENTS.get(address)
    if c is None or c.status not in ("running", "connecting"):
        c = Client(address, timeout="20s", set_as_default=False)
        _CLIENTS[address] = c
    return c


# ------------------------------------------------------------------------------------ the rows
def submit(kind: str, label: str, func: Callable[..., Any], *, store_url: str | None = None,
           address: str | None = None, meta: dict | None = None, **kwargs) -> str:
    """Run ``func(progress, **kwargs)`` on a worker as a job; returns the job id.

    ``func`` must be importable by the workers (a module-level function) and ``kwargs`` plain data;
    ``meta`` (e.g. ``{"clip_id": 3}``) is stored for the job list's filters; the job's row goes to
    the store at ``store_url`` (default: ``PARTLAB_DATABASE_URL``)."""
    from distributed import fire_and_forget

    from partlab.labelling.store import JobRow

    store = _store(store_url)
    meta = dict(meta or {})
    job_id = f"{kind}-{uuid.uuid4().hex[:12]}"
    with store._session() as s:
        s.add(JobRow(id=job_id, kind=kind, label=label, meta=meta, status="queued", error="", worker="",
                     created=_now(), updated=_now()))
        s.commit()
    target = f"{func.__module__}:{func.__qualname__}"
    try:
        c = client(address)
        future = c.submit(run_job, job_id, store.url, target, kwargs, key=job_id, pure=False)
        fire_and_forget(future)
        _until_kept(c, future)
    except Exception as exc:
        _finish(store, job_id, "failed", error=f"could not reach the Dask scheduler: {exc}")
    return job_id


def _until_kept(c, future, wait: float = 10.0) -> None:
    """Return once the scheduler keeps the task for the "fire-and-forget" client, so that a server
    stopping right after the submit (its client gone) cannot lose it.

    The scheduler handles a graph update asynchronously: a fire-and-forget request that arrives
    before the task is known is dropped with a warning ("desires key ... but key is unknown"), and
    the task would then go with the submitting client (measured: a job left queued for ever). So
    the request is repeated until the scheduler holds it."""
    from distributed import fire_and_forget

    end = time.time() + wait
    while time.time() < end:
        if c.run_on_scheduler(_kept, key=future.key):
            return
        time.sleep(0.05)
        fire_and_forget(future)
    raise RuntimeError(f"the scheduler did not take job {future.key} within {wait:.0f} s")


def _kept(key: str, dask_scheduler=None) -> bool:
    """Whether the scheduler holds ``key`` for the fire-and-forget client (runs on the scheduler)."""
    task = dask_scheduler.tasks.get(key)
    return task is not None and any(cs.client_key == "fire-and-forget" for cs in task.who_wants or ())


def _update(store, job_id: str, **values) -> bool:
    """Write ``values`` to the job's row; returns whether the job was asked to stop."""
    from partlab.labelling.store import JobRow

    with store._session() as s:
        row = s.get(JobRow, job_id)
        if row is None:  # cleared from the list meanwhile: stop
            return True
        for k, v in values.items():
            setattr(row, k, v)
        row.updated = _now()
        s.commit()
        return bool(row.cancel)


def _finish(store, job_id: str, status: str, *, error: str = "", result: Any = None) -> None:
    _update(store, job_id, status=status, error=error, result=result, finished=_now())


def run_job(job_id: str, url: str, target: str, kwargs: dict) -> str:
    """The Dask task of a job (runs on a worker): the work with progress, cancellation, outcome."""
    store = _store(url)
    if _update(store, job_id, status="running", worker=f"{socket.gethostname()}:{os.getpid()}"):
        _finish(store, job_id, "cancelled")
        return "cancelled"
    last = [0.0]

    def progress(done: int, total: int) -> None:
        now = time.monotonic()
        if now - last[0] < PROGRESS_EVERY and done < total:
            return
        last[0] = now
        if _update(store, job_id, done=int(done), total=int(total)):
            raise Cancelled(job_id)

    module, _, name = target.partition(":")
    try:
        func = getattr(importlib.import_module(module), name)
        result = func(progress, **kwargs)
    except Cancelled:
        _finish(store, job_id, "cancelled")
        return "cancelled"
    except Exception as exc:  # shown in the job list; the trace goes to the worker's log
        traceback.print_exc()
        _finish(store, job_id, "failed", error=f"{type(exc).__name__}: {exc}")
        return "failed"
    _finish(store, job_id, "done", result=json.loads(json.dumps(result, default=str)))
    return "done"


def list_jobs(url: str | None = None) -> list[dict]:
    """Every job row, newest first, as dicts (id, kind, label, meta, status, done, total, error,
    result, cancel, worker, created, updated, finished)."""
    from partlab.labelling.store import JobRow

    store = _store(url)
    with store._session() as s:
        rows = s.scalars(select(JobRow).order_by(JobRow.created.desc())).all()
        return [{c: getattr(r, c) for c in ("id", "kind", "label", "meta", "status", "done", "total", "error",
                                             "result", "cancel", "worker", "created", "updated", "finished")}
                for r in rows]


def cancel(job_id: str, url: str | None = None, address: str | None = None) -> None:
    """Ask a job to stop: a queued one is withdrawn and marked cancelled at once, a running one
    stops at its next progress report (within about a second of work)."""
    from partlab.labelling.store import JobRow

    store = _store(url)
    with store._session() as s:
        row = s.get(JobRow, job_id)
        if row is None or row.status not in ACTIVE:
            return
        row.cancel = True
        queued = row.status == "queued"
        if queued:
            row.status, row.finished = "cancelled", _now()
        s.commit()
    if queued:
        try:
            from distributed import Future

            Future(job_id, client(address)).cancel()
        except Exception:  # the flag alone stops it when it starts
            pass


def clear_finished(url: str | None = None) -> int:
    """Forget the jobs that have ended; returns how many."""
    from partlab.labelling.store import JobRow

    store = _store(url)
    with store._session() as s:
        n = s.execute(delete(JobRow).where(JobRow.status.not_in(ACTIVE))).rowcount
        s.commit()
    return int(n or 0)


def wait(job_id: str, timeout: float = 120.0, url: str | None = None) -> dict:
    """Block until a job ends (tests and scripts); returns its row."""
    end = time.time() + timeout
    while True:
        row = next((j for j in list_jobs(url) if j["id"] == job_id), None)
        if row is None or row["status"] not in ACTIVE:
            return row
        if time.time() > end:
            raise TimeoutError(f"job {job_id} still {row['status']} after {timeout} s")
        time.sleep(0.2)
