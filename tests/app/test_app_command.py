"""``partlab app``'s command line: upload limit from PARTLAB_MAX_UPLOAD_MB, headless."""

from __future__ import annotations

import pytest

from partlab.cli import CommandError
from partlab.commands.app import streamlit_command


def _opt(cmd: list[str], name: str) -> str:
    return cmd[cmd.index(name) + 1]


def test_upload_limit_and_address(monkeypatch):
    cmd = streamlit_command("127.0.0.1", 8599)
    assert cmd[1:4] == ["-m", "streamlit", "run"] and cmd[4].endswith("streamlit_app.py")
    assert (_opt(cmd, "--server.maxUploadSize"), _opt(cmd, "--server.port"), _opt(cmd, "--server.headless")) == \
        ("1024", "8599", "true")
    monkeypatch.setenv("PARTLAB_MAX_UPLOAD_MB", "200")
    assert _opt(streamlit_command("0.0.0.0", 1), "--server.maxUploadSize") == "200"
    monkeypatch.setenv("PARTLAB_MAX_UPLOAD_MB", "-3")
    with pytest.raises(CommandError, match="PARTLAB_MAX_UPLOAD_MB must be positive"):
        streamlit_command("127.0.0.1", 1)


def test_allowed_hosts_are_loopback_the_bind_address_and_the_extras():
    from partlab.commands.app import allowed_hosts

    assert allowed_hosts("0.0.0.0") == ["localhost", "127.0.0.1", "::1"]
    assert allowed_hosts("10.0.0.5", "lab.example.org, *.lab.example.org") == \
        ["localhost", "127.0.0.1", "::1", "10.0.0.5", "lab.example.org", "*.lab.example.org"]


def test_a_page_on_another_host_cannot_drive_the_app(tmp_path):
    """DNS rebinding: a web page whose name resolves to 127.0.0.1 opens the app's websocket with
    its own Host and Origin; the server refuses it, and still accepts the app's own address."""
    import asyncio
    import socket
    import subprocess
    import time
    import urllib.request

    import websockets

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen(streamlit_command("127.0.0.1", port), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env={**__import__("os").environ, "PARTLAB_DATA": str(tmp_path)})

    async def opens(name: str, origin: str) -> bool:
        try:
            async with websockets.connect(f"ws://{name}:{port}/_stcore/stream", host="127.0.0.1", port=port,
                                          origin=origin, open_timeout=20):
                return True
        except websockets.exceptions.InvalidStatus as exc:
            assert exc.response.status_code == 403
            return False

    try:
        deadline = time.time() + 120
        while True:
            try:
                urllib.request.urlopen(f"http://127.0.0.1:{port}/_stcore/health", timeout=2)
                break
            except OSError:
                assert time.time() < deadline, "the app did not start"
                time.sleep(0.5)
        assert asyncio.run(opens("127.0.0.1", f"http://127.0.0.1:{port}"))
        assert not asyncio.run(opens("evil.example", f"http://evil.example:{port}"))
        assert not asyncio.run(opens("127.0.0.1", "http://evil.example"))
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def test_when_the_server_stops_it_says_the_job_service_runs_on_and_how_to_stop_it(tmp_path, monkeypatch):
    import json
    import socket

    from partlab.commands.app import job_service_note
    from partlab.engine import jobs

    assert job_service_note() is None  # no job was ever run: nothing left behind
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen()
        port = listener.getsockname()[1]
        jobs.service_file().write_text(json.dumps({"address": f"tcp://127.0.0.1:{port}", "pid": 4242}))
        said = job_service_note()
        assert "keeps running" in said and said.endswith("kill 4242")
    assert job_service_note() is None  # its address no longer answers: it has stopped


def test_a_sigterm_to_partlab_app_stops_its_server_too(tmp_path):
    """A service manager stops ``partlab app`` with SIGTERM to that process alone; the Streamlit
    server it started must stop with it, not keep the port open without a parent."""
    import contextlib
    import os
    import signal
    import socket
    import subprocess
    import sys
    import time
    import urllib.request

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen([sys.executable, "-m", "partlab", "app", "--port", str(port)], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env={**os.environ, "PARTLAB_DATA": str(tmp_path)},
                            start_new_session=True)

    def answers() -> bool:
        try:
            urllib.request.urlopen(f"http://127.0.0.1:{port}/_stcore/health", timeout=2)
            return True
        except OSError:
            return False

    try:
        deadline = time.time() + 120
        while not answers():
            assert proc.poll() is None and time.time() < deadline, "the app did not start"
            time.sleep(0.5)
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=30)
        deadline = time.time() + 30
        while answers() and time.time() < deadline:
            time.sleep(0.5)
        assert not answers(), "the server outlived partlab app"
    finally:
        with contextlib.suppress(ProcessLookupError):  # the server too, if it outlived partlab app
            os.killpg(proc.pid, signal.SIGKILL)
