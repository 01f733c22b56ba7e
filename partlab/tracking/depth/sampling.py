"""Xu, Deng & Jia sec. 4: depth-based importance sampling.

A hand's candidate region ``R = (x_c, y_c, w, h)`` (Table 1) defines the importance function of
eq. 3, ``g(x_trans) = N(u, K)`` with ``u = (x_c, y_c)`` and ``K = diag((w/2)^2, (h/2)^2)``. A
fraction ``q`` of the samples draws its translation from ``g`` (its scale alpha from the previous
alpha plus noise); the other ``1 - q`` are standard samples from the dynamics.

The paper gives no weight for this mixture. Samples drawn from ``g`` instead of from the prior
``f`` (the dynamics' prediction, a mixture over the previous samples) must carry the correction
``f / g``, as in ICONDENSATION (Isard & Blake 1998, sec. 3); standard samples carry 1. ``f`` has a
small uniform part (``prior_floor``) for sudden motion (ICONDENSATION's reinitialisation
component), so an importance sample far from every prediction keeps a small weight, not none.
"""

from __future__ import annotations

import numpy as np


def importance_density(xy: np.ndarray, u: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """``g`` of eq. 3 at ``xy (M, 2)``: the 2D Gaussian with mean ``u (2,)`` and std ``sigma (2,)``."""
    z = (xy - u) / sigma
    return np.exp(-0.5 * (z * z).sum(axis=1)) / (2 * np.pi * sigma[0] * sigma[1])


def prior_density(xy: np.ndarray, predicted: np.ndarray, noise: float, floor: float, area: float) -> np.ndarray:
    """``f`` at ``xy (M, 2)``: the dynamics' prediction, ``(1 - floor) mean_j N(xy; predicted_j,
    noise^2 I) + floor / area`` (``predicted (N, 2)``: each previous sample moved by its velocity)."""
    d2 = ((xy[:, None, :] - predicted[None, :, :]) ** 2).sum(axis=2)  # (M, N)
    gauss = np.exp(-0.5 * d2 / noise**2).mean(axis=1) / (2 * np.pi * noise**2)
    return (1.0 - floor) * gauss + floor / area


def draw_importance(rng: np.random.Generator, m: int, u: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """``(m, 2)`` translations drawn from eq. 3's ``g``."""
    return u + rng.standard_normal((m, 2)) * sigma


def icondensation_correction(xy: np.ndarray, u: np.ndarray, sigma: np.ndarray, predicted: np.ndarray,
                             noise: float, floor: float, area: float) -> np.ndarray:
    """The weight ``f / g`` of importance samples ``xy (M, 2)`` (standard samples carry 1)."""
    ratio = prior_density(xy, predicted, noise, floor, area) / np.maximum(importance_density(xy, u, sigma), 1e-300)
    return ratio
