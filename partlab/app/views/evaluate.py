"""Evaluate and compare: per-part tracking-rate curves of two bundles side by side
(seed 002 Fig. 4 style) against a clip's truth, and a trajectory plot per track."""

import io

import plotly.graph_objects as go
import streamlit as st

from partlab.app import jobs, state
from partlab.app.box_editor import track_colour
from partlab.app.demo import demo_files
from partlab.app.runs import bundle_choices, first_boxes, start_comparison_run, training_truth
from partlab.app.views.common import pick_clip, plain, require_project
from partlab.labelling import evaluation
from partlab.tracking.tracks import read_tracks_csv

s = state.store()
st.title("Evaluate and compare")
project = require_project(s)
clip = pick_clip(s, project.id)

# ---- truth: an uploaded truth CSV, or the clip's corrected frames
truth_file = st.file_uploader("Truth CSV for this clip (optional; else the corrected frames are the truth)",
                              type=["csv"], key=f"truth:{clip.id}")
truth = None
synthetic = demo_files(clip.name).get("truth")
if truth_file is None and synthetic is not None:
    truth = read_tracks_csv(synthetic)
    st.caption("Truth: the synthetic scene's exact boxes.")
if truth_file is not None:
    try:
        truth = read_tracks_csv(io.StringIO(truth_file.getvalue().decode("utf-8", "replace")), name=truth_file.name)
    except ValueError as exc:
        st.error(plain(f"Truth not read: {exc}"))
if truth is None:
    truth = training_truth(s, clip.id)
    st.caption(f"Truth: {truth.frame.nunique()} corrected frames of this clip.")

# ---- two bundles, each tracked fresh (not stored)
options = bundle_choices(s, project)
c1, c2, c3 = st.columns(3)
a = c1.selectbox("Bundle A", list(options), index=0)
b = c2.selectbox("Bundle B", list(options), index=min(1, len(options) - 1))
tracker = c3.radio("Tracker", ("body", "limbs", "all"), horizontal=True, key="eval_tracker")
if st.button("Track with both and compare", type="primary"):
    init = first_boxes(truth) if len(truth) else None  # both start from the truth's first boxes
    for name in dict.fromkeys((a, b)):
        start_comparison_run(clip, tracker, name, options[name], init=init)


@st.fragment(run_every=1 if jobs.active("compare", clip_id=clip.id) else None)
def comparison():
    cols = st.columns(2)
    for side, (col, name) in enumerate(zip(cols, (a, b))):
        with col:
            st.markdown(f"**{plain(name)}**")
            runs = jobs.jobs("compare", clip_id=clip.id, bundle=name, tracker=tracker)
            if not runs:
                st.caption("not run yet")
                continue
            job = runs[0]
            if job.active:
                st.progress(job.fraction, text=f"tracking: {job.done}/{job.total or '?'}")
            elif job.status == "failed":
                st.error(job.error)
            elif len(truth):
                report = evaluation.evaluate(truth, job.result, at=105)
                st.plotly_chart(evaluation.rate_curve_figure(report), key=f"rates:{side}:{name}")
                if report.note:
                    st.caption(report.note)
                st.dataframe(report.summary, key=f"summary:{side}")


comparison()

# ---- trajectories of the stored tracks
st.subheader("Trajectories (stored boxes)")
tracks = s.tracks(clip.id)
if not len(tracks):
    st.caption("No boxes stored for this clip yet.")
else:
    part = st.selectbox("Part", sorted(tracks.part.unique()), key="traj_part")
    sel = tracks[tracks.part == part]
    fig = go.Figure()
    for tid, g in sel.groupby("track_id"):
        fig.add_trace(go.Scatter(x=g.x + g.w / 2, y=g.y + g.h / 2, mode="lines+markers", name=f"#{tid}",
                                 marker=dict(size=3), line=dict(color=track_colour(int(tid))),
                                 text=g.frame, hovertemplate="frame %{text}: (%{x:.0f}, %{y:.0f})"))
    if len(truth):
        t = truth[truth.part == part]
        for tid, g in t.groupby("track_id"):
            fig.add_trace(go.Scatter(x=g.x + g.w / 2, y=g.y + g.h / 2, mode="lines", name=f"truth #{tid}",
                                     line=dict(color="gray", dash="dot")))
    fig.update_yaxes(autorange="reversed", scaleanchor="x", range=[clip.height, 0])
    fig.update_xaxes(range=[0, clip.width])
    fig.update_layout(height=420, title=f"{part} centre per track (image coordinates)",
                      margin=dict(l=10, r=10, t=40, b=10))
    st.plotly_chart(fig, key="trajectories")
