"""``partlab export TRACKS.csv --video VIDEO --format FMT -o OUT``."""

from __future__ import annotations

from app.cli import CommandError

FORMATS = ["mot", "cvat", "coco", "yolo", "voc", "parquet"]


def add_arguments(p) -> None:
    p.add_argument("tracks", metavar="TRACKS.csv")
    p.add_argument("--video", metavar="VIDEO", required=True)
    p.add_argument("--format", choices=FORMATS, required=True)
    p.add_argument("-o", "--output", metavar="OUT", required=True, help="output directory")


def run(args) -> int:
    raise CommandError("not yet available")
