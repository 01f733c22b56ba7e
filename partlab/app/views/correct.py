"""Correct: step, play, zoom and fix boxes from a frame cache in the browser; keyframes and
track mode; the track list with delete / merge / split / change id; a review pass; re-track
between keyframes.

A clip that is one view of a calibrated take (several cameras) shows a view selector and the take's
other views at the same frame beside the editor; moving a head or hand box in one view moves that
target's 3D point and its boxes in the other views (:mod:`partlab.labelling.multiview`), in the same
step of undo.

Edits are written to the store as they are made (a refused stale edit says so), each
action one step of undo; the frames are the decoder's frames by index, the same the
tracker used. The page only glues: the operations are in :mod:`partlab.labelling.trackops`
and :mod:`partlab.app.editing`, the editor in :mod:`partlab.app.box_editor`.
"""

import threading
from collections import OrderedDict

import pandas as pd
import streamlit as st

from partlab.app import state
from partlab.app.box_editor import box_editor, encode_image, pack_boxes, pending_events, track_colour, view
from partlab.app.editing import Step, apply_events, record, refine_step
from partlab.app.runs import start_tracking
from partlab.app.views.common import job_panel, pick_clip, plain, require_project
from partlab.labelling import multiview, trackops
from partlab.labelling.events import KINDS
from partlab.labelling.formats.events import KIND_COLOURS
from partlab.labelling.store import Store, StoreError
from partlab.labelling.video import VideoClip, VideoError
from partlab.tracking.parts import BOX_PARTS

s = state.store()
project = require_project(s)
top = st.columns([3, 2, 2], vertical_alignment="bottom")
with top[0]:
    clip = pick_clip(s, project.id)
last = max(clip.frame_count - 1, 0)
fkey = state.frame_key(clip.id)
st.session_state[fkey] = state.frame(clip.id, clip.frame_count)
history = state.history(clip.id)
occluder_mode = top[2].toggle("Edit occluder regions", key=f"occluders:{clip.id}",
                              help="regions that hide people (shelves, pillars); drawn once per clip")
editor_key = state.editor_key(clip.id, "occluders" if occluder_mode else "boxes")
jkey = f"jump:{clip.id}"
st.session_state.setdefault(jkey, dict(seq=0, frame=st.session_state[fkey]))
views = multiview.take_views(s, clip.id)


def jump(frame: int) -> None:
    """Make the editor show ``frame`` (it otherwise keeps its own frame)."""
    frame = min(max(int(frame), 0), last)
    st.session_state[fkey] = frame
    st.session_state[jkey] = dict(seq=st.session_state[jkey]["seq"] + 1, frame=frame)


class FrameCache:
    """JPEG data URLs of one clip's frames, newest used last; decoding in order is what
    makes a chunk cheap (a seek costs a keyframe's worth of decoding)."""

    def __init__(self, path: str, size: int = 900):
        self.clip, self.lock, self.size = VideoClip(path), threading.Lock(), size
        self.urls: OrderedDict[int, str] = OrderedDict()

    def url(self, index: int) -> str:
        with self.lock:
            if index in self.urls:
                self.urls.move_to_end(index)
                return self.urls[index]
            url = encode_image(self.clip.read(index), quality=80)
            self.urls[index] = url
            while len(self.urls) > self.size:
                self.urls.popitem(last=False)
            return url


@st.cache_resource(max_entries=4)
def frame_cache(path: str) -> FrameCache:
    """One decoder and JPEG cache per clip, shared by the sessions."""
    return FrameCache(path)


@st.cache_resource(max_entries=8, show_spinner=False)
def clip_boxes(url: str, clip_id: int, version) -> dict:
    """Everything the page and the editor read from the clip's boxes, once per data version:
    the boxes by frame, the timeline and the track list."""
    store = Store(url)
    df = store.tracks(clip_id)
    verdicts = store.reviews(clip_id)
    tracks, rows = [], []
    for tid, g in df.groupby("track_id", sort=True):
        frames = sorted(set(g.frame.astype(int)))
        spans, start = [], frames[0]
        for a, b in zip(frames, frames[1:] + [None]):
            if b is None or b != a + 1:
                spans.append([start, a])
                start = b
        keys = sorted(set(g[g.source == "human"].frame.astype(int)))
        fails = sorted(set(g[g.failure.astype(bool)].frame.astype(int)))
        mine = verdicts[verdicts.track_id == tid] if len(verdicts) else verdicts
        acc = [[int(r.start), int(r.stop)] for r in mine.itertuples() if r.accepted] if len(mine) else []
        rej = [[int(r.start), int(r.stop)] for r in mine.itertuples() if not r.accepted] if len(mine) else []
        lost = g.state.astype(str).str.contains("lost").groupby(g.frame).any()
        tracks.append(dict(id=int(tid), colour=track_colour(int(tid)), spans=spans, keys=keys, fails=fails, acc=acc,
                           rej=rej))
        rows.append(dict(track=int(tid), parts=", ".join(sorted(set(g.part))), first=frames[0], last=frames[-1],
                         frames=len(frames), keyframes=len(keys), flagged=len(fails),
                         lost=int(lost.sum()), reviewed=sum(b - a + 1 for a, b in acc)))
    flagged = sorted(set(df[df.failure.astype(bool)].frame.astype(int)))
    return dict(by_frame=pack_boxes(df), timeline=dict(tracks=tracks, flagged=flagged), table=pd.DataFrame(rows),
                parts=[p for p in BOX_PARTS if p in set(df.part)] or list(BOX_PARTS), ids=[t["id"] for t in tracks])


def switch_view(key: str, clip_ids: dict[str, int], frame: int) -> None:
    """Open the chosen view's clip at ``frame`` (run by the view choice before the page reruns)."""
    other = clip_ids[st.session_state[key]]
    state.set_frame(other, frame)
    old = st.session_state.get(f"jump:{other}", dict(seq=0))
    st.session_state[f"jump:{other}"] = dict(seq=int(old["seq"]) + 1, frame=frame)
    st.session_state[state.CLIP] = other


def pick_view() -> None:
    """The take's views as a choice; another view opens its clip at the frame shown."""
    key = f"view_pick:{views[0].clip_id}"  # one widget per take (a rerun does not draw a second one)
    st.session_state[key] = next(v.name for v in views if v.clip_id == clip.id)
    st.radio("View", [v.name for v in views], horizontal=True, key=key, on_change=switch_view,
             args=(key, {v.name: v.clip_id for v in views}, st.session_state[fkey]),
             help="the streams of this take; a head or hand box moved in one view moves the same target in the "
                  "others (its 3D point is re-triangulated)")


def other_views(frame: int) -> None:
    """The take's other views at ``frame`` with their boxes, side by side."""
    others = [v for v in views if v.clip_id != clip.id]
    for col, v in zip(st.columns(len(others)), others):
        other = s.clip(v.clip_id)
        try:
            cache = frame_cache(str(other.path))
            with cache.lock:
                image = cache.clip.read(min(frame, other.frame_count - 1))
        except (VideoError, IndexError, ValueError) as exc:
            col.caption(plain(f"{v.name}: cannot show frame {frame}: {exc}"))
            continue
        boxes = s.frame_boxes(v.clip_id, frame)
        drawn = multiview.draw_view(image, boxes, {int(t): track_colour(int(t)) for t in set(boxes.track_id)})
        col.image(drawn[:, :, ::-1], caption=f"{v.name} at frame {frame}", width="stretch")


def timeline_events() -> list[dict]:
    """The clip's events as the editor's timeline draws them (newest revision of each, not deleted)."""
    return [dict(id=int(r.event_id), revision=int(r.revision), start=int(r.start_frame), end=int(r.end_frame),
                 type=str(r.type), colour=KIND_COLOURS.get(str(r.type), "#bab0ac"))
            for r in s.events(clip.id).itertuples()]


def apply(events: list[dict]) -> None:
    """Write the editor's events; the messages show above the editor on this run."""
    fill = any(e.get("fill") for e in events if e.get("kind") == "edit")
    result = apply_events(s, clip.id, events, history, author=state.author(), fill=fill,
                          follow=multiview.follow if views else None)
    refine(result.refills)
    st.session_state.setdefault("correct_messages", []).extend(result.errors + result.notes)
    if result.frame is not None and any(e.get("kind") in ("undo", "redo") for e in events):
        jump(result.frame)


@st.cache_resource(show_spinner=False)
def warm_tracker() -> threading.Thread:
    """Load the body tracker and its compiled kernels once per server process, in the
    background, so that the first keyframe a user moves does not wait for them."""
    from partlab.tracking.keyframes import warm_up

    thread = threading.Thread(target=warm_up, name="partlab-warm-tracker", daemon=True)
    thread.start()
    return thread


def refine(steps: list[Step]) -> None:
    """Keyframe-guided tracking of each refilled track and part, restricted to that track's region
    and stretch, as a background job; the straight line between the keyframes shows until it ends."""
    from partlab.app import jobs
    from partlab.tracking.keyframes import stretch_proposer

    for step in steps:
        tid, part, _ = step.refill[0]

        def work(progress, step=step):
            with VideoClip(clip.path) as video:
                return refine_step(Store(s.url), clip.id, history, step, stretch_proposer(video.read, fps=clip.fps),
                                   progress)

        jobs.submit("refine", f"Tracker boxes between the keyframes of {part} #{tid}", work, clip_id=clip.id)


def current_frame() -> int:
    """The frame the editor shows (it steps on its own and reports the frame in its view)."""
    shown = view(editor_key)
    if "frame" in shown and shown.get("frame") != st.session_state.get(f"seen_view:{clip.id}"):
        st.session_state[fkey] = min(max(int(shown["frame"]), 0), last)
        st.session_state[f"seen_view:{clip.id}"] = shown.get("frame")
    return st.session_state[fkey]


@st.fragment
def editor_panel() -> None:
    """The editor and what it needs; its own requests (frames, boxes, edits) rerun only this
    fragment, so the browser is not busy redrawing the page while it plays."""
    # events the user made since the last run are applied first, so the editor is drawn with their result
    events = pending_events(editor_key)
    apply(events)
    if any(e.get("kind") not in ("frame",) for e in events):
        # the track list, timeline counts and progress below show the edit; the messages of
        # apply() wait in the session for that run (shown now, a full rerun would wipe them at once)
        st.rerun(scope="app")
    frame = current_frame()
    version = s.data_version(clip.id)
    data = clip_boxes(s.url, clip.id, version)
    notes = st.container()  # always drawn, so that a message never shifts (and remounts) the editor below it
    for message in st.session_state.pop("correct_messages", []):
        (notes.error if message.startswith("Not saved") else notes.info)(plain(message))
    try:
        cache = frame_cache(str(clip.path))
        cache.url(frame)
    except (VideoError, IndexError, ValueError) as exc:
        st.error(plain(f"Cannot show frame {frame}: {exc}"))
        return
    tracks = [dict(id=t, colour=track_colour(t)) for t in data["ids"]]
    late = box_editor(key=editor_key, width=clip.width, height=clip.height, frame_count=clip.frame_count,
                      fps=clip.fps, frame_url=cache.url, boxes_by_frame={} if occluder_mode else data["by_frame"],
                      version=version, jump=st.session_state[jkey], tracks=tracks,
                      next_track_id=s.next_track_id(clip.id), used_parts=data["parts"],
                      timeline=dict(data["timeline"], events=timeline_events(), kinds=list(KINDS)),
                      mode="occluders" if occluder_mode else "boxes",
                      occluders=[dict(x=b.x, y=b.y, w=b.w, h=b.h) for b in s.occluders(clip.id)])
    if late:  # events the early read did not see (not expected; kept so none is ever dropped)
        apply(late)
        st.rerun()
    if views:
        other_views(frame)


warm_tracker()
if views:
    pick_view()
editor_panel()
job_panel("refine", limit=1, clip_id=clip.id)
frame = current_frame()
version = s.data_version(clip.id)
data = clip_boxes(s.url, clip.id, version)
progress = s.progress(clip.id)
top[1].caption(f"{progress['corrected_frames']} corrected · {progress['accepted_frames']} accepted of "
               f"{clip.frame_count} frames · undo {len(history.undo)} / redo {len(history.redo)}")

tab_tracks, tab_review, tab_retrack, tab_keys = st.tabs(["Tracks", "Review", "Re-track", "Keys and help"])
ids = data["ids"]

with tab_tracks:
    st.dataframe(data["table"], hide_index=True, width="stretch", height=min(36 * (len(ids) + 1) + 3, 260))
    if ids:
        c1, c2, c3, c4 = st.columns([1.2, 2.2, 1.2, 1], vertical_alignment="bottom")
        tid = c1.selectbox("Track", ids, key=f"op_track:{clip.id}", format_func=lambda t: f"#{t}")
        op = c2.selectbox("Operation", ("delete from this frame on", "split at this frame", "merge into track",
                                        "change id to"), key=f"op:{clip.id}")
        other = c3.number_input("Other / new id", min_value=1, step=1, value=int(s.next_track_id(clip.id)),
                                key=f"op_other:{clip.id}", disabled=op in ("delete from this frame on",
                                                                           "split at this frame"))
        if c4.button("Apply", key=f"op_go:{clip.id}", width="stretch"):
            try:
                if op == "delete from this frame on":
                    changes, label = trackops.delete_from(s, clip.id, tid, frame), f"deletion of #{tid} from {frame}"
                elif op == "split at this frame":
                    changes, label = trackops.split(s, clip.id, tid, frame), f"split of #{tid} at {frame}"
                elif op == "merge into track":
                    changes, label = trackops.merge(s, clip.id, int(other), tid), f"merge of #{tid} into #{int(other)}"
                else:
                    changes = trackops.change_id(s, clip.id, tid, int(other))
                    label = f"id change #{tid} -> #{int(other)}"
                record(s, clip.id, changes, history, label, frame, author=state.author())
                st.session_state["correct_messages"] = [
                    f"Done: {label} ({len(changes)} box revisions; Ctrl+Z undoes it)."]
                jump(frame)
                st.rerun()
            except StoreError as exc:
                st.error(plain(f"Not saved: {exc}"))
        st.caption(f"Operations apply at the frame shown (frame {frame}); each is one step of undo (Ctrl+Z in the "
                   "editor) and is stored as revisions of the boxes it changes.")

with tab_review:
    if ids:
        c1, c2, c3, c4, c5 = st.columns([1.2, 1.2, 1.2, 1, 1], vertical_alignment="bottom")
        rtid = c1.selectbox("Track", ids, key=f"rv_track:{clip.id}", format_func=lambda t: f"#{t}")
        span = next(([a, b] for t in data["timeline"]["tracks"] if t["id"] == rtid for a, b in t["spans"]
                     if a <= frame <= b), [frame, frame])
        a = c2.number_input("From frame", 0, last, int(span[0]), key=f"rv_a:{clip.id}:{rtid}:{span[0]}")
        b = c3.number_input("To frame", 0, last, int(span[1]), key=f"rv_b:{clip.id}:{rtid}:{span[1]}")
        for col, label, ok in ((c4, "Accept", True), (c5, "Reject", False)):
            if col.button(label, key=f"rv_{label}:{clip.id}", width="stretch"):
                try:
                    rid = s.review(clip.id, rtid, min(a, b), max(a, b), ok, author=state.author())
                    st.session_state[f"last_review:{clip.id}"] = rid
                    st.rerun()
                except StoreError as exc:
                    st.error(plain(exc))
        rid = st.session_state.get(f"last_review:{clip.id}")
        if rid is not None and st.button("Undo my last verdict", key=f"rv_undo:{clip.id}"):
            s.undo_review(clip.id, rid)
            st.session_state.pop(f"last_review:{clip.id}")
            st.rerun()
        st.caption("A verdict covers frames From..To of one track; the newest covering a frame counts. Accepted "
                   "frames are green under the track's timeline row, rejected red; Export can keep accepted "
                   "frames only.")

with tab_retrack:
    sel = st.selectbox("Tracks", ["every track at the start frame"] + [f"#{t}" for t in ids],
                       key=f"rt_tracks:{clip.id}")
    only = None if sel.startswith("every") else int(sel[1:])
    start, stop, rt_ids = trackops.retrack_window(s, clip.id, frame, only)
    st.write(f"Runs the tracker from frame {start} (" + ("a keyframe" if start != frame or progress["corrected_frames"]
                                                         else "this frame") + ") to "
             + (f"frame {stop} (the next keyframe)" if stop is not None else "the end of the clip")
             + f" for tracks {', '.join(f'#{t}' for t in rt_ids) or '(none)'}; every other track and every "
               "human correction stay as they are.")
    tracker = st.radio("Tracker", ("body", "limbs", "all"), horizontal=True, key="retrack_tracker")
    if st.button("Re-track", disabled=not rt_ids):
        try:
            job = start_tracking(s, clip, tracker=tracker, start=frame, retrack=True, track_id=only,
                                 bundle_path=next((b.path for b in s.bundles(project.id)
                                                   if b.id == project.default_bundle_id), None))
            st.success(f"Started: {plain(job.label)}")
        except (RuntimeError, ValueError) as exc:
            st.error(plain(exc))
    runs = s.runs(clip.id)
    if len(runs):
        r = runs.iloc[-1]
        if st.button(f"Undo the newest tracker run (run {int(r.id)}: {r.tracker} from frame {int(r.start_frame)})",
                     key=f"undo_run:{clip.id}"):
            s.undo_run(clip.id, int(r.id))
            st.session_state["correct_messages"] = [f"Undid run {int(r.id)}: the boxes it replaced are back."]
            jump(frame)
            st.rerun()
    job_panel("track", limit=1, clip_id=clip.id)

with tab_keys:
    st.markdown(
        "Click the frame first. **←/→** or **A/D**: previous/next frame (from the browser's frame cache) · "
        "**Space**: play/pause · **G** / **Shift+G**: next/previous flagged frame · **K** / **Shift+K**: next/previous "
        "keyframe of the selected track · **N** or **Tab**: next track · **F**: failure · **O**: occluded · "
        "**Delete**: delete the box · **B** or Shift+drag: draw a new box (even inside another) · **T**: track mode "
        "(moving a keyframe refills the track's boxes up to its neighbouring keyframes) · **L**: labels on all boxes "
        "or on hover · wheel, **+**/**-**: zoom at the mouse · **0**: fit · **1**: 1:1 · right- or middle-drag: pan · "
        "**Ctrl+Z / Ctrl+Y**: undo/redo a step. The timeline under the frame shows each track's presence (colour), "
        "keyframes (white ticks), failure flags (black ticks), reviewed ranges (green/red) and flagged frames (red "
        "strip on top); click it to jump. Its bottom row holds the **events** (activities over a range of frames, "
        "a colour per kind): **E** or *add event* adds one of the chosen kind from the shown frame; click an event "
        "to select it and jump to its start, drag its left or right end to stretch it, pick another kind to retype "
        "it, *delete event* removes it; **J** / **Shift+J**: next/previous event. Event changes are undone with "
        "Ctrl+Z like box edits and stored as revisions.")
