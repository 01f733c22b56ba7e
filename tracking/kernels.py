"""Compiled (numba) kernels for the particle filters' hot loop (seed 002 sec. 3.1).

The numpy version (``tracking.integral_histogram`` with ``cv2.LUT``, a gather of one-hot
planes and ``cv2.integral``) builds four temporary images per part and frame; here one
pass over the pixels the particles cover bins each pixel with the target's
equalization map and accumulates the fused 24-bin integral histogram directly, and a
second loop reads every particle's four corners and returns its Bhattacharyya
coefficient. Results are those of the numpy path: the same integer counts, the
coefficient computed in float64.

Every function here has a numpy equivalent elsewhere; ``HAVE_NUMBA`` says whether the
compiled one is used (numba is a dependency, the fallback only keeps the tracker working
where it cannot be installed). Compiled code is cached on disk (``cache=True``).
"""

from __future__ import annotations

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; numpy fallback
    numba = None

HAVE_NUMBA = numba is not None


def _jit(fn):
    return numba.njit(cache=True, nogil=True)(fn) if HAVE_NUMBA else fn


@_jit
def rectangles(states, width, height):
    """Integer corners ``(N, 4) int32 [x1, y1, x2, y2]`` of centre-size float32 states
    ``(N, >=4)``, rounded half to even and clipped to the frame (as
    :func:`tracking.integral_histogram.particle_rectangles`)."""
    n = states.shape[0]
    out = np.empty((n, 4), dtype=np.int32)
    half = np.float32(0.5)
    for i in range(n):
        hw = half * states[i, 2]
        hh = half * states[i, 3]
        x1 = np.rint(states[i, 0] - hw)
        y1 = np.rint(states[i, 1] - hh)
        x2 = np.rint(states[i, 0] + hw)
        y2 = np.rint(states[i, 1] + hh)
        out[i, 0] = int(min(max(x1, 0.0), width))
        out[i, 1] = int(min(max(y1, 0.0), height))
        out[i, 2] = int(min(max(x2, 0.0), width))
        out[i, 3] = int(min(max(y2, 0.0), height))
    return out


@_jit
def _grid(v, r0, stride):
    """Sample index of the first grid point at or after ``v`` on a grid from ``r0``."""
    return -((r0 - v) // stride)


@_jit
def rectangle_rho(ycc, mapping, rects, stride, sqrt_target):
    """Bhattacharyya coefficients ``(N,) float64`` and sampled areas ``(N,) float64`` of the
    rectangles ``rects (N, 4) int32 [x1, y1, x2, y2]`` (clipped to the image) of the YCrCb
    image ``ycc (H, W, 3) uint8`` against ``sqrt_target (3 * bins,)`` (square root of the
    per-channel normalised target), each pixel binned by ``mapping (3, 256) uint8``.

    One integral histogram over the union of the rectangles, sampled every ``stride``
    pixels (see :func:`tracking.integral_histogram.rectangle_histograms`); an empty
    rectangle gets ``rho = 0``.
    """
    n = rects.shape[0]
    nb = sqrt_target.shape[0]
    bins = nb // 3
    rho = np.zeros(n, dtype=np.float64)
    areas = np.zeros(n, dtype=np.float64)
    if n == 0:
        return rho, areas
    rx1, ry1 = rects[0, 0], rects[0, 1]
    rx2, ry2 = rects[0, 2], rects[0, 3]
    for i in range(1, n):
        rx1 = min(rx1, rects[i, 0])
        ry1 = min(ry1, rects[i, 1])
        rx2 = max(rx2, rects[i, 2])
        ry2 = max(ry2, rects[i, 3])
    if rx2 <= rx1 or ry2 <= ry1:
        return rho, areas
    w = (rx2 - rx1 + stride - 1) // stride
    h = (ry2 - ry1 + stride - 1) // stride
    integral = np.empty((h + 1, w + 1, nb), dtype=np.int32)
    integral[0, :, :] = 0
    row = np.empty(nb, dtype=np.int32)
    for yy in range(h):
        y = ry1 + yy * stride
        row[:] = 0
        integral[yy + 1, 0, :] = 0
        for xx in range(w):
            x = rx1 + xx * stride
            row[mapping[0, ycc[y, x, 0]]] += 1
            row[bins + mapping[1, ycc[y, x, 1]]] += 1
            row[2 * bins + mapping[2, ycc[y, x, 2]]] += 1
            for b in range(nb):
                integral[yy + 1, xx + 1, b] = integral[yy, xx + 1, b] + row[b]
    for i in range(n):
        x1 = _grid(rects[i, 0], rx1, stride)
        y1 = _grid(rects[i, 1], ry1, stride)
        x2 = _grid(rects[i, 2], rx1, stride)
        y2 = _grid(rects[i, 3], ry1, stride)
        if x2 <= x1 or y2 <= y1:
            continue
        area = float((x2 - x1) * (y2 - y1))
        s = 0.0
        for b in range(nb):
            c = (integral[y2, x2, b] - integral[y1, x2, b] - integral[y2, x1, b] + integral[y1, x1, b])
            if c > 0:
                s += np.sqrt(float(c)) * sqrt_target[b]
        rho[i] = s / (3.0 * np.sqrt(area))
        areas[i] = area
    return rho, areas


@_jit
def level_histogram_box(ycc, x1, y1, x2, y2):
    """256-level histogram ``(3, 256) float64`` of ``ycc[y1:y2, x1:x2]`` (corners already
    clipped), each channel summing to one (uniform when empty)."""
    out = np.zeros((3, 256), dtype=np.float64)
    count = 0
    for y in range(y1, y2):
        for x in range(x1, x2):
            out[0, ycc[y, x, 0]] += 1.0
            out[1, ycc[y, x, 1]] += 1.0
            out[2, ycc[y, x, 2]] += 1.0
            count += 1
    if count == 0:
        out[:, :] = 1.0 / 256
        return out
    return out / count


@_jit
def drift(particles, noise, sigma, lo, hi):
    """Constant-velocity step in place: ``X += dX, Y += dY``, plus ``noise * sigma`` per
    component, then W and H clipped to ``[lo, hi]`` (each ``(2,) float32``)."""
    for i in range(particles.shape[0]):
        particles[i, 0] += particles[i, 4]
        particles[i, 1] += particles[i, 5]
        for k in range(6):
            particles[i, k] += noise[i, k] * sigma[k]
        for k in range(2):
            v = particles[i, 2 + k]
            particles[i, 2 + k] = min(max(v, lo[k]), hi[k])
