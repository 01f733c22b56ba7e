"""The measures partlab reports, each defined once: the right box, the person box and the
tracking rate (Zhao & Lee sec. 5.2-5.3). Evaluation (:mod:`partlab.labelling.evaluation`),
training's validation (:mod:`partlab.models.selection`), the failure detectors' labels
(:mod:`partlab.models.labels`), the benchmarks and the tests all use these.

**Right box** (sec. 5.2): a tracked box is wrong when half of it or more covers other things;
so it is right when at least :data:`MIN_COVER` of its area lies on the true box. We also ask
that its centre lies inside the true box (DESIGN.md), edges included; for rectangles the first
condition almost implies the second, which is kept because the definition names it. A box of
zero area, or a missing one (NaN), is never right.

**Person box**: the minimum bounding rectangle (MBR) of a person's head, torso and hip-leg
(sec. 5.3, Fig. 4 (d)); in a table, only where at least :data:`MIN_MBR_PARTS` of them are present.

**Tracking rate** (sec. 5.3): the rate at offset ``i`` is the fraction of people (per part)
tracked right ``i`` frames after their initialisation, over the people who have that part in
the truth then (so the count varies with ``i``); the *averaged* rate is the mean of that curve
over the offsets tracked, 1 onwards (offset 0 is the initialisation itself).

Boxes are ``(..., 4)`` arrays ``[x, y, w, h]`` (top-left corner and size) or tracks tables
(``frame, track_id, part, x, y, w, h``).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np

from partlab.tracking.core.box import Box
from partlab.tracking.parts import BODY_PARTS

if TYPE_CHECKING:
    import pandas as pd

#: Zhao & Lee sec. 5.2: a box is wrong when half of it or more covers other things.
MIN_COVER: float = 0.5
#: a single body part (e.g. the head of the limb tracker) is no person box
MIN_MBR_PARTS: int = 2
#: the first offset the averaged rate counts (offset 0: the initialisation)
FIRST_TRACKED_OFFSET: int = 1
XYWH = ["x", "y", "w", "h"]


def cover_fraction(boxes: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Fraction of each box's area lying on the matching true box (0 for a box of no area)."""
    b = np.asarray(boxes, dtype=np.float64)
    t = np.asarray(truth, dtype=np.float64)
    iw = np.clip(np.minimum(b[..., 0] + b[..., 2], t[..., 0] + t[..., 2]) - np.maximum(b[..., 0], t[..., 0]), 0, None)
    ih = np.clip(np.minimum(b[..., 1] + b[..., 3], t[..., 1] + t[..., 3]) - np.maximum(b[..., 1], t[..., 1]), 0, None)
    area = b[..., 2] * b[..., 3]
    with np.errstate(invalid="ignore"):
        return np.where(area > 0, iw * ih / np.where(area > 0, area, 1.0), 0.0)


def centre_inside(boxes: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Whether each box's centre lies inside the matching true box (edges included)."""
    b = np.asarray(boxes, dtype=np.float64)
    t = np.asarray(truth, dtype=np.float64)
    cx, cy = b[..., 0] + b[..., 2] / 2, b[..., 1] + b[..., 3] / 2
    return (t[..., 0] <= cx) & (cx <= t[..., 0] + t[..., 2]) & (t[..., 1] <= cy) & (cy <= t[..., 1] + t[..., 3])


def right_box(boxes: np.ndarray, truth: np.ndarray, min_cover: float = MIN_COVER) -> np.ndarray:
    """Whether each box is right for the matching true box (the module docstring); NaN boxes are wrong."""
    b = np.asarray(boxes, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        ok = (cover_fraction(b, truth) >= min_cover) & centre_inside(b, truth)
    return ok & ~np.isnan(b).any(axis=-1)


def right_box_one(box: Box, truth: Box) -> bool:
    """:func:`right_box` of two :class:`~partlab.tracking.core.box.Box` objects."""
    return bool(right_box(np.array(box.as_tuple()), np.array(truth.as_tuple())))


def person_box(boxes: Iterable[Box]) -> Box:
    """The person box: the MBR of its parts' boxes."""
    boxes = list(boxes)
    if not boxes:
        raise ValueError("no boxes to bound")
    out = boxes[0]
    for b in boxes[1:]:
        out = out.union_box(b)
    return out


def person_boxes(df: pd.DataFrame, parts: Iterable[str] = BODY_PARTS) -> pd.DataFrame:
    """The person box of every (frame, track_id) of a tracks table: the MBR of its rows whose part
    is in ``parts``, where at least :data:`MIN_MBR_PARTS` of them are present."""
    d = df[df["part"].isin(tuple(parts))]
    g = d.assign(x2=d["x"] + d["w"], y2=d["y"] + d["h"]).groupby(["frame", "track_id"])
    out = g.agg(x=("x", "min"), y=("y", "min"), x2=("x2", "max"), y2=("y2", "max"),
                n=("part", "size")).reset_index()
    out = out[out["n"] >= MIN_MBR_PARTS]
    out["w"] = out["x2"] - out["x"]
    out["h"] = out["y2"] - out["y"]
    return out[["frame", "track_id"] + XYWH]


def judge(truth: pd.DataFrame, tracks: pd.DataFrame, keys: list[str] | None = None) -> pd.DataFrame:
    """The truth rows with ``right``: whether the tracks' box with the same ``keys`` (default
    frame, track_id, part; ids already matched) is right there. A missing box is wrong. The
    tracked box is in ``x_k, y_k, w_k, h_k``."""
    keys = keys or ["frame", "track_id", "part"]
    m = truth.merge(tracks[keys + XYWH], on=keys, how="left", suffixes=("", "_k"))
    return m.assign(right=right_box(m[[c + "_k" for c in XYWH]].to_numpy(float), m[XYWH].to_numpy(float)))


def with_offsets(judged: pd.DataFrame, truth: pd.DataFrame) -> pd.DataFrame:
    """``judged`` with ``offset``: frames since its track's initialisation (its first truth frame)."""
    first = truth.groupby("track_id")["frame"].min()
    return judged.assign(offset=judged["frame"] - judged["track_id"].map(first))


def rate_curve(judged: pd.DataFrame) -> pd.Series:
    """The tracking rate at every offset (index ``offset``) of judged rows of one part."""
    return judged.groupby("offset")["right"].mean().astype(float)


def rate_at(curve: pd.Series, at: int) -> float:
    """The rate ``at`` frames after initialisation (NaN when nobody was in view then)."""
    return float(curve.get(at, np.nan))


def averaged_rate(curve: pd.Series) -> float:
    """The mean of the rate curve over the offsets tracked (:data:`FIRST_TRACKED_OFFSET` on)."""
    tracked = curve[curve.index >= FIRST_TRACKED_OFFSET]
    return float(tracked.mean()) if len(tracked) else float("nan")


def part_rates(tracks: pd.DataFrame, truth: pd.DataFrame, parts: Iterable[str] = BODY_PARTS,
               at: int | None = None) -> dict[str, float]:
    """Per part, the averaged tracking rate of ``tracks`` (ids as in ``truth``), or the rate at
    offset ``at``; NaN for a part the truth does not have."""
    out = {}
    for part in parts:
        t = truth[truth["part"] == part]
        if t.empty:
            out[part] = float("nan")
            continue
        curve = rate_curve(with_offsets(judge(t, tracks[tracks["part"] == part]), truth))
        out[part] = averaged_rate(curve) if at is None else rate_at(curve, at)
    return out
