"""``partlab app``: start the Streamlit labelling app, headless (no browser opened).

Sign-in (``--auth``): ``none`` is partlab as a single-user tool and is allowed on a loopback address
only; ``password`` asks every browser session to sign in as a user made with ``partlab users add``
and shows each user only the projects they hold a role in. The default is ``none`` on loopback and
``password`` anywhere else; ``--host 0.0.0.0 --auth none`` is refused (exit 2).
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

from partlab.cli import CommandError

PAGE = Path(__file__).resolve().parent.parent / "app" / "streamlit_app.py"


LOOPBACK_NAMES = ("localhost", "127.0.0.1", "::1")


def add_arguments(p) -> None:
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    p.add_argument("--port", type=int, default=8501, help="port to listen on (default 8501)")
    p.add_argument("--allowed-hosts", metavar="NAMES", default=os.environ.get("PARTLAB_ALLOWED_HOSTS", ""),
                   help="comma-separated host names the app may be reached by besides localhost and --host "
                        "(PARTLAB_ALLOWED_HOSTS); requests naming any other host are refused (DNS rebinding)")
    p.add_argument("--auth", choices=("none", "password"), default=os.environ.get("PARTLAB_AUTH") or None,
                   help="'password': every browser signs in as a user of `partlab users` and sees only their "
                        "projects; 'none': no sign-in, allowed on loopback only (default: none on loopback, "
                        "password on any other address; PARTLAB_AUTH)")
    p.add_argument("--jobs", choices=("engine", "threads"), default=os.environ.get("PARTLAB_JOBS", "engine"),
                   help="where tracking and training run: 'engine' (default) on Dask workers outside the server, "
                        "so they survive a restart and can be cancelled; 'threads' inside the server process")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT", default=os.environ.get("PARTLAB_SCHEDULER"),
                   help="the Dask scheduler for jobs (PARTLAB_SCHEDULER); default: partlab's own local cluster, "
                        "started on the first job and left running (its address in DATA/engine.json)")


def allowed_hosts(host: str, extra: str = "") -> list[str]:
    """Host names a browser may use to reach the app: loopback names, the bind address (unless it is
    a wildcard) and ``extra``. Anything else in a request's ``Host`` is refused by the server."""
    names = list(LOOPBACK_NAMES)
    if host not in ("0.0.0.0", "::", ""):
        names.append(host)
    names += [n.strip() for n in extra.split(",") if n.strip()]
    return list(dict.fromkeys(names))


def streamlit_command(host: str, port: int, extra_hosts: str = "") -> list[str]:
    """The command line that serves the app; also used by the browser tests.

    The upload limit comes from ``PARTLAB_MAX_UPLOAD_MB`` (default 1024), the same
    number :mod:`partlab.app.uploads` checks again on the server side. The Host allow-list
    (:func:`allowed_hosts`) and CORS keep other web pages from driving the app.
    """
    from partlab.app.uploads import UploadRefused, max_upload_mb  # lazy: `partlab --help` stays light

    try:
        max_mb = max_upload_mb()
    except UploadRefused as exc:
        raise CommandError(str(exc)) from None
    return [
        sys.executable, "-m", "streamlit", "run", str(PAGE),
        "--server.headless", "true",
        "--server.address", host,
        "--server.port", str(port),
        "--browser.gatherUsageStats", "false",
        "--server.fileWatcherType", "none",
        "--server.maxUploadSize", str(max_mb),
        "--server.runOnSave", "false",
        "--client.toolbarMode", "minimal",  # no "Deploy" button: this is a local labelling tool
        "--server.enableCORS", "true",
        "--server.enableXsrfProtection", "true",
    ] + [arg for name in allowed_hosts(host, extra_hosts) for arg in ("--server.allowedHosts", name)]


def free_port(host: str = "127.0.0.1") -> int:
    """A TCP port nothing listens on now (the OS picks it)."""
    import socket

    with socket.socket() as s:
        s.bind((host, 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def serving(env: dict, log, cwd: str | os.PathLike | None = None, port: int | None = None,
            wait_s: float = 60.0) -> Iterator[tuple[str, subprocess.Popen]]:
    """Serve the app on 127.0.0.1 in a child process (``env`` its environment, output to the
    open file ``log``), wait until its health check answers, yield ``(url, process)``, and stop it
    on exit. For the browser tests and the page benchmark: raises RuntimeError when the app exits
    or does not answer within ``wait_s``."""
    import time
    import urllib.request

    port = port or free_port()
    proc = subprocess.Popen(streamlit_command("127.0.0.1", port), cwd=cwd, env=env, stdout=log,
                            stderr=subprocess.STDOUT)
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + wait_s
        while True:
            try:
                if urllib.request.urlopen(url + "/_stcore/health", timeout=1).status == 200:
                    break
            except OSError:
                time.sleep(0.1)
            if proc.poll() is not None:
                raise RuntimeError(f"the app exited with code {proc.returncode}")
            if time.monotonic() > deadline:
                raise RuntimeError(f"the app did not answer within {wait_s:.0f} s")
        yield url, proc
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()


def is_loopback(host: str) -> bool:
    """Whether ``host`` is reachable from this machine only (a loopback name or address)."""
    import ipaddress

    if host in LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def auth_mode(host: str, asked: str | None) -> str:
    """The sign-in mode to serve with; no sign-in on an address other machines reach is refused."""
    mode = asked or ("none" if is_loopback(host) else "password")
    if mode == "none" and not is_loopback(host):
        raise CommandError(f"refusing to serve {host} without sign-in (--auth none is for loopback only); "
                           "add users with `partlab users add NAME --project P --role owner` and use --auth password")
    return mode


def check_data_dir() -> None:
    """Refuse to start when the data directory or the database cannot be written (a sentence, exit 2)."""
    import tempfile

    from partlab.cli import describe_os_error
    from partlab.labelling.config import data_dir

    try:
        where = data_dir()
        with tempfile.TemporaryFile(dir=where):
            pass
    except OSError as exc:
        raise CommandError(f"the data directory {os.environ.get('PARTLAB_DATA', 'partlab-data')} cannot be written "
                           f"({describe_os_error(exc)}); set PARTLAB_DATA to a writable directory") from None


def check_users() -> None:
    from partlab.labelling.access import has_users
    from partlab.labelling.store import Store, StoreError

    try:
        found = has_users(Store())
    except StoreError as exc:
        raise CommandError(str(exc)) from None
    if not found:
        raise CommandError("sign-in is on but there are no users yet: add one with "
                           "`partlab users add NAME --project P --create-project --role owner`")


def run(args) -> int:
    mode = auth_mode(args.host, args.auth)
    check_data_dir()  # clips, uploads and exports live there whatever the database
    if mode == "password":
        check_users()
    print(f"partlab app: serving on http://{args.host}:{args.port} "
          f"({'sign-in on' if mode == 'password' else 'no sign-in'}; Ctrl+C to stop)", flush=True)
    env = os.environ.copy()
    env["PARTLAB_AUTH"] = mode
    env["PARTLAB_JOBS"] = args.jobs
    if args.scheduler:
        env["PARTLAB_SCHEDULER"] = args.scheduler
    try:
        return serve(streamlit_command(args.host, args.port, args.allowed_hosts), env)
    finally:
        said = job_service_note() if args.jobs == "engine" and not args.scheduler else None
        if said:
            print(said, flush=True)


def serve(command: list[str], env: dict[str, str]) -> int:
    """Run the Streamlit server ``command`` until it exits; a SIGTERM or SIGHUP to ``partlab app``
    (a service manager stopping it, a closed terminal) is passed on to the server, which then stops
    too instead of being left running without its parent. Returns the server's exit code."""
    proc = subprocess.Popen(command, env=env)

    def stop(signum, _frame):
        proc.send_signal(signum)

    previous = {s: signal.signal(s, stop) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        return proc.wait()
    except KeyboardInterrupt:  # Ctrl+C reaches the whole process group: let the server finish stopping
        return proc.wait()
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


def job_service_note() -> str | None:
    """What the user should know when the server stops: partlab's local job service (started on
    the first job, :mod:`partlab.engine.service`) keeps running, with any queued or running job;
    None when there is none."""
    from partlab.engine import jobs

    known = jobs.running_service()
    if known is None:
        return None
    try:
        pid = int(known["pid"])
    except (KeyError, TypeError, ValueError):
        return None
    return (f"partlab app: the job service (pid {pid}) keeps running, with any job still queued or running; "
            f"the next `partlab app` uses it again. To stop it: kill {pid}")
