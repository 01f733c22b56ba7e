"""Video input through OpenCV: metadata, seeking and iteration by decode index.

The frame index is the decoder's: frame ``i`` is the ``i``-th frame OpenCV decodes
from the start. The app, the trackers and every export use this one numbering
(browser players and other decoders may disagree on frame counts). Seeking decodes
forward from the last keyframe OpenCV chooses, then checks the position; for codecs
that seek inexactly it falls back to decoding from the start.
"""

from __future__ import annotations

import hashlib
import shutil
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Iterator

import cv2
import numpy as np

from partlab.errors import UserError
from partlab.limits import check_frame_size, max_frames

VIDEO_EXTENSIONS: tuple[str, ...] = (".mp4", ".avi", ".mov", ".mkv", ".m4v", ".webm", ".mpg", ".mpeg")


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
    if not p.exists():
        raise VideoError(f"{p}: no such file")
    if p.is_dir():
        raise VideoError(f"{p}: is a directory, not a video file")
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

    def __enter__(self) -> "VideoClip":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def read(self, index: int) -> np.ndarray:
        """Frame ``index`` (0-based decode index)."""
        if not 0 <= index < self.frame_count:
            raise IndexError(f"frame {index} is outside the clip (0..{self.frame_count - 1})")
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
        shutil.copyfile(src, tmp)
        tmp.replace(dest)
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
