"""Projects and clips: create a project, upload clips, see each clip's state."""

import base64

import cv2
import pandas as pd
import streamlit as st

from partlab.app import state
from partlab.app.runs import clip_state
from partlab.app.upload_notice import show_refusals
from partlab.app.uploads import UPLOAD_EXTENSIONS, UploadRefused, max_upload_mb, save_upload
from partlab.app.views.common import plain, require_project
from partlab.labelling import access
from partlab.labelling.multiview import import_take_folder
from partlab.labelling.store import StoreError
from partlab.labelling.video import VideoClip, VideoError

s = state.store()
st.title("Projects and clips")

def new_project_form() -> None:
    with st.form("new_project", clear_on_submit=True):
        name = st.text_input("Project name")
        if st.form_submit_button("Create project"):
            try:
                project = s.create_project(name)
                st.session_state[state.PROJECT] = project.id
                st.session_state["projects_flash"] = f"Created project {plain(repr(project.name))}."
                st.rerun()  # the sidebar's project picker shows the new project
            except StoreError as exc:
                st.error(plain(exc))


if s.projects():
    with st.expander("New project"):
        new_project_form()
else:  # the first thing to do: the form in plain view
    st.markdown("**New project**: name it, then upload its clips.")
    new_project_form()
    st.stop()
if "projects_flash" in st.session_state:
    st.success(st.session_state.pop("projects_flash"))

project = require_project(s)
st.subheader(f"Project: {plain(project.name)}")

try:
    limit = max_upload_mb()
except UploadRefused as exc:
    st.error(plain(exc))
    st.stop()
uploaded = None
if access.may(s, project.id, "annotator"):  # a viewer gets no uploader (the store would refuse the clip too)
    uploaded = st.file_uploader(f"Upload clips ({', '.join(UPLOAD_EXTENSIONS)}; up to {limit} MB each)",
                                type=list(UPLOAD_EXTENSIONS), accept_multiple_files=True, key=f"upload:{project.id}")
    show_refusals()  # a file over the limit, refused by the browser: its sentence shown, not just an icon
if access.may(s, project.id, "annotator"):
    with st.expander("Add a take folder (several calibrated cameras)"):
        st.caption("A folder on this server with one video per camera and calibration.json (docs/formats.md, "
                   "\"Takes\"), e.g. written by `partlab synth TAKE --scenario handshake --cameras 3`. Each camera "
                   "becomes a clip; with a tracks CSV of the take (`partlab track TAKE --tracker limbs3d -o "
                   "TAKE/tracks.csv`, one box per view in its camera column) its boxes are stored in every view. "
                   "On the Correct page the views show side by side and a hand or head moved in one view moves "
                   "in the others.")
        take_path = st.text_input("Take folder", key=f"take_path:{project.id}")
        tracks_path = st.text_input("Tracks CSV of the take (optional)", key=f"take_tracks:{project.id}")
        if st.button("Add the take", key=f"take_add:{project.id}"):
            try:
                take = import_take_folder(s, project.id, take_path.strip(), tracks_path.strip() or None)
                st.session_state[state.CLIP] = take.streams[0].clip_id
                st.success(plain(f"Added take {take.name!r}: views {', '.join(st_.name for st_ in take.streams)}."))
            except (StoreError, OSError, ValueError) as exc:
                st.error(plain(f"Not added: {exc}"))
seen = st.session_state.setdefault("uploads_done", {})
for f in uploaded or []:
    if f.file_id in seen:
        kind, message = seen[f.file_id]
    else:
        try:
            with st.spinner(f"Checking and storing {plain(f.name)}..."):
                clip = save_upload(s, project.id, f.name, f)
            kind, message = "success", f"Added {plain(clip.name)}: {clip.frame_count} frames, {clip.fps:.1f} fps, " \
                                       f"{clip.width}x{clip.height}."
            st.session_state[state.CLIP] = clip.id
        except UploadRefused as exc:
            kind, message = "error", plain(f"Upload {exc}")
        seen[f.file_id] = (kind, message)
    getattr(st, kind)(message)


@st.cache_data(max_entries=500, show_spinner=False)
def thumbnail(path: str, sha: str) -> str:
    """A small JPEG data URL of frame 0 (cached by content hash)."""
    try:
        frame = VideoClip(path).read(0)
    except (VideoError, IndexError):
        return ""
    h, w = frame.shape[:2]
    small = cv2.resize(frame, (120, max(1, round(120 * h / w))))
    ok, buf = cv2.imencode(".jpg", small)
    return "data:image/jpeg;base64," + base64.b64encode(buf.tobytes()).decode() if ok else ""


clips = s.clips(project.id)
if not clips:
    st.info("No clips yet: upload one above.")
    st.stop()
rows = [dict(id=c.id, thumbnail=thumbnail(str(c.path), c.sha256), name=c.name, frames=c.frame_count,
             seconds=round(c.frame_count / c.fps, 1) if c.fps else None, fps=round(c.fps, 2),
             size=f"{c.width}x{c.height}", state=clip_state(s, c),
             accepted=f"{s.progress(c.id)['accepted_frames']} of {c.frame_count}") for c in clips]
st.dataframe(pd.DataFrame(rows), hide_index=True, width="stretch", row_height=70,
             column_config={"thumbnail": st.column_config.ImageColumn("thumbnail", width="small")})
st.caption("Pick a clip on the Track or Correct page; new uploads become the current clip.")
