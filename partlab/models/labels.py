"""Training labels for the failure SVMs: is a tracked part on its corrected box?

Seed 002 sec. 4.2: "The state vectors not covering the target body part are labeled
as negative, while those falling inside are labeled as positive. The samples not
satisfying these two criteria are eliminated". Here a tracked box is

* **on** its part (label 1) when it is right by :func:`partlab.tracking.measures.right_box`
  with ``on_part`` (0.5) as the cover: at least half of its area inside the corrected box and
  its centre inside it (Zhao & Lee sec. 5.2, the same rule the evaluation uses);
* **off** (label 0) when less than ``off_part`` (0.2) of it lies inside the corrected
  box: it clearly covers something else;
* in between: dropped (label -1), so the two classes stay separable.

Every failure flag a user set by hand (``failure`` true and ``source == "human"``)
is a negative for that part and frame whatever the geometry says.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from partlab.models.features import BODY_PARTS
from partlab.tracking import measures

POSITIVE, NEGATIVE, DROPPED = 1, 0, -1
#: Names of the four SVMs: one per part (tracked or not) and single vs multi-part failure.
SVM_NAMES: tuple[str, ...] = BODY_PARTS + ("multi",)


@dataclass(frozen=True)
class LabelRule:
    """Thresholds on the fraction of a tracked box lying inside the corrected box."""

    on_part: float = 0.5
    off_part: float = 0.2

    def __post_init__(self):
        if not 0.0 <= self.off_part < self.on_part <= 1.0:
            raise ValueError(f"need 0 <= off_part < on_part <= 1, got {self.off_part}, {self.on_part}")


def _xywh(centred: np.ndarray) -> np.ndarray:
    """``[cx, cy, w, h]`` -> ``[x, y, w, h]`` (the failure features' states are centred)."""
    b = np.asarray(centred, dtype=np.float64)
    return np.concatenate([b[..., :2] - b[..., 2:4] / 2, b[..., 2:4]], axis=-1)


def inside_fraction(boxes: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Fraction of each ``[cx, cy, w, h]`` box's area inside the matching truth box
    (``(..., 4)`` each; a box of zero area counts as 0): :func:`partlab.tracking.measures.cover_fraction`."""
    return measures.cover_fraction(_xywh(boxes), _xywh(truth))


def label_states(states: np.ndarray, truth: np.ndarray, rule: LabelRule = LabelRule()) -> np.ndarray:
    """Labels (1 on, 0 off, -1 dropped) of ``(..., 4)`` ``[cx, cy, w, h]`` boxes against truth."""
    b, t = _xywh(states), _xywh(truth)
    on = measures.right_box(b, t, min_cover=rule.on_part)
    off = measures.cover_fraction(b, t) < rule.off_part
    return np.where(on, POSITIVE, np.where(off, NEGATIVE, DROPPED)).astype(np.int8)


def _centre_table(df: pd.DataFrame) -> pd.DataFrame:
    df = df[df["part"].isin(BODY_PARTS)]
    return df.assign(cx=df["x"] + df["w"] / 2.0, cy=df["y"] + df["h"] / 2.0)


def label_tracks(tracked: pd.DataFrame, truth: pd.DataFrame, rule: LabelRule = LabelRule()) -> pd.DataFrame:
    """Label every head/torso/hip-leg box of ``tracked`` against ``truth`` (same track ids).

    Returns columns ``track_id, frame, part, label``. A tracked box with no truth box
    at its frame is dropped (nobody said where the part was), unless a user flagged it
    as failed by hand in either table, which makes it a negative.
    """
    tr = _centre_table(tracked)
    tt = _centre_table(truth)[["track_id", "frame", "part", "cx", "cy", "w", "h"]]
    merged = tr.merge(tt, on=["track_id", "frame", "part"], how="left", suffixes=("", "_t"))
    have = merged["cx_t"].notna().to_numpy()
    labels = np.full(len(merged), DROPPED, dtype=np.int8)
    if have.any():
        m = merged[have]
        labels[have] = label_states(m[["cx", "cy", "w", "h"]].to_numpy(), m[["cx_t", "cy_t", "w_t", "h_t"]].to_numpy(),
                                    rule)
    out = merged[["track_id", "frame", "part"]].copy()
    out["label"] = labels
    flags = pd.concat([d[(d["source"] == "human") & d["failure"].astype(bool)][["track_id", "frame", "part"]]
                       for d in (tracked, truth) if "source" in d.columns and "failure" in d.columns])
    if len(flags):
        key = pd.MultiIndex.from_frame(out[["track_id", "frame", "part"]])
        flagged = key.isin(pd.MultiIndex.from_frame(flags.drop_duplicates()))
        out.loc[flagged, "label"] = NEGATIVE
    return out.reset_index(drop=True)


def labels_for_keys(labels: pd.DataFrame, keys: pd.DataFrame) -> np.ndarray:
    """``(len(keys), 3)`` labels of head, torso, hip-leg for each ``track_id, frame`` key
    (-1 where a part has no label)."""
    wide = labels.pivot_table(index=["track_id", "frame"], columns="part", values="label", aggfunc="min")
    wide = wide.reindex(columns=list(BODY_PARTS))
    idx = pd.MultiIndex.from_frame(keys[["track_id", "frame"]])
    return wide.reindex(idx).fillna(DROPPED).to_numpy(dtype=np.int8)


def svm_targets(labels: np.ndarray) -> dict[str, np.ndarray]:
    """Targets of the four SVMs from ``(N, 3)`` part labels; -1 = not a sample of that SVM.

    Part SVMs: 1 tracked, 0 failed, from frames where at most one part failed: when two
    or three are lost no part's relative state is trustworthy (seed 002 sec. 4.2 says
    the part SVMs "may become ineffective" then), and it is the ``multi`` SVM's job to
    say so; such frames would only blur the part SVMs' boundaries. The ``multi`` SVM learns from frames where every
    part is labelled and at least one failed: 1 = a single part failed (adjust it from
    the other two), 0 = two or three failed (re-initialise). Positive is always the
    milder case, so "high true-negative rate" means "failures are caught".
    """
    labels = np.asarray(labels)
    n_failed = np.sum(labels == NEGATIVE, axis=1)
    out = {p: np.where(n_failed <= 1, labels[:, k], DROPPED).astype(np.int8) for k, p in enumerate(BODY_PARTS)}
    complete = np.all(labels >= 0, axis=1)
    multi = np.full(len(labels), DROPPED, dtype=np.int8)
    multi[complete & (n_failed == 1)] = 1
    multi[complete & (n_failed >= 2)] = 0
    out["multi"] = multi
    return out
