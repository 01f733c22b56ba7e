"""What corrected person boxes teach the body tracker, without a single part box.

Many teams label whole people only (PETS09-S2L1's truth, the MOT benchmarks). Such boxes say
nothing of head, torso or hip-leg, so they give the failure SVMs (Zhao & Lee sec. 4.2) no sample;
but measured against what the tracker and its people detector do on the same frames they say:

1. **the person box around the parts** (``output.person``): the box a person draws around a whole
   person against the tracker's person box (the minimum bounding rectangle of the reported parts,
   sec. 5.3), as the median ratio of sizes and offset of centres, on frames where the tracker is on
   the person (its centre inside the corrected box) -- the same rule as the part extent of
   :mod:`partlab.models.extent`;
2. **the detector's threshold and window** (``detector.min_score``, ``detector.shrink``): the HOG
   detector is run on the corrected frames exactly where the detection cue would run it (foreground
   blobs and the tracks' boxes, every ``detector.every`` frames) with no threshold; a detection on a
   corrected box (IoU >= 0.5) is true, any other false. The threshold is the one that maximises F1
   over the corrected boxes of those frames (a false window starts a ghost track or drags a track
   off its person, a missed one leaves a box unsteered); the window's share of the body is the
   median ratio of corrected box to detector window over the true detections;
3. **when tracks end** (``detector.undetected_frames``, ``detection.leave_fraction``): how long the
   detector goes without finding people who *are* there (the longest run of scans without a
   detection on each corrected track); a track undetected for much longer than the people on the
   corrected frames ever were is a ghost. Where the detector misses people for over
   :data:`MAX_UNDETECTED_S` seconds, this cannot tell ghosts from people and stays off. And how
   much of a person is in view where the corrected tracks begin and end at the frame's sides
   (:func:`fit_leave_fraction`): a track goes on no longer than the annotator would label it;
4. **the dynamics**: a person's parts move with the person, so the person boxes' constant-velocity
   noise (:func:`partlab.models.variance.fit_body_noise` on the ``person`` rows) widens each part's
   position and velocity noise where it is larger (the fits only ever widen, as for parts).

Each is a handful of numbers from medians, a quantile and one threshold, nothing tied to where or
when the corrected people were; validation on the training clips (:func:`select_person`: the
detector, steering, ending and noise, then the extent refitted with them) keeps each only if it lowers the
annotator's edits (:func:`partlab.labelling.evaluation.count_edits`, the measure the issue judges
the tracker by) on the later corrected frames after being fitted on the earlier ones, so a fit
that does not help, or helps only the frames it was fitted on, is not used.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment

from partlab.tracking.core.box import iou_xywh
from partlab.tracking.params import BodyParams
from partlab.tracking.parts import BODY_PARTS

#: corrected/tracked (or corrected/detected) pairs needed before a value is refitted
MIN_PAIRS = 20
#: false detections needed before the threshold is refitted (with fewer, F1 only says "lower it")
MIN_FALSE = 5
#: a detector that misses people on the corrected frames for longer than this cannot end ghosts
MAX_UNDETECTED_S = 4.0
#: the highest ``detection.leave_fraction`` training sets. The tracker compares *its own* person box
#: with the frame, and that box is ~1.2x the truth's width and jitters (PETS09), so a person still
#: wholly in view at the frame's edge has up to a fifth of it outside: at 1.0 ("end as the person
#: starts to leave", annotators who draw only people wholly in view) such walkers were ended and drawn
#: again (PETS09 trained on frames 0-199: +2.2 edits/100 on frames 200-794, docs/measurements).
MAX_LEAVE_FRACTION = 0.8
#: the IoU at which a detection is on a corrected box (the MOT rule, and the edits')
TRUE_IOU = 0.5
XYWH = ["x", "y", "w", "h"]


def has_person_rows(truth: pd.DataFrame) -> bool:
    return bool((truth["part"] == "person").any())


def person_only(truth: pd.DataFrame) -> bool:
    """Person boxes and no body-part box: what the failure SVMs cannot learn from."""
    return has_person_rows(truth) and not truth["part"].isin(BODY_PARTS).any()


# -- 1. the person box around the parts ---------------------------------------------------------

def _person_pairs(tracked: list[pd.DataFrame], truths: list[pd.DataFrame], empty: pd.DataFrame) -> pd.DataFrame:
    """The tracker's person boxes beside the corrected ones of the same frame and track (``x`` ..
    and ``x_t`` ..), each track's first frame (its drawn box) left out; ``empty`` when no clip."""
    pairs = []
    for t, g in zip(tracked, truths):
        t = t[t["part"] == "person"]
        t = t[t["frame"] > t.groupby("track_id")["frame"].transform("min")]
        g = g[g["part"] == "person"]
        pairs.append(t[["frame", "track_id", *XYWH]].merge(g[["frame", "track_id", *XYWH]],
                                                           on=["frame", "track_id"], suffixes=("", "_t")))
    return pd.concat(pairs, ignore_index=True) if pairs else empty


def fit_person_extent(tracked: list[pd.DataFrame], truths: list[pd.DataFrame],
                      current: tuple[float, float, float, float]) -> tuple[float, float, float, float] | None:
    """New ``output.person`` from the tracker's person rows (written with ``current``) and the
    corrected person boxes of the same clips and tracks; None with fewer than :data:`MIN_PAIRS`
    frames where the tracker is on the person. A track's first frame (its drawn box) and boxes
    touching the frame's edge (clipped) are left out."""
    m = _person_pairs(tracked, truths, pd.DataFrame())
    if m.empty:
        return None
    m = m[(m.w > 1) & (m.h > 1) & (m.w_t > 0) & (m.h_t > 0) & (m.x > 0.5) & (m.y > 0.5)]
    cx, cy = m.x + m.w / 2, m.y + m.h / 2
    m = m[(cx >= m.x_t) & (cx <= m.x_t + m.w_t) & (cy >= m.y_t) & (cy <= m.y_t + m.h_t)]
    if len(m) < MIN_PAIRS:
        return None
    sw, sh, dx, dy = current
    mbr_w, mbr_h = m.w / sw, m.h / sh
    median = (round(sw * float(np.median(m.w_t / m.w)), 3), round(sh * float(np.median(m.h_t / m.h)), 3),
              round(dx + float(np.median((m.x_t + m.w_t / 2 - m.x - m.w / 2) / mbr_w)), 3),
              round(dy + float(np.median((m.y_t + m.h_t / 2 - m.y - m.h / 2) / mbr_h)), 3))
    return _fewest_edits(m, current, median)


#: the neighbourhood of the median fit :func:`_fewest_edits` searches: width x 0.8-1.25, height
#: x 0.9-1.1, centre +-0.06 of the box's size
EXTENT_SEARCH = (np.round(np.arange(0.8, 1.251, 0.05), 3), np.round(np.arange(0.9, 1.101, 0.025), 3),
                 np.round(np.arange(-0.06, 0.061, 0.02), 3))


def _fewest_edits(m: pd.DataFrame, current: tuple[float, float, float, float],
                  median: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """The extent near ``median`` that leaves the most of the tracker's person boxes (``m``'s, written
    with ``current``) on their corrected box at IoU >= :data:`TRUE_IOU`, the edits' own rule (ties:
    the nearest to ``median``). The median ratio maps a typical box onto its corrected one, but a
    box whose centre is off its person keeps more overlap a little wider: on PETS09 the median fit
    narrows the tracker's box to 0.875 and costs edits on the later frames (seeds 1-3, frames
    200-794: +0.38 edits/100), while the box the edits prefer is a little wider and shorter and sits
    higher (1.05, 0.95, 0, -0.05: -0.61, lower on every seed)."""
    sw, sh, dx, dy = current
    w0, h0 = (m.w / sw).to_numpy(), (m.h / sh).to_numpy()  # the parts' bounding box (the MBR)
    cx0 = (m.x + m.w / 2).to_numpy() - dx * w0
    cy0 = (m.y + m.h / 2).to_numpy() - dy * h0
    tx1, ty1 = m.x_t.to_numpy(), m.y_t.to_numpy()
    tx2, ty2, t_area = tx1 + m.w_t.to_numpy(), ty1 + m.h_t.to_numpy(), (m.w_t * m.h_t).to_numpy()
    fw, fh, shifts = EXTENT_SEARCH
    best, best_key = median, None
    for a in fw:
        w = w0 * median[0] * a
        for b in fh:
            h = h0 * median[1] * b
            for ox in shifts:
                cx = cx0 + (median[2] + ox) * w0
                iw = np.clip(np.minimum(cx + w / 2, tx2) - np.maximum(cx - w / 2, tx1), 0, None)
                for oy in shifts:
                    cy = cy0 + (median[3] + oy) * h0
                    ih = np.clip(np.minimum(cy + h / 2, ty2) - np.maximum(cy - h / 2, ty1), 0, None)
                    inter = iw * ih
                    n = int((inter >= TRUE_IOU * (w * h + t_area - inter)).sum())
                    key = (n, -(abs(np.log(a)) + abs(np.log(b)) + abs(ox) + abs(oy)))
                    if best_key is None or key > best_key:
                        best_key = key
                        best = (median[0] * a, median[1] * b, median[2] + ox, median[3] + oy)
    return tuple(round(float(v), 3) for v in best)


# -- 2. the detector's threshold and window ----------------------------------------------------

def detection_samples(frames, truth: pd.DataFrame, params: BodyParams,
                      tracked: pd.DataFrame | None = None) -> pd.DataFrame:
    """Every window the detection cue's scan finds on the corrected frames, with no threshold:
    one row per detection ``frame, x, y, w, h, score, iou, truth`` (``iou`` with the corrected box
    the Hungarian assignment gives it, ``truth`` that box's track id or -1), plus one row per
    corrected box of a scanned frame (``score`` NaN) so that misses are counted. ``frames``: a
    frames factory (``() -> iterator of (index, BGR frame)``); regions are the foreground blobs
    and the tracks' person boxes (``tracked``'s, else the corrected ones), as in
    :class:`partlab.tracking.body.cue.DetectionCue`."""
    from partlab.tracking.body.cue import _blob_regions
    from partlab.tracking.core.background import BackgroundModel
    from partlab.tracking.core.box import Box
    from partlab.tracking.core.people import PeopleDetector

    p = params.detector
    detector = PeopleDetector(replace(p.scan(), min_score=0.0))
    truth = truth[truth["part"] == "person"]
    boxes = tracked[tracked["part"] == "person"] if tracked is not None else truth
    t_by = {f: g for f, g in truth.groupby("frame")}
    b_by = {f: g[XYWH].to_numpy(float) for f, g in boxes.groupby("frame")}
    last = int(truth["frame"].max()) if len(truth) else -1
    background = BackgroundModel(params)
    rows = []
    for index, frame in frames():
        if index > last:
            break
        mask = background.apply(frame)
        if index % p.every or index not in t_by:
            continue
        regions = _blob_regions(mask, p.min_region_height) + [Box(*b) for b in b_by.get(index, [])]
        dets = detector.detect(frame, regions)
        rows.extend(_label_scan(index, dets, t_by[index]))
    return pd.DataFrame(rows, columns=["frame", *XYWH, "score", "iou", "truth"])


def _label_scan(index: int, dets: np.ndarray, truth: pd.DataFrame) -> list[tuple]:
    gt = truth[XYWH].to_numpy(float)
    ids = truth["track_id"].to_numpy()
    iou = iou_xywh(dets[:, :4], gt) if len(dets) and len(gt) else np.zeros((len(dets), len(gt)))
    got = np.zeros(len(dets)), np.full(len(dets), -1)
    if iou.size:
        r, c = linear_sum_assignment(iou, maximize=True)
        ok = iou[r, c] > 0
        got[0][r[ok]], got[1][r[ok]] = iou[r[ok], c[ok]], ids[c[ok]]
    out = [(index, *d[:4], d[4], got[0][k], int(got[1][k])) for k, d in enumerate(dets)]
    out += [(index, *g, np.nan, np.nan, int(i)) for g, i in zip(gt, ids)]
    return out


def fit_min_score(samples: pd.DataFrame, current: float) -> tuple[float | None, dict]:
    """The detector threshold of highest F1 on the corrected boxes of the scanned frames (ties:
    the one nearest ``current``), and a record (counts, F1 at ``current`` and at the fit); None
    with fewer than :data:`MIN_PAIRS` true or :data:`MIN_FALSE` false detections."""
    det = samples[samples["score"].notna()]
    n_truth = int(samples["score"].isna().sum())
    true = det["iou"].to_numpy() >= TRUE_IOU
    scores = det["score"].to_numpy()
    record = {"detections": int(len(det)), "true": int(true.sum()), "false": int((~true).sum()), "boxes": n_truth}

    def f1(t: float) -> float:
        tp, fp = int((true & (scores >= t)).sum()), int((~true & (scores >= t)).sum())
        return 2 * tp / max(2 * tp + fp + (n_truth - tp), 1)

    record["f1_current"] = round(f1(current), 4)
    if true.sum() < MIN_PAIRS or (~true).sum() < MIN_FALSE:
        return None, record
    grid = np.round(np.arange(0.0, max(float(scores.max()), current) + 0.05, 0.05), 2)
    values = np.array([f1(t) for t in grid])
    best = grid[np.isclose(values, values.max())]
    fitted = float(best[np.argmin(np.abs(best - current))])
    record["f1_fitted"] = round(f1(fitted), 4)
    return fitted, record


def fit_shrink(samples: pd.DataFrame, current: tuple[float, float], min_score: float) -> tuple[float, float] | None:
    """The body's share of the detector window: median corrected size over window size (the
    detections were shrunk by ``current``) of the true detections at ``min_score``; None with
    fewer than :data:`MIN_PAIRS`."""
    det = samples[samples["score"].notna() & (samples["iou"] >= TRUE_IOU) & (samples["score"] >= min_score)]
    truth = samples[samples["score"].isna()][["frame", "truth", "w", "h"]]
    m = det.merge(truth, on=["frame", "truth"], suffixes=("", "_t"))
    if len(m) < MIN_PAIRS:
        return None
    sw = current[0] * float(np.median(m.w_t / m.w))
    sh = current[1] * float(np.median(m.h_t / m.h))
    return (round(min(sw, 1.0), 3), round(min(sh, 1.0), 3))


def _box_errors(a: pd.DataFrame, suffix: str = "_t") -> np.ndarray:
    """Squared error of boxes against corrected ones, in the corrected box's height (centre) and
    in log size, averaged over the four terms: how far off a person-box estimate is."""
    h = a["h" + suffix]
    dcx = (a.x + a.w / 2 - a["x" + suffix] - a["w" + suffix] / 2) / h
    dcy = (a.y + a.h / 2 - a["y" + suffix] - h / 2) / h
    return ((dcx ** 2 + dcy ** 2 + np.log(a.w / a["w" + suffix]) ** 2 + np.log(a.h / h) ** 2) / 4).to_numpy()


def fit_steer(samples: pd.DataFrame, tracked: list[pd.DataFrame], truths: list[pd.DataFrame],
              min_score: float) -> tuple[float | None, dict]:
    """``detector.steer``, the share of the way a matched detection moves a track's person box,
    as the blend of two noisy estimates of one box that errs least (the Kalman gain of a scalar
    state): ``e_t / (e_t + e_d)``, with ``e_t`` the tracker's and ``e_d`` the detector's median
    squared error (:func:`_box_errors`) against the corrected boxes: the tracker's person boxes
    on frames where it is on the person, the detections at ``min_score`` matched to a corrected
    box at IoU >= 0.3 (what the cue matches). To 0.05 in [0.1, 1]; None with fewer than
    :data:`MIN_PAIRS` of either."""
    det = samples[samples["score"].notna() & (samples["iou"] >= 0.3) & (samples["score"] >= min_score)]
    key = ["clip", "frame", "truth"] if "clip" in samples else ["frame", "truth"]  # clips share frame numbers
    truth_rows = samples[samples["score"].isna()][[*key, *XYWH]]
    d = det.merge(truth_rows, on=key, suffixes=("", "_t"))
    m = _person_pairs(tracked, truths, pd.DataFrame(columns=["x", "x_t"]))
    if len(m):
        cx, cy = m.x + m.w / 2, m.y + m.h / 2
        m = m[(m.w > 0) & (m.h > 0) & (cx >= m.x_t) & (cx <= m.x_t + m.w_t) & (cy >= m.y_t) & (cy <= m.y_t + m.h_t)]
    record = {"tracker_pairs": int(len(m)), "detector_pairs": int(len(d))}
    if len(m) < MIN_PAIRS or len(d) < MIN_PAIRS:
        return None, record
    e_t, e_d = float(np.median(_box_errors(m))), float(np.median(_box_errors(d)))
    record.update(tracker_error=round(e_t, 5), detector_error=round(e_d, 5))
    gain = e_t / max(e_t + e_d, 1e-12)
    return float(np.clip(round(gain * 20) / 20, 0.1, 1.0)), record


# -- 2b. how far a detection's motion moves a track's velocity -------------------------------------

def _centres(df: pd.DataFrame) -> pd.DataFrame:
    return df.assign(cx=df.x + df.w / 2, cy=df.y + df.h / 2)[["frame", "track_id", "cx", "cy", "h"]]


def _detection_velocities(det: pd.DataFrame, window: int) -> pd.DataFrame:
    """Per matched detection, the velocity the detection cue keeps for its person
    (:func:`partlab.tracking.body.cue.detection_velocity`)."""
    from partlab.tracking.body.cue import detection_velocity

    rows = []
    for tid, g in det.sort_values("frame").groupby("truth"):
        prev, old = None, None
        for r in g.itertuples():
            now = (r.frame, r.x + r.w / 2, r.y + r.h / 2)
            old = detection_velocity(prev, now, old, window)
            if old is not None:
                rows.append((r.frame, tid, *old))
            prev = now
    return pd.DataFrame(rows, columns=["frame", "track_id", "vx", "vy"])


def _tracker_velocities(tracked: pd.DataFrame, window: int) -> pd.DataFrame:
    """Per frame and track, the velocity the tracker coasts on (:func:`partlab.tracking.body.tracker
    .median_velocity` of its person box over the last ``window`` frames, none across a gap)."""
    from partlab.tracking.body.tracker import median_velocity

    c = _centres(tracked[tracked["part"] == "person"])
    rows = []
    for tid, g in c.sort_values("frame").groupby("track_id"):
        fc = g[["frame", "cx", "cy"]].to_numpy(float)
        for k in range(window, len(g)):
            if fc[k, 0] - fc[k - window, 0] == window:  # no gap: the tracker's history is whole
                rows.append((int(fc[k, 0]), tid, *median_velocity(fc[k - window:k + 1])))
    return pd.DataFrame(rows, columns=["frame", "track_id", "vx", "vy"])


def _truth_velocities(truth: pd.DataFrame, ahead: int) -> pd.DataFrame:
    """Per frame and person, the corrected box's per-frame motion over the next ``ahead`` frames
    (what a velocity set at a scan should predict until the next scan), and its height."""
    c = _centres(truth[truth["part"] == "person"])
    later = c.assign(frame=c["frame"] - ahead)
    m = c.merge(later, on=["frame", "track_id"], suffixes=("", "_n"))
    return m.assign(tx=(m.cx_n - m.cx) / ahead, ty=(m.cy_n - m.cy) / ahead)[["frame", "track_id", "tx", "ty", "h"]]


def fit_steer_velocity(samples: pd.DataFrame, tracked: list[pd.DataFrame], truths: list[pd.DataFrame],
                       min_score: float, every: int, window: int) -> tuple[float | None, dict]:
    """``detector.steer_velocity``, the share of the way a matched detection moves a track's
    velocity to the motion its detections show, as the blend of two noisy estimates of one velocity
    that errs least (the scalar Kalman gain, as :func:`fit_steer`): ``e_t / (e_t + e_d)``, with
    ``e_t`` the median squared error (in corrected box heights per frame) of the velocity the
    tracker coasts on (its person box's median motion over ``velocity_frames``) and ``e_d`` that of
    the detections' velocity (the cue's own estimate), each against the corrected boxes' motion over
    the next ``every`` frames (until the next scan). To 0.05 in [0, 1]; None with fewer than
    :data:`MIN_PAIRS` of either."""
    det = samples[samples["score"].notna() & (samples["iou"] >= 0.3) & (samples["score"] >= min_score)
                  & (samples["truth"] >= 0)]
    if "clip" not in det:
        det = det.assign(clip=0)
    key = ["frame", "track_id"]
    err_d, err_t = [], []
    for i, (t, truth) in enumerate(zip(tracked, truths)):  # clip by clip: clips share frame numbers and ids
        tv = _truth_velocities(truth, max(every, 1))
        vd = _detection_velocities(det[det["clip"] == i], window).merge(tv, on=key)
        # the tracker's velocity on the frames the detector's is known (the same people, the same moments)
        vt = _tracker_velocities(t, window).merge(vd[key], on=key).merge(tv, on=key)
        for v, out in ((vd, err_d), (vt, err_t)):
            out.extend(((v.vx - v.tx) ** 2 + (v.vy - v.ty) ** 2) / v.h ** 2)
    record = {"tracker_pairs": len(err_t), "detector_pairs": len(err_d)}
    if len(err_t) < MIN_PAIRS or len(err_d) < MIN_PAIRS:
        return None, record
    e_t, e_d = float(np.median(err_t)), float(np.median(err_d))
    record.update(tracker_error=round(e_t, 7), detector_error=round(e_d, 7))
    gain = e_t / max(e_t + e_d, 1e-12)
    return float(np.clip(round(gain * 20) / 20, 0.0, 1.0)), record


# -- 3. when an undetected track ends -------------------------------------------------------------

def fit_undetected_frames(samples: pd.DataFrame, min_score: float, every: int, fps: float) -> int | None:
    """``detector.undetected_frames`` from how long corrected people went undetected: 1.5 times
    the longest run of scans without a true detection (at ``min_score``) of 90 % of the corrected
    tracks, plus one scan; None (leave it) with fewer than 3 tracks seen in 5 scans or more, or
    when that is over :data:`MAX_UNDETECTED_S`."""
    det = samples[samples["score"].notna() & (samples["iou"] >= TRUE_IOU) & (samples["score"] >= min_score)]
    hit = set(zip(det["frame"], det["truth"]))
    gaps = []
    for tid, g in samples[samples["score"].isna()].groupby("truth"):
        frames = np.sort(g["frame"].to_numpy())
        if len(frames) < 5:
            continue
        run = longest = 0
        for f in frames:
            run = 0 if (f, tid) in hit else run + 1
            longest = max(longest, run)
        gaps.append(longest * every)
    if len(gaps) < 3:
        return None
    value = int(np.ceil(1.5 * np.quantile(gaps, 0.9))) + every
    return value if value <= MAX_UNDETECTED_S * fps else None


def fit_leave_fraction(truths: list[pd.DataFrame], sizes: list[tuple[int, int]]) -> float | None:
    """``detection.leave_fraction`` from where the corrected tracks begin and end at the frame's
    sides: for each track whose first or last box lies within half its width (height) of a side
    (top or bottom), that box's width (height) over the track's median, at most 1 (a person's box
    cut by the frame is narrower); the median over those, to 0.05, at most
    :data:`MAX_LEAVE_FRACTION`. None with fewer than 3 such ends. Annotators who draw people only
    once wholly in view give that most (end a track as its person starts to leave, allowing for the
    tracker's wider box); those who draw the visible part of a person half out give less."""
    shares = []
    for truth, (W, H) in zip(truths, sizes):
        t = truth[truth["part"] == "person"]
        for _tid, g in t.groupby("track_id"):
            if len(g) < 5:
                continue
            g = g.sort_values("frame")
            mw, mh = float(g["w"].median()), float(g["h"].median())
            for r in (g.iloc[0], g.iloc[-1]):
                if min(r.x, W - r.x - r.w) <= 0.5 * r.w:
                    shares.append(min(r.w / mw, 1.0))
                elif min(r.y, H - r.y - r.h) <= 0.5 * r.h:
                    shares.append(min(r.h / mh, 1.0))
    if len(shares) < 3:
        return None
    return float(np.clip(round(np.median(shares) * 20) / 20, 0.05, MAX_LEAVE_FRACTION))


# -- 4. the dynamics ------------------------------------------------------------------------------

def part_noise_from_person(noise: dict, person_rows: pd.DataFrame) -> dict:
    """Each body part's position and velocity noise widened to the person box's fitted values
    (rows of :func:`partlab.models.variance.fit_body_noise`'s table for part ``person``)."""
    fitted = {r.parameter: r.fitted for r in person_rows.itertuples() if np.isfinite(r.fitted)}
    out = dict(noise)
    for part in BODY_PARTS:
        if part in out:
            out[part] = replace(out[part], **{k: max(getattr(out[part], k), float(v))
                                              for k, v in fitted.items() if k in ("x", "y", "vx", "vy")})
    return out


# -- fitting and validation -----------------------------------------------------------------------

@dataclass
class PersonFit:
    """What person boxes gave: candidate parameter changes by component, and the record."""

    components: dict[str, dict] = field(default_factory=dict)
    record: dict = field(default_factory=dict)


def fit_person(clips, truths: list[pd.DataFrame], tracked: list[pd.DataFrame], base: BodyParams,
               noise_table: pd.DataFrame | None = None, progress: Callable[[str], None] | None = None) -> PersonFit:
    """Every fit above on the clips' person rows: ``components`` maps ``extent``, ``detector``,
    ``ending`` and ``noise`` to the :meth:`BodyParams.updated` changes each would make (absent:
    nothing fitted or the same as ``base``). ``tracked``: the tracker's runs with ``base``."""
    step = progress or (lambda _msg: None)
    out = PersonFit()
    ext = fit_person_extent(tracked, truths, base.output.person)
    out.record["person_extent"] = list(ext) if ext else None
    if ext and ext != base.output.person:
        out.components["extent"] = {"output.person": ext}
    if base.detector.enabled:
        samples = []
        for (factory, _fps, _truth), truth, t in zip(clips, truths, tracked):
            step("detections on the corrected frames")
            samples.append(detection_samples(factory, truth, base, t).assign(clip=len(samples)))
        s = pd.concat(samples, ignore_index=True)
        det = base.detector
        score, rec = fit_min_score(s, det.min_score)
        shrink = fit_shrink(s, det.shrink, det.min_score if score is None else score)
        out.record["detector"] = {**rec, "min_score": score, "shrink": list(shrink) if shrink else None}
        changes = {}
        if score is not None and score != det.min_score:
            changes["detector.min_score"] = score
        if shrink and shrink != det.shrink:
            changes["detector.shrink"] = shrink
        if changes:
            out.components["detector"] = changes
        steer, rec = fit_steer(s, tracked, truths, det.min_score if score is None else score)
        out.record["steer"] = {**rec, "steer": steer}
        if steer is not None and steer != det.steer:
            out.components["steer"] = {"detector.steer": steer}
        velocity, rec = fit_steer_velocity(s, tracked, truths, det.min_score if score is None else score,
                                           det.every, det.velocity_frames)
        out.record["steer_velocity"] = {**rec, "steer_velocity": velocity}
        if velocity is not None and velocity != det.steer_velocity:
            out.components["velocity"] = {"detector.steer_velocity": velocity}
        fps = float(clips[0][1])
        undetected = fit_undetected_frames(s, det.min_score if score is None else score, det.every, fps)
        out.record["undetected_frames"] = undetected
        if undetected is not None and undetected != det.undetected_frames:
            out.components.setdefault("ending", {})["detector.undetected_frames"] = undetected
    sizes = [_frame_size(factory) for factory, _fps, _t in clips]
    leave = fit_leave_fraction(truths, sizes)
    out.record["leave_fraction"] = leave
    if leave is not None and leave != base.detection.leave_fraction:
        out.components.setdefault("ending", {})["detection.leave_fraction"] = leave
    if noise_table is not None:
        rows = noise_table[(noise_table["tracker"] == "body") & (noise_table["part"] == "person")]
        noise = part_noise_from_person(base.dynamics.noise, rows)
        if noise != base.dynamics.noise:
            out.components["noise"] = {"dynamics.noise": noise}
    return out


def _frame_size(factory) -> tuple[int, int]:
    for _index, frame in factory():
        return frame.shape[1], frame.shape[0]
    return 0, 0


def person_edits(tracks: list[pd.DataFrame], truths: list[pd.DataFrame]) -> float:
    """Edits per 100 corrected person boxes over all clips (:func:`~partlab.labelling.evaluation.count_edits`)."""
    from partlab.labelling.evaluation import count_edits

    edits = boxes = 0
    for t, g in zip(tracks, truths):
        e = count_edits(g, t, "person")
        edits, boxes = edits + e.edits, boxes + e.truth_boxes
    return 100.0 * edits / max(boxes, 1)


def person_error(tracks: list[pd.DataFrame], truths: list[pd.DataFrame]) -> float:
    """Soft edits per 100 corrected person boxes over all clips
    (:func:`~partlab.labelling.evaluation.soft_edits`): what validation compares models by."""
    from partlab.labelling.evaluation import soft_edits

    edits = boxes = 0.0
    for t, g in zip(tracks, truths):
        e, n = soft_edits(g, t, "person")
        edits, boxes = edits + e, boxes + n
    return 100.0 * edits / max(boxes, 1)


def before_cut(df: pd.DataFrame, cut: float) -> pd.DataFrame:
    """The rows a fit is made on: those before ``cut`` (all for ``-inf``: no holdout)."""
    return df[df["frame"] < cut] if np.isfinite(cut) else df


def _from(df: pd.DataFrame, cut: float) -> pd.DataFrame:
    return df[df["frame"] >= cut]


#: the order :func:`select_person` tries the components in: what changes the tracking, then the
#: extent, refitted on the runs of the model so far (it maps *that* tracker's box onto the drawn
#: one, and changes what is written, not how people are tracked)
ORDER = ("detector", "steer", "velocity", "ending", "noise", "extent")
#: components that change only the boxes written, not the tracking (the same runs, rewritten)
OUTPUT_ONLY = frozenset({"extent"})


#: how many standard errors of the paired differences a component's mean gain must reach
#: (:func:`select_person`): one, a gain larger than its own uncertainty over the validation seeds
MARGIN_SE = 1.0


def paired_gain(candidate: list[float], best: list[float]) -> tuple[float, float]:
    """Mean and standard error of ``candidate - best`` over paired validation seeds (the same tracker
    seeds and starting boxes for both); standard error 0 for a single seed."""
    d = np.asarray(candidate, float) - np.asarray(best, float)
    se = float(np.std(d, ddof=1) / np.sqrt(len(d))) if len(d) > 1 else 0.0
    return float(d.mean()), se


def select_person(run: Callable[[int, BodyParams], pd.DataFrame], truths: list[pd.DataFrame], base: BodyParams,
                  fit: PersonFit, base_tracks: list[pd.DataFrame] | None = None,
                  progress: Callable[[str], None] | None = None,
                  groups: list[int] | None = None, cuts: list[float] | None = None,
                  fit_runs: Callable[[BodyParams], list[pd.DataFrame]] | None = None,
                  fit_truths: list[pd.DataFrame] | None = None, margin: float = MARGIN_SE) -> tuple[BodyParams, dict]:
    """Add the fitted components to ``base`` one at a time (:data:`ORDER`: detector, steer,
    velocity, ending, noise, extent), keeping each only if it lowers the person boxes' error on the
    validation runs below the best so far, by more than chance: ``(params, record)``.

    ``run(i, params)`` tracks validation run ``i`` against ``truths[i]``; ``groups`` (None: one
    group) gives each run's tracker seed. The error is the soft edits per 100 corrected person boxes
    (:func:`person_error`: the edits with their IoU threshold blurred, so that it moves with the
    boxes rather than by whole boxes at IoU 0.5). Candidate and best so far are run with the same
    seeds from the same boxes, so each seed gives a paired difference; a component is kept only if
    the mean difference is below zero by at least ``margin`` standard errors of it
    (:func:`paired_gain`; a tie or a gain within the seeds' spread keeps the simpler model). The
    rule asks for a gain beyond the seeds' spread rather than on every seed: one seed that loses a
    walker (tens of edits on PETS09) no longer vetoes a component that helps all others, and one
    seed that keeps a walker no longer carries one that helps none. The person box's extent rewrites
    the boxes of the same runs, so its differences carry no tracking chaos and the same rule passes
    it as soon as its gain is consistent.

    The extent goes last, refitted (:func:`fit_person_extent`, on the frames before the cuts) on
    the runs of the model so far: the detection cue steers each track's person box towards its
    detection and the velocity gain moves it along, so the extent that fits depends on what was
    kept before it. ``fit_runs(params)`` (None: the validation runs before their cuts) gives those
    runs on the frames the fits were made on, against ``fit_truths``.

    ``cuts`` (None: every run scored on all its frames): per run, the first frame that is scored;
    the frames before it are the ones ``fit`` was made on, so a component is kept only if what it
    learnt on the earlier corrected frames lowers the error on the later ones: whether it *carries
    over in time*, as it must for the rest of the clip (:func:`partlab.models.training._learn_from_people`)."""
    step = progress or (lambda _msg: None)
    groups = list(groups) if groups is not None else [0] * len(truths)
    seeds = sorted(set(groups))
    cuts = list(cuts) if cuts is not None else [-np.inf] * len(truths)
    scored = [_from(g, c) for g, c in zip(truths, cuts)]
    fitted_on = [before_cut(g, c) for g, c in zip(truths, cuts)]

    def error(tracks, which=None, measure=person_error) -> float:
        which = which if which is not None else range(len(tracks))
        return measure([_from(tracks[j], cuts[j]) for j in which], [scored[j] for j in which])

    def by_seed(tracks, measure=person_error) -> list[float]:
        return [error(tracks, [j for j, g in enumerate(groups) if g == k], measure) for k in seeds]

    def score(params, name):
        step(f"validating {name}")
        return [run(i, params) for i in range(len(truths))]

    if base_tracks is None:
        base_tracks = score(base, "start")
    scores = {"start": error(base_tracks)}
    per_seed = {"start": by_seed(base_tracks)}
    edits = {"start": error(base_tracks, measure=person_edits)}
    edits_seeds = {"start": by_seed(base_tracks, person_edits)}
    gains = {}
    params, tracks, kept, used = base, base_tracks, {}, {}
    best_seeds = per_seed["start"]
    for comp in ORDER:
        changes = fit.components.get(comp)
        if comp == "extent" and (changes is not None or any(kept.values())):
            if fit_runs is not None:
                ext = fit_person_extent(fit_runs(params), fit_truths, params.output.person)
            else:
                ext = fit_person_extent([before_cut(t, c) for t, c in zip(tracks, cuts)], fitted_on,
                                        params.output.person)
            changes = {"output.person": ext} if ext and ext != params.output.person else None
            fit.record["person_extent"] = list(ext) if ext else None
        if changes is None:
            continue
        trial = params.updated(changes)
        trial_tracks = score(trial, comp)
        s_seeds = by_seed(trial_tracks)
        scores[f"+{comp}"], per_seed[f"+{comp}"] = error(trial_tracks), s_seeds
        edits[f"+{comp}"] = error(trial_tracks, measure=person_edits)
        edits_seeds[f"+{comp}"] = by_seed(trial_tracks, person_edits)
        mean, se = paired_gain(s_seeds, best_seeds)
        gains[comp] = {"mean": round(mean, 3), "se": round(se, 3)}
        kept[comp] = bool(mean < 0 and mean <= -margin * se)
        if kept[comp]:
            best_seeds, params, tracks, used[comp] = s_seeds, trial, trial_tracks, changes
    fields = sorted(f for changes in used.values() for f in changes)
    rule = ("each fitted component is kept only if it lowers the soft edits per 100 corrected person boxes on "
            "the training clips below the best so far")
    if len(seeds) > 1:
        rule += (f", paired over {len(seeds)} tracker seeds, by at least {margin:g} standard error(s) of the "
                 "mean difference")
    if any(np.isfinite(c) for c in cuts):
        rule += (", fitted on the earlier corrected frames and scored on the later ones (from frame "
                 + ", ".join(sorted({str(int(c)) for c in cuts if np.isfinite(c)})) + ")")
    return params, {"scores": {k: round(v, 3) for k, v in scores.items()},
                    "scores_by_seed": {k: [round(x, 3) for x in v] for k, v in per_seed.items()},
                    "edits": {k: round(v, 3) for k, v in edits.items()},
                    "edits_by_seed": {k: [round(x, 3) for x in v] for k, v in edits_seeds.items()},
                    "gains": gains, "kept": kept, "fields": fields, "rule": rule, "measure": "soft edits/100",
                    "scored_from": sorted({int(c) for c in cuts if np.isfinite(c)})}


def person_rows(record: dict) -> list[dict]:
    """The summary's ``person`` record as rows ``component, edits/100, soft edits/100, gain, decision,
    fitted``: what was fitted, the edits and soft edits (what decides) each component gave on the
    training clips' validation runs, its mean paired gain ± standard error, and whether it was kept."""
    det = record.get("detector") or {}
    shrink = tuple(det["shrink"]) if det.get("shrink") else "-"
    fitted = {
        "detector": (f"min_score = {det.get('min_score')}, shrink = {shrink} ({det.get('true', 0)} true / "
                     f"{det.get('false', 0)} false detections on {det.get('boxes', 0)} corrected boxes)")
        if det else "-",
        "steer": f"steer = {(record.get('steer') or {}).get('steer')} (median squared error: tracker "
                 f"{(record.get('steer') or {}).get('tracker_error')}, detector "
                 f"{(record.get('steer') or {}).get('detector_error')})",
        "velocity": f"steer_velocity = {(record.get('steer_velocity') or {}).get('steer_velocity')} (median "
                    f"squared error: tracker {(record.get('steer_velocity') or {}).get('tracker_error')}, detector "
                    f"{(record.get('steer_velocity') or {}).get('detector_error')})",
        "extent": f"output.person = {tuple(record['person_extent'])}" if record.get("person_extent") else "-",
        "ending": f"undetected_frames = {record.get('undetected_frames')}, "
                  f"leave_fraction = {record.get('leave_fraction')}",
        "noise": "parts' position/velocity noise widened to the person's" if "noise" in record.get("fitted", [])
        else "the person moves no faster than the parts' defaults",
    }
    scores, kept, edits = record.get("scores", {}), record.get("kept", {}), record.get("edits", {})
    gains = record.get("gains", {})

    def gain(comp):
        g = gains.get(comp)
        return f"{g['mean']:+.2f} ± {g['se']:.2f}" if g else ""

    rows = [dict(component="start", **{"edits/100": edits.get("start"), "soft edits/100": scores.get("start")},
                 gain="", decision="baseline", fitted="")]
    for comp, text in fitted.items():
        decision = ("kept" if kept.get(comp) else "dropped") if comp in kept else "not tried"
        rows.append(dict(component=comp, **{"edits/100": edits.get(f"+{comp}"),
                                            "soft edits/100": scores.get(f"+{comp}")},
                         gain=gain(comp), decision=decision, fitted=text))
    return rows


def person_table(record: dict) -> str:
    """:func:`person_rows` as aligned text (``partlab train``)."""
    def num(v):
        return v if v is not None else float("nan")

    lines = [f"{'component':9} {'edits/100':>9} {'soft':>7} {'gain ± se':>14}  {'decision':10} fitted"]
    for r in person_rows(record):
        lines.append(f"{r['component']:9} {num(r['edits/100']):9.2f} {num(r['soft edits/100']):7.2f} "
                     f"{r['gain']:>14}  {r['decision']:10} {r['fitted']}")
    return "\n".join(lines)
