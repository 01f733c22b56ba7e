"""The Depth page's top-view section: skeletons of ``--tracker topview`` tracks over the depth
frame and the colour frame, a joint moved to a pixel, and the model re-fitted from that frame.

Imported by ``depth.py``; drawing and editing are :mod:`partlab.labelling.topview_view`'s.
"""

from __future__ import annotations

import os
from pathlib import Path

import streamlit as st

from partlab.app.box_editor import track_colour
from partlab.errors import UserError
from partlab.labelling.depth_view import depth_colours
from partlab.labelling.topview_view import draw_skeletons, joint_pixel, joint_rows, move_joint, refit_from
from partlab.tracking.topview.model import JOINTS
from partlab.tracking.tracks import TracksCSVError, read_tracks_csv, write_tracks_csv


def _bgr(hex_colour: str) -> tuple[int, int, int]:
    r, g, b = (int(hex_colour[i:i + 2], 16) for i in (1, 3, 5))
    return b, g, r


def _save(tracks, path: Path) -> None:
    """Write the tracks next to ``path`` first and then over it: a failed write loses nothing."""
    tmp = path.with_name(path.name + ".part")
    write_tracks_csv(tracks, tmp)
    os.replace(tmp, path)


def _load(path: Path):
    key = f"topview_tracks:{path}"
    mtime = path.stat().st_mtime_ns
    if st.session_state.get(key + ":mtime") != mtime:
        st.session_state[key] = read_tracks_csv(path)
        st.session_state[key + ":mtime"] = mtime
    return st.session_state[key]


def skeleton_section(take, take_path: str, index: int, frames) -> None:
    """Shown when the take has depth: pick a tracks CSV with 3D joints, see and correct them."""
    st.subheader("Top-view skeletons")
    default = Path(take_path) / "tracks.csv"
    if "depth_tracks" not in st.session_state:
        st.session_state["depth_tracks"] = str(default) if default.is_file() else ""
    path_text = st.text_input("Tracks CSV with 3D joints (`partlab track TAKE --tracker topview -o TAKE/tracks.csv`)",
                              key="depth_tracks")
    if not path_text:
        return
    path = Path(path_text)
    try:
        tracks = _load(path)
    except (OSError, TracksCSVError, UserError) as exc:
        st.error(f"{path}: {exc}" if not str(exc).startswith(str(path)) else str(exc))
        return
    view = next((v for v in frames.views.values() if v.depth is not None), None)
    camera = view.camera or take.cameras.get(view.stream) if view is not None else None
    rows = joint_rows(tracks, index)
    if camera is None or rows.empty:
        st.info(f"frame {index}: no joints with X,Y,Z in {path.name}" if camera is not None
                else "this take has no calibration for its depth stream: joints cannot be drawn")
        return
    ids = sorted(int(t) for t in rows["track_id"].unique())
    c1, c2 = st.columns(2)
    tid = c1.selectbox("Person (track)", ids, key="skel_track")
    part = c2.selectbox("Joint", [j for j in JOINTS if j in set(rows[rows["track_id"] == tid]["part"])],
                        key="skel_joint")
    colours = {t: _bgr(track_colour(t)) for t in ids}
    left, right = st.columns(2)
    left.image(draw_skeletons(depth_colours(view.depth), tracks, index, camera, colours, (tid, part))[..., ::-1],
               caption=f"depth with the skeletons, frame {index}")
    if view.color is not None:
        right.image(draw_skeletons(view.color, tracks, index, camera, colours, (tid, part))[..., ::-1],
                    caption="colour with the skeletons")
    u0, v0 = joint_pixel(tracks, index, tid, part, camera)
    c1, c2, c3 = st.columns(3)
    u = c1.number_input("Joint x (pixel)", value=float(round(u0, 1)), step=1.0, key=f"skel_u:{index}:{tid}:{part}")
    v = c2.number_input("Joint y (pixel)", value=float(round(v0, 1)), step=1.0, key=f"skel_v:{index}:{tid}:{part}")
    if c3.button("Move joint", key="skel_move"):
        try:
            moved = move_joint(tracks, index, tid, part, (u, v), view.depth, camera)
        except UserError as exc:
            st.error(str(exc))
        else:
            _save(moved, path)
            st.session_state["skel_message"] = f"moved {part} of track {tid} at frame {index}; saved {path.name}"
            st.rerun()
    if st.button(f"Re-fit the model from frame {index} on", key="skel_refit"):
        with st.spinner("Tracking from this frame..."):
            try:
                refit = refit_from(take, tracks, index)
            except UserError as exc:
                st.error(str(exc))
            else:
                _save(refit, path)
                st.session_state["skel_message"] = f"re-fitted from frame {index}; saved {path.name}"
                st.rerun()
    if "skel_message" in st.session_state:
        st.success(st.session_state.pop("skel_message"))
