"""``partlab synth OUTDIR --scenario NAME --seed N``."""

from __future__ import annotations

from app.cli import CommandError


def add_arguments(p) -> None:
    p.add_argument("outdir", metavar="OUTDIR")
    p.add_argument("--scenario", default="single")
    p.add_argument("--seed", type=int, default=0)


def run(args) -> int:
    raise CommandError("not yet available")
