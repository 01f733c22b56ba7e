"""One body part's colour particle filter (seed 002 sec. 3, 3.1, 3.2; Nummiaro et al.).

State of a particle: ``(N, 6) float32 [X, Y, W, H, dX, dY]``, (X, Y) the centre of the
rectangle, (W, H) its size and (dX, dY) the centre's velocity in pixels per frame.
Dynamics are constant velocity, ``X_t = X_{t-1} + dX_{t-1}`` plus Gaussian process
noise per component (``partlab.tracking.params.PartNoise``: the "variance parameters" that
retraining fits). Weights are ``exp(-lam (1 - rho))`` of the Bhattacharyya
coefficient ``rho`` between a particle's equalized histogram and the target's
(sec. 3.1); the estimate is the weighted mean; particles are then resampled
systematically to the count of eq. (2) (entropy-adaptive, C = 1.2, 200..1000).

The per-particle work runs in compiled kernels (``partlab.tracking.core.kernels``, numba; the numpy +
OpenCV path remains when numba is missing); ``ycc`` is an array or a
``partlab.tracking.core.lazy_ycc.LazyYcc`` converted only where the particles are.

A frame is ``predict()`` then ``measure(ycc)`` (or ``coast()`` when the part is
occluded: dynamics only, appearance frozen, sec. 4.3), then ``update_model(ycc)`` and
``resample()``.
"""

from __future__ import annotations

import numpy as np

from partlab.tracking.core import kernels
from partlab.tracking.core.box import Box
from partlab.tracking.core.histogram import (
    _smooth,
    bhattacharyya,
    bhattacharyya_counts,
    binned_histogram,
    equalization_map,
    fused_lut,
    level_histogram,
    likelihood,
    update_reference,
)
from partlab.tracking.core.integral_histogram import particle_rectangles, rectangle_histograms, sampled_areas
from partlab.tracking.core.lazy_ycc import as_array, cover, cover_rects
from partlab.tracking.core.resampling import adaptive_particle_count, normalise_weights, systematic_resample
from partlab.tracking.params import BodyParams, PartNoise


def box_to_state(box: Box) -> np.ndarray:
    """``Box`` (top-left, size) -> ``(6,) float64 [X, Y, W, H, 0, 0]`` (centre, size, no velocity)."""
    return np.array([box.x + box.w / 2.0, box.y + box.h / 2.0, box.w, box.h, 0.0, 0.0])


def state_to_box(state: np.ndarray) -> Box:
    """``[X, Y, W, H, ...]`` -> ``Box`` with its top-left corner."""
    x, y, w, h = (float(v) for v in state[:4])
    return Box(x - w / 2.0, y - h / 2.0, max(w, 0.0), max(h, 0.0))


class PartFilter:
    """The particle filter and appearance model of one tracked rectangle."""

    def __init__(self, box: Box, ycc: np.ndarray, params: BodyParams, noise: PartNoise,
                 rng: np.random.Generator, n: int | None = None, surround: np.ndarray | None = None):
        if box.w < 2 or box.h < 2:
            raise ValueError(f"a tracked part needs a box of at least 2 x 2 pixels, got {box}")
        self.params = params
        self.noise = noise
        self.rng = rng
        self._sigma = np.array([noise.x, noise.y, noise.w, noise.h, noise.vx, noise.vy], dtype=np.float32)
        #: 256-level counts ``(3, 256)`` of the ring around the person (``appearance.surround``), or None
        self.surround = surround
        self.weighted = False  # the target is background-weighted (while the camera moves)
        self.reseed(box, ycc, n=n)

    # -- initialisation -------------------------------------------------------------
    def reseed(self, box: Box, ycc: np.ndarray, n: int | None = None, keep_velocity: bool = False,
               keep_model: bool = False) -> None:
        """Restart at ``box``: new particles around it and a new appearance model from it
        (initialisation, and the adjustment of sec. 4.3); ``keep_model``: keep the current
        model (the adjustment found the part with it)."""
        velocity = self.state[4:6].copy() if keep_velocity and hasattr(self, "state") else np.zeros(2)
        self.state = box_to_state(box)
        self.state[4:6] = velocity
        self.base_size = np.array([box.w, box.h], dtype=np.float64)
        lo, hi = self.params.dynamics.size_range
        self._size_lo = (lo * self.base_size).astype(np.float32)
        self._size_hi = (hi * self.base_size).astype(np.float32)
        n = int(n or self.params.particles.initial)
        spread = self._sigma * np.float32(self.params.dynamics.init_spread)
        self.particles = (self.state.astype(np.float32)
                          + self.rng.standard_normal((n, 6), dtype=np.float32) * spread)
        self._clip_sizes()
        self.weights = np.full(n, 1.0 / n)
        self.similarity = 1.0
        if keep_model and hasattr(self, "reference"):
            return
        self.reference = _box_histogram(ycc, box)
        self._refresh_map()

    def _refresh_map(self) -> None:
        p = self.params
        if kernels.HAVE_NUMBA:
            smoothed = _smooth(np.asarray(self.reference, dtype=np.float64), p.appearance.equalization_smoothing)
            self.mapping, self.target, self.sqrt_target = kernels.equalize(
                smoothed, self.reference, p.appearance.bins_per_channel, p.appearance.equalization_floor)
            self._weigh_by_surround()
            return
        self.mapping = equalization_map(self.reference, p.appearance.bins_per_channel,
                                        p.appearance.equalization_smoothing,
                                        p.appearance.equalization_floor)
        self.lut = fused_lut(self.mapping, p.appearance.bins_per_channel)
        self.target = binned_histogram(self.reference, self.mapping, p.appearance.bins_per_channel)
        per_channel = self.target.reshape(3, -1)
        per_channel = per_channel / np.maximum(per_channel.sum(axis=1, keepdims=True), 1e-12)
        self.sqrt_target = np.sqrt(per_channel).reshape(-1)
        self._weigh_by_surround()

    def _weigh_by_surround(self) -> None:
        """The background-weighted target (``appearance.surround``): bins common in the ring
        around the person count less, ``v_u = max(min(o* / o_u, 1), surround_floor)``; renormalised
        per channel."""
        if self.surround is None or not self.weighted:
            return
        b = self.params.appearance.bins_per_channel
        o = binned_histogram(self.surround, self.mapping, b).reshape(3, b)
        positive = np.where(o > 0, o, np.inf)
        v = np.where(o > 0, np.minimum(positive.min(axis=1, keepdims=True) / positive, 1.0), 1.0)
        v = np.maximum(v, self.params.appearance.surround_floor)
        target = self.target.reshape(3, b) * v
        self.target = target.reshape(-1)
        per_channel = target / np.maximum(target.sum(axis=1, keepdims=True), 1e-12)
        self.sqrt_target = np.sqrt(per_channel).reshape(-1)

    def weigh_by_background(self, on: bool) -> None:
        """Turn the background-weighted target on or off (the tracker: while the camera moves)."""
        if self.surround is not None and on != self.weighted:
            self.weighted = on
            self._refresh_map()

    def _clip_sizes(self) -> None:
        wh = self.particles[:, 2:4]
        np.maximum(wh, self._size_lo, out=wh)
        np.minimum(wh, self._size_hi, out=wh)

    # -- one frame --------------------------------------------------------------------
    @property
    def n(self) -> int:
        return len(self.particles)

    @property
    def box(self) -> Box:
        """The estimate as a ``Box`` (cached while the estimate's X, Y, W, H do not change)."""
        key = self.state[:4].tobytes()
        if key != getattr(self, "_box_key", None):
            x, y, w, h = self.state[:4].tolist()
            self._box = Box(x - w / 2.0, y - h / 2.0, max(w, 0.0), max(h, 0.0))
            self._box_key = key
        return self._box

    def predict(self) -> None:
        """Constant-velocity motion plus process noise (seed 002 sec. 3)."""
        p = self.particles
        noise = kernels.standard_normal(self.rng, p.shape)
        if kernels.HAVE_NUMBA:
            kernels.drift(p, noise, self._sigma, self._size_lo, self._size_hi)
            return
        p[:, 0] += p[:, 4]
        p[:, 1] += p[:, 5]
        p += noise * self._sigma
        self._clip_sizes()

    def predicted_box(self) -> Box:
        """Where dynamics alone put the part this frame (the previous estimate moved by its velocity)."""
        s = self.state.copy()
        s[0:2] += s[4:6]
        return state_to_box(s)

    def measure(self, ycc: np.ndarray, anchor_x: float | None = None, anchor_sigma: float = 0.0,
                anchor_y: float | None = None, anchor_sigma_y: float = 0.0) -> None:
        """Weigh every particle by its colour likelihood (one integral histogram) and take
        the weighted mean as the estimate.

        With ``anchor_x`` and ``anchor_sigma > 0`` the weights are also multiplied by
        ``exp(-0.5 ((X - anchor_x) / anchor_sigma)^2)``: a part of a body stays near the
        body's axis (the torso's centre line) instead of following a look-alike part of
        someone else (see ``BodyParams.dynamics.coherence``); ``anchor_y`` likewise keeps its height
        relative to the torso near the one it started with."""
        _, rho, areas = self._similarities(ycc, self.particles)
        if kernels.HAVE_NUMBA:
            ax, sx = (float(anchor_x), float(anchor_sigma)) if anchor_x is not None else (0.0, 0.0)
            ay, sy = (float(anchor_y), float(anchor_sigma_y)) if anchor_y is not None else (0.0, 0.0)
            self.weights, self.state = kernels.weigh(self.particles, rho, areas, float(self.noise.lam),
                                                     ax, sx, ay, sy)
            return
        weights = likelihood(rho, self.noise.lam)
        weights[areas < 4] = 0.0
        if anchor_x is not None and anchor_sigma > 0:
            weights *= np.exp(-0.5 * ((self.particles[:, 0] - anchor_x) / anchor_sigma) ** 2)
        if anchor_y is not None and anchor_sigma_y > 0:
            weights *= np.exp(-0.5 * ((self.particles[:, 1] - anchor_y) / anchor_sigma_y) ** 2)
        self.weights = normalise_weights(weights)
        self.state = (self.weights[:, None] * self.particles.astype(np.float64)).sum(axis=0)

    def probe(self, ycc: np.ndarray, spread: float, n: int = 200,
              centre: tuple[float, float] | None = None, allowed=None) -> tuple[np.ndarray, float]:
        """Look for the part around the current estimate (or around ``centre``) without
        changing the filter: ``n`` candidate centres within ``spread`` pixels (Gaussian), the
        one whose histogram matches the (frozen) model best. Returns ``(state (6,), rho)``; used
        to end an occlusion when the hidden person shows again away from where its dynamics
        put it (``allowed``: which candidates may be it), and by the adjustment to find a lost
        part on its body (``partlab.tracking.body.adjustment``)."""
        cand = self.candidates(spread, n, centre)
        rho = self.similarities(ycc, cand)
        if allowed is not None:  # ``allowed(cand) -> (n,) bool``: the others count as no match
            rho = rho * allowed(cand)
        k = int(np.argmax(rho))
        return cand[k].astype(np.float64), float(rho[k])

    def candidates(self, spread: float, n: int = 200, centre: tuple[float, float] | None = None) -> np.ndarray:
        """``(n, 6) float32`` states of the estimate's size at centres drawn around ``centre``
        (default: the estimate) with standard deviation ``spread`` pixels."""
        cand = np.repeat(self.state[None, :].astype(np.float32), n, axis=0)
        if centre is not None:
            cand[:, 0:2] = np.asarray(centre, dtype=np.float32)
        cand[:, 0:2] += self.rng.standard_normal((n, 2), dtype=np.float32) * np.float32(spread)
        return cand

    def similarities(self, ycc: np.ndarray, states: np.ndarray) -> np.ndarray:
        """Bhattacharyya coefficients ``(N,)`` of ``states`` with the (frozen) model; 0 for a
        rectangle cut to less than 0.8 of its area by the frame edge."""
        states = np.asarray(states, dtype=np.float32)
        rects, rho, _ = self._similarities(ycc, states)
        full = ((rects[:, 2] - rects[:, 0]) * (rects[:, 3] - rects[:, 1])).astype(np.float32)
        rho = np.array(rho, dtype=np.float64)
        rho[full < 0.8 * states[:, 2] * states[:, 3]] = 0.0  # cut by the frame edge
        return rho

    def _similarities(self, ycc: np.ndarray, states: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Rectangles ``(N, 4) int32``, Bhattacharyya coefficients ``(N,)`` with the model and
        areas ``(N,)`` (pixels, a sampled pixel standing for ``stride**2``) of ``states``: one
        integral histogram over the region they cover (compiled kernel, or numpy + OpenCV)."""
        H, W = ycc.shape[:2]
        stride = self._stride()
        if kernels.HAVE_NUMBA:
            rects = kernels.rectangles(states, W, H)
            pixels = cover_rects(ycc, rects)
            rho, areas = kernels.rectangle_rho(pixels, self.mapping, rects, stride, self.sqrt_target)
        else:
            rects = particle_rectangles(states, W, H)
            counts = rectangle_histograms(as_array(ycc), self.lut, rects, stride)
            areas = sampled_areas(rects, stride)
            rho = bhattacharyya_counts(counts, areas, self.sqrt_target)
        return rects, rho, areas * (stride * stride)

    def shift(self, delta: np.ndarray) -> None:
        """Move the estimate and every particle by ``delta`` (dx, dy)."""
        self.state[0:2] += delta
        self.particles[:, 0:2] += np.asarray(delta, dtype=np.float32)

    def steer(self, target: Box, gain: float) -> None:
        """Move the estimate ``gain`` of the way to ``target`` (centre and size), the particles with
        it (shifted, sizes scaled), and let the size bounds follow (a detection re-sizes the part;
        ``dynamics.size_range`` then holds it near its new size)."""
        t = box_to_state(target)
        old = self.state[2:4].astype(np.float64).copy()
        delta = gain * (t[0:2] - self.state[0:2])
        self.shift(delta)
        new = np.maximum(old + gain * (t[2:4] - old), 2.0)
        self.state[2:4] = new
        self.particles[:, 2:4] *= (new / np.maximum(old, 1e-6)).astype(np.float32)
        self.base_size = new.astype(np.float64)
        lo, hi = self.params.dynamics.size_range
        self._size_lo = (lo * self.base_size).astype(np.float32)
        self._size_hi = (hi * self.base_size).astype(np.float32)
        self._clip_sizes()

    def _stride(self) -> int:
        """2 (every second pixel) for parts at least ``histogram_stride_min`` wide and tall."""
        m = self.params.appearance.histogram_stride_min
        return 2 if m > 0 and min(self.state[2], self.state[3]) >= m else 1

    def coast(self) -> None:
        """Dynamics only (occlusion, sec. 4.3.1-4.3.2): the estimate moves by its velocity and
        the particles are re-centred on it, so the cloud does not drift or spread."""
        self.state[0:2] += self.state[4:6]
        noise = kernels.standard_normal(self.rng, self.particles.shape)
        if kernels.HAVE_NUMBA:
            kernels.scatter(self.particles, self.state.astype(np.float32), noise, self._sigma, self._size_lo,
                            self._size_hi)
        else:
            self.particles[:, :] = self.state.astype(np.float32)
            self.particles += noise * self._sigma
            self._clip_sizes()
        self.weights = np.full(self.n, 1.0 / self.n)

    def set_velocity(self, velocity: np.ndarray) -> None:
        """Replace the velocity of the estimate and of every particle (e.g. an occluded part
        follows the visible parts of its person)."""
        self.state[4:6] = velocity
        self.particles[:, 4:6] = np.asarray(velocity, dtype=np.float32)

    def nudge_velocity(self, velocity: np.ndarray, gain: float) -> None:
        """Move the velocity of the estimate and of every particle ``gain`` of the way to
        ``velocity`` (the particles keep their spread)."""
        delta = gain * (np.asarray(velocity, dtype=np.float64) - self.state[4:6])
        self.state[4:6] += delta
        self.particles[:, 4:6] += delta.astype(np.float32)

    def appearance(self, ycc: np.ndarray) -> np.ndarray:
        """``Q_t``: the 256-level histogram ``(3, 256)`` of the current estimate's rectangle."""
        return _box_histogram(ycc, self.box)

    def score(self, observed: np.ndarray) -> float:
        """Bhattacharyya coefficient of a 256-level histogram with this part's model."""
        if kernels.HAVE_NUMBA:
            return float(kernels.similarity(observed, self.mapping, self.sqrt_target))
        b = self.params.appearance.bins_per_channel
        return float(bhattacharyya(binned_histogram(observed, self.mapping, b), self.target, b))

    def update_model(self, observed: np.ndarray) -> None:
        """Seed 002 eq. (1) on the 256-level reference, then a new equalization map."""
        self.reference = update_reference(self.reference, observed, self.params.appearance.model_update)
        self._refresh_map()

    def resample(self) -> None:
        """Systematic resampling to the entropy-adaptive count of seed 002 eq. (2)."""
        p = self.params
        if kernels.HAVE_NUMBA:  # the weights are normalised (measure, coast, reseed)
            self.particles, self.weights = kernels.resample(self.particles, self.weights, p.particles.c,
                                                            p.particles.min, p.particles.max, self.rng.random())
            return
        n = adaptive_particle_count(self.weights, p.particles.c, p.particles.min, p.particles.max)
        idx = systematic_resample(self.weights, n, self.rng)
        self.particles = self.particles[idx]
        self.weights = np.full(n, 1.0 / n)


def surround_counts(ycc: np.ndarray, box: Box, share: float) -> np.ndarray | None:
    """256-level counts ``(3, 256)`` of the ring around ``box``, ``share`` of its width and height
    wide on each side (clipped to the frame), or None when ``share`` is 0 or the ring is empty."""
    if share <= 0:
        return None
    H, W = ycc.shape[:2]
    x, y, w, h = _int_box(box)
    dx, dy = int(round(share * w)), int(round(share * h))
    x1, y1, x2, y2 = max(x - dx, 0), max(y - dy, 0), min(x + w + dx, W), min(y + h + dy, H)
    if x2 <= x1 or y2 <= y1:
        return None
    region = np.asarray(ycc[y1:y2, x1:x2])
    keep = np.ones(region.shape[:2], bool)
    keep[max(y - y1, 0):max(y + h - y1, 0), max(x - x1, 0):max(x + w - x1, 0)] = False
    pixels = region[keep]
    if len(pixels) == 0:
        return None
    return np.stack([np.bincount(pixels[:, c], minlength=256) for c in range(3)]).astype(np.float64)


def _box_histogram(ycc, box: Box) -> np.ndarray:
    """256-level histogram ``(3, 256)`` of ``box`` (rounded to whole pixels) in ``ycc`` (an
    array or a :class:`partlab.tracking.core.lazy_ycc.LazyYcc`)."""
    x, y, w, h = _int_box(box)
    return level_histogram(cover(ycc, x, y, x + w, y + h), (x, y, w, h))


def _int_box(box: Box) -> tuple[int, int, int, int]:
    return (int(round(box.x)), int(round(box.y)), max(int(round(box.w)), 1), max(int(round(box.h)), 1))
