"""The Dask cluster partlab's work runs on: a :class:`distributed.LocalCluster` on this machine by
default, or an existing scheduler by address (``tcp://HOST:8786``).

Tracking is CPU-bound numpy/numba in Python, so a local cluster runs one single-threaded worker
process per core asked for (threads would share one interpreter lock). A worker is one core all
through: OpenCV's own thread pool (resize, colour conversion, HOG) would otherwise take every core
of the machine in each worker, and two workers would fight over them (measured: 1.20x for 2
workers instead of about 2x). Each worker process compiles partlab's kernels on its first task;
that start-up is part of the per-task overhead measured by ``benchmarks/batch_scaling.py``.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
from collections.abc import Iterator

from partlab.errors import UserError

#: The environment of a local worker process: one thread for every library that keeps a pool.
ONE_CORE_ENV = {"OPENCV_FOR_THREADS_NUM": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
                "MKL_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1"}


def one_core() -> None:
    """Keep this process's OpenCV on one thread (a worker of a cluster started elsewhere, whose
    environment partlab did not set)."""
    import cv2

    cv2.setNumThreads(1)


def no_interrupt() -> None:
    """Leave Ctrl-C to the parent: a local worker shares the terminal, and the client shuts the
    cluster down itself (else each worker prints its own KeyboardInterrupt traceback)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def _set_up_workers(c, local: bool) -> None:
    """On every worker, now and on workers that join later: a local cluster's worker leaves Ctrl-C
    to us (:func:`no_interrupt`; its threads are set by :data:`ONE_CORE_ENV` before it starts),
    a worker started elsewhere is kept to one OpenCV thread (:func:`one_core`)."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class PartlabWorker(WorkerPlugin):
        name = "partlab-worker"

        def setup(self, worker) -> None:
            if local:
                no_interrupt()
            else:
                one_core()

    c.register_plugin(PartlabWorker())


_LOGGERS = ("distributed", "distributed.nanny", "distributed.scheduler", "distributed.worker",
            "distributed.core", "distributed.http.proxy", "bokeh", "tornado", "tornado.application")


def _quiet_logs(level: int = logging.ERROR) -> None:
    for name in _LOGGERS:
        logging.getLogger(name).setLevel(level)


@contextlib.contextmanager
def client(scheduler: str | None = None, workers: int | None = None,
           dashboard: str | None = ":0") -> Iterator[distributed.Client]:  # noqa: F821
    """A connected :class:`distributed.Client`, closed (and a local cluster shut down) on exit.

    ``scheduler``: address of a running scheduler; None starts a local cluster of ``workers``
    single-threaded worker processes (default: the machine's cores). ``dashboard``: the local
    cluster's dashboard address (``":0"`` any free port, None no dashboard).
    """
    from distributed import Client, LocalCluster

    _quiet_logs()
    if scheduler:
        try:
            c = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise UserError(f"--scheduler {scheduler}: cannot reach the Dask scheduler ({exc})") from None
        try:
            _set_up_workers(c, local=False)
            yield c
        finally:
            c.close()
        return
    n = workers or os.cpu_count() or 1
    if n < 1:
        raise UserError(f"--workers must be at least 1, got {n}")
    with _spawn_safe_main():  # worker processes are spawned once, here
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=dashboard,
                               silence_logs=logging.ERROR, env=ONE_CORE_ENV)
    try:
        with Client(cluster) as c:
            _set_up_workers(c, local=True)
            yield c
    except KeyboardInterrupt:  # Ctrl-C: the cluster is torn down mid-task; its shutdown errors are noise
        _quiet_logs(logging.CRITICAL + 1)
        raise
    finally:
        cluster.close()


@contextlib.contextmanager
def _spawn_safe_main() -> Iterator[None]:
    """Spawned worker processes re-run the parent's ``__main__`` script unless it is a module run by
    name. When partlab is embedded (a Streamlit page script, a test runner that ran one) that script
    is not meant to run again: hide its file while the workers start."""
    main = sys.modules.get("__main__")
    spec = getattr(main, "__spec__", None)
    path = getattr(main, "__file__", None)
    if main is None or spec is not None or path is None:
        yield
        return
    del main.__file__
    try:
        yield
    finally:
        main.__file__ = path


def dashboard_link(c) -> str | None:
    """The dashboard's URL, or None when the scheduler has none (bokeh missing)."""
    try:
        link = c.dashboard_link
    except (AttributeError, KeyError):
        return None
    return link or None
