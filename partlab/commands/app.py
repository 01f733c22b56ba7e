"""``partlab app``: start the Streamlit labelling app, headless (no browser opened)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from partlab.cli import CommandError

PAGE = Path(__file__).resolve().parent.parent / "app" / "streamlit_app.py"


def add_arguments(p) -> None:
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    p.add_argument("--port", type=int, default=8501, help="port to listen on (default 8501)")


def streamlit_command(host: str, port: int) -> list[str]:
    """The command line that serves the app; also used by the browser tests.

    The upload limit comes from ``PARTLAB_MAX_UPLOAD_MB`` (default 1024), the same
    number :mod:`partlab.app.uploads` checks again on the server side.
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
    ]


def run(args) -> int:
    print(f"partlab app: serving on http://{args.host}:{args.port} (Ctrl+C to stop)", flush=True)
    return subprocess.call(streamlit_command(args.host, args.port), env=os.environ.copy())
