"""Foreground masks from OpenCV's adaptive Gaussian-mixture background model (MOG2).

Seed 002 sec. 4 segments people with an adaptive Gaussian background model [15]; MOG2
is OpenCV's implementation of that model. One model serves every tracker of a run
(the pipeline computes the mask once per frame). Shadows (MOG2's grey value 127) are
dropped, and the mask is opened (removes speckle) and closed (fills holes in a body)
with elliptic kernels. For speed the model runs on a frame scaled by
``BodyParams.background.scale`` and the mask is scaled back; it is only used for
blobs, decomposition and support, never for the colour likelihood.
"""

from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.body.params import BodyParams  # not partlab.tracking.params: no limb parameters to import


def _ellipse(size: int) -> np.ndarray | None:
    size = int(size)
    if size < 2:
        return None
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size))


class BackgroundModel:
    """``apply(frame)`` -> ``(H, W) uint8`` mask, 255 where something moves."""

    def __init__(self, params: BodyParams | None = None):
        self.params = params or BodyParams()
        p = self.params
        if not 0 < p.background.scale <= 1:
            raise ValueError(f"body.background.scale must be in (0, 1], got {p.background.scale}")
        self._mog = cv2.createBackgroundSubtractorMOG2(
            history=int(p.background.history), varThreshold=float(p.background.var_threshold), detectShadows=True)
        self._mog.setBackgroundRatio(float(p.background.ratio))
        self._frames = 0
        s = p.background.scale
        self._open = _ellipse(round(p.background.morph_open * s))
        self._close = _ellipse(round(p.background.morph_close * s))

    def learning_rate(self) -> float:
        """``1 / min(max(2 n, warmup), history)`` for the n-th frame (the first frame initialises)."""
        p = self.params
        if self._frames == 0:
            return 1.0
        return 1.0 / min(max(2 * self._frames, p.background.warmup), p.background.history)

    def apply(self, frame: np.ndarray) -> np.ndarray:
        if frame.ndim != 3 or frame.dtype != np.uint8:
            raise ValueError(f"expected a BGR (H, W, 3) uint8 frame, got {frame.shape} {frame.dtype}")
        H, W = frame.shape[:2]
        s = self.params.background.scale
        small = frame if s == 1 else cv2.resize(frame, (max(round(W * s), 1), max(round(H * s), 1)),
                                                interpolation=cv2.INTER_AREA)
        raw = self._mog.apply(small, learningRate=self.learning_rate())
        self._frames += 1
        _, mask = cv2.threshold(raw, 200, 255, cv2.THRESH_BINARY)  # drop shadows (127)
        if self._open is not None:
            mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, self._open)
        if self._close is not None:
            mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, self._close)
        if s != 1:
            mask = cv2.resize(mask, (W, H), interpolation=cv2.INTER_NEAREST)
        return mask


def half_size(image: np.ndarray) -> np.ndarray:
    """``image`` at half resolution (a 2 x 2 area average, which also halves the sensor noise)."""
    return cv2.resize(image, (image.shape[1] // 2, image.shape[0] // 2), interpolation=cv2.INTER_AREA)


def plate_silhouette(color_half: np.ndarray, plate_half: np.ndarray, threshold: float) -> np.ndarray:
    """``(H/2, W/2) uint8`` 0/1 person mask from an empty-scene plate (background subtraction
    against a fixed image, *3D tracking of the hands and head ...* sec. 6.1): a pixel is a person's
    where one of its channels differs from the plate by more than ``threshold``, opened by 3 x 3
    (speckle). Both images at half resolution (:func:`half_size`)."""
    b, g, r = cv2.split(cv2.absdiff(color_half, plate_half))
    sil = cv2.threshold(cv2.max(cv2.max(b, g), r), threshold, 1, cv2.THRESH_BINARY)[1]
    return cv2.morphologyEx(sil, cv2.MORPH_OPEN, np.ones((3, 3), np.uint8))
