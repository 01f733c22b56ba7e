"""Shared fixtures: every test gets its own data directory and SQLite store."""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def _isolated_data_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("PARTLAB_DATA", str(tmp_path / "partlab-data"))
    monkeypatch.delenv("PARTLAB_DATABASE_URL", raising=False)
    yield
