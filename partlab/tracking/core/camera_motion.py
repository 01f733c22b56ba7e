"""Is the camera moving? The global shift between consecutive frames, from sparse optical flow.

A background model (:mod:`partlab.tracking.core.background`) assumes a static camera: when the
camera pans, every textured pixel changes and the foreground mask reports the whole scene, so
foreground support says nothing about where a person is. Trackers that lean on the mask (blob
starts, foreground support ending tracks, decomposition) need to know when to stop trusting it.

The grey frames are scaled down to ``width`` pixels across and a ``grid`` of points is followed
from one to the next by pyramidal Lucas-Kanade (``cv2.calcOpticalFlowPyrLK``); the shift is the
median of their displacements. A pan or tilt moves every point by about one vector; people walking
through a static scene move only the few points on them, which the median ignores. (Phase
correlation of whole frames, tried first, follows the walkers on PETS09's low-texture lawn: a
median 48 px net shift over 25 frames of a static camera.) Measured per frame, full-frame pixels:
PETS09-S2L1 (static) at most 0.02, OTB Crossing (static) at most 0.14, OTB Human3 (panning) median
2.1. ``moving`` says the shift reached ``threshold`` in one of the last ``hold`` frames: after a pan
stops, the background model still holds the old view until it relearns the scene.

While the camera moves, :meth:`CameraMotion.moving_mask` stands in for the foreground: the grey
frame against the previous one shifted by the global shift (blurred, thresholded, closed), so what
moves in the scene shows and what the pan only carries along does not. On OTB Human3 (panning) it
covers a median 0.55 of the walker's box (0.15 at least, behind a sign) and 0.04 of a litter bin a
track had taken for him; 0.03 of the whole frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np


@dataclass(frozen=True)
class MotionSettings:
    """``width``: frames are scaled down to this width; ``grid``: points across and down followed by
    the flow; ``threshold``: a median shift of at least this many full-frame pixels is camera motion
    (5x the largest seen on the static clips above, a quarter of the panning one's median);
    ``hold``: frames the mask stays distrusted after the last camera motion (the background model's
    warm-up)."""

    width: int = 160
    grid: tuple[int, int] = (12, 10)
    threshold: float = 0.5
    hold: int = 60
    residual: float = 0.0   # grey levels a pixel must change by to move in the scene (0: no moving_mask)
    blur: int = 5           # Gaussian blur (pixels) before the difference: sub-pixel shifts, JPEG noise
    close: int = 9          # closing (pixels) of the moving pixels into bodies


class CameraMotion:
    """Feed every frame to :meth:`update`; it returns the frame's global shift ``(dx, dy)`` in
    full-frame pixels (where the previous frame's content moved to)."""

    def __init__(self, settings: MotionSettings | None = None):
        self.s = settings or MotionSettings()
        self._prev: np.ndarray | None = None
        self._scale = 1.0
        self.since_motion: int | None = None  # frames since the last camera motion (None: never)
        self.shift = np.zeros(2)
        self._frames: tuple[np.ndarray | None, np.ndarray | None] = (None, None)  # previous, current
        self._greys: dict[int, np.ndarray] = {}

    def _small(self, frame: np.ndarray) -> np.ndarray:
        H, W = frame.shape[:2]
        self._scale = min(1.0, self.s.width / max(W, 1))
        small = frame
        if self._scale < 1:
            small = cv2.resize(frame, (max(round(W * self._scale), 16), max(round(H * self._scale), 16)),
                               interpolation=cv2.INTER_AREA)
        return cv2.cvtColor(small, cv2.COLOR_BGR2GRAY) if small.ndim == 3 else small

    def _points(self, shape: tuple[int, int]) -> np.ndarray:
        h, w = shape
        gx, gy = self.s.grid
        xs, ys = np.meshgrid(np.linspace(8, w - 9, gx), np.linspace(8, h - 9, gy))
        return np.stack([xs.ravel(), ys.ravel()], axis=1).astype(np.float32).reshape(-1, 1, 2)

    def update(self, frame: np.ndarray) -> np.ndarray:
        if self.s.residual > 0:  # kept for moving_mask (grey only when asked)
            self._frames = (self._frames[1], frame)
            self._greys = {k: v for k, v in self._greys.items() if k == id(self._frames[0])}
        small = self._small(frame)
        shift = np.zeros(2)
        if self._prev is not None and self._prev.shape == small.shape:
            pts = self._points(small.shape)
            nxt, status, _ = cv2.calcOpticalFlowPyrLK(self._prev, small, pts, None, winSize=(15, 15), maxLevel=2)
            d = (nxt - pts).reshape(-1, 2)[status.ravel() == 1]
            if len(d) >= 0.25 * len(pts):  # most points followed: a reliable median
                shift = np.median(d, axis=0).astype(np.float64) / self._scale
        self._prev = small
        self.shift = shift
        if np.hypot(*shift) >= self.s.threshold:
            self.since_motion = 0
        elif self.since_motion is not None:
            self.since_motion += 1
        return shift

    @property
    def moving(self) -> bool:
        """The camera moved in one of the last ``hold`` frames."""
        return self.since_motion is not None and self.since_motion < self.s.hold

    def _grey(self, frame: np.ndarray) -> np.ndarray:
        key = id(frame)
        if key not in self._greys:
            grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame
            k = self.s.blur | 1
            self._greys[key] = cv2.GaussianBlur(grey, (k, k), 0) if k > 1 else grey
        return self._greys[key]

    def moving_mask(self) -> np.ndarray | None:
        """``(H, W) uint8``, 255 where the last frame differs by more than ``residual`` grey levels
        from the one before shifted by the camera's shift: what moves in the scene. None when
        ``residual`` is 0 or there is no previous frame of the same size."""
        before, now = self._frames
        if self.s.residual <= 0 or before is None or before.shape != now.shape:
            return None
        g0, g1 = self._grey(before), self._grey(now)
        H, W = g1.shape
        M = np.float32([[1, 0, self.shift[0]], [0, 1, self.shift[1]]])
        carried = cv2.warpAffine(g0, M, (W, H), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        _, mask = cv2.threshold(cv2.absdiff(g1, carried), self.s.residual, 255, cv2.THRESH_BINARY)
        if self.s.close >= 2:
            mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE,
                                    cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (self.s.close, self.s.close)))
        return mask
