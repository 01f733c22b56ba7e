"""Sign-in of the app: who this browser session is, and the store as they may see it.

``partlab app --auth password`` (the default on any address but loopback) sets ``PARTLAB_AUTH=password``
for the server; then every page run needs a signed-in user (:func:`signed_in_store`), gets a
:class:`~partlab.labelling.access.GuardedStore` (projects without the user's role do not exist, a
viewer's writes are refused) and records edits under the user's name. ``PARTLAB_AUTH=none`` (loopback
only) is partlab as a single-user tool: one store, a typed name on edits.

A sign-in lasts for the browser tab's session (Streamlit keeps ``st.session_state`` on the server; the
browser holds no token): a reload or a new tab asks again. Users and roles are made with
``partlab users`` (:mod:`partlab.commands.users`).
"""

from __future__ import annotations

import os
import time

import streamlit as st

from partlab.app.views.common import plain
from partlab.labelling import access
from partlab.labelling.store import Store, StoreError

#: session-state key of the signed-in user's name
USER = "signed_in_user"
MODES = ("none", "password")
#: seconds a wrong password waits before the form comes back (slows guessing through the form)
FAILED_SIGN_IN_DELAY = 1.0


def mode() -> str:
    """``PARTLAB_AUTH``: ``none`` (default) or ``password``."""
    value = os.environ.get("PARTLAB_AUTH", "none").strip().lower() or "none"
    if value not in MODES:
        raise StoreError(f"PARTLAB_AUTH must be one of {', '.join(MODES)}, got {value!r}")
    return value


def enabled() -> bool:
    return mode() == "password"


def user() -> str | None:
    """The signed-in user's name (None: nobody, or sign-in is off)."""
    return st.session_state.get(USER) if enabled() else None


def signed_in_store() -> Store:
    """The store for this page run: a plain one without sign-in; with sign-in, the signed-in user's
    guarded store, or the page stops with a sentence when nobody is signed in."""
    if not enabled():
        return Store()
    name = st.session_state.get(USER)
    if not name:
        st.info("Sign in to see your projects.")
        st.stop()
    try:
        return access.GuardedStore(name)
    except access.AccessError as exc:  # removed while signed in
        st.session_state.pop(USER, None)
        st.error(plain(exc))
        st.stop()


def sign_in_form() -> None:
    """The sign-in form; on success the session's user is set and the app reruns."""
    st.title("partlab")
    st.caption("This partlab server asks you to sign in (an administrator adds users with `partlab users add`).")
    with st.form("sign_in"):
        name = st.text_input("User name", autocomplete="username")
        password = st.text_input("Password", type="password", autocomplete="current-password")
        go = st.form_submit_button("Sign in", type="primary")
    if go:
        found = access.authenticate(Store(), name.strip(), password)
        if found is None:
            time.sleep(FAILED_SIGN_IN_DELAY)
            st.error("Wrong user name or password.")
            return
        for key in list(st.session_state):  # nothing of an earlier user's session carries over
            del st.session_state[key]
        st.session_state[USER] = found.name
        st.rerun()


def sign_out() -> None:
    for key in list(st.session_state):
        del st.session_state[key]
