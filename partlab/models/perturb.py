"""Failure samples from corrected trajectories: perturbed copies of true part states.

A few corrected clips hold few real tracker failures, and the four SVMs need
negatives of every kind (seed 002 sec. 4.2 trains each on 150 hand-labelled
samples). So failures are simulated on the truth the way colour particle filters
fail: a part's box **sticks** where it was (caught by a background object of similar
colour while the person walks on), **jumps** to a nearby wrong place and follows from
there, **drifts** away steadily, is **swapped** onto another part's position, or
**blows up / shrinks** (the filter spreads over a large similar-coloured region).
One part failing gives single-part samples, two or three give multi-part samples.
Every part of every sample is then labelled by the same rule as the tracker's
output (:func:`partlab.models.labels.label_states`), so a mild perturbation that stays on
the part is a positive or is dropped, never a false negative. All parts get a small
jitter (the tracker is never exact).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from partlab.models.features import DEFAULT_DT, dt_frames, features_from_history
from partlab.models.labels import LabelRule, label_states

FAILURE_MODES: tuple[str, ...] = ("stuck", "jump", "drift", "swap", "scale")


@dataclass(frozen=True)
class PerturbConfig:
    """How many samples of each kind one person's trajectory gives, and how hard they fail."""

    clean_fraction: float = 0.35   # untouched states (plus jitter): positives for all parts
    multi_fraction: float = 0.3    # of the perturbed ones: 2 or 3 parts failing
    jitter: float = 0.06           # std of the tracker-like noise, fraction of the part size
    offset_min: float = 0.8        # jump/stuck offsets, in part sizes
    offset_max: float = 3.0


def _failed_box(hist: np.ndarray, truth_hist: np.ndarray, part: int, onset: int, mode: str,
                rng: np.random.Generator, cfg: PerturbConfig) -> np.ndarray:
    """``(W, 4)`` failed trajectory of ``part`` over a window, failing from index ``onset``."""
    w = hist.shape[0]
    out = hist[:, part].copy()
    size = np.maximum(truth_hist[onset, part, 2:4], 1.0)
    angle = rng.uniform(0, 2 * np.pi)
    direction = np.array([np.cos(angle), np.sin(angle)])
    steps = np.arange(w - onset)[:, None]
    if mode == "stuck":
        offset = direction * size * rng.uniform(0.0, cfg.offset_min)
        out[onset:, :2] = hist[onset, part, :2] + offset
        out[onset:, 2:] = hist[onset, part, 2:]
    elif mode == "jump":
        offset = direction * size * rng.uniform(cfg.offset_min, cfg.offset_max)
        out[onset:, :2] = hist[onset:, part, :2] + offset
    elif mode == "drift":
        rate = direction * size * rng.uniform(0.1, 0.4)
        out[onset:, :2] = hist[onset:, part, :2] + rate * (steps + 1)
    elif mode == "swap":
        other = rng.choice([k for k in range(3) if k != part])
        out[onset:, :2] = hist[onset:, other, :2] + direction * size * rng.uniform(0.0, 0.3)
    elif mode == "scale":
        factor = rng.choice([rng.uniform(0.15, 0.4), rng.uniform(2.5, 5.0)])
        out[onset:, 2:] = hist[onset:, part, 2:] * factor
        out[onset:, :2] = hist[onset:, part, :2] + direction * size * rng.uniform(0.5, 1.5) * max(factor, 1.0)
    else:
        raise ValueError(f"unknown failure mode {mode!r}; expected one of {', '.join(FAILURE_MODES)}")
    return out


def perturbed_samples(frames: np.ndarray, history: np.ndarray, fps: float, n_samples: int,
                      rng: np.random.Generator, cfg: PerturbConfig = PerturbConfig(),
                      rule: LabelRule = LabelRule(), dt: float = DEFAULT_DT,
                      truth: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``n_samples`` feature vectors with part labels from one person's trajectory.

    ``frames``: ``(T,)`` increasing indices; ``history``: ``(T, 3, 4)`` ``[cx, cy, w, h]``,
    the truth itself or the tracker's output. ``truth``: ``(T, 3, 4)`` true states at the
    same frames to label against (NaN where unknown: dropped); default ``history``.
    Perturbing the tracker's own boxes keeps its geometry (inner rectangles are smaller
    and sit differently from tight truth boxes): trained on perturbed truth alone, the
    head SVM flagged ~40 % of correctly tracked heads of the body tracker.
    Returns ``X (n, 24)`` and ``labels (n, 3)`` (1 on, 0 off, -1 dropped).
    """
    history = np.asarray(history, dtype=np.float64)
    truth = history if truth is None else np.asarray(truth, dtype=np.float64)
    if truth.shape != history.shape:
        raise ValueError(f"truth {truth.shape} and history {history.shape} must have the same shape")
    frames = np.asarray(frames)
    t_len = history.shape[0]
    if t_len == 0 or n_samples <= 0:
        return np.zeros((0, 24)), np.zeros((0, 3), dtype=np.int8)
    k = dt_frames(fps, dt)
    xs, ys = [], []
    for _ in range(n_samples):
        t = int(rng.integers(0, t_len))
        start = int(np.searchsorted(frames, frames[t] - k, side="left"))
        # a failure that began up to 1.5 dt before t0 (onset index inside the window)
        truth_w = history[start:t + 1]   # the reference trajectory the failures depart from
        win = truth_w.copy()
        w = win.shape[0]
        u = rng.uniform()
        if u >= cfg.clean_fraction:
            n_fail = int(rng.choice([2, 3])) if rng.uniform() < cfg.multi_fraction else 1
            parts = rng.choice(3, size=n_fail, replace=False)
            for p in parts:
                onset = int(rng.integers(0, w))
                mode = FAILURE_MODES[int(rng.integers(0, len(FAILURE_MODES)))]
                win[:, p] = _failed_box(win, truth_w, int(p), onset, mode, rng, cfg)
        sizes = np.nan_to_num(np.maximum(truth_w[..., 2:4], 1.0), nan=1.0)
        noise = rng.normal(0.0, cfg.jitter, size=win.shape) * np.concatenate([sizes, sizes], axis=-1)
        win = win + noise
        win[..., 2:] = np.maximum(win[..., 2:], 1.0)
        xs.append(features_from_history(win, fps, frames[start:t + 1], dt)[-1])
        ys.append(label_states(win[-1], truth[t], rule))
    return np.asarray(xs), np.asarray(ys, dtype=np.int8)
