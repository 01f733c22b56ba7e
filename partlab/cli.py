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
    "batch": "track every clip of a folder, manifest or project on Dask (resumable)",
    "train": "train failure detectors and variance parameters from corrected clips",
    "eval": "compare tracks with truth: per-part tracking rates and MOT metrics",
    "export": "export tracks as a dataset (mot, cvat, coco, yolo, voc, parquet, labelstudio)",
    "import": "import a dataset (mot, cvat, coco, parquet, labelstudio) as a tracks CSV",
    "synth": "render a synthetic scene with exact ground truth",
    "calibrate": "calibrate cameras from chessboard clips (or import OpenCV/PETS XML) into calibration.json",
    "app": "start the Streamlit labelling app (headless)",
    "users": "add users who sign in to the app and grant them roles in projects",
    "serve-ml": "serve partlab as a Label Studio ML backend (predict part boxes, retrain from annotations)",
}


class CommandError(UserError):
    """A user-facing failure: printed as ``partlab CMD: message`` with exit code 2."""


def seed(text: str) -> int:
    """argparse type of ``--seed``: a whole number from 0 to 2**32 - 1 (what numpy seeds take)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 0 <= value < 2**32:
        raise argparse.ArgumentTypeError(f"{value} is outside 0..{2**32 - 1}")
    return value


def _module(name: str):
    return importlib.import_module(f"partlab.commands.{name.replace('-', '_')}")


class _Version(argparse.Action):
    """``--version``, reading the version only when asked."""

    def __call__(self, parser, namespace, values, option_string=None):
        import partlab

        print(f"partlab {partlab.__version__}")
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="partlab",
        description="Label human body parts in video: track, correct, learn, export.",
    )
    parser.add_argument("--version", action=_Version, nargs=0, help="print partlab's version and exit")
    parser.add_argument("--debug", action="store_true",
                        help="show the full traceback of an unexpected error instead of one line")
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
        print(f"partlab {args.command}: {_one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"partlab {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - the top-level handler: one line, not a traceback
        if args.debug:
            raise
        print(f"partlab {args.command}: {describe_unexpected(exc)} (rerun with --debug for the traceback)",
              file=sys.stderr)
        return 2 if isinstance(exc, (OSError, ValueError, MemoryError, RecursionError)) else 1


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def describe_os_error(exc: OSError) -> str:
    """What went wrong with a file, in words: a full disk and permissions said as such."""
    import errno

    if exc.errno == errno.ENOSPC:
        return "no space left on the device (earlier outputs are left as they were)"
    if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return f"not allowed to write here ({exc.strerror})"
    return (exc.strerror or _one_line(exc)).lower()


def describe_unexpected(exc: BaseException) -> str:
    """One line for an error no check caught."""
    if isinstance(exc, OSError):
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        return where + describe_os_error(exc)
    if isinstance(exc, MemoryError):
        return "out of memory (the input is too large for this machine)"
    if isinstance(exc, RecursionError):
        return "the input is nested too deeply to read"
    return f"unexpected {type(exc).__name__}: {_one_line(exc)}"


if __name__ == "__main__":  # python -m partlab.cli
    # dispatch through the imported module, so that commands' ``partlab.cli.CommandError``
    # is the class caught here (under ``-m`` this file is ``__main__``, a second copy)
    from partlab.cli import main as _main

    sys.exit(_main())
