"""Video input through OpenCV: metadata, seeking and iteration by decode index.

A clip is a video file or an image sequence (:class:`FrameFiles`): a folder of JPEG/PNG frames, a
zip of them, or a printf pattern such as ``img1/%06d.jpg``, as MOTChallenge, OTB and CVAT tasks ship
them. Frame ``i`` of a sequence is its ``i``-th file in the order of the number in the file names
(``0001.jpg`` is frame 0); a gap in that numbering is refused, since it would shift every later frame.

The frame index is the decoder's: frame ``i`` is the ``i``-th frame OpenCV decodes
from the start. The app, the trackers and every export use this one numbering
(browser players and other decoders may disagree on frame counts). Seeking decodes
forward from the last keyframe OpenCV chooses, then checks the position; for codecs
that seek inexactly it falls back to decoding from the start.
"""

from __future__ import annotations

import configparser
import hashlib
import re
import shutil
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import cv2
import numpy as np

from partlab.errors import UserError
from partlab.limits import check_frame_size, max_frames

VIDEO_EXTENSIONS: tuple[str, ...] = (".mp4", ".avi", ".mov", ".mkv", ".m4v", ".webm", ".mpg", ".mpeg")
IMAGE_EXTENSIONS: tuple[str, ...] = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".webp")
#: fps of an image sequence that does not state one (a MOT ``seqinfo.ini`` beside it does):
#: PAL video's rate, which most of the public sequences (MOT, PETS) were recorded at
SEQUENCE_FPS = 25.0


class VideoError(UserError):
    """A file that cannot be used as a clip; the message says why."""


@dataclass(frozen=True)
class VideoInfo:
    path: Path
    fps: float
    width: int
    height: int
    frame_count: int

    @property
    def duration(self) -> float:
        return self.frame_count / self.fps if self.fps > 0 else 0.0


_NUMBER = re.compile(r"(\d+)(?!.*\d)")  # the last run of digits in a name


def _order(names: list[str], where: str) -> list[str]:
    """``names`` in frame order (by the last number in each stem; by name when some have none),
    refusing a gap or a repeat in the numbering."""
    stems = [Path(n).stem for n in names]
    numbers = [m.group(1) for m in map(_NUMBER.search, stems) if m]
    if len(numbers) != len(names):
        return sorted(names)
    pairs = sorted(zip((int(n) for n in numbers), names))
    nums = [k for k, _ in pairs]
    repeated = [k for k, j in zip(nums, nums[1:]) if k == j]
    if repeated:
        raise VideoError(f"{where}: two frames are numbered {repeated[0]}; expected one image per frame number")
    gaps = [(a, b) for a, b in zip(nums, nums[1:]) if b != a + 1]
    if gaps:
        a, b = gaps[0]
        raise VideoError(f"{where}: frame files jump from number {a} to {b} ({len(gaps)} gap(s)); a missing "
                         "frame would shift every later one. Fill or renumber the sequence")
    return [n for _, n in pairs]


def _is_image(name: str) -> bool:
    base = name.rsplit("/", 1)[-1]
    return Path(base).suffix.lower() in IMAGE_EXTENSIONS and not base.startswith(".") and "__MACOSX" not in name


def _pattern(name: str) -> re.Pattern | None:
    """The file names a printf pattern like ``%06d.jpg`` matches, or None when ``name`` is none."""
    parts = re.split(r"(%0?\d*d)", name)
    if len(parts) != 3:
        return None
    return re.compile("^" + re.escape(parts[0]) + r"(\d+)" + re.escape(parts[2]) + "$")


def is_image_sequence(path: str | PathLike) -> bool:
    """True for a folder holding image files (and no video), a ``.zip`` of images, or a ``%d`` pattern."""
    p = Path(path)
    if _pattern(p.name) is not None:
        return True
    if p.is_dir():
        entries = [e for e in p.iterdir() if e.is_file()]
        return (any(_is_image(e.name) for e in entries) and not (p / "take.json").exists()
                and not any(e.suffix.lower() in VIDEO_EXTENSIONS for e in entries))
    if p.is_file() and p.suffix.lower() == ".zip":
        try:
            with zipfile.ZipFile(p) as zf:
                return any(_is_image(n) for n in zf.namelist())
        except (zipfile.BadZipFile, OSError):
            return False
    return False


class FrameFiles:
    """An image sequence read by frame index (BGR ``uint8``); see the module docstring."""

    def __init__(self, path: str | PathLike):
        self.path = Path(path)
        self._zip: zipfile.ZipFile | None = None
        p = self.path
        rx = _pattern(p.name)
        if rx is not None:
            folder = p.parent
            if not folder.is_dir():
                raise VideoError(f"{folder}: no such folder (from the pattern {p.name})")
            names = [e.name for e in folder.iterdir() if rx.match(e.name)]
            self._files: list = [folder / n for n in _order(names, str(p))]
        elif p.is_dir():
            names = [e.name for e in p.iterdir() if e.is_file() and _is_image(e.name)]
            self._files = [p / n for n in _order(names, str(p))]
        elif p.suffix.lower() == ".zip":
            try:
                self._zip = zipfile.ZipFile(p)
            except (zipfile.BadZipFile, OSError) as exc:
                raise VideoError(f"{p}: not a readable zip of frames ({exc})") from None
            members = [i.filename for i in self._zip.infolist() if not i.is_dir() and _is_image(i.filename)]
            self._files = _order(members, str(p))
        else:
            raise VideoError(f"{p}: not an image sequence (a folder of frames, a zip of them or a %06d pattern)")
        if not self._files:
            raise VideoError(f"{p}: no frames ({', '.join(IMAGE_EXTENSIONS)} files) in this sequence")
        if len(self._files) > max_frames():
            raise VideoError(f"{p}: more than the limit of {max_frames()} frames (set PARTLAB_MAX_FRAMES to change it)")
        self.width = self.height = 0
        first = self.read(0)
        check_frame_size(first.shape[1], first.shape[0], str(p), VideoError)
        self.height, self.width = first.shape[:2]

    def __len__(self) -> int:
        return len(self._files)

    def name(self, index: int) -> str:
        f = self._files[index]
        return f if isinstance(f, str) else f.name

    def read(self, index: int) -> np.ndarray:
        f = self._files[index]
        if self._zip is not None:
            image = cv2.imdecode(np.frombuffer(self._zip.read(f), np.uint8), cv2.IMREAD_COLOR)
        else:
            image = cv2.imread(str(f), cv2.IMREAD_COLOR)
        if image is None:
            raise VideoError(f"{self.path}: frame {index} ({self.name(index)}) is not an image OpenCV can read")
        if self.width and (image.shape[1], image.shape[0]) != (self.width, self.height):
            raise VideoError(f"{self.path}: frame {index} ({self.name(index)}) is {image.shape[1]}x{image.shape[0]} "
                             f"but the sequence starts at {self.width}x{self.height}")
        return image

    def fps(self) -> float:
        """``frameRate`` of a MOT ``seqinfo.ini`` in the folder or its parent, else :data:`SEQUENCE_FPS`."""
        base = self.path if self.path.is_dir() else self.path.parent
        for ini in (base / "seqinfo.ini", base.parent / "seqinfo.ini"):
            if ini.is_file():
                seq = configparser.ConfigParser()
                try:
                    seq.read(ini, encoding="utf-8")
                    rate = float(seq["Sequence"]["frameRate"])
                except (configparser.Error, KeyError, ValueError):
                    continue
                if 0 < rate <= 1000:
                    return rate
        return SEQUENCE_FPS

    def close(self) -> None:
        if self._zip is not None:
            self._zip.close()
            self._zip = None


def _count_frames(cap: cv2.VideoCapture, limit: int, path: Path) -> int:
    n = 0
    while cap.grab():
        n += 1
        if n >= limit:
            raise VideoError(f"{path}: more than the limit of {limit} frames (set PARTLAB_MAX_FRAMES to change it)")
    return n


def probe(path: str | PathLike, exact_count: bool = True) -> VideoInfo:
    """Open ``path`` and read its metadata; refuse empty, missing or non-video files.

    With ``exact_count`` the frames are counted by decoding (container headers are
    often wrong, and the decoder's count is the one every other part uses).
    """
    p = Path(path)
    if is_image_sequence(p):
        seq = FrameFiles(p)
        try:
            return VideoInfo(p, seq.fps(), int(seq.width), int(seq.height), len(seq))
        finally:
            seq.close()
    if not p.exists():
        raise VideoError(f"{p}: no such file")
    if p.is_dir():
        raise VideoError(f"{p}: is a directory with no frames (expected a video file, or a folder of "
                         f"{'/'.join(IMAGE_EXTENSIONS[:2])}/png frames)")
    if p.stat().st_size == 0:
        raise VideoError(f"{p}: the file is empty")
    cap = cv2.VideoCapture(str(p))
    try:
        if not cap.isOpened():
            raise VideoError(f"{p}: not a video OpenCV can decode (expected one of {', '.join(VIDEO_EXTENSIONS)})")
        meta_w, meta_h = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH) or 0), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT) or 0)
        if meta_w > 0 and meta_h > 0:  # refuse a huge frame before decoding one
            check_frame_size(meta_w, meta_h, str(p), VideoError)
        ok, frame = cap.read()
        if not ok or frame is None:
            raise VideoError(f"{p}: no decodable frame (empty or corrupt video)")
        check_frame_size(frame.shape[1], frame.shape[0], str(p), VideoError)
        height, width = frame.shape[:2]
        fps = float(cap.get(cv2.CAP_PROP_FPS) or 0.0)
        if not np.isfinite(fps) or fps <= 0 or fps > 1000:
            fps = 25.0
        if exact_count:
            count = 1 + _count_frames(cap, max_frames(), p)
        else:
            count = int(cap.get(cv2.CAP_PROP_FRAME_COUNT) or 0)
    finally:
        cap.release()
    return VideoInfo(p, fps, int(width), int(height), int(count))


class VideoClip:
    """A clip opened for reading frames by index (BGR ``(H, W, 3) uint8`` arrays)."""

    def __init__(self, path: str | PathLike, info: VideoInfo | None = None):
        self.info = info or probe(path)
        self.path = self.info.path
        self._cap: cv2.VideoCapture | None = None
        self._next = 0  # index of the frame the capture will return next
        self._files: FrameFiles | None = FrameFiles(self.path) if is_image_sequence(self.path) else None

    @property
    def fps(self) -> float:
        return self.info.fps

    @property
    def width(self) -> int:
        return self.info.width

    @property
    def height(self) -> int:
        return self.info.height

    @property
    def frame_count(self) -> int:
        return self.info.frame_count

    def __len__(self) -> int:
        return self.info.frame_count

    def _open(self) -> cv2.VideoCapture:
        if self._cap is None:
            self._cap = cv2.VideoCapture(str(self.path))
            self._next = 0
        return self._cap

    def close(self) -> None:
        if self._cap is not None:
            self._cap.release()
            self._cap = None
        if self._files is not None:
            self._files.close()

    def __enter__(self) -> VideoClip:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def read(self, index: int) -> np.ndarray:
        """Frame ``index`` (0-based decode index)."""
        if not 0 <= index < self.frame_count:
            raise IndexError(f"frame {index} is outside the clip (0..{self.frame_count - 1})")
        if self._files is not None:
            return self._files.read(index)
        cap = self._open()
        if index < self._next or index - self._next > 50:
            cap.set(cv2.CAP_PROP_POS_FRAMES, index)
            pos = int(cap.get(cv2.CAP_PROP_POS_FRAMES))
            if pos != index:  # inexact seek: decode from the start
                cap.release()
                self._cap = None
                cap = self._open()
            else:
                self._next = index
        while self._next < index:
            if not cap.grab():
                raise VideoError(f"{self.path}: could not decode frame {self._next}")
            self._next += 1
        ok, frame = cap.read()
        if not ok:
            raise VideoError(f"{self.path}: could not decode frame {index}")
        self._next = index + 1
        return frame

    def frames(self, start: int = 0, stop: int | None = None) -> Iterator[tuple[int, np.ndarray]]:
        """Yield ``(index, frame)`` from ``start`` up to ``stop`` (exclusive), decoding once."""
        stop = self.frame_count if stop is None else min(stop, self.frame_count)
        if self._files is not None:
            files = FrameFiles(self.path)  # its own reader, as each call decodes independently
            try:
                for i in range(start, stop):
                    yield i, files.read(i)
            finally:
                files.close()
            return
        cap = cv2.VideoCapture(str(self.path))
        try:
            if start > 0:
                for _ in range(start):
                    if not cap.grab():
                        return
            for i in range(start, stop):
                ok, frame = cap.read()
                if not ok:
                    return
                yield i, frame
        finally:
            cap.release()


def open_video(path: str | PathLike) -> VideoClip:
    """Open a clip for reading; raises :class:`VideoError` with a clear message."""
    return VideoClip(path)


def sha256_file(path: str | PathLike, chunk: int = 1 << 20) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while block := f.read(chunk):
            h.update(block)
    return h.hexdigest()


def store_by_hash(path: str | PathLike, clips_dir: str | PathLike) -> tuple[Path, str]:
    """Copy a clip to ``clips_dir/<sha256><ext>`` (once per content); returns (path, hash)."""
    src = Path(path)
    digest = sha256_file(src)
    dest_dir = Path(clips_dir)
    dest_dir.mkdir(parents=True, exist_ok=True)
    dest = dest_dir / f"{digest}{src.suffix.lower()}"
    if not dest.exists():
        tmp = dest.with_suffix(dest.suffix + ".part")
        try:
            shutil.copyfile(src, tmp)
            tmp.replace(dest)
        except OSError:  # a full disk: no half copy is left to look like a clip
            tmp.unlink(missing_ok=True)
            raise
    return dest, digest


def write_video(path: str | PathLike, frames, fps: float) -> Path:
    """Write BGR frames to ``path`` (mp4v for .mp4, MJPG for .avi)."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    writer = None
    try:
        for frame in frames:
            if writer is None:
                h, w = frame.shape[:2]
                fourcc = cv2.VideoWriter_fourcc(*("MJPG" if p.suffix.lower() == ".avi" else "mp4v"))
                writer = cv2.VideoWriter(str(p), fourcc, float(fps), (w, h))
                if not writer.isOpened():
                    raise VideoError(f"{p}: OpenCV cannot write this video format")
            writer.write(frame)
    finally:
        if writer is not None:
            writer.release()
    return p
