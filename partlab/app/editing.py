"""Apply the box editor's events to the store, with a per-session undo/redo history.

Every edit is written at once with the revision the user saw, so a stale edit is
refused with the store's message instead of overwriting someone else's work, and a
killed app loses nothing that was shown as saved. Undo/redo walk this session's own
*steps*: one step is everything one action wrote (a box and the person box recomputed
from it, the in-between boxes refilled from it, every box of a merged track), undone
together. The store keeps every revision, so an undo is itself a new revision
(``Store.undo_many``) and a redo writes the undone content again.

Events (activities over a range of frames, ``Store.add_event``) are edited the same way: adding,
stretching, retyping or deleting one is a step whose undo writes the event's fields from before it
as a new revision (an added event is deleted, a deleted one comes back).

Track mode refills in two passes: the straight line between the keyframes at once (part of the
edit's step), then keyframe-guided tracking of that one track (:func:`refine_step`, which the page
runs as a background job: about 1-2 s a stretch) written into the same step, so one undo takes
back the edit, the line and the tracker's boxes. A refinement is dropped unwritten when its step
was undone meanwhile or a later step refilled the same track and part (the newer boxes stay).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field

from partlab.labelling import trackops
from partlab.labelling.store import StaleEditError, Store, StoreError
from partlab.tracking.core.box import Box
from partlab.tracking.parts import BODY_PARTS
from partlab.tracking.tracks import TracksCSVError, check_value


@dataclass
class Step:
    """One undoable action: the keys it wrote ``(frame, track_id, part, revision)``, the
    human layer of those keys before and after it (changes for ``Store.edit_boxes``), the
    tracker run it wrote (in-between boxes; None: none), the keys whose in-betweens it
    refilled ``(track_id, part, frame)``, a label for the messages and the frame to show;
    ``refined``: the runs :func:`refine_step` added later (undone first)."""

    keys: list[tuple[int, int, str, int]]
    before: list[dict]
    after: list[dict]
    label: str
    frame: int
    run_id: int | None = None
    refill: list[tuple[int, str, int]] = field(default_factory=list)
    #: events the step changed: ``(event_id, fields before, fields after)``; None = no such event
    events: list[tuple[int, dict | None, dict | None]] = field(default_factory=list)
    refined: list[int] = field(default_factory=list)
    fills: dict[tuple[int, str], int] = field(default_factory=dict)  # EditHistory.fills when it refilled
    #: what it wrote in the other views of a take: ``(clip_id, step of that clip)`` (undone with it)
    views: list[tuple[int, Step]] = field(default_factory=list)
    #: other views it could not write (their messages)
    view_errors: list[str] = field(default_factory=list)


@dataclass
class EditHistory:
    """Undo/redo stacks of one session and clip (newest last); ``revs``: the revision this
    session wrote last for each key (what its next undo or redo of that key expects);
    ``fills``: how often each ``(track_id, part)`` was refilled or un-refilled (a refinement
    started at one count is stale at another); ``lock``: held while the stacks change (a
    refinement job writes from another thread)."""

    undo: list[Step] = field(default_factory=list)
    redo: list[Step] = field(default_factory=list)
    revs: dict[tuple[int, int, str], int] = field(default_factory=dict)
    #: the revision this session wrote last for each event
    event_revs: dict[int, int] = field(default_factory=dict)
    fills: dict[tuple[int, str], int] = field(default_factory=dict)
    #: ``revs`` of the other views of a take this session wrote into, by clip id
    view_revs: dict[int, dict[tuple[int, int, str], int]] = field(default_factory=dict)
    #: ``seq`` of this session's box edits that were refused as stale: an edit the editor based on
    #: one of them (``based_on``) carries that edit's optimistic revision and is refused too
    refused: set[int] = field(default_factory=set)
    lock: threading.RLock = field(default_factory=threading.RLock, repr=False, compare=False)

    def touched(self, refill: list[tuple[int, str, int]]) -> dict[tuple[int, str], int]:
        """Count a refill (or its undo) of these tracks and parts; returns their new counts."""
        for tid, part, _ in refill:
            self.fills[(tid, part)] = self.fills.get((tid, part), 0) + 1
        return {(tid, part): self.fills[(tid, part)] for tid, part, _ in refill}

    def wrote(self, keys: list[tuple[int, int, str, int]]) -> None:
        for f, t, p, r in keys:
            self.revs[(f, t, p)] = r


@dataclass
class ApplyResult:
    """What applying a batch of events did: ``frame`` to show next (or None), the
    number of writes, and messages for the user (errors are refusals, not crashes)."""

    frame: int | None = None
    written: int = 0
    errors: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    refills: list[Step] = field(default_factory=list)  # steps whose straight lines a tracker may refine


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


def _write(store: Store, clip_id: int, changes: list[dict], author: str) -> tuple[list, list, list]:
    """Write ``changes``; returns (keys written, human layer before, human layer after)."""
    keys = [(int(c["frame"]), int(c["track_id"]), str(c["part"])) for c in changes]
    before = store.edit_state(clip_id, keys)
    written = trackops.apply(store, clip_id, changes, author=author)
    return written, before, store.edit_state(clip_id, keys)


def record(store: Store, clip_id: int, changes: list[dict], history: EditHistory, label: str, frame: int,
           author: str = "", fill: bool = False) -> Step:
    """Write ``changes`` as one step (plus the person boxes recomputed from body-part edits
    and, with ``fill``, the in-between boxes of the edited key) and push it on the undo stack."""
    with history.lock:
        return _record(store, clip_id, changes, history, label, frame, author, fill)


def _record(store: Store, clip_id: int, changes: list[dict], history: EditHistory, label: str, frame: int,
            author: str, fill: bool) -> Step:
    keys, before, after = _write(store, clip_id, changes, author)
    boxes = [c for c in changes if c.get("box") is not None and c.get("kind", "box") == "box"]
    person = []
    for tid in sorted({int(c["track_id"]) for c in boxes if c["part"] in BODY_PARTS}):
        for f in sorted({int(c["frame"]) for c in boxes if int(c["track_id"]) == tid}):
            person += trackops.person_update(store, clip_id, f, tid)
    if person:
        k, b, a = _write(store, clip_id, person, author)
        keys, before, after = keys + k, before + b, after + a
    history.wrote(keys)
    step = Step(keys=keys, before=before, after=after, label=label, frame=frame)
    if fill and len(boxes) == 1:  # one tracker run per step keeps the step undoable
        c = boxes[0]
        step.refill = [(int(c["track_id"]), str(c["part"]), int(c["frame"]))]
        step.run_id = _refill(store, clip_id, step.refill)
        step.fills = history.touched(step.refill)
    history.undo.append(step)
    history.redo.clear()
    return step


def _refill(store: Store, clip_id: int, refill: list[tuple[int, str, int]]) -> int | None:
    run = None
    for tid, part, f in refill:
        run = trackops.fill_between(store, clip_id, tid, part, f)
    return run


def _rewrite(store: Store, clip_id: int, revs: dict, step: Step, contents: list[dict], author: str) -> list:
    """Write ``contents`` over the keys ``step`` wrote, expecting the revisions this session wrote
    last (``revs``, updated)."""
    changes = [dict(c, expected_revision=revs.get(k[:3], k[3])) for c, k in zip(contents, step.keys)]
    keys = trackops.apply(store, clip_id, changes, author=author)
    for f, t, p, r in keys:
        revs[(f, t, p)] = r
    return keys


def _rewrite_views(store: Store, history: EditHistory, step: Step, after: bool, author: str) -> list:
    """Undo (``after`` False) or redo the other views' part of ``step``; returns their new steps."""
    out = []
    for clip_id, sub in step.views:
        keys = _rewrite(store, clip_id, history.view_revs.setdefault(clip_id, {}), sub,
                        sub.after if after else sub.before, author)
        out.append((clip_id, Step(keys=keys, before=sub.before, after=sub.after, label=sub.label, frame=sub.frame)))
    return out


def undo_step(store: Store, clip_id: int, history: EditHistory, author: str = "") -> Step:
    """Take the newest step back: its keys get their human layer from before it (a key the
    tracker had goes back to the tracker), its tracker runs are undone (newest first) and its
    events get their fields from before it."""
    with history.lock:
        step = history.undo[-1]
        for run in [*reversed(step.refined), step.run_id]:
            if run is not None:
                store.undo_run(clip_id, run)
        keys = _rewrite(store, clip_id, history.revs, step, step.before, author) if step.keys else []
        views = _rewrite_views(store, history, step, False, author)
        for event_id, before, _after in step.events:
            _set_event(store, clip_id, history, event_id, before, author)
        history.undo.pop()
        history.touched(step.refill)
        history.redo.append(Step(keys=keys, before=step.before, after=step.after, label=step.label,
                                 frame=step.frame, refill=step.refill, events=step.events, views=views))
    return step


def redo_step(store: Store, clip_id: int, history: EditHistory, author: str = "") -> Step:
    with history.lock:
        step = history.redo[-1]
        keys = _rewrite(store, clip_id, history.revs, step, step.after, author) if step.keys else []
        views = _rewrite_views(store, history, step, True, author)
        for event_id, _before, after in step.events:
            _set_event(store, clip_id, history, event_id, after, author)
        history.redo.pop()
        again = Step(keys=keys, before=step.before, after=step.after, label=step.label, frame=step.frame,
                     refill=step.refill, events=step.events, views=views)
        if step.refill:
            again.run_id = _refill(store, clip_id, step.refill)
            again.fills = history.touched(step.refill)
        history.undo.append(again)
        return again


def refine_step(store: Store, clip_id: int, history: EditHistory, step: Step, propose: trackops.Proposer,
                progress: Callable[[int, int], None] | None = None) -> dict | None:
    """Replace the straight in-between boxes ``step`` wrote with ``propose``'s (keyframe-guided
    tracking) and add that run to the step, so that undoing the step undoes it too. Returns
    ``{run_id, boxes}``, or None when the step was undone meanwhile or a later step refilled one
    of its tracks and parts (then nothing is written)."""
    proposals = [(t, p, *trackops.propose_fill(store, clip_id, t, p, f, propose, progress)) for t, p, f in step.refill]
    with history.lock:
        live = any(s is step for s in history.undo)
        if not live or any(history.fills.get(k, 0) != n for k, n in step.fills.items()):
            return None
        runs = [trackops.write_fill(store, clip_id, t, p, spans, table) for t, p, spans, table in proposals]
        step.refined.extend(r for r in runs if r is not None)
    boxes = sum(len(table) for *_, table in proposals if table is not None)
    return dict(run_id=step.refined[-1], boxes=boxes) if step.refined else None


def _event_now(store: Store, clip_id: int, event_id: int) -> tuple[int, dict | None]:
    """The newest revision of an event and its fields (None when it is deleted)."""
    hist = store.events(clip_id, history=True)
    rows = hist[hist.event_id == event_id]
    if not len(rows):
        raise StoreError(f"no event {event_id} in clip {clip_id}")
    last = rows.iloc[-1]
    conf = float(last.confidence)
    fields = dict(start_frame=int(last.start_frame), end_frame=int(last.end_frame), type=str(last.type),
                  tracks=[int(t) for t in last.tracks], parts=[str(p) for p in last.parts],
                  confidence=None if conf != conf else conf, attributes=dict(last.attributes))
    return int(last.revision), (None if bool(last.deleted) else fields)


def _set_event(store: Store, clip_id: int, history: EditHistory, event_id: int, fields: dict | None,
               author: str) -> None:
    """Give an event ``fields`` (None: delete it) as a new revision, expecting the one this session wrote."""
    revision, _ = _event_now(store, clip_id, event_id)
    expected = history.event_revs.get(event_id, revision)
    if fields is None:
        rev = store.edit_event(clip_id, event_id, expected_revision=expected, author=author, delete=True)
    else:
        rev = store.edit_event(clip_id, event_id, expected_revision=expected, author=author, **fields)
    history.event_revs[event_id] = rev


def _frames(ev: dict, before: dict | None = None) -> tuple[int, int]:
    start = int(ev.get("start_frame", before["start_frame"] if before else 0))
    end = int(ev.get("end_frame", before["end_frame"] if before else start))
    return min(start, end), max(start, end)


def apply_event_edit(store: Store, clip_id: int, ev: dict, history: EditHistory, author: str = "") -> Step:
    """One event action of the editor (``event_add``, ``event_edit``, ``event_delete``) as one step."""
    kind = ev["kind"]
    if kind == "event_add":
        start, end = _frames(ev)
        etype = str(ev.get("type") or "").strip()
        event_id = store.add_event(clip_id, start, end, etype, tracks=ev.get("tracks") or (),
                                   parts=ev.get("parts") or (), source="human", author=author)
        revision, after = _event_now(store, clip_id, event_id)
        history.event_revs[event_id] = revision
        change, label = (event_id, None, after), f"new {etype} event {start}-{end}"
    else:
        event_id = int(ev["event_id"])
        revision, before = _event_now(store, clip_id, event_id)
        if ev.get("revision") is not None:
            history.event_revs[event_id] = int(ev["revision"])  # what the user saw: a stale edit is refused
        if before is None:
            raise StoreError(f"event {event_id} was deleted")
        if kind == "event_delete":
            after, label = None, f"deletion of the {before['type']} event {before['start_frame']}-{before['end_frame']}"
        else:
            start, end = _frames(ev, before)
            after = dict(before, start_frame=start, end_frame=end, type=str(ev.get("type") or before["type"]))
            label = f"change of the {after['type']} event to {start}-{end}"
        _set_event(store, clip_id, history, event_id, after, author)
        change = (event_id, before, after)
    shown = change[2] or change[1]
    step = Step(keys=[], before=[], after=[], label=label, frame=int(ev.get("frame", shown["start_frame"])),
                events=[change])
    with history.lock:  # a refinement job may push steps from another thread
        history.undo.append(step)
        history.redo.clear()
    return step


#: ``follow(store, clip_id, frame, track_id, part, box) -> {clip_id: [change]}``: the changes that make
#: the other views of a take agree with a corrected box (:func:`partlab.labelling.multiview.follow`)
Follow = Callable[[Store, int, int, int, str, Box], dict[int, list[dict]]]


def _follow_views(store: Store, clip_id: int, change: dict, history: EditHistory, follow: Follow,
                  author: str) -> tuple[list[tuple[int, list[dict]]], list[str]]:
    """The other views' changes for ``change`` (its own gets the point's ``camera`` and ``xyz``)."""
    try:
        by_clip = follow(store, clip_id, change["frame"], change["track_id"], change["part"], change["box"])
    except (StoreError, ValueError) as exc:
        return [], [f"The other views were not moved: {exc}"]
    own = by_clip.pop(clip_id, [])
    if own:
        change.update(camera=own[0]["camera"], xyz=own[0]["xyz"])
    return sorted(by_clip.items()), []


def _write_views(store: Store, step: Step, history: EditHistory, others: list[tuple[int, list[dict]]],
                 author: str) -> None:
    """Write the other views' changes as parts of ``step`` (each view on its own: one refused
    view does not stop the others)."""
    for other, changes in others:
        try:
            keys, before, after = _write(store, other, changes, author)
        except StoreError as exc:
            step.view_errors.append(f"Not saved in another view (clip {other}): {exc}")
            continue
        revs = history.view_revs.setdefault(other, {})
        for f, t, p, r in keys:
            revs[(f, t, p)] = r
        step.views.append((other, Step(keys=keys, before=before, after=after, label=step.label, frame=step.frame)))


def _box_edit(store: Store, clip_id: int, ev: dict, history: EditHistory, author: str, fill: bool,
              follow: Follow | None = None) -> Step:
    """One box moved, resized, flagged or deleted in the editor, as a step; with ``follow``, the
    same target's boxes in the other views of the take move with it (part of the same step)."""
    kind = ev["kind"]
    frame, tid, part = int(ev["frame"]), int(ev["track_id"]), str(ev["part"])
    expected = ev.get("revision")
    if expected is None or ev.get("added"):
        # a new key: nobody's edit to be stale against, unless one appeared meanwhile
        expected = store.revision(clip_id, frame, tid, part)
    change = dict(frame=frame, track_id=tid, part=part, expected_revision=int(expected),
                  box=_box(ev["box"]) if kind == "edit" else None)
    others, errors = [], []
    if kind == "edit":
        change.update(failure=_flag(ev.get("failure")), occluded=ev.get("occluded") or 0.0)
        if follow is not None:
            others, errors = _follow_views(store, clip_id, change, history, follow, author)
    with history.lock:
        step = record(store, clip_id, [change], history, f"{kind} of {part} #{tid} at frame {frame}", frame,
                      author=author, fill=fill and kind == "edit")
        step.view_errors.extend(errors)
        _write_views(store, step, history, others, author)
    return step


def _check_basis(ev: dict, history: EditHistory) -> None:
    """Refuse a box edit made on top of one of this session's refused edits.

    The editor counts a box's revision up as soon as it sends an edit (so the next drag of the
    same box expects the revision its own edit will make). When that edit is refused, a drag made
    before the page's answer arrives expects the revision someone else's edit made, and would
    overwrite it unseen; ``based_on`` names the edit the editor's revision came from."""
    based = ev.get("based_on")
    if based and int(based) in history.refused:
        raise StaleEditError(f"{ev.get('part')} #{ev.get('track_id')} at frame {ev.get('frame')} was changed by "
                             "someone else before your previous edit of it (not saved either); the page now "
                             "shows the stored box: apply your change again")


def apply_events(store: Store, clip_id: int, events: list[dict], history: EditHistory,
                 author: str = "", fill: bool = False, follow: Follow | None = None) -> ApplyResult:
    """Write the editor's events to the store in order; see :mod:`partlab.app.box_editor` for
    their shape. ``fill``: refill the in-between boxes of an edited track between its keyframes;
    ``follow``: move the other views' boxes of an edited target (a view of a calibrated take)."""
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
                _check_basis(ev, history)
                step = _box_edit(store, clip_id, ev, history, author, fill, follow)
                if step.run_id is not None:
                    res.refills.append(step)
                res.errors.extend(step.view_errors)
                res.written += 1
            elif kind in ("event_add", "event_edit", "event_delete"):
                apply_event_edit(store, clip_id, ev, history, author=author)
                res.written += 1
            elif kind == "undo":
                if not history.undo:
                    res.notes.append("nothing to undo in this session")
                    continue
                step = undo_step(store, clip_id, history, author=author)
                res.frame = step.frame
                res.written += 1
                res.notes.append(f"undid the {step.label}")
            elif kind == "redo":
                if not history.redo:
                    res.notes.append("nothing to redo")
                    continue
                step = redo_step(store, clip_id, history, author=author)
                if step.run_id is not None:
                    res.refills.append(step)
                res.frame = step.frame
                res.written += 1
                res.notes.append(f"redid the {step.label}")
        except StaleEditError as exc:
            if kind in ("edit", "delete") and ev.get("seq") is not None:
                history.refused.add(int(ev["seq"]))
            res.errors.append(f"Not saved: {exc}")
        except (StoreError, ValueError, KeyError, TypeError) as exc:
            res.errors.append(f"Not saved ({kind}): {exc}")
    return res
