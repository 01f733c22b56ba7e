"""Shared fixtures: every test gets its own data directory and SQLite store; tests that take the
``backend`` fixture run on SQLite and on a throw-away PostgreSQL server.

PostgreSQL: the store must work the same on it (by URL) as on the embedded SQLite. The server is
started once per test session from the ``initdb``/``pg_ctl`` binaries in a temporary directory and
listens on loopback only; if the binaries are missing the PostgreSQL variants are skipped with the
reason, unless ``PARTLAB_REQUIRE_POSTGRES=1`` (CI), where they fail.
"""

from __future__ import annotations

import itertools
import os
import shutil
import socket
import subprocess
import sys
import tempfile

import pytest

#: ``PARTLAB_TEST_BACKEND=postgresql`` runs every test's store on a fresh PostgreSQL database (CI)
TEST_BACKEND = os.environ.get("PARTLAB_TEST_BACKEND", "sqlite")


@pytest.fixture(autouse=True)
def _isolated_data_dir(request, tmp_path, monkeypatch):
    monkeypatch.setenv("PARTLAB_DATA", str(tmp_path / "partlab-data"))
    monkeypatch.delenv("PARTLAB_DATABASE_URL", raising=False)
    if TEST_BACKEND == "postgresql":
        monkeypatch.setenv("PARTLAB_DATABASE_URL", _fresh_database(request.getfixturevalue("postgres_server")))
    elif TEST_BACKEND != "sqlite":
        pytest.fail(f"PARTLAB_TEST_BACKEND must be sqlite or postgresql, got {TEST_BACKEND!r}")
    yield
    if "partlab.labelling.store" in sys.modules:  # each test's database: its pool closes with the test
        sys.modules["partlab.labelling.store"].dispose_engines()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _as_user() -> list[str]:
    # PostgreSQL refuses to run as root: drop to the postgres (or nobody) user.
    if os.geteuid() != 0:
        return []
    for user in ("postgres", "nobody"):
        try:
            subprocess.run(["id", user], check=True, capture_output=True)
            return ["runuser", "-u", user, "--"]
        except (subprocess.CalledProcessError, FileNotFoundError):
            continue
    return []


@pytest.fixture(scope="session")
def postgres_server():
    initdb, pg_ctl = shutil.which("initdb"), shutil.which("pg_ctl")
    required = os.environ.get("PARTLAB_REQUIRE_POSTGRES") == "1"
    if not initdb or not pg_ctl:
        (pytest.fail if required else pytest.skip)("PostgreSQL server binaries (initdb, pg_ctl) are not installed")
    try:
        import psycopg  # noqa: F401
    except ImportError:
        (pytest.fail if required else pytest.skip)("psycopg is not installed")
    root = tempfile.mkdtemp(prefix="partlab-pg-")
    prefix = _as_user()
    if prefix:
        shutil.chown(root, user=prefix[2])
    port = _free_port()
    data = os.path.join(root, "db")
    subprocess.run(prefix + [initdb, "-D", data, "-A", "trust", "-U", "partlab"], check=True, capture_output=True)
    subprocess.run(prefix + [pg_ctl, "-D", data, "-l", os.path.join(root, "log"), "-w", "-o",
                             f"-p {port} -k {root} -c listen_addresses=127.0.0.1 -c max_connections=1000", "start"],
                   check=True, capture_output=True)
    try:
        yield f"postgresql+psycopg://partlab@127.0.0.1:{port}"
    finally:
        subprocess.run(prefix + [pg_ctl, "-D", data, "-m", "immediate", "stop"], capture_output=True)
        shutil.rmtree(root, ignore_errors=True)


_counter = itertools.count()


@pytest.fixture(params=["sqlite", "postgresql"])
def backend(request, monkeypatch):
    """Point ``PARTLAB_DATABASE_URL`` at a fresh database of each kind."""
    if request.param == "postgresql":
        monkeypatch.setenv("PARTLAB_DATABASE_URL", _fresh_database(request.getfixturevalue("postgres_server")))
    else:
        monkeypatch.delenv("PARTLAB_DATABASE_URL", raising=False)
    return request.param


def _fresh_database(base: str) -> str:
    import psycopg

    name = f"t{os.getpid()}_{next(_counter)}"
    with psycopg.connect(base.replace("postgresql+psycopg", "postgresql") + "/postgres", autocommit=True) as c:
        c.execute(f"CREATE DATABASE {name}")
    return f"{base}/{name}"
