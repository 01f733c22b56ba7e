"""``partlab import PATH --format FMT -o TRACKS.csv``."""

from __future__ import annotations

from app.cli import CommandError

FORMATS = ["mot", "cvat", "coco"]


def add_arguments(p) -> None:
    p.add_argument("path", metavar="PATH", help="the format's file or directory, or our export directory")
    p.add_argument("--format", choices=FORMATS, required=True)
    p.add_argument("-o", "--output", metavar="TRACKS.csv", required=True)


def run(args) -> int:
    raise CommandError("not yet available")
