"""``partlab track VIDEO -o TRACKS.csv``."""

from __future__ import annotations

from app.cli import CommandError


def add_arguments(p) -> None:
    p.add_argument("video", metavar="VIDEO", help="input clip (any format OpenCV decodes)")
    p.add_argument("-o", "--output", metavar="TRACKS.csv", required=True, help="tracks CSV to write")
    p.add_argument("--tracker", choices=["body", "limbs", "all", "whole"], default="body",
                   help="body: head/torso/hip-leg; limbs: head and hands; all: both; whole: one box per person")
    p.add_argument("--init", metavar="INIT.csv", help="start tracks from these boxes instead of detecting people")
    p.add_argument("--model", metavar="BUNDLE_DIR", help="model bundle (default: the one shipped with partlab)")
    p.add_argument("--seed", type=int, default=0, help="random seed; the same seed gives the same output")


def run(args) -> int:
    raise CommandError("not yet available")
