"""Resampling and particle-count adaptation shared by every particle filter.

Small pure functions over numpy arrays; randomness always comes from a
``numpy.random.Generator`` passed in, so a ``--seed`` makes whole runs repeatable.
"""

from __future__ import annotations

import numpy as np


def normalise_weights(weights: np.ndarray) -> np.ndarray:
    """Weights scaled to sum to one; all-zero or non-finite weights become uniform."""
    w = np.asarray(weights, dtype=np.float64)
    w = np.where(np.isfinite(w) & (w > 0), w, 0.0)
    total = w.sum()
    if total <= 0:
        return np.full(w.shape, 1.0 / max(w.size, 1))
    return w / total


def systematic_resample(weights: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """Indexes of ``n`` particles drawn by systematic resampling.

    One uniform offset, then every sample is exactly 1/n apart along the cumulative
    weights (Kitagawa 1996; the scheme of filterpy's ``systematic_resample``), which
    gives the lowest variance of the standard schemes. ``n`` may differ from
    ``len(weights)``, as the entropy-adaptive count needs.
    """
    w = normalise_weights(weights)
    positions = (rng.random() + np.arange(n)) / n
    cumulative = np.cumsum(w)
    cumulative[-1] = 1.0  # guard against round-off leaving the last bin short
    return np.searchsorted(cumulative, positions, side="right").clip(0, w.size - 1)


def weight_entropy(weights: np.ndarray) -> float:
    """Shannon entropy ``-sum w log w`` of normalised weights (0 log 0 = 0)."""
    w = normalise_weights(weights)
    nz = w[w > 0]
    return float(-(nz * np.log(nz)).sum())


def adaptive_particle_count(weights: np.ndarray, c: float = 1.2, lo: int = 200, hi: int = 1000) -> int:
    """Next particle count from the entropy of the current weights (seed 002, eq. (2)).

    ``N_t = C * N_{t-1} * H(w) / log(N_{t-1})``: uniform weights (the target is lost
    or many regions look alike) give the largest count, ``C * N_{t-1}``; weights
    concentrated on few particles shrink it. Bounded to ``[lo, hi]`` as in the paper
    (200..1000) so that it never changes drastically.
    """
    n_prev = int(np.asarray(weights).size)
    if n_prev <= 1:
        return lo
    ratio = weight_entropy(weights) / np.log(n_prev)
    return int(np.clip(round(c * n_prev * ratio), lo, hi))
