"""Apply the box editor's events to the store, with a per-session undo/redo history.

Every edit is written at once (``Store.edit_box``) with the revision the user saw, so
a stale edit is refused with the store's message instead of overwriting someone
else's work, and a killed app loses nothing that was shown as saved. Undo/redo walk
this session's own edits; the store keeps every revision, so an undo is itself a new
revision (``Store.undo``) and a redo writes the undone content again.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from partlab.labelling.store import StaleEditError, Store, StoreError
from partlab.tracking.core.box import Box
from partlab.tracking.tracks import TracksCSVError, check_value


@dataclass(frozen=True)
class EditRef:
    """One of this session's writes: the key and the revision it produced;
    ``content`` is what a redo writes back (``None`` for undo entries)."""

    frame: int
    track_id: int
    part: str
    revision: int
    content: dict | None = None


@dataclass
class EditHistory:
    """Undo/redo stacks of one session and clip (newest last)."""

    undo: list[EditRef] = field(default_factory=list)
    redo: list[EditRef] = field(default_factory=list)


@dataclass
class ApplyResult:
    """What applying a batch of events did: ``frame`` to show next (or None), the
    number of writes, and messages for the user (errors are refusals, not crashes)."""

    frame: int | None = None
    written: int = 0
    errors: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def _box(values) -> Box:
    """The box of an editor event, by the tracks CSV's rules (finite, in range, no negative size)."""
    if not isinstance(values, (list, tuple)) or len(values) != 4:
        raise StoreError(f"a box is [x, y, w, h], got {str(values)[:60]}")
    try:
        x, y, w, h = (check_value(c, v, f"box {c}") for c, v in zip("xywh", values))
    except TracksCSVError as exc:
        raise StoreError(f"Not a usable box: {exc}") from None
    return Box(x, y, w, h)


def _flag(value) -> bool:
    try:
        return check_value("failure", value, "failure")
    except TracksCSVError as exc:
        raise StoreError(str(exc)) from None


def _current(store: Store, clip_id: int, frame: int, track_id: int, part: str) -> dict | None:
    df = store.frame_boxes(clip_id, frame)
    row = df[(df.track_id == track_id) & (df.part == part)]
    if not len(row):
        return None
    r = row.iloc[0]
    return dict(box=[float(r.x), float(r.y), float(r.w), float(r.h)], failure=bool(r.failure),
                occluded=float(r.occluded))


def apply_events(store: Store, clip_id: int, events: list[dict], history: EditHistory,
                 author: str = "") -> ApplyResult:
    """Write the editor's events to the store in order; see :mod:`partlab.app.box_editor` for their shape."""
    res = ApplyResult()
    for ev in events:
        kind = ev.get("kind")
        try:
            if kind == "frame":
                res.frame = int(ev["target"])
            elif kind == "occluders":
                store.set_occluders(clip_id, [_box(b) for b in ev.get("boxes", [])])
                res.written += 1
            elif kind in ("edit", "delete"):
                frame, tid, part = int(ev["frame"]), int(ev["track_id"]), str(ev["part"])
                expected = ev.get("revision")
                if expected is None or ev.get("added"):
                    # a new key: nobody's edit to be stale against, unless one appeared meanwhile
                    expected = store.revision(clip_id, frame, tid, part)
                box = _box(ev["box"]) if kind == "edit" else None
                rev = store.edit_box(clip_id, frame, tid, part, box,
                                     failure=_flag(ev.get("failure")) if kind == "edit" else None,
                                     occluded=ev.get("occluded") or 0.0 if kind == "edit" else None,
                                     expected_revision=int(expected), author=author)
                history.undo.append(EditRef(frame, tid, part, rev))
                history.redo.clear()
                res.written += 1
            elif kind == "undo":
                if not history.undo:
                    res.notes.append("nothing to undo in this session")
                    continue
                ref = history.undo[-1]
                before = _current(store, clip_id, ref.frame, ref.track_id, ref.part)
                rev = store.undo(clip_id, ref.frame, ref.track_id, ref.part, expected_revision=ref.revision,
                                 author=author)
                history.undo.pop()
                history.redo.append(EditRef(ref.frame, ref.track_id, ref.part, rev, content=before or {}))
                res.frame = ref.frame
                res.written += 1
                res.notes.append(f"undid the edit of {ref.part} #{ref.track_id} at frame {ref.frame}")
            elif kind == "redo":
                if not history.redo:
                    res.notes.append("nothing to redo")
                    continue
                ref = history.redo[-1]
                c = ref.content or {}
                box = _box(c["box"]) if c.get("box") else None
                rev = store.edit_box(clip_id, ref.frame, ref.track_id, ref.part, box, failure=c.get("failure"),
                                     occluded=c.get("occluded"), expected_revision=ref.revision, author=author)
                history.redo.pop()
                history.undo.append(EditRef(ref.frame, ref.track_id, ref.part, rev))
                res.frame = ref.frame
                res.written += 1
                res.notes.append(f"redid the edit of {ref.part} #{ref.track_id} at frame {ref.frame}")
        except StaleEditError as exc:
            res.errors.append(f"Not saved: {exc}")
        except (StoreError, ValueError, KeyError, TypeError) as exc:
            res.errors.append(f"Not saved ({kind}): {exc}")
    return res
