"""Correcting a take in several views at once: a head or hand box moved in one view moves its
3D point, and the boxes of the same target in the other views follow it.

A take (``Store.add_take``) is a set of streams, each stream's video a clip of its own, each
with its calibration; the 3D tracker (``limbs3d``) writes per view one box per target with its
``camera`` and ``X, Y, Z`` (world mm), which :func:`store_take_tracks` stores as one tracker run
per stream clip. The same target is the same ``(frame, track_id, part)`` in every stream clip.

For a correction about to be written (:func:`follow`):

- with two or more views holding a human box of the target at that frame (the corrected one
  among them), the 3D point is re-triangulated from their box centres
  (:func:`partlab.tracking.multiview.triangulate`, ``cv2.triangulatePoints``);
- with the corrected view the only one, the point is the one on its line of sight through the
  new box centre that the other views' boxes agree with best
  (:func:`~partlab.tracking.multiview.point_on_line_of_sight`), so the corrected box stays
  exactly where the user put it;

and every other view's box is moved to the reprojection of that point, keeping its size (a
view without a box of the target gets one, sized from the corrected box by the ratio of
depths), stored as edits of kind ``view`` with ``camera`` and ``X, Y, Z`` (not keyframes: a
later correction in that view re-triangulates from the views people corrected). The human
boxes get the new ``X, Y, Z`` too, so every view of the target holds the same point.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from partlab.labelling.store import Store, StoreError
from partlab.tracking.camera import Camera
from partlab.tracking.core.box import Box
from partlab.tracking.multiview import point_on_line_of_sight, triangulate

#: the parts the 3D tracker gives a point to (one box per view and target)
MULTIVIEW_PARTS: tuple[str, ...] = ("head", "left_hand", "right_hand")


@dataclass(frozen=True)
class View:
    """One calibrated stream of a take: its name, its clip and its camera."""

    name: str
    clip_id: int
    camera: Camera


def take_views(store: Store, clip_id: int) -> list[View]:
    """The calibrated views (with a clip) of the take ``clip_id`` is a stream of, in the take's
    order; empty when the clip is no stream of a take or fewer than two of its views are calibrated."""
    found = store.take_of_clip(clip_id)
    if found is None:
        return []
    take, _ = found
    views = [View(st.name, st.clip_id, Camera.from_dict(st.calibration, st.name)) for st in take.streams
             if st.clip_id is not None and st.calibration]
    return views if len(views) >= 2 else []


def store_take_tracks(store: Store, take_id: int, tracks: pd.DataFrame, tracker: str = "limbs3d",
                      seed: int = 0) -> dict[str, int]:
    """Store a take's tracks (rows with a ``camera`` column naming the stream) as one tracker run
    per stream clip; returns the run id by stream. Refused when a row names no stream of the take."""
    take = store.take(take_id)
    if "camera" not in tracks.columns:
        raise StoreError(f"take {take.name!r}: the tracks have no camera column (which view is each box in?)")
    clips = {st.name: st.clip_id for st in take.streams if st.clip_id is not None}
    unknown = sorted(set(tracks["camera"].astype(str)) - set(clips))
    if unknown:
        raise StoreError(f"take {take.name!r} has no stream {unknown[0]!r} (streams: {', '.join(clips)})")
    return {name: store.save_tracker_run(clips[name], tracks[tracks["camera"].astype(str) == name],
                                         tracker=tracker, seed=seed)
            for name in clips if (tracks["camera"].astype(str) == name).any()}


def import_take_folder(store: Store, project_id: int, path: str, tracks: str | None = None):
    """Add the take folder ``path`` to the project (``Store.import_take``) and, with ``tracks`` (a
    tracks CSV with a ``camera`` column), store its boxes per view; returns the take. A tracks file
    that cannot be read or names no stream of the take adds nothing (the check comes first)."""
    from partlab.tracking.tracks import TracksCSVError, read_tracks_csv

    if not str(path).strip() or not Path(path).is_dir():
        raise StoreError(f"{path or 'the take folder'}: no such folder")
    table = None
    if tracks:
        try:
            table = read_tracks_csv(tracks)
        except (TracksCSVError, OSError) as exc:
            raise StoreError(f"{tracks}: {exc}") from None
        if "camera" not in table.columns or table["camera"].astype(str).eq("").all():
            raise StoreError(f"{tracks}: no camera column (which view is each box in?)")
    take = store.import_take(project_id, path)
    if table is not None:
        store_take_tracks(store, take.id, table)
    return store.take(take.id)


def _row(store: Store, clip_id: int, frame: int, track_id: int, part: str):
    df = store.frame_boxes(clip_id, frame)
    df = df[(df.track_id == track_id) & (df.part == part)]
    return df.iloc[0] if len(df) else None


def _centre(row) -> np.ndarray:
    return np.array([row.x + row.w / 2, row.y + row.h / 2], float)


def _point(views: list[View], rows: dict[str, object], edited: str) -> np.ndarray | None:
    """The target's 3D point after the correction in view ``edited`` (see the module's docstring)."""
    human = [v for v in views if rows.get(v.name) is not None and rows[v.name].source == "human"]
    if len(human) >= 2:
        return triangulate([v.camera for v in human], [_centre(rows[v.name]) for v in human])
    me = next(v for v in views if v.name == edited)
    others = [v for v in views if v.name != edited and rows.get(v.name) is not None]
    old = rows[edited]
    near = np.array([old.X, old.Y, old.Z], float)
    return point_on_line_of_sight(me.camera, _centre(old), [v.camera for v in others],
                                  [_centre(rows[v.name]) for v in others], near=near)


def _reprojected(view: View, point: np.ndarray, row, size_from: tuple[View, object]) -> Box | None:
    """``view``'s box of the target centred on ``point``'s projection (its own size, or, without a
    box, the corrected box's scaled by the ratio of focal length over depth); None when the point
    is behind the camera or projects outside the picture."""
    depth = view.camera.to_camera(point[None])[0, 2]
    u, v = view.camera.project(point[None])[0]
    W, H = view.camera.size
    if depth <= 0 or not (0 <= u < W and 0 <= v < H):
        return None
    if row is not None:
        w, h = float(row.w), float(row.h)
    else:
        src, srow = size_from
        scale = (view.camera.K[0, 0] / depth) / (src.camera.K[0, 0] / src.camera.to_camera(point[None])[0, 2])
        w, h = float(srow.w) * scale, float(srow.h) * scale
    return Box(float(u - w / 2), float(v - h / 2), w, h)


def follow(store: Store, clip_id: int, frame: int, track_id: int, part: str, box: Box) -> dict[int, list[dict]]:
    """The changes (``Store.edit_boxes``' dicts, by clip id) that make every view of the take agree
    with ``box``, the correction of ``(frame, track_id, part)`` in ``clip_id`` about to be written:
    for ``clip_id`` itself that box with the new point, for the other views their reprojected boxes.
    Empty when the clip is no calibrated take's view, the part has no 3D point, the box did not move
    (only a flag changed) or the point cannot be found."""
    views = take_views(store, clip_id)
    if part not in MULTIVIEW_PARTS or not views:
        return {}
    edited = next((v for v in views if v.clip_id == clip_id), None)
    if edited is None:
        return {}
    rows = {v.name: _row(store, v.clip_id, frame, track_id, part) for v in views}
    old = rows[edited.name]
    if old is not None and np.allclose([old.x, old.y, old.w, old.h], [box.x, box.y, box.w, box.h], atol=1e-6):
        return {}  # the box did not move (a flag was toggled): the point stays
    rows[edited.name] = pd.Series(dict(x=box.x, y=box.y, w=box.w, h=box.h, source="human",
                                       X=np.nan if old is None else old.X, Y=np.nan if old is None else old.Y,
                                       Z=np.nan if old is None else old.Z,
                                       revision=0 if old is None else int(old.revision)))
    point = _point(views, rows, edited.name)
    if point is None or not np.all(np.isfinite(point)):
        return {}
    xyz = tuple(float(c) for c in point)
    out: dict[int, list[dict]] = {}
    for v in views:
        row = rows[v.name]
        key = dict(frame=int(frame), track_id=int(track_id), part=part, camera=v.name, xyz=xyz,
                   expected_revision=int(row.revision) if row is not None else store.revision(v.clip_id, frame,
                                                                                            track_id, part))
        if row is not None and row.source == "human":  # a correction keeps its box; it gets the point
            new, kind = Box(float(row.x), float(row.y), float(row.w), float(row.h)), "box"
        else:
            new, kind = _reprojected(v, point, row, (edited, rows[edited.name])), "view"
            if new is None:
                continue
        out.setdefault(v.clip_id, []).append(dict(key, box=new, kind=kind))
    return out


def draw_view(image: np.ndarray, boxes: pd.DataFrame, colours: dict[int, str]) -> np.ndarray:
    """A copy of a BGR frame with ``boxes`` (tracks rows of that frame and view) drawn in their
    track's colour (``#rrggbb`` by track id), thicker for human boxes, labelled ``part #id``."""
    out = image.copy()
    for r in boxes.itertuples():
        hexa = colours.get(int(r.track_id), "#ffffff").lstrip("#")
        bgr = tuple(int(hexa[i:i + 2], 16) for i in (4, 2, 0))
        p0, p1 = (int(round(r.x)), int(round(r.y))), (int(round(r.x + r.w)), int(round(r.y + r.h)))
        cv2.rectangle(out, p0, p1, bgr, 2 if r.source == "human" else 1)
        cv2.putText(out, f"{r.part} #{int(r.track_id)}", (p0[0], max(p0[1] - 3, 9)), cv2.FONT_HERSHEY_SIMPLEX, 0.35,
                    bgr, 1, cv2.LINE_AA)
    return out
