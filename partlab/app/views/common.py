"""Small page helpers shared by the page scripts (choosing a project and a clip, showing
names as text)."""

from __future__ import annotations

import re

import streamlit as st

from partlab.app import state
from partlab.labelling.store import Clip, Store

_MARKDOWN = re.compile(r"([\\`*_{}\[\]<>#$:|~])")


def plain(text) -> str:
    """``text`` escaped so that Streamlit's Markdown shows it as typed: a project called
    ``**x**`` or ``:red[x]`` stays those characters (names are the users', not markup)."""
    return _MARKDOWN.sub(r"\\\1", str(text))


def storage_message(exc: BaseException) -> str:
    """A refused write, a full disk or a read-only data directory as one sentence (shown as text)."""
    if isinstance(exc, OSError):
        from partlab.cli import describe_os_error

        where = f" {exc.filename}" if getattr(exc, "filename", None) else ""
        said = describe_os_error(exc)  # a full disk says itself that earlier outputs stay
        return plain(f"Cannot write{where}: {said}." + ("" if "earlier outputs" in said else
                                                        " Nothing was changed; what was saved before is intact."))
    return plain(f"Not done: {exc}")


def require_project(s: Store):
    """The current project, or stop the page with a hint; a viewer is told that changes are refused."""
    from partlab.labelling import access

    pid = state.project_id(s)
    if pid is None:
        st.info("No project yet: create one on the Projects page."
                if not isinstance(s, access.GuardedStore) else
                "No project of yours yet: create one on the Projects page, or ask a project's owner for a role.")
        st.stop()
    project = s.project(pid)
    if not access.may(s, pid, "annotator"):
        st.caption(f"You are a viewer of {plain(project.name)}: you can look and export; changes are refused "
                   "(a project owner can make you an annotator).")
    return project


def bound_widget(widget, persistent_key: str, widget_key: str, *args, **kwargs):
    """Show ``widget`` whose value lives under ``persistent_key`` (which survives page
    switches, unlike a widget's own key, which Streamlit drops when it is not shown)."""
    st.session_state[widget_key] = st.session_state[persistent_key]

    def copy():
        st.session_state[persistent_key] = st.session_state[widget_key]

    return widget(*args, key=widget_key, on_change=copy, **kwargs)


def pick_clip(s: Store, project_id: int, label: str = "Clip") -> Clip:
    """A clip chooser bound to the session's current clip; stops the page when there are none."""
    clips = s.clips(project_id)
    if not clips:
        st.info("This project has no clips yet: upload one on the Projects page.")
        st.stop()
    ids = [c.id for c in clips]
    state.clip_id(ids)
    names = {c.id: f"{c.name} (#{c.id})" for c in clips}
    bound_widget(st.selectbox, state.CLIP, "clip_select", label, ids, format_func=names.get)
    return s.clip(st.session_state[state.CLIP])


def job_panel(kind: str, limit: int = 5, **meta) -> None:
    """Progress of this kind of background job, refreshed every second while one runs;
    when a job this session watched ends, the whole page reruns to show its result."""
    from partlab.app import jobs

    watched = st.session_state.setdefault("watched_jobs", set())
    for job in jobs.active(kind, **meta):
        watched.add(job.id)
    st.session_state.setdefault("page_jobs", set()).update(watched)  # the sidebar leaves these to the panel

    @st.fragment(run_every=1 if jobs.active(kind, **meta) else None)
    def panel():
        ended = False
        for job in jobs.jobs(kind, **meta)[:limit]:
            if job.active:
                st.progress(job.fraction, text=f"{plain(job.label)}: {job.done} of {job.total or '?'}")
                continue
            if job.id in watched:
                watched.discard(job.id)
                ended = True
            if job.status == "done":
                said = describe(job.result)
                st.success(f"{plain(job.label)}: done" + (f" ({said})" if said else "."))
            elif job.status == "cancelled":
                st.info(f"{plain(job.label)}: cancelled (what it had stored stays).")
            else:
                st.error(f"{plain(job.label)}: failed: {plain(job.error)}")
        if ended:
            st.rerun()

    panel()


def describe(result) -> str:
    """A one-line account of a job's result dict."""
    if not isinstance(result, dict):
        return ""
    if "run_id" in result:
        return f"{result['boxes']} boxes stored as run {result['run_id']}"
    if "bundle_id" in result:
        return f"bundle saved in {result['path']}"
    return ""
