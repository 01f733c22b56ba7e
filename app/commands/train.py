"""``partlab train --clip VIDEO --truth TRUTH.csv [...] -o BUNDLE_DIR``."""

from __future__ import annotations

from app.cli import CommandError


def add_arguments(p) -> None:
    p.add_argument("--clip", metavar="VIDEO", action="append", required=True, help="a corrected clip (repeatable)")
    p.add_argument("--truth", metavar="TRUTH.csv", action="append", required=True,
                   help="its corrected boxes, one per --clip in the same order")
    p.add_argument("-o", "--output", metavar="BUNDLE_DIR", required=True, help="model bundle directory to write")
    p.add_argument("--seed", type=int, default=0)


def run(args) -> int:
    raise CommandError("not yet available")
