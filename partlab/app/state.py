"""Session-state keys of the app, by project, clip and frame, in one place.

Streamlit reruns every page script from the top on each interaction; what must
survive a rerun (the chosen project and clip, the frame shown per clip, the undo
history per clip) lives in ``st.session_state`` under the keys made here.
"""

from __future__ import annotations

import streamlit as st

from partlab.app.editing import EditHistory
from partlab.labelling.store import Store

PROJECT = "project_id"
CLIP = "clip_id"
AUTHOR = "author"


def store() -> Store:
    """The annotation store (cheap: engines are shared per database URL); with sign-in on, the
    signed-in user's view of it, and the page stops when nobody is signed in (:mod:`partlab.app.auth`)."""
    from partlab.app import auth

    return auth.signed_in_store()


def frame_key(clip_id: int) -> str:
    return f"frame:{clip_id}"


def slider_key(clip_id: int) -> str:
    return f"frame_slider:{clip_id}"


def editor_key(clip_id: int, mode: str = "boxes") -> str:
    return f"editor:{mode}:{clip_id}"


def history_key(clip_id: int) -> str:
    return f"history:{clip_id}"


def project_id(s: Store) -> int | None:
    """The chosen project, falling back to the newest one that is not the demo (a new
    session of someone with projects of their own does not open the demo)."""
    from partlab.app.demo import DEMO_PROJECT

    pid = st.session_state.get(PROJECT)
    projects = s.projects()
    if pid is not None and any(p.id == pid for p in projects):
        return int(pid)
    if projects:
        own = [p for p in projects if p.name != DEMO_PROJECT]
        pick = own[-1] if own else projects[0]
        st.session_state[PROJECT] = pick.id
        return pick.id
    return None


def clip_id(clip_ids: list[int]) -> int | None:
    """The chosen clip if it belongs to ``clip_ids``, else the first of them."""
    cid = st.session_state.get(CLIP)
    if cid in clip_ids:
        return int(cid)
    if clip_ids:
        st.session_state[CLIP] = clip_ids[0]
        return clip_ids[0]
    return None


def frame(clip_id: int, frame_count: int) -> int:
    f = int(st.session_state.get(frame_key(clip_id), 0))
    return min(max(f, 0), max(frame_count - 1, 0))


def set_frame(clip_id: int, value: int) -> None:
    st.session_state[frame_key(clip_id)] = int(value)


def history(clip_id: int) -> EditHistory:
    key = history_key(clip_id)
    if key not in st.session_state:
        st.session_state[key] = EditHistory()
    return st.session_state[key]


def author() -> str:
    """The name saved with edits: the signed-in user's, else the one typed in the sidebar."""
    from partlab.app import auth

    return auth.user() or str(st.session_state.get(AUTHOR, ""))
