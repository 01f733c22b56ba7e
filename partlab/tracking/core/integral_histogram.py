"""Histograms of all particles of a frame from one integral histogram (seed 002 sec. 3).

Rather than crop and bin every particle's rectangle, each pixel of the region the
particles cover is turned into a fused one-hot vector of ``3 * bins`` entries (its
Y, Cr and Cb bins under the target's equalization map), and one integral image of
those planes is built (``cv2.integral``, all planes in one call). The histogram of
any rectangle is then four lookups: ``I[y2, x2] - I[y1, x2] - I[y2, x1] + I[y1, x1]``.
Only the bounding region of the particles is processed, not the whole frame.
"""

from __future__ import annotations

import cv2
import numpy as np


def particle_rectangles(states: np.ndarray, width: int, height: int) -> np.ndarray:
    """Integer corners ``(N, 4) int32 [x1, y1, x2, y2]`` of centre-size states
    ``(N, >=4) [X, Y, W, H, ...]``, clipped to a ``width`` x ``height`` frame."""
    s = np.asarray(states)
    half = 0.5 * s[:, 2:4]
    corners = np.concatenate([s[:, 0:2] - half, s[:, 0:2] + half], axis=1)
    np.rint(corners, out=corners)
    np.maximum(corners, 0, out=corners)
    np.minimum(corners, np.array([width, height, width, height], dtype=corners.dtype), out=corners)
    return corners.astype(np.int32)


def rectangle_histograms(ycc: np.ndarray, lut, rects: np.ndarray, stride: int = 1) -> np.ndarray:
    """Fused histograms (pixel counts) of rectangles ``rects (N, 4) int [x1, y1, x2, y2]``
    (already clipped to the image) of the YCrCb image ``ycc (H, W, 3) uint8``.

    ``lut`` is either ``(channel_lut, code_planes)`` from :func:`partlab.tracking.core.histogram.fused_lut`
    (fast: one ``cv2.LUT`` and one gather) or the ``(3, 256, B)`` one-hot table of
    :func:`partlab.tracking.core.histogram.onehot_lut`. Returns ``(N, B) float32`` counts; an empty
    rectangle gives zeros. One integral image is built over the union of the rectangles only.

    With ``stride`` 2 only every second pixel of every second row is counted (the grid
    anchored at the union's corner): four times less work for large parts, whose
    histograms hardly change. The counts are then those of the sampled pixels; divide by
    :func:`sampled_areas`, not by the rectangles' areas.
    """
    n = len(rects)
    fused = isinstance(lut, tuple)
    nb = lut[1].shape[1] if fused else lut.shape[2]
    if n == 0:
        return np.zeros((0, nb), dtype=np.float32)
    rx1, ry1 = int(rects[:, 0].min()), int(rects[:, 1].min())
    rx2, ry2 = int(rects[:, 2].max()), int(rects[:, 3].max())
    if rx2 <= rx1 or ry2 <= ry1:
        return np.zeros((n, nb), dtype=np.float32)
    roi = ycc[ry1:ry2:stride, rx1:rx2:stride]
    if fused:
        channel_lut, code_planes = lut
        bins = nb // 3
        b = cv2.LUT(roi, channel_lut)
        code = b[..., 0].astype(np.uint16)
        code *= bins
        code += b[..., 1]
        code *= bins
        code += b[..., 2]
        planes = np.take(code_planes, code, axis=0)  # np.take: several times faster than [code]
    else:
        planes = lut[0][roi[..., 0]]
        planes += lut[1][roi[..., 1]]
        planes += lut[2][roi[..., 2]]
    integral = cv2.integral(planes, sdepth=cv2.CV_32S)  # (h + 1, w + 1, B) int32
    x1, y1, x2, y2 = _grid_corners(rects, rx1, ry1, stride)
    row = integral.shape[1]
    y1 = y1 * row
    y2 = y2 * row
    corners = np.take(integral.reshape(-1, nb), np.concatenate([y2 + x2, y1 + x2, y2 + x1, y1 + x1]), axis=0)
    corners = corners.reshape(4, n, nb)
    counts = corners[0] - corners[1] - corners[2] + corners[3]
    return counts.astype(np.float32)


def _grid_corners(rects: np.ndarray, rx1: int, ry1: int, stride: int):
    """Corners of ``rects`` on the sampling grid that starts at ``(rx1, ry1)``: sample ``k``
    (pixel ``rx1 + k * stride``) lies in ``[x1, x2)`` for ``ceil((x1 - rx1) / stride) <= k <
    ceil((x2 - rx1) / stride)``."""
    if stride == 1:
        return rects[:, 0] - rx1, rects[:, 1] - ry1, rects[:, 2] - rx1, rects[:, 3] - ry1
    s = stride
    return (-((rx1 - rects[:, 0]) // s), -((ry1 - rects[:, 1]) // s),
            -((rx1 - rects[:, 2]) // s), -((ry1 - rects[:, 3]) // s))


def sampled_areas(rects: np.ndarray, stride: int = 1) -> np.ndarray:
    """How many pixels of each rectangle :func:`rectangle_histograms` counts: ``(N,) float32``."""
    if len(rects) == 0:
        return np.zeros(0, dtype=np.float32)
    rx1, ry1 = int(rects[:, 0].min()), int(rects[:, 1].min())
    x1, y1, x2, y2 = _grid_corners(rects, rx1, ry1, stride)
    return (np.clip(x2 - x1, 0, None) * np.clip(y2 - y1, 0, None)).astype(np.float32)
