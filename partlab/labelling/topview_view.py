"""Seeing and correcting top-view tracks (``--tracker topview``): skeletons over the depth frame,
a joint moved to where the user puts it, and the model re-fitted from that frame on.

The app's Depth page calls these; the numbers stay in the tracks table (``X, Y, Z`` in mm in the
take's world frame, one row per joint), this module only draws them and edits rows.
"""

from __future__ import annotations

import cv2
import numpy as np
import pandas as pd

from partlab.errors import UserError
from partlab.tracking.camera import Camera
from partlab.tracking.topview.model import JOINTS

#: the skeleton's bones, as pairs of :data:`JOINTS` names
BONES: tuple[tuple[str, str], ...] = (
    ("head", "right_shoulder"), ("head", "left_shoulder"), ("right_shoulder", "left_shoulder"),
    ("right_shoulder", "right_elbow"), ("right_elbow", "right_hand"),
    ("left_shoulder", "left_elbow"), ("left_elbow", "left_hand"),
)


def joint_rows(tracks: pd.DataFrame, frame: int) -> pd.DataFrame:
    """The 3D joint rows (:data:`JOINTS` parts with ``X, Y, Z``) of one frame."""
    if not {"X", "Y", "Z"} <= set(tracks.columns):
        return tracks.iloc[0:0]
    rows = tracks[(tracks["frame"] == frame) & tracks["part"].isin(JOINTS)]
    return rows.dropna(subset=["X", "Y", "Z"])


def draw_skeletons(image: np.ndarray, tracks: pd.DataFrame, frame: int, camera: Camera,
                   colours: dict[int, tuple[int, int, int]] | None = None, selected: tuple[int, str] | None = None
                   ) -> np.ndarray:
    """A copy of BGR ``image`` with every person's skeleton of ``frame`` drawn on it: bones in the
    track's colour (``colours``: track id -> BGR), joints as white dots, the ``selected``
    ``(track_id, part)`` joint ringed."""
    out = image.copy()
    scale = max(1, round(out.shape[1] / 320))
    for tid, rows in joint_rows(tracks, frame).groupby("track_id"):
        uv = dict(zip(rows["part"], camera.project(rows[["X", "Y", "Z"]].to_numpy(float))))
        colour = (colours or {}).get(int(tid), (0, 0, 0))
        for a, b in BONES:
            if a in uv and b in uv:
                cv2.line(out, _pt(uv[a]), _pt(uv[b]), colour, 2 * scale, cv2.LINE_AA)
        for part, p in uv.items():
            cv2.circle(out, _pt(p), 3 * scale, (255, 255, 255), -1, cv2.LINE_AA)
            if selected == (int(tid), part):
                cv2.circle(out, _pt(p), 7 * scale, (255, 255, 255), scale, cv2.LINE_AA)
    return out


def _pt(p) -> tuple[int, int]:
    return int(round(float(p[0]))), int(round(float(p[1])))


def joint_pixel(tracks: pd.DataFrame, frame: int, track_id: int, part: str, camera: Camera) -> tuple[float, float]:
    """Where joint ``part`` of ``track_id`` at ``frame`` is in the image (pixels)."""
    row = _row(tracks, frame, track_id, part)
    u, v = camera.project(tracks.loc[[row], ["X", "Y", "Z"]].to_numpy(float))[0]
    return float(u), float(v)


def _row(tracks: pd.DataFrame, frame: int, track_id: int, part: str):
    rows = joint_rows(tracks, frame)
    rows = rows[(rows["track_id"] == track_id) & (rows["part"] == part)]
    if rows.empty:
        raise UserError(f"frame {frame} has no {part} joint of track {track_id}")
    return rows.index[0]


def move_joint(tracks: pd.DataFrame, frame: int, track_id: int, part: str, uv: tuple[float, float],
               depth: np.ndarray, camera: Camera) -> pd.DataFrame:
    """A copy of ``tracks`` with one joint moved to image point ``uv``: to the 3D point the depth
    image sees there less the joint's own depth below the surface (a joint lies inside its limb:
    the shift from the surface seen above it to the joint is kept), or at the joint's old
    camera depth where the depth is missing. Its box is re-centred and its source becomes
    ``human``."""
    out = tracks.copy()
    row = _row(out, frame, track_id, part)
    old = out.loc[[row], ["X", "Y", "Z"]].to_numpy(float)
    old_uv = camera.project(old)[0]
    z_old = float(camera.to_camera(old)[0, 2])
    u, v = float(uv[0]), float(uv[1])
    h, w = depth.shape
    if not (0 <= u < w and 0 <= v < h):
        raise UserError(f"pixel ({u:.0f}, {v:.0f}) is outside the {w}x{h} depth image")
    below = z_old - _depth_at(depth, *old_uv, fallback=z_old)  # how far the joint lies under the surface
    z = _depth_at(depth, u, v, fallback=np.nan) + below
    if not np.isfinite(z):
        z = z_old
    X = camera.back_project(np.array([[u, v]]), np.array([z]))[0]
    out.loc[row, ["X", "Y", "Z"]] = X
    if {"x", "y", "w", "h"} <= set(out.columns):
        bw, bh = float(out.at[row, "w"]), float(out.at[row, "h"])
        out.loc[row, ["x", "y"]] = u - bw / 2, v - bh / 2
    if "source" in out.columns:
        out.at[row, "source"] = "human"
    return out


def _depth_at(depth: np.ndarray, u: float, v: float, fallback: float, radius: int = 2) -> float:
    """The median measured depth in a small window around pixel ``(u, v)`` (``fallback`` if none)."""
    h, w = depth.shape
    iu, iv = int(round(u)), int(round(v))
    win = depth[max(iv - radius, 0):min(iv + radius + 1, h), max(iu - radius, 0):min(iu + radius + 1, w)]
    good = win[np.isfinite(win) & (win > 0)]
    return float(np.median(good)) if good.size else fallback


def refit_from(take, tracks: pd.DataFrame, frame: int, *, seed: int = 0, stop: int | None = None,
               model=None) -> pd.DataFrame:
    """Re-run ``--tracker topview`` from ``frame`` started from that frame's joints (as corrected),
    keeping the rows before ``frame`` and those of frames from ``stop`` on."""
    from partlab.tracking.run import track

    init = joint_rows(tracks, frame)
    if init.empty:
        raise UserError(f"frame {frame} has no joints with X,Y,Z to re-fit from")
    result = track(take, "topview", init=init, model=model, seed=seed, start=frame, stop=stop)
    end = take.frame_count if stop is None else int(stop)
    keep = tracks[(tracks["frame"] < frame) | (tracks["frame"] >= end)]
    new = result.tracks
    out = pd.concat([keep, new], ignore_index=True) if len(keep) else new.reset_index(drop=True)
    return out.sort_values(["frame", "track_id", "part"], kind="stable").reset_index(drop=True)
