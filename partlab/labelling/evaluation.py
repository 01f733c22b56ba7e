"""Compare tracks with truth: Zhao & Lee's tracking rate per part, the person MBR rate, mean
IoU, and MOT metrics per part (py-motmetrics; HOTA through TrackEval when importable).

The right box, the person box and the tracking rate are defined once, in
:mod:`partlab.tracking.measures` (Zhao & Lee sec. 5.2-5.3): the rate at frame offset ``i`` is
the fraction of (person, part) pairs, among truth tracks that have that part ``i`` frames after
their initialisation (their first truth frame), whose tracked box is right; the averaged rate is
the mean of that curve over the offsets tracked (1 on). The person MBR rate compares the minimum
bounding rectangle of the tracked head, torso and hip-leg with that of the true ones (Fig. 4 (d)),
where at least two of the three are present in the truth; tracks without body parts (a
whole-body tracker) are judged by their ``person`` boxes, as in that figure.

Tracks are matched to truth by ``track_id`` when the ids agree (runs from ``--init``
keep them): at least 80 % of the truth tracks have a tracker track of the same id whose boxes
overlap them with IoU >= 0.3 at their first common frame (:func:`ids_agree`). Otherwise (automatic runs)
each truth track
is matched to the tracker track with the greatest mean IoU over the truth's boxes
(Hungarian assignment, scipy), and the report says so.

MOT metrics need no matching: per part, every frame's truth and tracker boxes are
compared with the distance ``1 - IoU`` (NaN, i.e. never matched, below IoU 0.5; we
compute it ourselves because motmetrics 1.4's ``iou_matrix`` calls numpy's removed
``asfarray``) and fed to ``motmetrics.MOTAccumulator``.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment

from partlab.tracking import measures
from partlab.tracking.core.box import iou_xywh
from partlab.tracking.parts import BODY_PARTS, PART_NAMES
from partlab.tracking.tracks import normalise_tracks

DEFAULT_AT = 105  # seed 002 reports its rates at the 105th frame after initialisation
MIN_COVER = measures.MIN_COVER
MOT_IOU = 0.5  # the usual MOTChallenge threshold for a match
# Ids agree when at least ID_AGREE_SHARE of the truth tracks have a same-id tracker track overlapping
# them by ID_AGREE_IOU at their first common frame. A run from --init starts every track on its
# truth box, but its person box is the tracker's own (the body tracker's: the minimum bounding
# rectangle of the decomposed parts, IoU 0.35-0.85 with the drawn box on PETS09-S2L1) and a track
# may be gone (ended early); automatic runs number their tracks 1, 2, ... in their own order, and
# the chance that 80 % of them overlap the same-numbered truth track at its start is nil.
ID_AGREE_IOU = 0.3
ID_AGREE_SHARE = 0.8
MOT_METRICS: tuple[str, ...] = ("mota", "motp", "idf1", "num_switches", "num_false_positives", "num_misses",
                                "num_objects", "precision", "recall")
PERSON_MBR = "person_mbr"


class EvaluationError(ValueError):
    """Truth or tracks that cannot be compared; the message says why."""


@dataclass(frozen=True)
class EvaluationReport:
    """Everything ``partlab eval`` prints; the tables are DataFrames for the app to show.

    rates, counts: index ``offset`` (frames after initialisation), a column per part
    (and ``person_mbr``): the rate, and the number of (person, part) pairs it is over.
    summary: index part; ``rate_at``, ``rate_mean``, ``mean_iou``, ``boxes``.
    mot: index part and ``overall``; the motmetrics columns of :data:`MOT_METRICS`
    (plus ``hota``, ``deta``, ``assa`` when TrackEval is importable).
    pairs: ``truth_id, track_id, mean_iou`` of the matching used for the rates.
    """

    at: int
    matching: str  # "track_id" or "iou"
    note: str
    rates: pd.DataFrame
    counts: pd.DataFrame
    summary: pd.DataFrame
    mot: pd.DataFrame
    pairs: pd.DataFrame
    extras: dict = field(default_factory=dict)

    def rate_at(self, part: str) -> float:
        return float(self.summary.loc[part, "rate_at"]) if part in self.summary.index else float("nan")

    def to_dict(self) -> dict:
        def clean(v):
            if isinstance(v, dict):
                return {str(k): clean(x) for k, x in v.items()}
            if isinstance(v, (list, tuple)):
                return [clean(x) for x in v]
            if isinstance(v, (np.integer,)):
                return int(v)
            if isinstance(v, (float, np.floating)):
                return None if not math.isfinite(float(v)) else float(v)
            return v

        return clean({
            "at": self.at, "matching": self.matching, "note": self.note,
            "summary": self.summary.to_dict(orient="index"),
            "mot": self.mot.to_dict(orient="index"),
            "rates": {c: {int(i): v for i, v in self.rates[c].items() if not pd.isna(v)} for c in self.rates},
            "counts": {c: {int(i): int(v) for i, v in self.counts[c].items() if v > 0} for c in self.counts},
            "pairs": self.pairs.to_dict(orient="records"),
            **self.extras,
        })

    def to_json(self, indent: int | None = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent)


def box_correct(tracked: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Row-wise :func:`partlab.tracking.measures.right_box` of ``tracked (N, 4)`` against
    ``truth (N, 4)`` xywh boxes (NaN tracked rows, no box, are wrong)."""
    return measures.right_box(np.asarray(tracked, float).reshape(-1, 4), np.asarray(truth, float).reshape(-1, 4))


def _rowwise_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU of matching rows of two ``(N, 4)`` xywh arrays (0 where either is NaN)."""
    ix = np.minimum(a[:, 0] + a[:, 2], b[:, 0] + b[:, 2]) - np.maximum(a[:, 0], b[:, 0])
    iy = np.minimum(a[:, 1] + a[:, 3], b[:, 1] + b[:, 3]) - np.maximum(a[:, 1], b[:, 1])
    inter = np.clip(ix, 0, None) * np.clip(iy, 0, None)
    union = a[:, 2] * a[:, 3] + b[:, 2] * b[:, 3] - inter
    with np.errstate(invalid="ignore", divide="ignore"):
        iou = np.where(union > 0, inter / union, 0.0)
    return np.nan_to_num(iou, nan=0.0)


XYWH = ["x", "y", "w", "h"]


def _pair_iou(truth: pd.DataFrame, tracks: pd.DataFrame) -> pd.DataFrame:
    """Mean IoU of every (truth track, tracker track) pair over the truth's boxes."""
    m = truth[["frame", "track_id", "part"] + XYWH].merge(
        tracks[["frame", "track_id", "part"] + XYWH], on=["frame", "part"], suffixes=("_t", "_k"))
    n_truth = truth.groupby("track_id").size()
    if m.empty:
        return pd.DataFrame(columns=["truth_id", "track_id", "mean_iou"])
    m["iou"] = _rowwise_iou(m[[c + "_t" for c in XYWH]].to_numpy(), m[[c + "_k" for c in XYWH]].to_numpy())
    s = m.groupby(["track_id_t", "track_id_k"])["iou"].sum().reset_index()
    s["mean_iou"] = s["iou"] / s["track_id_t"].map(n_truth)
    return s.rename(columns={"track_id_t": "truth_id", "track_id_k": "track_id"})[["truth_id", "track_id", "mean_iou"]]


def ids_agree(truth: pd.DataFrame, tracks: pd.DataFrame) -> bool:
    """True when the truth tracks' same-id tracker tracks overlap them (IoU >= :data:`ID_AGREE_IOU`,
    averaged over the parts both have) at their first common frame for at least
    :data:`ID_AGREE_SHARE` of the truth tracks, as in runs started from ``--init``."""
    m = truth[["frame", "track_id", "part"] + XYWH].merge(
        tracks[["frame", "track_id", "part"] + XYWH], on=["frame", "track_id", "part"], suffixes=("_t", "_k"))
    if m.empty:
        return False
    m["iou"] = _rowwise_iou(m[[c + "_t" for c in XYWH]].to_numpy(), m[[c + "_k" for c in XYWH]].to_numpy())
    first = m[m["frame"] == m.groupby("track_id")["frame"].transform("min")]
    agree = int((first.groupby("track_id")["iou"].mean() >= ID_AGREE_IOU).sum())
    return agree >= ID_AGREE_SHARE * truth["track_id"].nunique()


def match_tracks(truth: pd.DataFrame, tracks: pd.DataFrame, how: str = "auto") -> tuple[str, pd.DataFrame]:
    """(``"track_id"`` or ``"iou"``, pairs ``truth_id, track_id, mean_iou``) of truth and tracker tracks."""
    pairs = _pair_iou(truth, tracks)
    if how not in ("auto", "id", "iou"):
        raise EvaluationError(f"matching must be auto, id or iou, got {how!r}")
    if how == "id" or (how == "auto" and ids_agree(truth, tracks)):
        ids = sorted(set(truth["track_id"]) & set(tracks["track_id"]))
        same = pairs[(pairs["truth_id"] == pairs["track_id"])].set_index("truth_id")["mean_iou"]
        out = pd.DataFrame({"truth_id": ids, "track_id": ids, "mean_iou": [float(same.get(i, 0.0)) for i in ids]})
        return "track_id", out
    t_ids = np.sort(truth["track_id"].unique())
    k_ids = np.sort(tracks["track_id"].unique())
    score = np.zeros((len(t_ids), len(k_ids)))
    if len(pairs):
        ti = np.searchsorted(t_ids, pairs["truth_id"].to_numpy())
        ki = np.searchsorted(k_ids, pairs["track_id"].to_numpy())
        score[ti, ki] = pairs["mean_iou"].to_numpy()
    rows, cols = linear_sum_assignment(score, maximize=True)
    keep = score[rows, cols] > 0
    out = pd.DataFrame({"truth_id": t_ids[rows[keep]], "track_id": k_ids[cols[keep]],
                        "mean_iou": score[rows[keep], cols[keep]]})
    return "iou", out


MIN_MBR_PARTS = measures.MIN_MBR_PARTS
_mbr = measures.person_boxes


def _person_boxes(df: pd.DataFrame, prefer_person: bool) -> pd.DataFrame:
    """Person box per (frame, track): the ``person`` row or the MBR of the body parts."""
    person = df[df["part"] == "person"][["frame", "track_id"] + XYWH]
    mbr = _mbr(df, BODY_PARTS)
    first, second = (person, mbr) if prefer_person else (mbr, person)
    extra = second.merge(first[["frame", "track_id"]], how="left", indicator=True)
    extra = extra[extra["_merge"] == "left_only"].drop(columns="_merge")
    return pd.concat([first, extra], ignore_index=True)


def _judge(truth: pd.DataFrame, matched: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    """Truth rows with ``correct`` and ``iou`` of the matched tracker box (wrong / 0 when missing)."""
    m = measures.judge(truth, matched, keys).rename(columns={"right": "correct"})
    m["iou"] = _rowwise_iou(m[XYWH].to_numpy(float), m[[c + "_k" for c in XYWH]].to_numpy(float))
    return m


def evaluate(truth_df: pd.DataFrame, tracks_df: pd.DataFrame, at: int = DEFAULT_AT, matching: str = "auto",
             hota: bool = True) -> EvaluationReport:
    """Evaluate tracks against truth (both tracks tables); see the module docstring."""
    truth = normalise_tracks(truth_df)
    tracks = normalise_tracks(tracks_df)
    if truth.empty:
        raise EvaluationError("the truth has no boxes")
    for name, df in (("truth", truth), ("tracks", tracks)):
        dup = df.duplicated(["frame", "track_id", "part"])
        if dup.any():
            r = df[dup].iloc[0]
            raise EvaluationError(f"{name}: {int(dup.sum())} repeated (frame, track_id, part) rows, e.g. frame "
                                  f"{r.frame}, track {r.track_id}, part {r.part}")
    how, pairs = match_tracks(truth, tracks, matching)
    rename = dict(zip(pairs["track_id"], pairs["truth_id"]))
    matched = tracks[tracks["track_id"].isin(rename)].assign(track_id=lambda d: d["track_id"].map(rename))

    judged = _judge(truth, matched, ["frame", "track_id", "part"])
    judged["column"] = judged["part"]
    truth_person = _mbr(truth, BODY_PARTS)  # no body parts: the "person" column already says it all
    if len(truth_person):
        track_person = _person_boxes(matched, prefer_person=not tracks["part"].isin(BODY_PARTS).any())
        pj = _judge(truth_person, track_person, ["frame", "track_id"])
        pj["column"] = PERSON_MBR
        judged = pd.concat([judged, pj], ignore_index=True)
    judged = measures.with_offsets(judged, truth)

    columns = [p for p in PART_NAMES if p in set(truth["part"])] + ([PERSON_MBR] if len(truth_person) else [])
    rates = judged.pivot_table(index="offset", columns="column", values="correct", aggfunc="mean")
    counts = judged.pivot_table(index="offset", columns="column", values="correct", aggfunc="size")
    rates = rates.reindex(columns=columns).astype(float)
    counts = counts.reindex(columns=columns).fillna(0).astype(int)
    rates.columns.name = counts.columns.name = None
    summary = pd.DataFrame({
        "rate_at": [measures.rate_at(rates[c], at) for c in columns],
        "rate_mean": [measures.averaged_rate(rates[c].dropna()) for c in columns],
        "mean_iou": [float(judged.loc[judged["column"] == c, "iou"].mean()) for c in columns],
        "boxes": [int((judged["column"] == c).sum()) for c in columns],
    }, index=pd.Index(columns, name="part"))

    mot = mot_metrics(truth, tracks)
    extras: dict = {}
    if hota:
        h = hota_metrics(truth, tracks)
        if h is not None:
            mot = mot.join(h)
        else:
            extras["hota"] = "not computed: TrackEval is not installed"
    if how == "track_id":
        note = "tracks matched to truth by track_id (the ids agree)"
    else:
        note = (f"ids differ: each truth track matched to the tracker track of greatest mean IoU (Hungarian); "
                f"{len(pairs)} of {truth['track_id'].nunique()} truth tracks matched")
    return EvaluationReport(int(at), how, note, rates, counts, summary, mot, pairs.reset_index(drop=True), extras)


def iou_distance(truth_boxes: np.ndarray, track_boxes: np.ndarray, threshold: float = MOT_IOU) -> np.ndarray:
    """``(N, M)`` distance ``1 - IoU`` with NaN (no match allowed) where IoU < ``threshold``."""
    iou = iou_xywh(truth_boxes, track_boxes)
    return np.where(iou >= threshold, 1.0 - iou, np.nan)


def _accumulator(truth: pd.DataFrame, tracks: pd.DataFrame):
    import motmetrics as mm

    acc = mm.MOTAccumulator(auto_id=False)
    t_by = {f: g for f, g in truth.groupby("frame")}
    k_by = {f: g for f, g in tracks.groupby("frame")}
    empty = truth.iloc[:0]
    for f in sorted(set(t_by) | set(k_by)):
        t = t_by.get(f, empty)
        k = k_by.get(f, empty)
        acc.update(t["track_id"].to_numpy(), k["track_id"].to_numpy(),
                   iou_distance(t[XYWH].to_numpy(), k[XYWH].to_numpy()), frameid=int(f))
    return acc


def mot_metrics(truth: pd.DataFrame, tracks: pd.DataFrame) -> pd.DataFrame:
    """motmetrics per part of the truth (rows) plus ``overall``; columns :data:`MOT_METRICS`."""
    import motmetrics as mm

    parts = [p for p in PART_NAMES if p in set(truth["part"])]
    accs = [_accumulator(truth[truth["part"] == p], tracks[tracks["part"] == p]) for p in parts]
    mh = mm.metrics.create()
    table = mh.compute_many(accs, names=parts, metrics=list(MOT_METRICS), generate_overall=len(parts) > 1)
    table = table.rename(index={"OVERALL": "overall"})
    table.index.name = "part"
    if len(parts) == 1:
        table.loc["overall"] = table.iloc[0]
    return table.astype(float)


def hota_metrics(truth: pd.DataFrame, tracks: pd.DataFrame) -> pd.DataFrame | None:
    """HOTA, DetA, AssA per part and overall (TrackEval, averaged over its IoU thresholds
    0.05..0.95), or None when TrackEval is not installed. TrackEval is optional: its PyPI
    metadata pins ``opencv-python``, which clashes with our headless OpenCV, so ``make test``
    installs it with ``--no-deps`` (its metrics need only numpy and scipy)."""
    try:
        # TrackEval prints notes about its optional parts to stdout on import; keep them out of
        # our output (``partlab eval --json`` must print JSON only).
        with contextlib.redirect_stdout(io.StringIO()):
            from trackeval.metrics import HOTA
    except Exception:  # not installed, or broken against this numpy
        return None
    metric = HOTA()
    results = {}
    for p in [p for p in PART_NAMES if p in set(truth["part"])]:
        t, k = truth[truth["part"] == p], tracks[tracks["part"] == p]
        frames = sorted(set(t["frame"]) | set(k["frame"]))
        t_ids = {v: i for i, v in enumerate(sorted(t["track_id"].unique()))}
        k_ids = {v: i for i, v in enumerate(sorted(k["track_id"].unique()))}
        t_by = {f: g for f, g in t.groupby("frame")}
        k_by = {f: g for f, g in k.groupby("frame")}
        empty = t.iloc[:0]
        data = {"num_timesteps": len(frames), "num_gt_ids": len(t_ids), "num_tracker_ids": len(k_ids),
                "num_gt_dets": len(t), "num_tracker_dets": len(k),
                "gt_ids": [], "tracker_ids": [], "similarity_scores": []}
        for f in frames:
            a, b = t_by.get(f, empty), k_by.get(f, empty)
            data["gt_ids"].append(a["track_id"].map(t_ids).to_numpy(dtype=int))
            data["tracker_ids"].append(b["track_id"].map(k_ids).to_numpy(dtype=int))
            data["similarity_scores"].append(iou_xywh(a[XYWH].to_numpy(), b[XYWH].to_numpy()))
        results[p] = metric.eval_sequence(data)
    if len(results) > 1:
        results["overall"] = metric.combine_sequences(dict(results))
    else:
        results["overall"] = next(iter(results.values()))
    rows = {name: {"hota": float(np.mean(r["HOTA"])), "deta": float(np.mean(r["DetA"])),
                   "assa": float(np.mean(r["AssA"]))} for name, r in results.items()}
    return pd.DataFrame.from_dict(rows, orient="index")


def rate_curve_figure(report: EvaluationReport):
    """Plotly figure of tracking rate against frames after initialisation, a line per part
    (seed 002 Fig. 4), with the reported offset marked."""
    import plotly.graph_objects as go

    fig = go.Figure()
    for column in report.rates.columns:
        s = report.rates[column].dropna()
        n = report.counts[column].reindex(s.index).fillna(0).astype(int)
        fig.add_trace(go.Scatter(x=s.index.to_numpy(), y=s.to_numpy(), mode="lines", name=column,
                                 customdata=n.to_numpy(),
                                 hovertemplate="offset %{x}: rate %{y:.2f} over %{customdata} boxes"))
    fig.add_vline(x=report.at, line_dash="dot", annotation_text=f"frame {report.at}")
    fig.update_layout(title=f"Tracking rate against frames after initialisation ({report.note})",
                      xaxis_title="frames after initialisation", yaxis_title="tracking rate",
                      yaxis_range=[0, 1.05], template="plotly_white")
    return fig


# -- takes of several calibrated views ------------------------------------------------------------

TRUTH3D_COLUMNS = ("frame", "track_id", "part", "X", "Y", "Z")


def read_truth3d(path) -> pd.DataFrame:
    """A ``truth3d.csv`` (``frame, track_id, part, X, Y, Z`` in mm); :class:`EvaluationError` names
    the file and what is missing."""
    try:
        df = pd.read_csv(path)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise EvaluationError(f"{path}: cannot read a 3D truth table ({exc})") from None
    missing = [c for c in TRUTH3D_COLUMNS if c not in df.columns]
    if missing:
        raise EvaluationError(f"{path}: a 3D truth table needs columns {', '.join(TRUTH3D_COLUMNS)}; "
                              f"missing {', '.join(missing)}")
    return df[list(TRUTH3D_COLUMNS)]


def error_3d(tracks: pd.DataFrame, truth3d: pd.DataFrame) -> pd.DataFrame:
    """Mean 3D error in mm per part (the multi-camera paper's protocol, sec. 8): tracked ``X, Y, Z``
    against the truth at every frame both have, matched by ``track_id`` and part. Columns
    ``frames, mean_mm, median_mm, p90_mm, within_100mm`` (fraction of frames under 10 cm); a
    missed frame (truth but no estimate) counts in ``missed``."""
    est = tracks.dropna(subset=["X", "Y", "Z"]).drop_duplicates(["frame", "track_id", "part"])
    m = truth3d.merge(est[["frame", "track_id", "part", "X", "Y", "Z"]], on=["frame", "track_id", "part"],
                      how="left", suffixes=("_t", ""))
    m["err"] = np.linalg.norm(m[["X", "Y", "Z"]].to_numpy(float) - m[["X_t", "Y_t", "Z_t"]].to_numpy(float), axis=1)
    rows = []
    for part, g in m.groupby("part", sort=False):
        e = g["err"].dropna()
        rows.append({"part": part, "frames": int(len(e)), "missed": int(g["err"].isna().sum()),
                     "mean_mm": float(e.mean()) if len(e) else float("nan"),
                     "median_mm": float(e.median()) if len(e) else float("nan"),
                     "p90_mm": float(e.quantile(0.9)) if len(e) else float("nan"),
                     "within_100mm": float((e < 100).mean()) if len(e) else float("nan")})
    return pd.DataFrame(rows).set_index("part")


def evaluate_views(truth: pd.DataFrame, tracks: pd.DataFrame, at: int = DEFAULT_AT) -> dict[str, EvaluationReport]:
    """Per view (``camera`` column), the 2D tracking-rate report of :func:`evaluate`."""
    out = {}
    for cam in sorted(set(truth["camera"]) - {""}):
        t, k = truth[truth["camera"] == cam], tracks[tracks["camera"] == cam]
        if len(k):
            out[cam] = evaluate(t.reset_index(drop=True), k.reset_index(drop=True), at=at, matching="id")
    return out


# -- annotation effort ---------------------------------------------------------------------------

EDIT_IOU = 0.5  # a proposal on a truth box at IoU >= 0.5 needs no correction


@dataclass(frozen=True)
class EditCount:
    """What correcting proposals into the truth costs (one part, e.g. ``person``).

    ``edits``: per frame ``max(truth boxes, proposals) - proposals matched to a truth box at
    IoU >= 0.5`` (one-to-one, Hungarian): a wrong box is moved once, a missing one drawn, a
    spurious one deleted; plus every keyframe box the annotator drew. ``per_100``: edits per 100
    truth boxes; ``moved``, ``drawn``, ``deleted`` split the corrections, ``keyframes`` the boxes
    drawn before the proposals were made.
    """

    edits: int
    truth_boxes: int
    keyframes: int
    moved: int
    drawn: int
    deleted: int

    @property
    def per_100(self) -> float:
        return 100.0 * self.edits / self.truth_boxes if self.truth_boxes else float("nan")


def _frame_assignments(truth_df: pd.DataFrame, proposals_df: pd.DataFrame, part: str):
    """Per frame of either table, ``(truth boxes, proposals, IoUs of the assigned pairs)`` for
    ``part``: the one-to-one assignment of largest total IoU that the edits are counted over."""
    truth = truth_df[truth_df["part"] == part] if "part" in truth_df else truth_df
    props = proposals_df[proposals_df["part"] == part] if "part" in proposals_df else proposals_df
    t_by = {f: g[XYWH].to_numpy(float) for f, g in truth.groupby("frame")}
    k_by = {f: g[XYWH].to_numpy(float) for f, g in props.groupby("frame")}
    for f in set(t_by) | set(k_by):
        t = t_by.get(f, np.empty((0, 4)))
        k = k_by.get(f, np.empty((0, 4)))
        iou = np.zeros(0)
        if len(t) and len(k):
            full = iou_xywh(t, k)
            rows, cols = linear_sum_assignment(full, maximize=True)
            iou = full[rows, cols]
        yield len(t), len(k), iou


def count_edits(truth_df: pd.DataFrame, proposals_df: pd.DataFrame, part: str = "person",
                keyframes: int = 0, threshold: float = EDIT_IOU) -> EditCount:
    """Corrections that turn ``proposals`` into ``truth`` for ``part`` (see :class:`EditCount`).

    ``keyframes``: boxes the annotator drew by hand to make the proposals (the init boxes of a
    tracker run, the keyframes of an interpolation); each costs one edit. Proposals are expected
    to contain them (at a keyframe the proposal *is* the drawn box, so it costs nothing more).
    Track ids play no part: an annotator corrects boxes, and a swapped id on a right box is
    corrected in the id column, which this measure does not count.
    """
    truth = truth_df[truth_df["part"] == part] if "part" in truth_df else truth_df
    moved = drawn = deleted = 0
    for n_truth, n_props, iou in _frame_assignments(truth_df, proposals_df, part):
        matched = int((iou >= threshold).sum())
        pairs = min(n_truth, n_props)
        moved += pairs - matched
        drawn += n_truth - pairs
        deleted += n_props - pairs
    edits = moved + drawn + deleted + int(keyframes)
    return EditCount(edits, len(truth), int(keyframes), moved, drawn, deleted)


#: the IoU band over which :func:`soft_edits` blurs the edits' threshold (:data:`EDIT_IOU` in its middle)
SOFT_EDIT_BAND = (0.3, 0.7)


def soft_edits(truth_df: pd.DataFrame, proposals_df: pd.DataFrame, part: str = "person") -> tuple[float, int]:
    """:func:`count_edits` with its IoU threshold blurred into a ramp: ``(soft edits, truth boxes)``.

    Per frame, ``max(truth boxes, proposals) - sum of s(IoU)`` over the same assignment as the edits,
    with ``s`` rising linearly from 0 at IoU 0.3 to 1 at 0.7 (:data:`SOFT_EDIT_BAND`) instead of
    jumping at 0.5: a missing or spurious box still costs one, a box well on its person nothing, and
    one near the threshold what its overlap says. The edits count a box at IoU 0.49 as wrong and one
    at 0.51 as right, so a small change to the tracker moves them by whole boxes where the boxes
    themselves hardly moved; this measure moves with the boxes, which is what training's validation
    needs to compare two models on a short stretch (:func:`partlab.models.person.select_person`).
    """
    lo, hi = SOFT_EDIT_BAND
    truth = truth_df[truth_df["part"] == part] if "part" in truth_df else truth_df
    total = 0.0
    for n_truth, n_props, iou in _frame_assignments(truth_df, proposals_df, part):
        total += max(n_truth, n_props) - float(np.clip((iou - lo) / (hi - lo), 0.0, 1.0).sum())
    return total, len(truth)


def keyframe_frames(first: int, last: int, every: int) -> np.ndarray:
    """The frames an annotator keys on a track seen from ``first`` to ``last``: every
    ``every``-th frame from its first, and its last (where it leaves)."""
    frames = np.arange(first, last + 1, max(int(every), 1))
    return np.unique(np.append(frames, last))


def keyframes_of(truth_df: pd.DataFrame, every: int, part: str = "person") -> pd.DataFrame:
    """The truth rows of ``part`` an annotator would key with a keyframe every ``every`` frames of
    each track (:func:`keyframe_frames`); what ``--keyframes`` and interpolation start from."""
    truth = truth_df[truth_df["part"] == part]
    out = []
    for _tid, g in truth.groupby("track_id"):
        keys = keyframe_frames(int(g["frame"].min()), int(g["frame"].max()), every)
        out.append(g[g["frame"].isin(keys)])
    return pd.concat(out, ignore_index=True) if out else truth.iloc[:0]


def interpolate_keyframes(keys_df: pd.DataFrame) -> pd.DataFrame:
    """Linear interpolation of every track's boxes between its consecutive keyframes (CVAT's
    track mode): rows ``frame, track_id, part, x, y, w, h`` for every frame from a track's first
    keyframe to its last, per part."""
    out = []
    for (tid, part), g in keys_df.groupby(["track_id", "part"]):
        g = g.sort_values("frame")
        f = g["frame"].to_numpy(int)
        frames = np.arange(f[0], f[-1] + 1)
        cols = {c: np.interp(frames, f, g[c].to_numpy(float)) for c in XYWH}
        out.append(pd.DataFrame({"frame": frames, "track_id": tid, "part": part, **cols}))
    if not out:
        return pd.DataFrame(columns=["frame", "track_id", "part"] + XYWH)
    return pd.concat(out, ignore_index=True)
