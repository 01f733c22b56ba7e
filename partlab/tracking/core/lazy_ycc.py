"""A frame's YCrCb image converted only where the particle filters look.

The observation model (seed 002 sec. 3.1) works in YCrCb, but the parts of a few people
cover a small share of the frame: converting the whole frame cost as much as tracking one
person. :class:`LazyYcc` holds a buffer the size of the frame and converts 32 x 32 tiles
on first use (``cover``); code that needs the whole image (decomposition, adjustment)
asks for ``full()``. Pixel values are exactly those of ``cv2.cvtColor``. The buffer is
reused from frame to frame (``load``), so a frame allocates nothing.

Functions that take a YCrCb image accept either an ``(H, W, 3) uint8`` array or a
``LazyYcc`` through :func:`cover` and :func:`as_array`.
"""

from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.core import kernels
from partlab.tracking.core.histogram import to_ycc


class LazyYcc:
    """YCrCb of one BGR frame, converted tile by tile on demand."""

    TILE = 32

    def __init__(self, frame_bgr: np.ndarray | None = None):
        self.shape: tuple[int, ...] = (0, 0, 3)
        self.data = np.empty((0, 0, 3), dtype=np.uint8)
        self.done: np.ndarray | None = None
        if frame_bgr is not None:
            self.load(frame_bgr)

    def load(self, frame_bgr: np.ndarray) -> LazyYcc:
        """Start on a new frame (nothing converted yet); reuses the buffer when the size matches."""
        if frame_bgr.ndim != 3 or frame_bgr.shape[2] != 3 or frame_bgr.dtype != np.uint8:
            raise ValueError(f"expected a BGR (H, W, 3) uint8 frame, got {frame_bgr.shape} {frame_bgr.dtype}")
        if not kernels.HAVE_NUMBA:
            self.bgr, self.shape, self.data, self.done = frame_bgr, frame_bgr.shape, to_ycc(frame_bgr), None
            return self
        self.bgr = np.ascontiguousarray(frame_bgr)
        if self.data.shape != frame_bgr.shape:
            self.shape = frame_bgr.shape
            self.data = np.empty_like(self.bgr)
            t = self.TILE
            self._tiles = np.zeros((-(-self.shape[0] // t), -(-self.shape[1] // t)), dtype=np.bool_)
        self._tiles[:] = False
        self.done = self._tiles
        return self

    def cover(self, x1: int, y1: int, x2: int, y2: int) -> np.ndarray:
        """The YCrCb buffer, with at least ``[x1, x2) x [y1, y2)`` converted."""
        if self.done is not None:
            kernels.ycc_tiles(self.bgr, self.data, self.done, self.TILE, int(x1), int(y1), int(x2), int(y2))
        return self.data

    def cover_rects(self, rects: np.ndarray) -> np.ndarray:
        """The buffer with the union of ``rects (N, 4) int32 [x1, y1, x2, y2]`` converted."""
        if self.done is None:
            return self.data
        return self.cover(*kernels.rects_bounds(rects))

    def full(self) -> np.ndarray:
        """The whole frame in YCrCb."""
        if self.done is not None:
            cv2.cvtColor(self.bgr, cv2.COLOR_BGR2YCrCb, dst=self.data)
            self.done = None
        return self.data


def cover(ycc, x1: int, y1: int, x2: int, y2: int) -> np.ndarray:
    """``ycc`` as an array valid at least on ``[x1, x2) x [y1, y2)``."""
    return ycc.cover(x1, y1, x2, y2) if isinstance(ycc, LazyYcc) else ycc


def cover_rects(ycc, rects: np.ndarray) -> np.ndarray:
    """``ycc`` as an array valid at least on the union of ``rects``."""
    return ycc.cover_rects(rects) if isinstance(ycc, LazyYcc) else ycc


def as_array(ycc) -> np.ndarray:
    """``ycc`` as a whole-frame array."""
    return ycc.full() if isinstance(ycc, LazyYcc) else ycc
