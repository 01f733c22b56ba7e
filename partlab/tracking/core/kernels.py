"""Compiled (numba) kernels for the particle filters' hot loop (seed 002 sec. 3.1).

The numpy version (``partlab.tracking.core.integral_histogram`` with ``cv2.LUT``, a gather of one-hot
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

import sys
import threading

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; numpy fallback
    numba = None

HAVE_NUMBA = numba is not None

# What numba's CPU target imports when it is set up (at the first call of any compiled function) for
# features no kernel here uses: scipy's BLAS (``numba.np.arraymath`` checks for it on import, for
# ``np.dot``/``np.vdot``/``np.inner``) and cffi (calling C functions declared with cffi). Together they
# are 0.15-0.25 s of a 5-frame ``partlab track`` (docs/measurements/startup.md).
UNUSED_BY_KERNELS = ("scipy.linalg.cython_blas", "cffi")
_prepared = False


def prepare() -> None:
    """Set up numba's CPU target once, before the first kernel call, without importing
    :data:`UNUSED_BY_KERNELS` (numba then treats them as absent: ``np.vdot``/``np.inner`` in compiled
    code fall back to a plain loop; ``np.dot`` would still load BLAS when compiled). Later imports of
    those modules work as usual. Skipped when other Python threads run, which could import one of
    them meanwhile; the kernels and their results are the same either way."""
    global _prepared
    if _prepared or not HAVE_NUMBA:
        return
    _prepared = True
    from numba.core.registry import cpu_target

    blocked = [m for m in UNUSED_BY_KERNELS if m not in sys.modules] if threading.active_count() == 1 else []
    for m in blocked:
        sys.modules[m] = None  # an import of it raises ImportError, which numba takes as "not installed"
    try:
        cpu_target.target_context.refresh()
    finally:
        for m in blocked:
            if m in sys.modules and sys.modules[m] is None:
                del sys.modules[m]


def _jit(fn=None, **options):
    """``numba.njit`` with an on-disk cache (the function itself without numba)."""
    if fn is None:
        return lambda f: _jit(f, **options)
    return numba.njit(cache=True, nogil=True, **options)(fn) if HAVE_NUMBA else fn


@_jit
def rectangles(states, width, height):
    """Integer corners ``(N, 4) int32 [x1, y1, x2, y2]`` of centre-size float32 states
    ``(N, >=4)``, rounded half to even and clipped to the frame (as
    :func:`partlab.tracking.core.integral_histogram.particle_rectangles`)."""
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


@_jit(fastmath=True)  # lets the 24-bin sum of square roots vectorise (rho changes by ~1e-16)
def rectangle_rho(ycc, mapping, rects, stride, sqrt_target):
    """Bhattacharyya coefficients ``(N,) float64`` and sampled areas ``(N,) float64`` of the
    rectangles ``rects (N, 4) int32 [x1, y1, x2, y2]`` (clipped to the image) of the YCrCb
    image ``ycc (H, W, 3) uint8`` against ``sqrt_target (3 * bins,)`` (square root of the
    per-channel normalised target), each pixel binned by ``mapping (3, 256) uint8``.

    One integral histogram over the union of the rectangles, sampled every ``stride``
    pixels (see :func:`partlab.tracking.core.integral_histogram.rectangle_histograms`); an empty
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
        prev = integral[yy]
        cur = integral[yy + 1]
        cur[0, :] = 0
        for xx in range(w):
            x = rx1 + xx * stride
            row[mapping[0, ycc[y, x, 0]]] += 1
            row[bins + mapping[1, ycc[y, x, 1]]] += 1
            row[2 * bins + mapping[2, ycc[y, x, 2]]] += 1
            for b in range(nb):
                cur[xx + 1, b] = prev[xx + 1, b] + row[b]
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
            c = integral[y2, x2, b] - integral[y1, x2, b] - integral[y2, x1, b] + integral[y1, x1, b]
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


@_jit
def weigh(particles, rho, areas, lam, anchor_x, sigma_x, anchor_y, sigma_y):
    """Normalised particle weights ``(N,) float64`` and their weighted-mean state ``(6,)``.

    ``exp(-lam (1 - rho))`` (Nummiaro et al.), zero for rectangles of fewer than 4 pixels,
    times ``exp(-0.5 ((X - anchor_x) / sigma_x)^2)`` if ``sigma_x > 0`` (and likewise for
    Y); all-zero weights become uniform (as :func:`partlab.tracking.core.resampling.normalise_weights`).
    """
    n = particles.shape[0]
    w = np.empty(n, dtype=np.float64)
    total = 0.0
    for i in range(n):
        v = 0.0
        if areas[i] >= 4:
            v = np.exp(-lam * max(1.0 - rho[i], 0.0))
            if sigma_x > 0:
                v *= np.exp(-0.5 * ((particles[i, 0] - anchor_x) / sigma_x) ** 2)
            if sigma_y > 0:
                v *= np.exp(-0.5 * ((particles[i, 1] - anchor_y) / sigma_y) ** 2)
            if not np.isfinite(v) or v < 0:
                v = 0.0
        w[i] = v
        total += v
    if total > 0:
        w /= total
    else:
        w[:] = 1.0 / max(n, 1)
    state = np.zeros(particles.shape[1], dtype=np.float64)
    for i in range(n):
        for k in range(particles.shape[1]):
            state[k] += w[i] * particles[i, k]
    return w, state


@_jit
def similarity(levels, mapping, sqrt_target):
    """Bhattacharyya coefficient of a 256-level histogram ``levels (3, 256)`` binned by
    ``mapping`` with the target (``sqrt_target``, per-channel normalised): the mean over the
    three channels, as :func:`partlab.tracking.core.histogram.bhattacharyya`."""
    bins = sqrt_target.shape[0] // 3
    q = np.zeros((3, bins), dtype=np.float64)
    for c in range(3):
        for level in range(256):
            q[c, mapping[c, level]] += levels[c, level]
    rho = 0.0
    for c in range(3):
        total = max(q[c].sum(), 1e-12)
        for b in range(bins):
            rho += np.sqrt(q[c, b] / total) * sqrt_target[c * bins + b]
    return rho / 3.0


@_jit
def equalize(smoothed, reference, bins, floor):
    """The equalization map of a (smoothed) reference, sec. 3.1, and the binned target.

    ``smoothed (3, 256)``: the reference after Gaussian smoothing; returns ``mapping (3,
    256) uint8`` (level -> ``floor(bins * F(level))``, ``F`` the mid-point cumulative
    distribution of the smoothed reference mixed with a uniform ``floor`` share), the
    ``reference`` binned by it ``(3 * bins,)`` and the square root of that target
    normalised per channel (as :func:`partlab.tracking.core.histogram.equalization_map`)."""
    mapping = np.empty((3, 256), dtype=np.uint8)
    target = np.zeros(3 * bins, dtype=np.float64)
    for c in range(3):
        total = max(smoothed[c].sum(), 1e-12)
        cum = 0.0
        for level in range(256):
            p = (1.0 - floor) * (smoothed[c, level] / total) + floor / 256
            cum += p
            b = int(np.floor((cum - 0.5 * p) * bins))
            b = min(max(b, 0), bins - 1)
            mapping[c, level] = b
            target[c * bins + b] += reference[c, level]
    sqrt_target = np.empty(3 * bins, dtype=np.float64)
    for c in range(3):
        total = max(target[c * bins:(c + 1) * bins].sum(), 1e-12)
        for b in range(bins):
            sqrt_target[c * bins + b] = np.sqrt(target[c * bins + b] / total)
    return mapping, target, sqrt_target


@_jit
def systematic_indices(weights, n, u):
    """Systematic resampling (as :func:`partlab.tracking.core.resampling.systematic_resample`) of
    normalised ``weights`` with the uniform offset ``u``: ``n`` indexes ``(n,) int64``."""
    m = weights.shape[0]
    out = np.empty(n, dtype=np.int64)
    cum = weights[0]
    j = 0
    for i in range(n):
        pos = (u + i) / n
        while j < m - 1 and cum <= pos:
            j += 1
            cum += weights[j]
        out[i] = j
    return out


@_jit
def entropy_count(weights, c, lo, hi):
    """Seed 002 eq. (2) for normalised ``weights``: ``C N H(w) / log N`` rounded, in [lo, hi]."""
    n = weights.shape[0]
    if n <= 1:
        return lo
    h = 0.0
    for i in range(n):
        if weights[i] > 0:
            h -= weights[i] * np.log(weights[i])
    return int(min(max(np.rint(c * n * h / np.log(n)), lo), hi))


@_jit(fastmath=True)
def ycc_tiles(bgr, out, done, tile, x1, y1, x2, y2):
    """Convert to YCrCb (into ``out``) the ``tile`` x ``tile`` tiles of ``bgr (H, W, 3) uint8``
    that meet ``[x1, x2) x [y1, y2)`` and are not ``done`` yet, then mark them done.

    OpenCV's fixed-point BGR -> YCrCb (14-bit coefficients), the same values as
    ``cv2.cvtColor(..., COLOR_BGR2YCrCb)`` for every 8-bit colour (checked on all 2^24).
    Each tile row is split into planes first so that the arithmetic vectorises.
    """
    H, W = bgr.shape[0], bgr.shape[1]
    x1, y1 = max(x1, 0), max(y1, 0)
    x2, y2 = min(x2, W), min(y2, H)
    if x2 <= x1 or y2 <= y1:
        return
    b = np.empty(tile, dtype=np.int32)
    g = np.empty(tile, dtype=np.int32)
    r = np.empty(tile, dtype=np.int32)
    lum = np.empty(tile, dtype=np.int32)
    cr = np.empty(tile, dtype=np.int32)
    cb = np.empty(tile, dtype=np.int32)
    half = 1 << 13
    delta = (128 << 14) + half
    for ty in range(y1 // tile, (y2 - 1) // tile + 1):
        for tx in range(x1 // tile, (x2 - 1) // tile + 1):
            if done[ty, tx]:
                continue
            done[ty, tx] = True
            xs, xe = tx * tile, min((tx + 1) * tile, W)
            n = xe - xs
            for y in range(ty * tile, min((ty + 1) * tile, H)):
                src = bgr[y, xs:xe]
                for i in range(n):
                    b[i] = src[i, 0]
                    g[i] = src[i, 1]
                    r[i] = src[i, 2]
                for i in range(n):
                    v = (r[i] * 4899 + g[i] * 9617 + b[i] * 1868 + half) >> 14
                    lum[i] = v
                    cr[i] = min(max(((r[i] - v) * 11682 + delta) >> 14, 0), 255)
                    cb[i] = min(max(((b[i] - v) * 9241 + delta) >> 14, 0), 255)
                dst = out[y, xs:xe]
                for i in range(n):
                    dst[i, 0] = lum[i]
                    dst[i, 1] = cr[i]
                    dst[i, 2] = cb[i]


@_jit
def rects_bounds(rects):
    """Union ``(x1, y1, x2, y2)`` of rectangles ``(N, 4) [x1, y1, x2, y2]`` (zeros if none)."""
    if rects.shape[0] == 0:
        return 0, 0, 0, 0
    x1, y1, x2, y2 = rects[0, 0], rects[0, 1], rects[0, 2], rects[0, 3]
    for i in range(1, rects.shape[0]):
        x1 = min(x1, rects[i, 0])
        y1 = min(y1, rects[i, 1])
        x2 = max(x2, rects[i, 2])
        y2 = max(y2, rects[i, 3])
    return x1, y1, x2, y2


@_jit
def scatter(particles, state, noise, sigma, lo, hi):
    """Every particle reset to ``state (6,) float32`` plus ``noise * sigma``, W and H clipped to
    ``[lo, hi]``, in place (a part that coasts on its dynamics, sec. 4.3)."""
    for i in range(particles.shape[0]):
        for k in range(6):
            particles[i, k] = state[k] + noise[i, k] * sigma[k]
        for k in range(2):
            particles[i, 2 + k] = min(max(particles[i, 2 + k], lo[k]), hi[k])


# Acklam's rational approximation of the standard normal quantile (relative error < 1.2e-9).
_A = (-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02, 1.383577518672690e+02,
      -3.066479806614716e+01, 2.506628277459239e+00)
_B = (-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02, 6.680131188771972e+01,
      -1.328068155288572e+01)
_C = (-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00, -2.549732539343734e+00,
      4.374664141464968e+00, 2.938163982698783e+00)
_D = (7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00, 3.754408661907416e+00)


@_jit(fastmath=True)
def _uniform_to_normal(u):
    """In place: uniforms ``u`` (float32 in [0, 1)) -> standard normals by the inverse CDF."""
    a0, a1, a2, a3, a4, a5 = _A
    b0, b1, b2, b3, b4 = _B
    c0, c1, c2, c3, c4, c5 = _C
    d0, d1, d2, d3 = _D
    flat = u.reshape(-1)
    for i in range(flat.size):
        p = np.float64(flat[i]) + 0.5 / 16777216.0  # centre of the float32 grid step: inside (0, 1)
        if p < 0.02425 or p > 0.97575:
            q = np.sqrt(-2.0 * np.log(min(p, 1.0 - p)))
            x = ((((((c0 * q + c1) * q + c2) * q + c3) * q + c4) * q + c5)
                 / ((((d0 * q + d1) * q + d2) * q + d3) * q + 1.0))
            if p > 0.5:
                x = -x
        else:
            q = p - 0.5
            r = q * q
            x = ((((((a0 * r + a1) * r + a2) * r + a3) * r + a4) * r + a5) * q
                 / (((((b0 * r + b1) * r + b2) * r + b3) * r + b4) * r + 1.0))
        flat[i] = x


def standard_normal(rng: np.random.Generator, shape) -> np.ndarray:
    """Standard normal ``float32`` samples of ``shape`` from ``rng``: uniforms through the
    inverse normal CDF (about twice as fast as ``rng.standard_normal`` for the particle
    filters' noise; ``rng.standard_normal`` itself without numba)."""
    if not HAVE_NUMBA:
        return rng.standard_normal(shape, dtype=np.float32)
    u = rng.random(shape, dtype=np.float32)
    _uniform_to_normal(u)
    return u


@_jit
def resample(particles, weights, c, lo, hi, u):
    """Seed 002 eq. (2) count, then systematic resampling with offset ``u``: the new particles
    ``(n, 6)`` and their uniform weights ``(n,)`` (one call for the two steps above)."""
    n = entropy_count(weights, c, lo, hi)
    idx = systematic_indices(weights, n, u)
    out = np.empty((n, particles.shape[1]), dtype=particles.dtype)
    for i in range(n):
        out[i, :] = particles[idx[i], :]
    return out, np.full(n, 1.0 / n)


@_jit
def box_bin_counts(bin_image, rects, bins):
    """Counts ``(N, bins) float64`` of each bin of ``bin_image (H, W) int16`` (-1 = no bin) inside
    the rectangles ``rects (N, 4) int [x1, y1, x2, y2]`` (clipped to the image, x2/y2 exclusive):
    the limb filter's per-particle hue histograms (``partlab.tracking.core.hue_histogram``) by
    direct counting, which for hand-sized boxes costs less than an integral histogram of the
    region the particles cover."""
    n = rects.shape[0]
    out = np.zeros((n, bins), dtype=np.float64)
    for i in range(n):
        for y in range(rects[i, 1], rects[i, 3]):
            for x in range(rects[i, 0], rects[i, 2]):
                b = bin_image[y, x]
                if b >= 0:
                    out[i, b] += 1.0
    return out
