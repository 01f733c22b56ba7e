"""Depth beside colour: a take's frame and its depth as a colour map, at the same frame index."""

import streamlit as st

from partlab.app import auth
from partlab.app.views.common import plain
from partlab.app.views.depth_skeleton import skeleton_section
from partlab.errors import UserError
from partlab.labelling.depth_view import depth_colours
from partlab.labelling.take import open_take

st.title("Depth")
if auth.enabled():  # it opens any folder the server can read: not for a shared server's users
    st.info("The Depth page opens folders on the server by path, so it is off while sign-in is on; "
            "use it on your own machine (partlab app on loopback).")
    st.stop()
path = st.text_input("Take folder (colour with depth, or a stereo pair; see docs/formats.md)", key="depth_take")
if not path:
    st.info("Give the path of a take folder, e.g. one written by `partlab synth OUT --scenario desk_depth`.")
    st.stop()
try:
    take = open_take(path)
except UserError as exc:
    st.error(plain(exc))
    st.stop()
with take:
    if not take.has_depth:
        st.warning(plain(f"{path}: this take has no depth stream."))
        st.stop()
    index = st.slider("Frame", 0, take.frame_count - 1, 0, key="depth_frame")
    frames = next(take.frames(index, index + 1))
    for name, view in frames.views.items():
        left, right = st.columns(2)
        if view.color is not None:
            left.image(view.color[..., ::-1], caption=f"{name} colour, frame {index}")
        if view.depth is not None:
            right.image(depth_colours(view.depth)[..., ::-1],
                        caption=f"{name} depth (near red, far blue, missing black)")
    skeleton_section(take, path, index, frames)
