"""Train: a new model bundle (failure SVMs + variance parameters) from corrected clips."""

import pandas as pd
import plotly.graph_objects as go
import streamlit as st

from partlab.app import state
from partlab.app.runs import SHIPPED, bundle_choices, start_training
from partlab.app.views.common import job_panel, plain, require_project
from partlab.labelling.store import StoreError
from partlab.models.training import NothingLearnt

s = state.store()
st.title("Train")
project = require_project(s)


clips = s.clips(project.id)
corrected = {c.id: c for c in clips if s.progress(c.id)["corrected_frames"] > 0}
with st.form("train"):
    picked = st.multiselect("Corrected clips", list(corrected),
                            format_func=lambda i: f"{corrected[i].name} ({s.progress(i)['corrected_frames']} frames)",
                            default=list(corrected))
    c1, c2, c3 = st.columns(3)
    name = c1.text_input("Bundle name", value=f"bundle-{len(s.bundles(project.id)) + 1}")
    seed = c2.number_input("Seed", min_value=0, value=0, step=1)
    make_default = c3.checkbox("Make it the project's default", value=True)
    starts = bundle_choices(s, project)
    labels = list(starts)
    first = next((k for k in labels if k.endswith("(project default)")), SHIPPED if SHIPPED in starts else labels[0])
    start_label = st.selectbox("Start from", labels, index=labels.index(first),
                               help="The model to improve on: its failure detector stays unless the one trained "
                                    "here does no worse on these clips, and fitted parameters are kept only if "
                                    "they raise the tracking rate on them.")
    go_train = st.form_submit_button("Train", type="primary", disabled=not corrected)
if not corrected:
    st.info("No clip has corrected frames yet: correct some boxes on the Correct page first.")
if go_train:
    try:
        job = start_training(s, project.id, picked, name.strip(), seed=int(seed), make_default=make_default,
                             start_path=starts[start_label])
        st.success(f"Started: {plain(job.label)}")
    except NothingLearnt as exc:
        st.error(f"Nothing to learn yet: {exc}.")
    except (RuntimeError, ValueError) as exc:
        st.error(plain(exc))


job_panel("train", limit=3, project_id=project.id)


def show_summary(summary: dict, key: str) -> None:
    """Cross-validated rates and a confusion matrix per SVM, fitted variances against defaults."""
    samples = summary.get("samples") or {}
    if samples:
        st.caption("Training samples: " + ", ".join(f"{k} {v}" for k, v in samples.items()))
    if summary.get("learnt"):
        st.caption("Learnt: " + ", ".join(summary["learnt"]))
    svms = summary.get("svms") or {}
    if svms:
        table = pd.DataFrame([dict(svm=k, trained=v.get("trained"), kernel=v.get("kernel"), C=v.get("C"),
                                   **{"CV TNR": v.get("tnr"), "CV TPR": v.get("tpr")},
                                   positives=v.get("n_positive"), negatives=v.get("n_negative"), note=v.get("note"))
                              for k, v in svms.items()])
        st.dataframe(table, hide_index=True)
        trained = {k: v for k, v in svms.items() if v.get("trained")}
        cols = st.columns(max(len(trained), 1))
        for col, (k, v) in zip(cols, trained.items()):  # rows truth, columns prediction: [[TN, FP], [FN, TP]]
            cm = v.get("confusion") or [[0, 0], [0, 0]]
            fig = go.Figure(go.Heatmap(z=cm, x=["pred. failed", "pred. tracked"], y=["failed", "tracked"], text=cm,
                                       texttemplate="%{text}", colorscale="Blues", showscale=False))
            fig.update_layout(title=k, height=230, margin=dict(l=10, r=10, t=40, b=10))
            fig.update_yaxes(autorange="reversed")
            col.plotly_chart(fig, key=f"cm:{key}:{k}")
    if summary.get("person"):
        from partlab.models.person import person_rows

        st.caption("From the person boxes (each kept only if it lowered the person boxes' error on the "
                   "training clips beyond the tracker seeds' spread):")
        st.dataframe(pd.DataFrame(person_rows(summary["person"])), hide_index=True)
    variances = pd.DataFrame(summary.get("variances") or [])
    if len(variances):
        v = variances.dropna(subset=["fitted"])
        labels = v.tracker + " " + v.part + " " + v.parameter
        fig = go.Figure([go.Bar(name="default", x=labels, y=v["default"]),
                         go.Bar(name="fitted", x=labels, y=v["fitted"])])
        fig.update_layout(barmode="group", title="Variance parameters: fitted vs default", height=340,
                          margin=dict(l=10, r=10, t=40, b=10))
        st.plotly_chart(fig, key=f"var:{key}")
    for note in summary.get("notes") or []:
        st.caption(note)
    if not svms and not len(variances):
        st.json(summary, expanded=False)


bundles = s.bundles(project.id)
if bundles:
    st.subheader("Bundles")
    ids = [None] + [b.id for b in bundles]
    labels = {None: "built-in parameters", **{b.id: b.name for b in bundles}}
    chosen = st.selectbox("Project default", ids, index=ids.index(project.default_bundle_id)
                          if project.default_bundle_id in ids else 0, format_func=labels.get)
    if chosen != project.default_bundle_id:
        try:
            s.set_default_bundle(project.id, chosen)
            st.success(f"Default bundle: {plain(labels[chosen])}")
        except StoreError as exc:
            st.error(plain(exc))
    for b in reversed(bundles):
        with st.expander(f"{plain(b.name)} · {b.created:%Y-%m-%d %H:%M} · {plain(b.path)}", expanded=b is bundles[-1]):
            show_summary(b.summary, key=str(b.id))
