"""Per-browser preferences: the chosen project and the user's name survive a new session.

A new Streamlit session (a new tab, a reload, the next morning) starts with empty session
state; this invisible component keeps ``{project, author}`` in the browser's
``localStorage`` and hands them back on the first run of a session, so nobody lands in the
demo project with their name forgotten. Nothing leaves the browser but these two values.
"""

from __future__ import annotations

from functools import lru_cache

import streamlit as st

from partlab.app import state

_JS = """
const KEY = "partlab.prefs";
const SENT = new WeakSet();
export default function ({ data, setStateValue, parentElement }) {
  if (data && data.save) {
    try { localStorage.setItem(KEY, JSON.stringify(data.save)); } catch (e) { /* private mode */ }
    return;
  }
  if (SENT.has(parentElement)) return;
  SENT.add(parentElement);
  let stored = {};
  try { stored = JSON.parse(localStorage.getItem(KEY) || "{}") || {}; } catch (e) { stored = {}; }
  setStateValue("stored", stored);
}
"""


@lru_cache(maxsize=1)
def _component():
    return st.components.v2.component("partlab_prefs", html="<span></span>", js=_JS)


RESTORED = "prefs_restored"


def remember(store) -> None:
    """Restore this browser's project and name on a session's first runs, then keep them saved."""
    value = st.session_state.get("prefs") or {}
    stored = value.get("stored") if hasattr(value, "get") else None
    if not st.session_state.get(RESTORED) and stored is not None:
        st.session_state[RESTORED] = True
        pid = stored.get("project") if hasattr(stored, "get") else None
        if pid is not None and any(p.id == pid for p in store.projects()):
            st.session_state[state.PROJECT] = int(pid)
        if stored.get("author") and not st.session_state.get(state.AUTHOR):
            st.session_state[state.AUTHOR] = str(stored.get("author"))[:100]
        st.rerun()
    save = dict(project=st.session_state.get(state.PROJECT), author=st.session_state.get(state.AUTHOR, "")) \
        if st.session_state.get(RESTORED) else None
    _component()(key="prefs", data=dict(save=save), on_stored_change=lambda: None)
