"""Correct: scrub frames, fix boxes and failure/occluded flags, re-track from a fix.

Edits are written to the store as they are made (a refused stale edit says so); the
frames are the decoder's frames by index, the same the tracker used.
"""

import threading
import time

import streamlit as st

from partlab.app import state
from partlab.app.box_editor import box_editor, pending_events
from partlab.app.editing import apply_events
from partlab.app.runs import next_human_frame, start_tracking
from partlab.app.views.common import bound_widget, job_panel, pick_clip, require_project
from partlab.labelling.store import Store
from partlab.labelling.video import VideoClip, VideoError
from partlab.tracking.parts import PART_NAMES

s = state.store()
st.title("Correct")
project = require_project(s)
clip = pick_clip(s, project.id)
last = max(clip.frame_count - 1, 0)
fkey = state.frame_key(clip.id)
st.session_state[fkey] = state.frame(clip.id, clip.frame_count)


@st.cache_resource(max_entries=8)
def video(path: str) -> tuple[VideoClip, threading.Lock]:
    """One open decoder per clip, shared by the sessions (seeking is the slow part);
    the lock keeps two sessions from moving the same decoder at once."""
    return VideoClip(path), threading.Lock()


def read_frame(path: str, index: int):
    clip_reader, lock = video(path)
    with lock:
        return clip_reader.read(index)


@st.cache_data(max_entries=32, show_spinner=False)
def track_ids(url: str, clip_id: int, n_runs: int, next_id: int) -> list[int]:
    """The clip's track ids; reading every box takes a while on long clips, so this is
    cached until a tracker run or a new track changes it (the arguments after the clip)."""
    return sorted(set(Store(url).tracks(clip_id).track_id.astype(int).tolist()))


def step(delta: int) -> None:
    st.session_state[fkey] = min(max(st.session_state[fkey] + delta, 0), last)


history = state.history(clip.id)
occluder_mode = bool(st.session_state.get(f"occluders:{clip.id}"))
editor_key = state.editor_key(clip.id, "occluders" if occluder_mode else "boxes")


def apply(events: list[dict]) -> None:
    """Write the editor's events; the messages show above the editor on this run."""
    result = apply_events(s, clip.id, events, history, author=state.author())
    st.session_state.setdefault("correct_messages", []).extend(result.errors + result.notes)
    if result.frame is not None:
        st.session_state[fkey] = min(max(result.frame, 0), last)


# events the user made since the last run are applied first, so the editor is drawn with their result
apply(pending_events(editor_key))

c1, c2, c3, c4, c5 = st.columns([5, 1, 1, 1.4, 2.6], vertical_alignment="bottom")
with c1:
    bound_widget(st.slider, fkey, state.slider_key(clip.id), "Frame", 0, max(last, 1), disabled=last == 0)
c2.button("◀", on_click=step, args=(-1,), help="previous frame", width="stretch")
c3.button("▶", on_click=step, args=(1,), help="next frame", width="stretch")
playing = c4.toggle("Play", key=f"play:{clip.id}")
c5.toggle("Edit occluder regions", key=f"occluders:{clip.id}",
          help="regions that hide people (shelves, pillars); drawn once per clip")
frame = st.session_state[fkey]

try:
    image = read_frame(str(clip.path), frame)
except (VideoError, IndexError) as exc:
    st.error(f"Cannot show frame {frame}: {exc}")
    st.stop()

for message in st.session_state.pop("correct_messages", []):
    (st.error if message.startswith("Not saved") else st.info)(message)
if occluder_mode:
    regions = [dict(x=b.x, y=b.y, w=b.w, h=b.h) for b in s.occluders(clip.id)]
    events = box_editor(image, regions, key=editor_key, frame=frame, frame_count=clip.frame_count,
                        mode="occluders")
else:
    boxes = s.frame_boxes(clip.id, frame)
    next_id = s.next_track_id(clip.id)
    tracks = track_ids(s.url, clip.id, len(s.runs(clip.id)), next_id)
    events = box_editor(image, boxes, key=editor_key, frame=frame, frame_count=clip.frame_count,
                        tracks=tracks, next_track_id=next_id, parts=PART_NAMES)
if events:  # events the early read did not see (not expected; kept so none is ever dropped)
    apply(events)
    st.rerun()

progress = s.progress(clip.id)
st.caption(f"Frame {frame} of {last} · {progress['corrected_frames']} corrected frames "
           f"({100 * progress['fraction']:.1f}%) · session edits: {len(history.undo)} "
           f"(undo {len(history.undo)}, redo {len(history.redo)})")

with st.expander("Re-track from this frame", expanded=False):
    stop = next_human_frame(s, clip.id, frame)
    st.write(f"Runs the tracker from the boxes of frame {frame} to "
             + (f"frame {stop} (the next corrected frame)." if stop is not None else "the end of the clip.")
             + " Human corrections are never overwritten.")
    tracker = st.radio("Tracker", ("body", "limbs", "all"), horizontal=True, key="retrack_tracker")
    if st.button("Re-track from here"):
        try:
            job = start_tracking(s, clip, tracker=tracker, start=frame, retrack=True,
                                 bundle_path=next((b.path for b in s.bundles(project.id)
                                                   if b.id == project.default_bundle_id), None))
            st.success(f"Started: {job.label}")
        except (RuntimeError, ValueError) as exc:
            st.error(str(exc))
    job_panel("track", limit=1, clip_id=clip.id)

with st.expander("Keyboard shortcuts"):
    st.markdown("Click the frame first. **←/→** or **A/D**: previous/next frame · **N** or **Tab**: next track · "
                "**F**: toggle failure · **O**: toggle occluded · **Delete**: delete the box · "
                "**Ctrl+Z / Ctrl+Y**: undo/redo · drag a box to move it, its corners to resize it, "
                "an empty area to draw a new box of the part and track chosen in the toolbar.")

if playing and frame < last:
    time.sleep(max(0.04, 1.0 / max(clip.fps, 1.0)))
    st.session_state[fkey] = frame + 1
    st.rerun()
