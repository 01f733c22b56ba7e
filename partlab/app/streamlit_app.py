"""Entry script of the Streamlit labelling app: project picker, job list and page navigation.

Run with ``partlab app`` (or ``make run``). Every page is a short script under
``app/views/`` that calls library functions; long work runs in :mod:`partlab.app.jobs`.
"""

import os

import streamlit as st

st.set_page_config(page_title="partlab", layout="wide")

from partlab.app import auth, jobs, prefs, state  # noqa: E402
from partlab.app.demo import ensure_demo, track_demo  # noqa: E402
from partlab.app.views.common import bound_widget, plain, storage_message  # noqa: E402
from partlab.labelling.config import data_dir  # noqa: E402
from partlab.labelling.store import StoreError  # noqa: E402


@st.cache_resource(show_spinner="Preparing the demo project (synthetic scenes)...")
def _demo_ready(data: str) -> bool:
    """Once per server process and data directory; the demo clips are tracked in the background.
    ``PARTLAB_DEMO=0`` leaves the demo out (a shared server, or a test that measures speed)."""
    if os.environ.get("PARTLAB_DEMO", "1") == "0" or auth.enabled():  # with sign-in: nobody's project
        return False
    ready = ensure_demo()
    if ready:
        track_demo()
    return ready



PROJECTS = st.Page("views/projects.py", title="Projects and clips", icon=":material/folder:", url_path="projects")
PAGES = [
    PROJECTS,
    st.Page("views/track.py", title="Track", icon=":material/directions_run:", url_path="track"),
    st.Page("views/correct.py", title="Correct", icon=":material/edit:", url_path="correct"),
    st.Page("views/train.py", title="Train", icon=":material/model_training:", url_path="train"),
    st.Page("views/evaluate.py", title="Evaluate and compare", icon=":material/insights:", url_path="evaluate"),
    st.Page("views/export.py", title="Export", icon=":material/download:", url_path="export"),
    st.Page("views/depth.py", title="Depth", icon=":material/layers:", url_path="depth"),
]


def _sign_in():
    auth.sign_in_form()


try:  # a read-only or full data directory, an unreachable database: a sentence, not a traceback
    if auth.enabled() and not auth.user():
        # every address (a link to /correct too) shows the sign-in form, and stays where it was after it
        st.navigation([st.Page(_sign_in, title="Sign in", default=True)]
                      + [st.Page(_sign_in, title="Sign in", url_path=p.url_path) for p in PAGES],
                      position="hidden").run()
        st.stop()
    _demo_ready(str(data_dir()))
    store = state.store()
except (StoreError, OSError) as exc:
    st.error(storage_message(exc))
    st.stop()


def _home():
    """``/`` opens the projects page under its own address, so /projects works as a link too
    (Streamlit serves a default page only at ``/``)."""
    st.switch_page(PROJECTS)


# the navigation is drawn by hand (page links) so that the hidden home page is not listed
current = st.navigation([st.Page(_home, title="partlab", default=True), *PAGES], position="hidden")


with st.sidebar:
    for page in PAGES:
        st.page_link(page)
    st.divider()
    st.markdown("### partlab")
    prefs.remember(store)  # this browser's project and name, across sessions
    projects = store.projects()
    if projects:
        state.project_id(store)
        names = {p.id: p.name for p in projects}
        bound_widget(st.selectbox, state.PROJECT, "project_select", "Project", list(names), format_func=names.get)
    if auth.enabled():  # edits are saved under the signed-in name
        st.caption(f"Signed in as {plain(auth.user())}")
        st.button("Sign out", on_click=auth.sign_out, type="tertiary")
    else:
        st.session_state.setdefault(state.AUTHOR, "")
        bound_widget(st.text_input, state.AUTHOR, "author_input", "Your name (saved with your edits)")
    visible = {p.id for p in projects}

    def _mine(job_meta: dict) -> bool:
        """Without sign-in every job; with it, the jobs of the user's projects only."""
        return not auth.enabled() or job_meta.get("project_id") in visible

    watched = st.session_state.setdefault("sidebar_watched_jobs", set())

    @st.fragment(run_every=2 if jobs.active() else None)
    def _job_list():
        running = [j for j in jobs.active() if _mine(j.meta)]
        # a job this session saw running has ended: rerun the page, whose tables (a clip's state,
        # its runs) were drawn before it ended
        ended = jobs.ended_since(watched, running, ignore=st.session_state.get("page_jobs", set()))
        recent = [j for j in jobs.jobs() if not j.active and _mine(j.meta)][:3]
        stopped = [e for e in jobs.interrupted() if _mine(e.get("meta") or {})][:3]
        if running or recent or stopped:
            st.caption("Background jobs")
        for j in running:
            st.progress(j.fraction, text=f"{plain(j.label)}: {j.done}/{j.total or '?'}"
                        + (" (cancelling)" if j.cancel_requested else ""))
            if not j.cancel_requested:
                st.button("Cancel", key=f"cancel_{j.id}", on_click=jobs.cancel, args=(j.id,), type="tertiary")
        for j in recent:
            word = j.status if j.status in ("done", "cancelled") else "FAILED"
            st.caption(f"{word}: {plain(j.label)}" +
                       (f" ({plain(j.error)})" if j.error else ""))
        for e in stopped:
            st.caption(f"INTERRUPTED: {plain(e['label'])} (the app stopped at {e['done']}/{e['total'] or '?'}; "
                       "start it again from its page)")
        if recent or stopped:
            st.button("Clear finished jobs", on_click=jobs.clear_finished, type="tertiary")
        if ended:
            st.rerun()

    _job_list()
    st.caption(f"Data: {data_dir()}")

try:
    current.run()
except (StoreError, OSError) as exc:  # what a page did not catch: a refused write, a full disk
    st.error(storage_message(exc))
