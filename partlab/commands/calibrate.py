"""``partlab calibrate CLIP [CLIP ...] -o calibration.json [--board 9x6] [--square 100] [--reference 0]``
and ``partlab calibrate --xml FILE [--xml FILE ...] -o calibration.json``.

From chessboard clips, one per camera and recorded at the same time (``partlab synth --cameras N``
writes them under ``chessboard/``): OpenCV finds the inner corners (``findChessboardCorners``,
refined by ``cornerSubPix``), each camera's intrinsics and distortion come from every frame where
its board was found (``calibrateCamera``), and the cameras are placed in one world frame, the board
of the ``--reference`` frame (first inner corner at the origin, x along the board's rows, z out of
the board's back): by ``solvePnP`` for a camera that sees that board, by ``stereoCalibrate`` with an
already placed camera over the frames both see otherwise. With ``--xml``, OpenCV ``FileStorage`` or
PETS 2009 / Tsai calibration files are imported instead. Prints each camera's reprojection error.
"""

from __future__ import annotations

import re
from pathlib import Path

from partlab.cli import CommandError


def add_arguments(p) -> None:
    p.add_argument("clips", nargs="*", metavar="CLIP",
                   help="chessboard clips, one per camera (or a folder of them); the stream name is the file's stem")
    p.add_argument("-o", "--output", required=True, help="calibration JSON to write (a take's calibration.json)")
    p.add_argument("--board", default="9x6", help="inner corners COLSxROWS (default: 9x6)")
    p.add_argument("--square", type=float, default=100.0, help="square side in mm (default: 100)")
    p.add_argument("--reference", type=int, default=0, help="frame whose board defines the world frame (default: 0)")
    p.add_argument("--xml", action="append", default=[], metavar="FILE",
                   help="import an OpenCV or PETS/Tsai calibration XML instead (repeat for each camera)")


def _board(text: str) -> tuple[int, int]:
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m or int(m.group(1)) < 2 or int(m.group(2)) < 2:
        raise CommandError(f"--board must look like 9x6 (inner corners), got {text!r}")
    return int(m.group(1)), int(m.group(2))


def _clips(paths: list[str]) -> list[Path]:
    from partlab.labelling.video import VIDEO_EXTENSIONS

    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            out += sorted(f for f in p.iterdir() if f.suffix.lower() in VIDEO_EXTENSIONS)
        elif p.is_file():
            out.append(p)
        else:
            raise CommandError(f"{p}: no such clip or folder")
    if not out:
        raise CommandError("no chessboard clips given (or the folder holds no video)")
    return out


def run(args) -> int:
    from partlab.labelling.calibration import read_opencv_xml, write_calibration
    from partlab.labelling.chessboard import calibrate_clips

    if args.xml:
        cams = [read_opencv_xml(x) for x in args.xml]
        path = write_calibration(cams, args.output)
        print(f"partlab calibrate: imported {len(cams)} camera(s) ({', '.join(c.name for c in cams)}) into {path}")
        return 0
    if args.square <= 0:
        raise CommandError(f"--square must be a positive length in mm, got {args.square}")
    board = _board(args.board)
    cameras, reproj = calibrate_clips(_clips(args.clips), board, args.square, args.reference)
    path = write_calibration(cameras, args.output)
    for cam in cameras:
        rms, err, n = reproj[cam.name]
        c = cam.centre
        print(f"{cam.name}: {n} boards, rms {rms:.3f} px (calibrateCamera), reference board {err:.3f} px, "
              f"centre ({c[0]:.1f}, {c[1]:.1f}, {c[2]:.1f}) mm")
    print(f"partlab calibrate: wrote {len(cameras)} camera(s) to {path}")
    return 0
