"""Operations on whole tracks and on keyframes, written to the store as revisions.

Each function returns the *changes* (dicts of :meth:`Store.edit_boxes`' arguments) that
carry it out, computed from the boxes in effect; :func:`apply` writes them in one
transaction, so an operation is one step of undo (``Store.undo_many`` of its keys).

- :func:`delete_from`: remove a track from a frame on;
- :func:`merge`: move every box of one track to another (where both have a part at a
  frame, the kept track's box stays);
- :func:`split`: give a track's boxes from a frame on a new id;
- :func:`change_id`: a split at the track's first frame (a merge when the id is taken);
- :func:`person_update`: the person box as the minimum bounding rectangle of the body
  parts (Zhao & Lee sec. 5.3) after one of them was edited;
- :func:`fill_between`: the in-between boxes of one track and part between two keyframes
  (a keyframe is a human box in effect, ``Store.keyframes``), stored as a tracker run of
  that track and part only; they come from a :data:`Proposer` (the app passes keyframe-guided
  tracking, :func:`partlab.tracking.keyframes.track_stretch`; :func:`linear_proposer` is the
  straight line).

Identity operations write revisions of kind ``track`` (the tracker's boxes moved, not
checked), except for human boxes, which stay ``box``: a keyframe moved to another id is
still a keyframe.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from partlab.labelling.store import Store, StoreError
from partlab.tracking.core.box import Box
from partlab.tracking.parts import BODY_PARTS

KEY = ["frame", "track_id", "part"]
MIN_MBR_PARTS = 2  # the same rule as evaluation: one part alone is no person box


def _revisions(store: Store, clip_id: int) -> dict[tuple[int, int, str], int]:
    return store.revisions(clip_id)


def _row_box(r) -> Box:
    return Box(float(r.x), float(r.y), max(float(r.w), 0.0), max(float(r.h), 0.0))


def _move(rows: pd.DataFrame, new_id: int, revs: dict) -> list[dict]:
    """Changes deleting ``rows`` and writing them under ``new_id``."""
    out = []
    for r in rows.itertuples(index=False):
        kind = "box" if r.source == "human" else "track"
        out.append(dict(frame=int(r.frame), track_id=int(r.track_id), part=r.part, box=None, kind=kind,
                        expected_revision=int(r.revision)))
        out.append(dict(frame=int(r.frame), track_id=int(new_id), part=r.part, box=_row_box(r), kind=kind,
                        failure=bool(r.failure), occluded=float(r.occluded),
                        expected_revision=revs.get((int(r.frame), int(new_id), r.part), 0)))
    return out


def delete_from(store: Store, clip_id: int, track_id: int, frame: int) -> list[dict]:
    df = store.tracks(clip_id)
    rows = df[(df.track_id == track_id) & (df.frame >= frame)]
    if not len(rows):
        raise StoreError(f"track {track_id} has no boxes from frame {frame} on")
    return [dict(frame=int(r.frame), track_id=int(track_id), part=r.part, box=None,
                 kind="box" if r.source == "human" else "track", expected_revision=int(r.revision))
            for r in rows.itertuples(index=False)]


def merge(store: Store, clip_id: int, keep: int, other: int) -> list[dict]:
    if int(keep) == int(other):
        raise StoreError("pick two different tracks to merge")
    df = store.tracks(clip_id)
    mine = df[df.track_id == keep]
    theirs = df[df.track_id == other]
    if not len(theirs) or not len(mine):
        raise StoreError(f"tracks {keep} and {other} must both have boxes to be merged")
    taken = set(zip(mine.frame, mine.part))
    clash = np.array([(f, p) in taken for f, p in zip(theirs.frame, theirs.part)], bool)
    revs = _revisions(store, clip_id)
    drop = [dict(frame=int(r.frame), track_id=int(other), part=r.part, box=None, expected_revision=int(r.revision),
                 kind="box" if r.source == "human" else "track") for r in theirs[clash].itertuples(index=False)]
    return drop + _move(theirs[~clash], keep, revs)


def split(store: Store, clip_id: int, track_id: int, frame: int, new_id: int | None = None) -> list[dict]:
    df = store.tracks(clip_id)
    new_id = store.next_track_id(clip_id) if new_id is None else int(new_id)
    if len(df[df.track_id == new_id]):
        raise StoreError(f"track {new_id} exists already; pick a free id (or merge)")
    rows = df[(df.track_id == track_id) & (df.frame >= frame)]
    if not len(rows):
        raise StoreError(f"track {track_id} has no boxes from frame {frame} on")
    return _move(rows, new_id, _revisions(store, clip_id))


def change_id(store: Store, clip_id: int, track_id: int, new_id: int) -> list[dict]:
    df = store.tracks(clip_id)
    if len(df[df.track_id == new_id]):
        return merge(store, clip_id, new_id, track_id)
    rows = df[df.track_id == track_id]
    if not len(rows):
        raise StoreError(f"there is no track {track_id}")
    return _move(rows, new_id, _revisions(store, clip_id))


def person_update(store: Store, clip_id: int, frame: int, track_id: int) -> list[dict]:
    """The change that makes the person box the MBR of the body parts at ``frame``: none
    when the track has no person box there, fewer than two body parts, a person box drawn
    by hand, or a person box that is the MBR already."""
    df = store.frame_boxes(clip_id, frame)
    rows = df[df.track_id == track_id]
    person = rows[rows.part == "person"]
    parts = rows[rows.part.isin(BODY_PARTS)]
    if not len(person) or len(parts) < MIN_MBR_PARTS or person.iloc[0].source == "human":
        return []
    x, y = float(parts.x.min()), float(parts.y.min())
    box = Box(x, y, float((parts.x + parts.w).max()) - x, float((parts.y + parts.h).max()) - y)
    p = person.iloc[0]
    if np.allclose([p.x, p.y, p.w, p.h], [box.x, box.y, box.w, box.h], atol=0.05):
        return []
    return [dict(frame=int(frame), track_id=int(track_id), part="person", box=box, kind="track",
                 failure=bool(p.failure), occluded=float(p.occluded), expected_revision=int(p.revision))]


def linear_in_between(first: tuple[int, Box], last: tuple[int, Box]) -> np.ndarray:
    """Boxes ``(n, 4)`` [x, y, w, h] of the frames strictly between two keyframes, by linear
    interpolation of corners and size."""
    (f0, b0), (f1, b1) = first, last
    t = (np.arange(f0 + 1, f1, dtype=float) - f0) / float(f1 - f0)
    a = np.array([b0.x, b0.y, b0.w, b0.h])
    b = np.array([b1.x, b1.y, b1.w, b1.h])
    return a[None, :] + t[:, None] * (b - a)[None, :]


#: ``propose(keys, track_id, part, start, end)``: the in-between boxes of one track and part, rows
#: ``frame, x, y, w, h`` (optionally ``score, failure, state``) of the frames strictly between
#: ``start`` and ``end``; ``keys`` holds every box of the track in effect at ``start`` and at
#: ``end`` (the part's keyframes among them), what a tracker starts from
Proposer = Callable[[pd.DataFrame, int, str, int, int], pd.DataFrame]


def linear_proposer(keys: pd.DataFrame, track_id: int, part: str, start: int, end: int) -> pd.DataFrame:
    """The straight line between the two keyframes (the fallback without a tracker, and CVAT's
    track mode)."""
    k = keys[(keys.track_id == track_id) & (keys.part == part)].set_index("frame")
    boxes = linear_in_between((start, _row_box(k.loc[start])), (end, _row_box(k.loc[end])))
    return pd.DataFrame(boxes, columns=["x", "y", "w", "h"]).assign(frame=np.arange(start + 1, end))


def keyframes_around(store: Store, clip_id: int, track_id: int, part: str, frame: int
                     ) -> tuple[int | None, int | None]:
    """The nearest keyframes of one track and part before and after ``frame`` (None: none)."""
    kf = store.keyframes(clip_id)
    kf = kf[(kf.track_id == track_id) & (kf.part == part) & ~kf.deleted.astype(bool)]
    before = kf[kf.frame < frame].frame
    after = kf[kf.frame > frame].frame
    return (int(before.max()) if len(before) else None, int(after.min()) if len(after) else None)


def refill_spans(store: Store, clip_id: int, track_id: int, part: str, frame: int) -> list[tuple[int, int]]:
    """The stretches ``(start, end)`` between keyframes that a keyframe of ``track_id``/``part`` at
    ``frame`` bounds (none when it is no keyframe or has no neighbouring keyframe)."""
    kf = store.keyframes(clip_id)
    kf = kf[(kf.track_id == track_id) & (kf.part == part) & ~kf.deleted.astype(bool)]
    if frame not in set(kf.frame.astype(int)):
        return []
    before, after = keyframes_around(store, clip_id, track_id, part, frame)
    return [(a, b) for a, b in ((before, frame), (frame, after)) if a is not None and b is not None and b - a > 1]


def stretch_keys(store: Store, clip_id: int, track_id: int, start: int, end: int) -> pd.DataFrame:
    """Every box of ``track_id`` in effect at ``start`` and at ``end`` (a proposer's ``keys``)."""
    rows = [b[b.track_id == track_id] for b in (store.frame_boxes(clip_id, start), store.frame_boxes(clip_id, end))]
    return pd.concat(rows, ignore_index=True)


def propose_fill(store: Store, clip_id: int, track_id: int, part: str, frame: int,
                 propose: Proposer = linear_proposer, progress: Callable[[int, int], None] | None = None
                 ) -> tuple[list[tuple[int, int]], pd.DataFrame | None]:
    """The stretches a keyframe of ``track_id``/``part`` at ``frame`` bounds (:func:`refill_spans`)
    and ``propose``'s rows for them (None: no stretch); reads the store, writes nothing.
    ``progress(done, total)`` after each stretch."""
    spans = refill_spans(store, clip_id, track_id, part, frame)
    if not spans:
        return spans, None
    cols = ["frame", "x", "y", "w", "h", "score", "failure", "state"]
    rows = []
    for k, (a, b) in enumerate(spans):
        got = propose(stretch_keys(store, clip_id, track_id, a, b), int(track_id), part, a, b)
        got = got[(got.frame > a) & (got.frame < b)]
        rows.append(got[[c for c in cols if c in got]])
        if progress is not None:
            progress(k + 1, len(spans))
    return spans, pd.concat(rows, ignore_index=True).assign(track_id=int(track_id), part=part, source="keyframes")


def write_fill(store: Store, clip_id: int, track_id: int, part: str, spans: list[tuple[int, int]],
               table: pd.DataFrame | None) -> int | None:
    """Store :func:`propose_fill`'s rows as a tracker run of that track and part only, replacing
    its in-between boxes over ``spans`` (None: nothing to write)."""
    if not spans or table is None:
        return None
    start, stop = spans[0][0] + 1, spans[-1][1]
    return store.save_tracker_run(clip_id, table, tracker="keyframes", start_frame=start,
                                  stop_frame=stop, track_ids=[int(track_id)], parts=[part])


def fill_between(store: Store, clip_id: int, track_id: int, part: str, frame: int,
                 propose: Proposer = linear_proposer) -> int | None:
    """Refill the in-between boxes of ``track_id``/``part`` on both sides of the keyframe at
    ``frame`` (up to the neighbouring keyframes) with ``propose``'s boxes; returns the tracker run
    written, or None when there is no neighbouring keyframe. Other tracks and parts are not touched."""
    spans, table = propose_fill(store, clip_id, track_id, part, frame, propose)
    return write_fill(store, clip_id, track_id, part, spans, table)


def apply(store: Store, clip_id: int, changes: list[dict], author: str = "") -> list[tuple[int, int, str, int]]:
    """Write ``changes`` in one transaction; returns ``(frame, track_id, part, revision)`` of
    each key written, what :meth:`Store.undo_many` takes to undo them as one step."""
    revs = store.edit_boxes(clip_id, changes, author=author)
    return [(int(c["frame"]), int(c["track_id"]), str(c["part"]), r) for c, r in zip(changes, revs)]


def retrack_window(store: Store, clip_id: int, frame: int, track_id: int | None = None
                   ) -> tuple[int, int | None, list[int]]:
    """Where "Re-track" runs: from the newest keyframe at or before ``frame`` (``frame``
    itself when there is none) to the next keyframe after it, for the tracks that have boxes
    at the start (only ``track_id`` when given). Returns ``(start, stop, track_ids)``;
    ``stop`` is exclusive (None: the end of the clip)."""
    kf = store.keyframes(clip_id)
    if track_id is not None:
        kf = kf[kf.track_id == track_id]
    earlier = kf[kf.frame <= frame].frame
    start = int(earlier.max()) if len(earlier) else int(frame)
    boxes = store.frame_boxes(clip_id, start)
    ids = sorted({int(t) for t in boxes.track_id} if track_id is None else
                 ({int(track_id)} if (boxes.track_id == track_id).any() else set()))
    later = kf[(kf.frame > start) & kf.track_id.isin(ids)].frame
    return start, (int(later.min()) if len(later) else None), ids
