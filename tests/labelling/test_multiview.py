"""Correcting one view of a calibrated take moves the target's 3D point and the other views'
boxes (partlab.labelling.multiview), and the geometry under it (partlab.tracking.multiview)."""

import cv2
import numpy as np
import pandas as pd
import pytest

from partlab.app.editing import EditHistory, apply_events
from partlab.labelling.calibration import write_calibration
from partlab.labelling.multiview import follow, store_take_tracks, take_views
from partlab.labelling.store import Store, StoreError
from partlab.labelling.synth.multiview import look_at
from partlab.labelling.video import write_video
from partlab.tracking.core.box import Box
from partlab.tracking.multiview import point_on_line_of_sight, triangulate

W, H = 320, 240
HAND = np.array([150.0, -80.0, 1100.0])  # the right hand of track 1 in the tracker's boxes (world mm)
HEAD = np.array([0.0, 0.0, 1600.0])


def _cameras():
    # three cameras 3 m around the person, at 1.5-2 m height, with different focal lengths
    return [look_at("cam0", (3000, 0, 1500), (0, 0, 1200), 300.0, (W, H)),
            look_at("cam1", (0, 3000, 1800), (0, 0, 1200), 260.0, (W, H)),
            look_at("cam2", (-2100, -2100, 2000), (0, 0, 1200), 330.0, (W, H))]


def _box(cam, point, size_mm=100.0):
    u, v = cam.project(point[None])[0]
    s = cam.K[0, 0] * size_mm / cam.to_camera(point[None])[0, 2]
    return dict(x=u - s / 2, y=v - s / 2, w=s, h=s)


@pytest.fixture
def take(tmp_path):
    """A 3-camera take of 4 frames in the store, with a tracker run per view holding the head and
    the right hand of track 1 (and camera, X, Y, Z) as the 3D tracker writes them."""
    d = tmp_path / "take"
    d.mkdir()
    cams = _cameras()
    for k, c in enumerate(cams):
        write_video(d / f"{c.name}.mp4", [np.full((H, W, 3), 40 + 20 * k, np.uint8) for _ in range(4)], fps=10)
    write_calibration(cams, d / "calibration.json")
    store = Store(clips_dir=tmp_path / "clips")
    project = store.create_project("p")
    rec = store.import_take(project.id, d)
    rows = [dict(frame=f, track_id=1, part=part, camera=c.name, X=p[0], Y=p[1], Z=p[2], source="tracker",
                 **_box(c, p, 230.0 if part == "head" else 100.0))
            for f in range(4) for c in cams for part, p in (("head", HEAD), ("right_hand", HAND))]
    runs = store_take_tracks(store, rec.id, pd.DataFrame(rows))
    assert sorted(runs) == ["cam0", "cam1", "cam2"]
    clips = {st.name: st.clip_id for st in rec.streams}
    return store, clips, {c.name: c for c in cams}


def _hand(store, clip_id, frame=2):
    df = store.frame_boxes(clip_id, frame)
    return df[(df.part == "right_hand") & (df.track_id == 1)].iloc[0]


def _centre(row):
    return np.array([row.x + row.w / 2, row.y + row.h / 2])


def test_triangulation_agrees_with_opencv_and_a_corrected_line_keeps_its_pixel():
    a, b, c = _cameras()
    X = np.array([120.0, -40.0, 1300.0])
    h = cv2.triangulatePoints(a.P, b.P, a.project(X[None]).T, b.project(X[None]).T).ravel()
    np.testing.assert_allclose(h[:3] / h[3], X, atol=1e-3)
    np.testing.assert_allclose(triangulate([a, b, c], [cam.project(X[None])[0] for cam in (a, b, c)]), X,
                               atol=1e-3)
    # a pixel 12 px off in camera a: the point lies on a's new line (it projects back exactly) and
    # is the least-squares meeting point with b's and c's lines through X
    px = a.project(X[None])[0] + [12.0, -5.0]
    P = point_on_line_of_sight(a, px, [b, c], [b.project(X[None])[0], c.project(X[None])[0]])
    np.testing.assert_allclose(a.project(P[None])[0], px, atol=1e-6)
    assert 10 < np.linalg.norm(P - X) < 150  # moved, by about 12 px at 2.8 m (~110 mm)
    # with one other view it is the common perpendicular's end on a's line: the gap is perpendicular
    Q = point_on_line_of_sight(a, px, [b], [b.project(X[None])[0]])
    wb = b.rays(b.project(X[None]))[0]
    gap = (Q - b.centre) - wb * (wb @ (Q - b.centre))
    assert abs(gap @ a.rays(px[None])[0]) < 1e-6
    # no other view: the point of the line nearest the point before the correction
    R = point_on_line_of_sight(a, px, [], [], near=X)
    assert abs((R - a.centre) @ a.rays(px[None])[0] - (X - a.centre) @ a.rays(px[None])[0]) < 1e-6
    assert point_on_line_of_sight(a, px, [], []) is None


def test_a_hand_moved_in_one_view_moves_the_other_views_to_the_reprojection(take):
    store, clips, cams = take
    assert [v.name for v in take_views(store, clips["cam1"])] == ["cam0", "cam1", "cam2"]
    before = {n: _hand(store, clips[n]) for n in cams}
    moved = Box(before["cam0"].x + 14, before["cam0"].y - 9, before["cam0"].w, before["cam0"].h)
    changes = follow(store, clips["cam0"], 2, 1, "right_hand", moved)
    assert sorted(changes) == sorted(clips.values())
    [own] = changes[clips["cam0"]]
    assert own["kind"] == "box" and own["box"] == moved and own["camera"] == "cam0"
    X = np.array(own["xyz"])
    np.testing.assert_allclose(cams["cam0"].project(X[None])[0], [moved.x + moved.w / 2, moved.y + moved.h / 2],
                               atol=1e-6)
    assert 40 < np.linalg.norm(X - HAND) < 200
    for name in ("cam1", "cam2"):
        [c] = changes[clips[name]]
        assert c["kind"] == "view" and c["xyz"] == own["xyz"] and c["camera"] == name
        b = c["box"]
        np.testing.assert_allclose([b.x + b.w / 2, b.y + b.h / 2], cams[name].project(X[None])[0], atol=1e-6)
        assert (b.w, b.h) == (before[name].w, before[name].h)
        assert np.hypot(b.x - before[name].x, b.y - before[name].y) > 2  # the box moved
    assert follow(store, clips["cam0"], 2, 1, "torso", moved) == {}  # no 3D point for body parts
    same = Box(before["cam0"].x, before["cam0"].y, before["cam0"].w, before["cam0"].h)
    assert follow(store, clips["cam0"], 2, 1, "right_hand", same) == {}  # a flag toggled: nothing moves


def test_the_editor_edit_moves_every_view_and_one_undo_takes_them_all_back(take):
    store, clips, cams = take
    history = EditHistory()
    before = {n: _hand(store, clips[n]) for n in cams}
    b0 = before["cam0"]
    ev = dict(kind="edit", frame=2, track_id=1, part="right_hand", box=[b0.x + 10, b0.y + 6, b0.w, b0.h],
              failure=False, occluded=0.0, revision=int(b0.revision), seq=1)
    res = apply_events(store, clips["cam0"], [ev], history, follow=follow)
    assert not res.errors
    after = {n: _hand(store, clips[n]) for n in cams}
    X = np.array([after["cam0"].X, after["cam0"].Y, after["cam0"].Z])
    assert after["cam0"].source == "human" and (after["cam0"].x, after["cam0"].y) == (b0.x + 10, b0.y + 6)
    for n in ("cam1", "cam2"):
        assert after[n].source == "tracker" and after[n].camera == n  # followed, not a keyframe
        np.testing.assert_allclose([after[n].X, after[n].Y, after[n].Z], X)
        np.testing.assert_allclose(_centre(after[n]), cams[n].project(X[None])[0], atol=1e-3)
        assert np.linalg.norm(_centre(after[n]) - _centre(before[n])) > 2
    assert _hand(store, clips["cam1"], frame=1).x == before["cam1"].x  # other frames untouched
    # one undo brings back every view's box; redo moves them all again
    apply_events(store, clips["cam0"], [dict(kind="undo", seq=2)], history, follow=follow)
    for n in cams:
        now = _hand(store, clips[n])
        assert (now.x, now.y, now.source) == (before[n].x, before[n].y, "tracker"), n
    apply_events(store, clips["cam0"], [dict(kind="redo", seq=3)], history, follow=follow)
    for n in cams:
        assert _hand(store, clips[n]).x == pytest.approx(after[n].x), n


def test_two_corrected_views_re_triangulate_and_the_third_follows(take):
    store, clips, cams = take
    history = EditHistory()
    target = HAND + [60.0, -90.0, 40.0]  # where the hand really is

    def correct(name):  # the user centres the hand's box on where it is in view ``name``
        row = _hand(store, clips[name])
        u, v = cams[name].project(target[None])[0]
        ev = dict(kind="edit", frame=2, track_id=1, part="right_hand", box=[u - row.w / 2, v - row.h / 2, row.w, row.h],
                  failure=False, occluded=0.0, revision=int(row.revision), seq=len(history.undo) + 1)
        assert not apply_events(store, clips[name], [ev], history, follow=follow).errors

    correct("cam0")  # one view: on cam0's line, where cam1 and cam2 (still at the old point) agree best
    one = _hand(store, clips["cam2"])
    assert np.linalg.norm([one.X - target[0], one.Y - target[1], one.Z - target[2]]) > 30
    correct("cam1")  # two corrected views: the point is triangulated from them, the true point
    rows = {n: _hand(store, clips[n]) for n in cams}
    for n in cams:
        np.testing.assert_allclose([rows[n].X, rows[n].Y, rows[n].Z], target, atol=0.5)
    assert [rows[n].source for n in ("cam0", "cam1", "cam2")] == ["human", "human", "tracker"]
    np.testing.assert_allclose(_centre(rows["cam2"]), cams["cam2"].project(target[None])[0], atol=0.05)


def test_take_tracks_name_their_views(take):
    store, clips, _ = take
    [rec] = store.takes(store.clip(clips["cam0"]).project_id)
    with pytest.raises(StoreError, match="no stream 'cam9'"):
        store_take_tracks(store, rec.id, pd.DataFrame([dict(frame=0, track_id=1, part="head", x=1, y=1, w=5, h=5,
                                                            camera="cam9")]))
    with pytest.raises(StoreError, match="no camera column"):
        store_take_tracks(store, rec.id, pd.DataFrame([dict(frame=0, track_id=1, part="head", x=1, y=1, w=5, h=5)]))
