"""Hue-histogram likelihood and mean-shift refinement (seed 003 sec. 3, eq. 1-2).

A target's colour is the normalised histogram of the H channel of HSV over its box
(grey pixels, whose hue is undefined, are left out). A candidate box scores
``pi = exp(-lam D^2)`` with ``D = sqrt(1 - sum_i sqrt(h_i h_ref_i))`` (eq. 1-2). All the
particles' boxes of one frame are scored at once from an integral histogram (one
cumulative sum per bin), so the cost does not grow with the box size.

The PF mean is then refined by OpenCV's ``cv2.meanShift`` on the back-projection of
the reference histogram (sec. 3): the window climbs to the nearest peak of the
skin-hue probability.
"""

from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.core import kernels


def hue_bin_image(hsv: np.ndarray, bins: int, min_saturation: int, min_value: int) -> np.ndarray:
    """``(H, W) int16`` hue bin of every pixel of an HSV frame; -1 where the pixel is too grey or dark."""
    h = hsv[..., 0].astype(np.int16)
    b = (h * bins) // 180  # OpenCV's 8-bit hue runs over 0..179
    valid = (hsv[..., 1] >= min_saturation) & (hsv[..., 2] >= min_value)
    return np.where(valid, np.minimum(b, bins - 1), -1).astype(np.int16)


def integral_histogram(bin_image: np.ndarray, bins: int) -> np.ndarray:
    """``(bins, H+1, W+1) int32`` integral images of the one-hot bins (``cv2.integral`` per
    plane, contiguous); any box's histogram then costs four lookups per bin."""
    hgt, wid = bin_image.shape
    out = np.empty((bins, hgt + 1, wid + 1), np.int32)
    for b in range(bins):
        out[b] = cv2.integral((bin_image == b).view(np.uint8))
    return out


def box_histograms(integral: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Normalised histograms ``(N, bins)`` of boxes ``(N, 4) x, y, w, h`` (clipped to the frame).

    A box with no valid pixel gets an all-zero histogram (Bhattacharyya distance 1).
    """
    hgt, wid = integral.shape[1] - 1, integral.shape[2] - 1
    b = np.asarray(boxes, dtype=float).reshape(-1, 4)
    x1 = np.clip(np.round(b[:, 0]), 0, wid).astype(int)
    y1 = np.clip(np.round(b[:, 1]), 0, hgt).astype(int)
    x2 = np.clip(np.round(b[:, 0] + b[:, 2]), 0, wid).astype(int)
    y2 = np.clip(np.round(b[:, 1] + b[:, 3]), 0, hgt).astype(int)
    counts = (integral[:, y2, x2] - integral[:, y1, x2] - integral[:, y2, x1] + integral[:, y1, x1]).T
    counts = counts.astype(float)
    total = counts.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, counts / np.maximum(total, 1e-12), 0.0)


def local_box_histograms(bin_image: np.ndarray, boxes: np.ndarray, bins: int) -> np.ndarray:
    """:func:`box_histograms` of ``boxes (N, 4)`` over ``bin_image (H, W)`` (-1 = no bin), from an
    integral histogram of only the region the boxes cover.

    One filter's particles cover a few times its box; the whole frame's integral histogram
    (``bins`` planes of the frame) cost more than the rest of the limb tracker on PETS09
    (768 x 576). The counts, and so the histograms, are the same as from the whole frame's
    (compiled: counted box by box, :func:`partlab.tracking.core.kernels.box_bin_counts`).
    """
    hgt, wid = bin_image.shape
    b = np.asarray(boxes, dtype=float).reshape(-1, 4)
    if len(b) == 0:
        return np.zeros((0, bins))
    x1 = np.clip(np.round(b[:, 0]), 0, wid).astype(int)
    y1 = np.clip(np.round(b[:, 1]), 0, hgt).astype(int)
    x2 = np.clip(np.round(b[:, 0] + b[:, 2]), 0, wid).astype(int)
    y2 = np.clip(np.round(b[:, 1] + b[:, 3]), 0, hgt).astype(int)
    if kernels.HAVE_NUMBA:
        counts = kernels.box_bin_counts(np.ascontiguousarray(bin_image, np.int16),
                                        np.column_stack([x1, y1, x2, y2]).astype(np.int64), int(bins))
        total = counts.sum(axis=1, keepdims=True)
        return np.where(total > 0, counts / np.maximum(total, 1e-12), 0.0)
    ox, oy = int(x1.min()), int(y1.min())
    crop = bin_image[oy:max(int(y2.max()), oy), ox:max(int(x2.max()), ox)]
    integral = np.zeros((bins, crop.shape[0] + 1, crop.shape[1] + 1), np.int32)
    if crop.size:
        onehot = (crop[None, :, :] == np.arange(bins, dtype=crop.dtype)[:, None, None]).astype(np.int32)
        integral[:, 1:, 1:] = onehot.cumsum(axis=1).cumsum(axis=2)
    return box_histograms(integral, np.column_stack([x1 - ox, y1 - oy, x2 - x1, y2 - y1]))


def bhattacharyya_distance(hists: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``D = (1 - sum sqrt(h h_ref))^(1/2)`` of each row of ``hists (N, B)`` to ``ref (B,)`` (seed 003 eq. 2)."""
    bc = np.sqrt(np.clip(hists, 0, None) * np.clip(ref, 0, None)[None, :]).sum(axis=1)
    return np.sqrt(np.clip(1.0 - bc, 0.0, 1.0))


def hue_confidence(hists: np.ndarray, ref: np.ndarray, lam: float) -> np.ndarray:
    """``pi = exp(-lam D^2)`` (seed 003 eq. 1, with a sharpness ``lam``; the paper has lam = 1)."""
    d = bhattacharyya_distance(hists, ref)
    return np.exp(-lam * d * d)


def reference_histogram(bin_image: np.ndarray, box, bins: int) -> np.ndarray | None:
    """Normalised hue histogram ``(bins,)`` of one box, or None when it holds no valid pixel."""
    x, y, w, h = (int(round(v)) for v in box)
    hgt, wid = bin_image.shape
    patch = bin_image[max(y, 0):min(y + h, hgt), max(x, 0):min(x + w, wid)]
    vals = patch[patch >= 0]
    if vals.size == 0:
        return None
    hist = np.bincount(vals, minlength=bins).astype(float)
    return hist / hist.sum()


def back_projection(bin_image: np.ndarray, ref: np.ndarray, weight: np.ndarray | None = None) -> np.ndarray:
    """``(H, W) uint8`` back-projection of ``ref`` scaled so its top bin is 255, times ``weight`` (0..1)
    if given (the foreground mask, so the window is not drawn to skin-hued background)."""
    lut = np.append(ref / max(float(ref.max()), 1e-12), 0.0)  # index -1 (invalid pixel) -> 0
    prob = lut[bin_image]
    if weight is not None:
        prob = prob * weight
    return np.clip(prob * 255.0, 0, 255).astype(np.uint8)


def mean_shift(backproj: np.ndarray, box, iterations: int, eps: float) -> tuple[float, float, float, float]:
    """Box ``x, y, w, h`` moved by ``cv2.meanShift`` to the nearest peak of ``backproj`` (seed 003 sec. 3).

    Returns the input box unchanged when the window holds no probability mass.
    """
    hgt, wid = backproj.shape
    x, y, w, h = box
    w_i, h_i = max(int(round(w)), 1), max(int(round(h)), 1)
    x_i = int(np.clip(round(x), 0, max(wid - w_i, 0)))
    y_i = int(np.clip(round(y), 0, max(hgt - h_i, 0)))
    window = (x_i, y_i, min(w_i, wid), min(h_i, hgt))
    if backproj[window[1]:window[1] + window[3], window[0]:window[0] + window[2]].sum() == 0:
        return (float(x), float(y), float(w), float(h))
    crit = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, int(iterations), float(eps))
    _, (nx, ny, _, _) = cv2.meanShift(backproj, window, crit)
    return (float(x + nx - x_i), float(y + ny - y_i), float(w), float(h))


def local_mean_shift(bin_image: np.ndarray, ref: np.ndarray, box, iterations: int, eps: float,
                     margin: float = 2.0) -> tuple[float, float, float, float]:
    """:func:`mean_shift` of ``box`` on the back-projection of ``ref``, computed only over the box
    grown by ``margin`` of its larger side on every side (seed 003 sec. 3).

    The window moves at most half its size a step and stops at the nearest peak, so it never
    needs the rest of the frame; back-projecting the whole frame for every target cost ten
    times the rest of the refinement on PETS09 (768 x 576). The result equals the whole-frame
    one unless the window would climb more than ``margin`` sides away.
    """
    hgt, wid = bin_image.shape
    x, y, w, h = (float(v) for v in box)
    m = margin * max(w, h, 1.0)
    x1, y1 = max(int(np.floor(x - m)), 0), max(int(np.floor(y - m)), 0)
    x2, y2 = min(int(np.ceil(x + w + m)), wid), min(int(np.ceil(y + h + m)), hgt)
    if x2 <= x1 or y2 <= y1:
        return (x, y, w, h)
    nx, ny, _, _ = mean_shift(back_projection(bin_image[y1:y2, x1:x2], ref), (x - x1, y - y1, w, h), iterations, eps)
    return (nx + x1, ny + y1, w, h)
