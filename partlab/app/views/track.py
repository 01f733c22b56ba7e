"""Track: run a tracker over a clip in the background, or import boxes from a tracks CSV."""

import io

import pandas as pd
import streamlit as st

from partlab.app import state
from partlab.app.demo import demo_files
from partlab.app.runs import TRACKERS, bundle_choices, start_tracking
from partlab.app.views.common import job_panel, pick_clip, plain, require_project
from partlab.labelling.store import Store
from partlab.tracking.tracks import read_tracks_csv

s = state.store()
st.title("Track")
project = require_project(s)
clip = pick_clip(s, project.id)

choices = bundle_choices(s, project)


@st.cache_data(max_entries=32, show_spinner=False)
def first_frame_with_boxes(url: str, clip_id: int, n_runs: int, n_human: int) -> int | None:
    """Cached until a run or a correction changes it (reading every box is slow on long clips)."""
    tracks = Store(url).tracks(clip_id)
    return int(tracks.frame.min()) if len(tracks) else None


with st.form("track"):
    c1, c2, c3 = st.columns(3)
    tracker = c1.radio("Tracker", TRACKERS, horizontal=True,
                       help="body: head/torso/hip-leg; limbs: head and hands; all: both")
    bundle = c2.selectbox("Model bundle", list(choices))
    seed = c3.number_input("Seed", min_value=0, value=0, step=1)
    first = first_frame_with_boxes(s.url, clip.id, len(s.runs(clip.id)), len(s.human_frames(clip.id)))
    demo_init = demo_files(clip.name).get("init")
    starts = ["detect people automatically"] + ([f"the stored boxes of frame {first}"] if first is not None else []) \
        + (["the synthetic scene's init boxes"] if demo_init else [])
    start_from = st.radio("Start from", starts, horizontal=True,
                          help="imported or drawn boxes make the tracker follow exactly those people")
    go = st.form_submit_button("Track the whole clip", type="primary")
if go:
    path = choices[bundle]
    try:
        from_boxes = start_from == starts[1] if len(starts) > 1 and first is not None else False
        init = read_tracks_csv(demo_init) if start_from == "the synthetic scene's init boxes" else None
        job = start_tracking(s, clip, tracker=tracker, bundle_path=path, seed=int(seed),
                             start=first if from_boxes else 0, init_from_boxes=from_boxes, init=init)
        st.success(f"Started: {plain(job.label)}. It keeps running while you use other pages.")
    except (RuntimeError, ValueError) as exc:
        st.error(plain(exc))


job_panel("track", clip_id=clip.id)

with st.expander("Import boxes from a tracks CSV (e.g. another tool's output or init.csv)"):
    csv = st.file_uploader("Tracks CSV", type=["csv"], key=f"import_csv:{clip.id}")
    if csv is not None and st.button("Store these boxes as a tracker run"):
        try:
            df = read_tracks_csv(io.StringIO(csv.getvalue().decode("utf-8", "replace")), name=csv.name)
            df = df[df.frame < clip.frame_count]
            run_id = s.save_tracker_run(clip.id, df, tracker="import", bundle=csv.name)
            st.session_state["track_flash"] = f"Stored {len(df)} boxes as run {run_id}; human corrections were kept."
            st.rerun()  # the form above offers to start from these boxes now
        except ValueError as exc:
            st.error(plain(f"Not imported: {exc}"))
if "track_flash" in st.session_state:
    st.success(st.session_state.pop("track_flash"))

runs = s.runs(clip.id)
if len(runs):
    st.subheader("Runs of this clip")
    st.dataframe(runs, hide_index=True)
    counts = s.tracks(clip.id).groupby(["source"]).size().rename("boxes").reset_index()
    st.dataframe(pd.DataFrame(counts), hide_index=True)
