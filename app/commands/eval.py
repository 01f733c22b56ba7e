"""``partlab eval TRUTH.csv TRACKS.csv``."""

from __future__ import annotations

from app.cli import CommandError


def add_arguments(p) -> None:
    p.add_argument("truth", metavar="TRUTH.csv")
    p.add_argument("tracks", metavar="TRACKS.csv")


def run(args) -> int:
    raise CommandError("not yet available")
