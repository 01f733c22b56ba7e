"""Events (activities with a start and an end frame): the events CSV and their evaluation.

The events CSV is what ``partlab track --events`` writes and ``partlab eval --events`` reads:
``start_frame,end_frame,kind`` first, then ``track_id_a,part_a,track_id_b,part_b`` (the tracks and
parts involved; ``track_id_b = 0`` for one-hand activities), ``ended_by``, ``object_colour``
(``#rrggbb``) and ``confidence``. Synthetic scenes write their truth as ``events.csv`` with
``kind,start_frame,end_frame,...,colour``; both are read here.

Evaluation follows the usual temporal-detection protocol: a predicted event is a true positive
when it has the kind of a truth event not matched yet and their temporal IoU (frames in common over
frames in either, ends included) is at least ``iou`` (0.5); matching is greedy by IoU.
"""

from __future__ import annotations

import math
from os import PathLike
from pathlib import Path

import pandas as pd

from partlab.errors import UserError
from partlab.limits import MAX_ID

KINDS: tuple[str, ...] = ("clap", "handshake", "exchange", "pick", "place", "hand_head")
REQUIRED: tuple[str, ...] = ("start_frame", "end_frame", "kind")


class EventsError(UserError):
    """An events file that cannot be used; the message names the file, line and column."""


def read_events(path: str | PathLike) -> pd.DataFrame:
    """An events CSV (ours or a synthetic scene's truth), checked: frames are whole numbers with
    ``start <= end``, kinds are known."""
    p = Path(path)
    if not p.is_file():
        raise EventsError(f"{p}: no such events file")
    try:
        df = pd.read_csv(p, dtype={"kind": str}, keep_default_na=False)
    except (UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise EventsError(f"{p}: not an events CSV ({' '.join(str(exc).split())})") from None
    missing = [c for c in REQUIRED if c not in df.columns]
    if missing:
        raise EventsError(f"{p} line 1: missing column(s) {', '.join(missing)}")
    for i, row in enumerate(df.itertuples(index=False), start=2):
        for col in ("start_frame", "end_frame"):
            v = getattr(row, col)
            try:
                f = float(v)
            except (TypeError, ValueError):
                raise EventsError(f"{p} line {i}, column '{col}': {v!r} is not a frame number") from None
            if not math.isfinite(f) or f < 0 or not f.is_integer():
                raise EventsError(f"{p} line {i}, column '{col}': {v!r} is not a frame number")
            if f > MAX_ID:
                raise EventsError(f"{p} line {i}, column '{col}': {v!r} is larger than the limit of {MAX_ID}")
        if int(float(row.start_frame)) > int(float(row.end_frame)):
            raise EventsError(f"{p} line {i}: start_frame {row.start_frame} is after end_frame {row.end_frame}")
        if row.kind not in KINDS:
            raise EventsError(f"{p} line {i}, column 'kind': unknown kind {row.kind!r}; expected one of "
                              f"{', '.join(KINDS)}")
    df["start_frame"] = df["start_frame"].astype(float).astype("int64")
    df["end_frame"] = df["end_frame"].astype(float).astype("int64")
    return df


def temporal_iou(a: tuple[int, int], b: tuple[int, int]) -> float:
    """Frames in common over frames in either (both ends included)."""
    inter = min(a[1], b[1]) - max(a[0], b[0]) + 1
    if inter <= 0:
        return 0.0
    return inter / (max(a[1], b[1]) - min(a[0], b[0]) + 1)


def match_events(truth: pd.DataFrame, predicted: pd.DataFrame, iou: float = 0.5) -> list[tuple[int, int, float]]:
    """Greedy one-to-one matches ``(truth row, predicted row, iou)`` of the same kind with IoU >= ``iou``."""
    pairs = []
    for i, t in enumerate(truth.itertuples(index=False)):
        for j, p in enumerate(predicted.itertuples(index=False)):
            if t.kind == p.kind:
                v = temporal_iou((t.start_frame, t.end_frame), (p.start_frame, p.end_frame))
                if v >= iou:
                    pairs.append((v, i, j))
    used_t, used_p, out = set(), set(), []
    for v, i, j in sorted(pairs, reverse=True):
        if i not in used_t and j not in used_p:
            used_t.add(i)
            used_p.add(j)
            out.append((i, j, v))
    return out


def evaluate_events(truth: pd.DataFrame, predicted: pd.DataFrame, iou: float = 0.5) -> pd.DataFrame:
    """Per kind: truth and predicted counts, true positives, precision and recall at temporal ``iou``;
    a last row ``all``. Precision of a kind nobody predicted and recall of a kind not in the truth
    are NaN (undefined, not 0 or 1)."""
    matches = match_events(truth, predicted, iou)
    kinds = [k for k in KINDS if k in set(truth["kind"]) | set(predicted["kind"])]
    rows = []
    for k in kinds + ["all"]:
        nt = int((truth["kind"] == k).sum()) if k != "all" else len(truth)
        npred = int((predicted["kind"] == k).sum()) if k != "all" else len(predicted)
        tp = sum(1 for i, _, _ in matches if k == "all" or truth.iloc[i]["kind"] == k)
        rows.append(dict(kind=k, truth=nt, predicted=npred, matched=tp,
                         precision=tp / npred if npred else float("nan"), recall=tp / nt if nt else float("nan")))
    return pd.DataFrame(rows).set_index("kind")


#: the events CSV's columns, in order (what ``partlab track --events`` writes)
CSV_COLUMNS: tuple[str, ...] = ("start_frame", "end_frame", "kind", "track_id_a", "part_a", "track_id_b", "part_b",
                                "ended_by", "object_colour", "confidence")


def _pair(values, k: int, default):
    values = list(values) if isinstance(values, (list, tuple)) else []
    return values[k] if len(values) > k else default


def from_store(stored: pd.DataFrame) -> pd.DataFrame:
    """The events CSV table (:data:`CSV_COLUMNS` plus ``event_id`` and ``source``) of
    :meth:`~partlab.labelling.store.Store.events` rows: ``type`` is the kind, the first two
    ``tracks``/``parts`` are the a and b sides, ``ended_by`` and ``object_colour`` come from the
    attributes."""
    rows = []
    for r in stored.itertuples(index=False):
        attrs = r.attributes if isinstance(r.attributes, dict) else {}
        tracks, parts = list(r.tracks or []), list(r.parts or [])
        if len(tracks) == 1 and len(parts) == 2:  # one person's two hands (a clap)
            tracks = tracks * 2
        conf = r.confidence
        rows.append(dict(start_frame=int(r.start_frame), end_frame=int(r.end_frame), kind=str(r.type),
                         track_id_a=int(_pair(tracks, 0, 0)), part_a=str(_pair(parts, 0, "")),
                         track_id_b=int(_pair(tracks, 1, 0)), part_b=str(_pair(parts, 1, "")),
                         ended_by=str(attrs.get("ended_by", "")), object_colour=str(attrs.get("object_colour", "")),
                         confidence=float("nan") if conf is None else float(conf), event_id=int(r.event_id),
                         source=str(r.source)))
    return pd.DataFrame(rows, columns=list(CSV_COLUMNS) + ["event_id", "source"])


def to_store(store, clip_id: int, events: pd.DataFrame, source: str = "tracker", author: str = "") -> list[int]:
    """Record the rows of an events table (:data:`CSV_COLUMNS`) in the store; returns their event ids."""
    ids = []
    for r in events.itertuples(index=False):
        two = bool(str(getattr(r, "part_b", "") or ""))  # side b is there when it names a part (0 is a track id)
        tracks = [int(r.track_id_a)] + ([int(r.track_id_b)] if two else [])
        parts = [str(getattr(r, c)) for c in ("part_a", "part_b") if str(getattr(r, c, "") or "")]
        attrs = {k: str(getattr(r, k)) for k in ("ended_by", "object_colour") if str(getattr(r, k, "") or "")}
        conf = getattr(r, "confidence", None)
        ids.append(store.add_event(clip_id, int(r.start_frame), int(r.end_frame), str(r.kind),
                                   tracks=list(dict.fromkeys(tracks)), parts=parts, source=source, author=author,
                                   confidence=None if conf is None or conf != conf else float(conf),
                                   attributes=attrs))
    return ids


def store_run_events(store, clip_id: int, events: pd.DataFrame | None, start: int = 0, stop: int | None = None,
                     track_ids=None, author: str = "") -> list[int]:
    """Record a tracker run's events over frames ``[start, stop)`` the way a run records its boxes:
    the tracker's earlier events there that nobody edited (``source == "tracker"``, one revision) are
    deleted (as a revision, so the history keeps them) and replaced; an event a person added or edited
    is never touched, and a new one of its kind that overlaps it by half (temporal IoU >= 0.5) is not
    added again. With ``track_ids`` (a re-track of some tracks) only events of those tracks are
    replaced. Events are clipped to the run's frames. Returns the new event ids."""
    frame_count = store.clip(clip_id).frame_count
    stop = frame_count if stop is None else min(int(stop), frame_count)
    hist = store.events(clip_id, history=True)
    now = store.events(clip_id)
    revisions = hist.groupby("event_id")["revision"].max() if len(hist) else pd.Series(dtype=int)
    kept = []
    for r in now.itertuples(index=False):
        inside = start <= int(r.start_frame) and int(r.end_frame) < stop
        ours = track_ids is None or set(r.tracks or []) <= {int(t) for t in track_ids}
        if r.source == "tracker" and int(revisions.get(r.event_id, 1)) == 1 and inside and ours:
            store.edit_event(clip_id, int(r.event_id), expected_revision=1, author=author, delete=True)
        else:
            kept.append((str(r.type), int(r.start_frame), int(r.end_frame)))
    if events is None or not len(events):
        return []
    new = events.assign(start_frame=events["start_frame"].clip(lower=start),
                        end_frame=events["end_frame"].clip(upper=stop - 1))
    new = new[new["start_frame"] <= new["end_frame"]]
    new = new[[not any(k == r.kind and temporal_iou((a, b), (r.start_frame, r.end_frame)) >= 0.5 for k, a, b in kept)
               for r in new.itertuples(index=False)]]
    return to_store(store, clip_id, new, source="tracker", author=author)
