"""Equalized YCbCr colour histograms: the observation model of seed 002 sec. 3.1.

A target keeps a *reference* histogram of 256 levels per channel, ``(3, 256) float64``
summing to one per channel, updated each frame by eq. (1), ``H_t = 0.9 H_{t-1} + 0.1 Q_t``.
From it an *equalization map* ``(3, 256) uint8`` sends each level to one of 8 bins so
that the reference falls evenly into the bins (bin edges differ per target and move
as the model updates). Candidates are binned with their target's map into a
24-vector (3 channels x 8 bins) and compared by the Bhattacharyya coefficient
(Nummiaro et al.); the particle weight is ``exp(-lam * d^2)`` with ``d = sqrt(1 - rho)``.

Why equalize: two close colour distributions (a grey shirt and a grey wall) fall
into the same uniform bin; bins cut at the reference's own quantiles split them
(sec. 5.1). The reference is lightly smoothed and floored before its cumulative
distribution is taken, so colours next to a narrow peak still land in distinct bins.

Channel order is OpenCV's YCrCb (Y, Cr, Cb): the three channels are treated
independently, so the order does not matter.
"""

from __future__ import annotations

from functools import lru_cache

import cv2
import numpy as np

from partlab.tracking.core import kernels

LEVELS = 256


def to_ycc(frame_bgr: np.ndarray) -> np.ndarray:
    """BGR ``(H, W, 3) uint8`` -> YCrCb ``(H, W, 3) uint8`` (OpenCV's conversion)."""
    if frame_bgr.ndim != 3 or frame_bgr.shape[2] != 3 or frame_bgr.dtype != np.uint8:
        raise ValueError(f"expected a BGR (H, W, 3) uint8 frame, got {frame_bgr.shape} {frame_bgr.dtype}")
    return cv2.cvtColor(frame_bgr, cv2.COLOR_BGR2YCrCb)


def level_histogram(ycc: np.ndarray, box: tuple[int, int, int, int] | None = None,
                    mask: np.ndarray | None = None) -> np.ndarray:
    """256-level histogram per channel of the pixels of ``ycc`` inside ``box = (x, y, w, h)``
    (integers, clipped to the image) and, if given, where ``mask`` is non-zero.

    Returns ``(3, 256) float64``, each channel summing to one (uniform when empty).
    """
    if box is not None:
        x, y, w, h = (int(round(v)) for v in box)
        H, W = ycc.shape[:2]
        x1, y1, x2, y2 = max(x, 0), max(y, 0), min(x + w, W), min(y + h, H)
        if mask is None and kernels.HAVE_NUMBA:
            return kernels.level_histogram_box(ycc, x1, y1, max(x2, x1), max(y2, y1))
        ycc = ycc[y1:max(y2, y1), x1:max(x2, x1)]
        if mask is not None:
            mask = mask[y1:max(y2, y1), x1:max(x2, x1)]
    pixels = ycc.reshape(-1, 3)
    if mask is not None:
        pixels = pixels[mask.reshape(-1) > 0]
    out = np.empty((3, LEVELS), dtype=np.float64)
    if len(pixels) == 0:
        out[:] = 1.0 / LEVELS
        return out
    for c in range(3):
        out[c] = np.bincount(pixels[:, c], minlength=LEVELS)
    return out / len(pixels)


def update_reference(reference: np.ndarray, observed: np.ndarray, rate: float = 0.1) -> np.ndarray:
    """Seed 002 eq. (1): ``H_t = (1 - rate) H_{t-1} + rate Q_t`` (rate 0.1 in the paper)."""
    return (1.0 - rate) * reference + rate * observed


def _smooth(hist: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian smoothing of each row of ``hist (C, 256)`` along the levels, edges replicated."""
    if sigma <= 0:
        return hist
    radius = int(np.ceil(3 * sigma))
    out = cv2.GaussianBlur(np.ascontiguousarray(hist, dtype=np.float64), (2 * radius + 1, 1), sigmaX=sigma,
                           sigmaY=1e-6, borderType=cv2.BORDER_REPLICATE)
    return out.reshape(hist.shape)


def equalization_map(reference: np.ndarray, bins: int = 8, smoothing: float = 2.0,
                     floor: float = 0.05) -> np.ndarray:
    """The map ``M`` of sec. 3.1: level -> bin so that ``reference`` is equalized.

    ``reference (3, 256)`` -> ``(3, 256) uint8`` bin indexes in ``0..bins-1``. The
    reference is smoothed (Gaussian, ``smoothing`` levels) and mixed with a uniform
    ``floor`` share; a level goes to ``floor(bins * F(level))`` with ``F`` the mid-point
    cumulative distribution, so each bin holds about ``1 / bins`` of the reference.
    """
    ref = np.asarray(reference, dtype=np.float64)
    if ref.shape != (3, LEVELS):
        raise ValueError(f"reference histogram must be (3, {LEVELS}), got {ref.shape}")
    p = _smooth(ref, smoothing)
    p = p / np.maximum(p.sum(axis=1, keepdims=True), 1e-12)
    p = (1.0 - floor) * p + floor / LEVELS
    cdf_mid = np.cumsum(p, axis=1) - 0.5 * p
    return np.clip(np.floor(cdf_mid * bins), 0, bins - 1).astype(np.uint8)


def uniform_map(bins: int = 8) -> np.ndarray:
    """The plain map (equal level ranges per bin), for comparison with equalization."""
    row = (np.arange(LEVELS) * bins // LEVELS).astype(np.uint8)
    return np.stack([row, row, row])


def binned_histogram(levels: np.ndarray, mapping: np.ndarray, bins: int = 8) -> np.ndarray:
    """A 256-level histogram ``(3, 256)`` pushed through ``mapping`` -> ``(3 * bins,)``,
    each channel's ``bins`` entries summing to its channel's mass."""
    index = (mapping.astype(np.intp) + (np.arange(3) * bins)[:, None]).ravel()
    return np.bincount(index, weights=np.asarray(levels, dtype=np.float64).ravel(), minlength=3 * bins)


def onehot_lut(mapping: np.ndarray, bins: int = 8) -> np.ndarray:
    """``(3, 256, 3 * bins) uint8``: for channel c and level l, a one in column ``c * bins + M_c(l)``.

    Summing ``lut[0][Y] + lut[1][Cr] + lut[2][Cb]`` over pixels gives the fused 24-bin
    histogram; the integral histogram is built from these planes.
    """
    lut = np.zeros((3, LEVELS, 3 * bins), dtype=np.uint8)
    levels = np.arange(LEVELS)
    for c in range(3):
        lut[c, levels, c * bins + mapping[c].astype(np.intp)] = 1
    return lut


@lru_cache(maxsize=4)
def _code_planes(bins: int) -> np.ndarray:
    codes = np.arange(bins ** 3)
    b = np.stack([codes // (bins * bins), (codes // bins) % bins, codes % bins], axis=1)
    planes = np.zeros((bins ** 3, 3 * bins), dtype=np.uint8)
    for c in range(3):
        planes[codes, c * bins + b[:, c]] = 1
    planes.flags.writeable = False
    return planes


def fused_lut(mapping: np.ndarray, bins: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """The map as two tables for the integral histogram's hot loop.

    ``channel_lut (1, 256, 3) uint8`` for ``cv2.LUT`` (each channel's level -> its bin) and
    ``code_planes (bins**3, 3 * bins) uint8`` (shared by all targets): for a pixel's bin code
    ``(b_Y * bins + b_Cr) * bins + b_Cb``, a one in columns ``b_Y``, ``bins + b_Cr`` and
    ``2 bins + b_Cb``. One gather of ``code_planes`` gives all 24 one-hot planes.
    """
    channel_lut = np.ascontiguousarray(mapping.T[None, :, :], dtype=np.uint8)
    return channel_lut, _code_planes(int(bins))


def bhattacharyya_counts(counts: np.ndarray, areas: np.ndarray, sqrt_target: np.ndarray) -> np.ndarray:
    """Fast ``rho`` for raw pixel counts ``(N, 3 * bins)`` of rectangles of ``areas (N,)`` pixels
    against ``sqrt_target = sqrt(p)`` of a per-channel-normalised target: every channel of a
    rectangle sums to its area, so ``rho = (sqrt(counts) . sqrt(p)) / (3 sqrt(area))``."""
    rho = np.sqrt(counts) @ sqrt_target.astype(counts.dtype)
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = rho / (3.0 * np.sqrt(areas))
    return np.where(areas > 0, rho, 0.0)


def bhattacharyya(candidates: np.ndarray, target: np.ndarray, bins: int = 8) -> np.ndarray:
    """Bhattacharyya coefficient ``rho`` of candidate histograms ``(..., 3 * bins)`` with
    ``target (3 * bins,)``; both normalised per channel here. ``rho`` is the mean of the
    three channels' coefficients (channels modelled independently, sec. 3.1), in [0, 1]."""
    q = np.asarray(candidates, dtype=np.float64)
    p = np.asarray(target, dtype=np.float64)
    qs = q.reshape(q.shape[:-1] + (3, bins))
    ps = p.reshape(3, bins)
    qs = qs / np.maximum(qs.sum(axis=-1, keepdims=True), 1e-12)
    ps = ps / np.maximum(ps.sum(axis=-1, keepdims=True), 1e-12)
    return np.sqrt(qs * ps).sum(axis=-1).mean(axis=-1)


def distance(rho: np.ndarray) -> np.ndarray:
    """Bhattacharyya distance ``d = sqrt(1 - rho)``."""
    return np.sqrt(np.clip(1.0 - np.asarray(rho, dtype=np.float64), 0.0, None))


def likelihood(rho: np.ndarray, lam: float) -> np.ndarray:
    """Particle weights ``exp(-lam * d^2) = exp(-lam * (1 - rho))`` (Nummiaro et al.)."""
    return np.exp(-lam * np.clip(1.0 - np.asarray(rho, dtype=np.float64), 0.0, None))
