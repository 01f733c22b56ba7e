"""Failure-detector features: relative part states and their change over 0.5 s.

Seed 002 sec. 4.2: a failed part shows as an abnormal position relative to the
other parts and as an irregular change of it. With the state ``S_K = [cx, cy, w, h]``
of part ``K`` in head (H), torso (T), hip-leg (L), eq. (3) defines the relative state

    RS_K(t) = S_K(t) - 1/3 * sum_{I in H,T,L} S_I(t)

and the feature vector of one person at frame ``t0`` is

    [RS_H(t0), RS_T(t0), RS_L(t0), RS_H(t0) - RS_H(t0 - dt), RS_T(...) - ..., RS_L(...) - ...]

(24 numbers, in that order), with ``dt = 0.5 s`` converted to frames from the
clip's fps. The paper uses pixels; with ``normalise=True`` (the default, and what
the bundles use) every number is divided by the person's scale at ``t0``, the
median of the three part heights (the torso's when all is well; a single failed
part cannot move the median far), so one detector serves people 100 and 220 px
tall alike: in pixels, a head 20 px too low on a small person looks like the
normal head of a large one. Where a track is younger than ``dt`` the change is taken from its first
frame (the shorter span the tracker really has), so every frame gets a vector.
The same function serves training (tracks tables) and the running tracker (a
``(T, 3, 4)`` history), so both see identical numbers.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

#: The three parts of the body tracker, in feature order (seed 002 sec. 4.1).
BODY_PARTS: tuple[str, ...] = ("head", "torso", "hipleg")
#: Seed 002 sec. 4.2: "Delta t = 0.5 seconds".
DEFAULT_DT: float = 0.5
N_FEATURES: int = 24

FEATURE_NAMES: tuple[str, ...] = tuple(
    f"{kind}{part[0].upper()}_{c}"
    for kind in ("RS", "dRS")
    for part in BODY_PARTS
    for c in ("cx", "cy", "w", "h")
)


def dt_frames(fps: float, dt: float = DEFAULT_DT) -> int:
    """``dt`` seconds as a whole number of frames (at least 1)."""
    if not np.isfinite(fps) or fps <= 0:
        raise ValueError(f"fps must be a positive number, got {fps!r}")
    return max(1, int(round(dt * fps)))


def relative_states(states: np.ndarray) -> np.ndarray:
    """Eq. (3): ``(..., 3, 4)`` part states minus their mean over the three parts."""
    states = np.asarray(states, dtype=np.float64)
    return states - states.mean(axis=-2, keepdims=True)


def person_scale(states: np.ndarray) -> np.ndarray:
    """``(...)`` scale of ``(..., 3, 4)`` part states: the median of the three heights (>= 1 px)."""
    states = np.asarray(states, dtype=np.float64)
    return np.maximum(np.median(states[..., 3], axis=-1), 1.0)


def features_from_history(history: np.ndarray, fps: float, frames: np.ndarray | None = None,
                          dt: float = DEFAULT_DT, normalise: bool = True) -> np.ndarray:
    """Feature vectors of every frame of one person's history.

    ``history``: ``(T, 3, 4)`` ``[cx, cy, w, h]`` of head, torso, hip-leg, oldest first.
    ``frames``: ``(T,)`` increasing frame indices (default ``0..T-1``); with gaps, the
    reference of frame ``f`` is the first available frame at or after ``f - dt``.
    Returns ``(T, 24)`` float64 (see :data:`FEATURE_NAMES`), in pixels, or in units of
    :func:`person_scale` at each row's frame with ``normalise``.
    """
    history = np.asarray(history, dtype=np.float64)
    if history.ndim != 3 or history.shape[1:] != (3, 4):
        raise ValueError(f"history must have shape (T, 3, 4), got {history.shape}")
    t = history.shape[0]
    if frames is None:
        frames = np.arange(t)
    frames = np.asarray(frames)
    if frames.shape != (t,):
        raise ValueError(f"frames must have shape ({t},), got {frames.shape}")
    if t > 1 and np.any(np.diff(frames) <= 0):
        raise ValueError("frames must be strictly increasing")
    k = dt_frames(fps, dt)
    ref = np.searchsorted(frames, frames - k, side="left")
    rs = relative_states(history).reshape(t, 12)
    out = np.concatenate([rs, rs - rs[ref]], axis=1)
    if normalise:
        out /= person_scale(history)[:, None]
    return out


def newest_features(history: np.ndarray, fps: float, dt: float = DEFAULT_DT, normalise: bool = True) -> np.ndarray:
    """``(24,)`` feature vector of the newest frame of a contiguous ``(T, 3, 4)`` history."""
    history = np.asarray(history, dtype=np.float64)
    if history.ndim != 3 or history.shape[1:] != (3, 4) or history.shape[0] < 1:
        raise ValueError(f"history must have shape (T >= 1, 3, 4), got {history.shape}")
    k = dt_frames(fps, dt)
    window = history[-(k + 1):]
    return features_from_history(window, fps, dt=dt, normalise=normalise)[-1]


def person_histories(tracks: pd.DataFrame) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per track id, ``(frames (T,), history (T, 3, 4) [cx, cy, w, h])`` over the frames
    where head, torso and hip-leg are all present (other parts are ignored)."""
    df = tracks[tracks["part"].isin(BODY_PARTS)]
    out: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    if df.empty:
        return out
    df = df.assign(cx=df["x"] + df["w"] / 2.0, cy=df["y"] + df["h"] / 2.0)
    for tid, g in df.groupby("track_id", sort=True):
        if g.duplicated(["frame", "part"]).any():
            dup = g[g.duplicated(["frame", "part"])].iloc[0]
            raise ValueError(f"track {tid} has two {dup['part']} boxes at frame {dup['frame']}")
        wide = g.pivot(index="frame", columns="part", values=["cx", "cy", "w", "h"])
        cols = [(c, p) for p in BODY_PARTS for c in ("cx", "cy", "w", "h")]
        if any(c not in wide.columns for c in cols):
            continue
        wide = wide[cols].dropna().sort_index()
        if wide.empty:
            continue
        out[int(tid)] = (wide.index.to_numpy(dtype=np.int64), wide.to_numpy(dtype=np.float64).reshape(-1, 3, 4))
    return out


def features_from_tracks(tracks: pd.DataFrame, fps: float, dt: float = DEFAULT_DT,
                         normalise: bool = True) -> tuple[pd.DataFrame, np.ndarray]:
    """Feature vectors of every person and frame of a tracks table.

    Returns ``(keys, X)``: ``keys`` a DataFrame with columns ``track_id, frame`` and ``X``
    ``(len(keys), 24)``, row ``i`` of one belonging to row ``i`` of the other.
    """
    keys, feats = [], []
    for tid, (frames, hist) in person_histories(tracks).items():
        feats.append(features_from_history(hist, fps, frames, dt, normalise))
        keys.append(pd.DataFrame({"track_id": tid, "frame": frames}))
    if not feats:
        return pd.DataFrame({"track_id": pd.Series(dtype="int64"), "frame": pd.Series(dtype="int64")}), \
            np.zeros((0, N_FEATURES))
    return pd.concat(keys, ignore_index=True), np.concatenate(feats, axis=0)
