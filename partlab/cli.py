"""The ``partlab`` command line.

Each sub-command lives in ``partlab/commands/<name>.py`` with two functions,
``add_arguments(parser)`` and ``run(args) -> int``; this module only builds the
parser and dispatches, importing a command's module lazily so that ``partlab eval``
does not pay for Streamlit and ``partlab app`` does not pay for scikit-learn.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from partlab.errors import UserError

#: sub-command -> one-line help (the order is the order of ``partlab --help``).
COMMANDS: dict[str, str] = {
    "track": "track people's parts in a video and write a tracks CSV",
    "train": "train failure detectors and variance parameters from corrected clips",
    "eval": "compare tracks with truth: per-part tracking rates and MOT metrics",
    "export": "export tracks as a dataset (mot, cvat, coco, yolo, voc, parquet)",
    "import": "import a dataset (mot, cvat, coco) as a tracks CSV",
    "synth": "render a synthetic scene with exact ground truth",
    "calibrate": "calibrate cameras from chessboard clips (or import OpenCV/PETS XML) into calibration.json",
    "app": "start the Streamlit labelling app (headless)",
}


class CommandError(UserError):
    """A user-facing failure: printed as ``partlab CMD: message`` with exit code 2."""


def _module(name: str):
    return importlib.import_module(f"partlab.commands.{name}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="partlab",
        description="Label human body parts in video: track, correct, learn, export.",
    )
    from partlab import __version__

    parser.add_argument("--version", action="version", version=f"partlab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, help_text in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        _module(name).add_arguments(p)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not args.command:
        parser.print_help()
        return 2
    try:
        return int(_module(args.command).run(args) or 0)
    except UserError as exc:
        print(f"partlab {args.command}: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"partlab {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # python -m partlab.cli
    # dispatch through the imported module, so that commands' ``partlab.cli.CommandError``
    # is the class caught here (under ``-m`` this file is ``__main__``, a second copy)
    from partlab.cli import main as _main

    sys.exit(_main())
