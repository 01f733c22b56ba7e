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
