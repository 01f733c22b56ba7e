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

import numpy as np

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


def orient(corners: np.ndarray, gray: np.ndarray, cols: int) -> np.ndarray:
    """Corners in one fixed order whatever end OpenCV starts from.

    A planar board's corners can be listed in four orders that fit the pattern: from either end
    (a half turn) and with the rows in either direction (a mirror, the board seen from its back).
    The printed side faces the camera, so the rows are put in the direction where row then column
    turn clockwise in the image (the board's z axis towards the camera), and the first corner at
    the end whose outer square is dark (a board of even x odd squares differs under a half turn)."""
    rows = len(corners) // cols
    c = corners.reshape(rows, cols, 2).copy()
    v1, v2 = c[0, 1] - c[0, 0], c[1, 0] - c[0, 0]
    if v1[0] * v2[1] - v1[1] * v2[0] > 0:
        c = c[::-1]

    def outer(k0, k1, k2):
        return k0 - 0.5 * (k1 - k0) - 0.5 * (k2 - k0)

    h, w = gray.shape
    a = outer(c[0, 0], c[0, 1], c[1, 0])
    b = outer(c[-1, -1], c[-1, -2], c[-2, -1])
    ga = gray[int(np.clip(round(a[1]), 0, h - 1)), int(np.clip(round(a[0]), 0, w - 1))]
    gb = gray[int(np.clip(round(b[1]), 0, h - 1)), int(np.clip(round(b[0]), 0, w - 1))]
    if ga > gb:
        c = c[::-1, ::-1]
    return np.ascontiguousarray(c.reshape(-1, 1, 2))


def find_corners(clip: Path, board: tuple[int, int]) -> tuple[dict[int, np.ndarray], tuple[int, int]]:
    """Frame index -> ``(N, 1, 2) float32`` refined corners, and the image size."""
    import cv2

    from partlab.labelling.video import VideoClip

    found: dict[int, np.ndarray] = {}
    with VideoClip(clip) as video:
        size = (video.width, video.height)
        for i, frame in video.frames(0, video.frame_count):
            gray = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
            flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
            ok, corners = cv2.findChessboardCorners(gray, board, flags)
            if not ok:
                continue
            corners = cv2.cornerSubPix(gray, corners, (5, 5), (-1, -1),
                                       (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 0.001))
            found[i] = orient(corners, gray, board[0])
    return found, size


def calibrate_clips(clips: list[Path], board: tuple[int, int], square: float, reference: int = 0):
    """Cameras (in one world frame) and per camera ``(rms, reprojection error)`` in pixels."""
    import cv2

    from partlab.tracking.camera import Camera

    obj = np.zeros((board[0] * board[1], 3), np.float32)
    obj[:, :2] = np.mgrid[0:board[0], 0:board[1]].T.reshape(-1, 2) * square
    found, intr, errors = {}, {}, {}
    for clip in clips:
        corners, size = find_corners(clip, board)
        if len(corners) < 3:
            raise CommandError(f"{clip}: chessboard {board[0]}x{board[1]} (inner corners) found in {len(corners)} "
                               f"frame(s), at least 3 are needed; check --board and that the board is in view")
        rms, K, dist, _, _ = cv2.calibrateCamera([obj] * len(corners), list(corners.values()), size, None, None)
        found[clip.stem], intr[clip.stem] = corners, (K, dist.ravel(), size)
        errors[clip.stem] = float(rms)
    placed: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for name, corners in found.items():
        if reference in corners:
            K, dist, _ = intr[name]
            ok, rvec, tvec = cv2.solvePnP(obj, corners[reference], K, dist)
            placed[name] = (cv2.Rodrigues(rvec)[0], tvec.ravel())
    if not placed:
        raise CommandError(f"no camera sees the board at the reference frame {reference}; choose another --reference")
    for _ in range(len(found)):
        for name in [n for n in found if n not in placed]:
            for ref, (R0, t0) in list(placed.items()):
                shared = sorted(set(found[name]) & set(found[ref]))
                if len(shared) < 3:
                    continue
                K1, d1, size = intr[ref]
                K2, d2, _ = intr[name]
                _, _, _, _, _, R, T, _, _ = cv2.stereoCalibrate(
                    [obj] * len(shared), [found[ref][i] for i in shared], [found[name][i] for i in shared],
                    K1, d1, K2, d2, size, flags=cv2.CALIB_FIX_INTRINSIC)
                placed[name] = (R @ R0, R @ t0 + T.ravel())
                break
    missing = [n for n in found if n not in placed]
    if missing:
        raise CommandError(f"cannot place {', '.join(missing)} in the world frame: they share fewer than 3 "
                           f"boards with a placed camera and miss the reference frame's board")
    cameras, reproj = [], {}
    for name in found:
        K, dist, size = intr[name]
        R, t = placed[name]
        cam = Camera(name, K, size, dist, R, t)
        # the world frame is the reference board: its corners reproject through the placed camera
        ref = found[name].get(reference)
        err = float(np.linalg.norm(cam.project(obj) - ref.reshape(-1, 2), axis=1).mean()) if ref is not None \
            else float("nan")
        reproj[name] = (errors[name], err, len(found[name]))
        cameras.append(cam)
    return cameras, reproj


def run(args) -> int:
    from partlab.labelling.calibration import read_opencv_xml, write_calibration

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
