"""Xu, Deng & Jia sec. 3: one hue-histogram particle filter refined by mean shift.

State ``(x, y, alpha)``: the window ``W = (x, y, alpha w, alpha h)`` centred at ``(x, y)`` with a
fixed reference size ``(w, h)``. Dynamics ``x_t - x_{t-1} = x_{t-1} - x_{t-2} + w_t``: each sample
carries its last displacement (``vel``), damped by ``velocity_decay``. A sample's confidence is
eq. 1-2, ``pi = exp(-lam D^2)`` with ``D`` the Bhattacharyya distance of the window's hue histogram
to the reference (:mod:`partlab.tracking.core.hue_histogram`, all samples from one integral
histogram). The estimate is the (weighted) mean of the samples; mean shift on the reference's
back-projection moves it to the nearest peak; the samples are then redistributed around the
refined estimate (shifted by the refinement) and resampled.

Arrays: ``pos (N, 3) float64 [x, y, alpha]``, ``vel (N, 3)``, ``weights (N,)``.
"""

from __future__ import annotations

import numpy as np

from partlab.tracking.core.hue_histogram import box_histograms, hue_confidence, mean_shift
from partlab.tracking.core.resampling import systematic_resample


class HueFilter:
    def __init__(self, centre, size, ref_hist: np.ndarray, n: int, rng: np.random.Generator,
                 alpha_range=(0.7, 1.4)):
        self.rng = rng
        self.size = np.asarray(size, float)  # reference (w, h), pixels
        self.ref = np.asarray(ref_hist, float)
        self.alpha_range = alpha_range
        self.pos = np.tile([float(centre[0]), float(centre[1]), 1.0], (n, 1))
        self.vel = np.zeros((n, 3))
        self.weights = np.full(n, 1.0 / n)
        self.conf = np.zeros(n)
        self.estimate = self.pos[0].copy()

    @property
    def n(self) -> int:
        return len(self.pos)

    def predicted(self, decay: float) -> np.ndarray:
        """``(N, 3)`` each sample moved by its damped velocity (the prior's centres, before noise)."""
        return self.pos + decay * self.vel

    def propagate(self, decay: float, noise_xy: float, noise_alpha: float) -> None:
        """Standard sampling: the second-order dynamics plus white noise ``w_t``."""
        new = self.predicted(decay)
        new[:, :2] += self.rng.standard_normal((self.n, 2)) * noise_xy
        new[:, 2] += self.rng.standard_normal(self.n) * noise_alpha
        self._move_to(new)

    def _move_to(self, new: np.ndarray) -> None:
        new[:, 2] = np.clip(new[:, 2], *self.alpha_range)
        self.vel = new - self.pos
        self.pos = new

    def replace(self, idx: np.ndarray, xy: np.ndarray, noise_alpha: float) -> None:
        """Samples ``idx`` get translations ``xy`` drawn elsewhere (importance sampling, sec. 4),
        their alpha the previous alpha plus noise."""
        new = self.pos.copy()
        prev = self.pos - self.vel
        new[idx, :2] = xy
        new[idx, 2] = prev[idx, 2] + self.rng.standard_normal(len(idx)) * noise_alpha
        new[idx, 2] = np.clip(new[idx, 2], *self.alpha_range)
        self.vel[idx] = new[idx] - prev[idx]
        self.pos = new

    def boxes(self, pos: np.ndarray | None = None) -> np.ndarray:
        """``(N, 4)`` windows ``x, y, w, h`` (top-left corner) of the samples."""
        p = self.pos if pos is None else np.atleast_2d(pos)
        w, h = self.size[0] * p[:, 2], self.size[1] * p[:, 2]
        return np.stack([p[:, 0] - w / 2, p[:, 1] - h / 2, w, h], axis=1)

    def weigh(self, integral: np.ndarray, lam: float, correction: np.ndarray | None = None) -> None:
        """Eq. 1-2 confidences times the importance correction (1 for standard samples)."""
        self.conf = hue_confidence(box_histograms(integral, self.boxes()), self.ref, lam)
        w = self.conf if correction is None else self.conf * correction
        total = w.sum()
        self.weights = w / total if total > 0 and np.isfinite(total) else np.full(self.n, 1.0 / self.n)

    def estimate_mean(self) -> np.ndarray:
        """Sec. 3: the state is estimated by the mean of the samples (weighted by their weights)."""
        self.estimate = self.weights @ self.pos
        return self.estimate

    def refine(self, backproj: np.ndarray | None, iterations: int, eps: float) -> np.ndarray:
        """Mean shift from the estimate's window; the samples are redistributed by the same shift."""
        if backproj is None:
            return self.estimate
        box = self.boxes(self.estimate)[0]
        nx, ny, _, _ = mean_shift(backproj, box, iterations, eps)
        shift = np.array([nx - box[0], ny - box[1], 0.0])
        self.estimate = self.estimate + shift
        self.pos += shift
        self.vel += shift
        return self.estimate

    def resample(self) -> None:
        idx = systematic_resample(self.weights, self.n, self.rng)
        self.pos, self.vel, self.conf = self.pos[idx], self.vel[idx], self.conf[idx]
        self.weights = np.full(self.n, 1.0 / self.n)

    def reset(self, centre, size=None, ref_hist=None) -> None:
        """Start again at ``centre`` (re-acquisition): no velocity, alpha 1."""
        if size is not None:
            self.size = np.asarray(size, float)
        if ref_hist is not None:
            self.ref = np.asarray(ref_hist, float)
        self.pos = np.tile([float(centre[0]), float(centre[1]), 1.0], (self.n, 1))
        self.vel = np.zeros((self.n, 3))
        self.weights = np.full(self.n, 1.0 / self.n)
        self.estimate = self.pos[0].copy()

    def box(self) -> tuple[float, float, float, float]:
        return tuple(float(v) for v in self.boxes(self.estimate)[0])
