"""Where partlab keeps its data: ``PARTLAB_DATA`` (default ``./partlab-data``) and the
database URL ``PARTLAB_DATABASE_URL`` (default SQLite in the data directory)."""

from __future__ import annotations

import os
from pathlib import Path

DEFAULT_DATA_DIR = "partlab-data"


def data_dir() -> Path:
    """The data directory (created on first use)."""
    path = Path(os.environ.get("PARTLAB_DATA", DEFAULT_DATA_DIR)).expanduser().resolve()
    path.mkdir(parents=True, exist_ok=True)
    return path


def database_url() -> str:
    """SQLAlchemy URL of the annotation store."""
    url = os.environ.get("PARTLAB_DATABASE_URL")
    if url:
        return url
    return f"sqlite:///{data_dir() / 'partlab.db'}"
