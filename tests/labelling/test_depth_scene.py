"""Synthetic depth and stereo scenes: colour, depth and 3D truth agree; seeds vary the people."""

import numpy as np
import pytest

from partlab.labelling.synth.depth_scene import HAND_L, HAND_R, HEAD, make_depth_scene, render_depth_scenario
from partlab.labelling.take import open_take


@pytest.fixture(scope="module")
def scene():
    return make_depth_scene("desk_depth", seed=2, n_frames=6)


def test_truth_points_project_into_their_boxes_and_depth_sees_their_surface(scene):
    cam = scene.cameras["cam0"]
    t = scene.truth
    for i in (0, 5):
        rows = t[t["frame"] == i].set_index("part")
        for part, label in (("head", HEAD), ("left_hand", HAND_L), ("right_hand", HAND_R)):
            r = rows.loc[part]
            (u, v), = cam.project(r[["X", "Y", "Z"]].to_numpy(float)[None])
            assert r.x <= u <= r.x + r.w and r.y <= v <= r.y + r.h
            # the z-buffer at the centre pixel is the part's front surface: nearer than its centre by
            # at most its radius (a hand is ~50 mm, a head ~100 mm deep)
            z = scene.depth[i, int(v), int(u)]
            if scene.labels[i, int(v), int(u)] == label:
                assert 0 < r.Z - z < (130 if part == "head" else 70)
        # the hands are in front of the face (the paper's constraint 1)
        assert rows.loc["left_hand", "Z"] < rows.loc["head", "Z"] - 100
        assert rows.loc["right_hand", "Z"] < rows.loc["head", "Z"] - 100
        # the person's left hand is on the image's right (facing the camera)
        assert rows.loc["left_hand", "X"] > rows.loc["head", "X"] > rows.loc["right_hand", "X"]


def test_elbows_sit_at_the_arms_lengths_from_shoulders_and_hands(scene):
    t = scene.truth[scene.truth["frame"] == 3].set_index("part")
    P = lambda n: t.loc[n, ["X", "Y", "Z"]].to_numpy(float)  # noqa: E731
    upper = [np.linalg.norm(P(f"{s}_elbow") - P(f"{s}_shoulder")) for s in ("left", "right")]
    fore = [np.linalg.norm(P(f"{s}_elbow") - P(f"{s}_hand")) for s in ("left", "right")]
    H = scene.meta["height_mm"]
    assert upper[0] == pytest.approx(upper[1], rel=1e-6) and 0.15 * H < upper[0] < 0.19 * H
    assert fore[0] == pytest.approx(fore[1], rel=1e-6) and 0.13 * H < fore[0] < 0.17 * H


def test_hands_move_fast_and_seeds_differ():
    a = make_depth_scene("standing_depth", seed=0, n_frames=20, width=160, height=120)
    b = make_depth_scene("standing_depth", seed=1, n_frames=2, width=160, height=120)
    assert a.meta["hand_speed_mm_s_max"] > 1500  # mm/s: the paper's "rapid" hands
    assert a.meta["skin"] != b.meta["skin"] or a.meta["shirt"] != b.meta["shirt"]
    assert a.meta["distance_mm"] != b.meta["distance_mm"]
    again = make_depth_scene("standing_depth", seed=0, n_frames=2, width=160, height=120)
    assert np.array_equal(again.frames[1], a.frames[1]) and np.array_equal(again.depth[1], a.depth[1])


def test_written_scene_is_a_take_with_rendered_and_stereo_depth(tmp_path):
    out = render_depth_scenario("standing_depth", tmp_path / "s", seed=3, n_frames=2)
    with open_take(out) as take, open_take(out / "stereo") as stereo:
        assert take.has_depth and stereo.has_depth and take.cameras["cam0"] is not None
        d = list(take.frames(1, 2))[0].first.depth
        s = list(stereo.frames(1, 2))[0].first.depth
    assert d.dtype == np.float32 and np.isfinite(d).all()
    near = d < np.nanpercentile(d, 30)  # the person
    assert np.nanmedian(np.abs(s - d)[near]) < 40


def test_a_hand_outside_the_frame_has_no_row_and_one_at_its_edge_is_half_occluded():
    from partlab.labelling.synth import depth_scene as ds

    rng = np.random.default_rng(0)
    lay = ds._layout(rng, "desk_depth", 1700.0, 160, 120)
    cam = lay.cams["cam0"]
    hands = np.tile(lay.torso_c, (1, 2, 1)).astype(float)
    elbows = hands.copy()
    z = lay.torso_c[2] - 200.0
    # the left hand's centre on the image's right edge, the right hand far outside the frame
    hands[0, 0] = cam.back_project(np.array([[159.5, 60.0]]), np.array([z]))[0]
    hands[0, 1] = cam.back_project(np.array([[-200.0, 60.0]]), np.array([z]))[0]
    buf = ds._Buffer(cam)
    buf.ellipsoid(hands[0, 0], np.array([lay.body.hand_r] * 3), ds.HAND_L, (0, 0, 255))
    rows = {r[2]: r for r in ds._truth_rows(0, buf.label, lay, hands, elbows)}
    assert "right_hand" not in rows and "left_hand" in rows
    x, y, w, h, occ = rows["left_hand"][3:8]
    assert x + w <= 160 and 0.4 < occ < 0.6  # half the hand's disc is past the edge
