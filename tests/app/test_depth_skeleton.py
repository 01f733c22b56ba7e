"""The Depth page's top-view section: skeletons over depth, a joint moved, the model re-fitted."""

from pathlib import Path

import numpy as np
import pytest
from streamlit.testing.v1 import AppTest

from partlab.labelling.calibration import read_calibration
from partlab.labelling.synth.topview import render_topview
from partlab.labelling.topview_view import draw_skeletons, move_joint
from partlab.tracking.tracks import read_tracks_csv, write_tracks_csv

PAGE = Path(__file__).resolve().parents[2] / "partlab" / "app" / "views" / "depth.py"


@pytest.fixture(scope="module")
def take(tmp_path_factory):
    out = render_topview("topview_s1", tmp_path_factory.mktemp("tv") / "take", seed=3, n_frames=3)
    truth = read_tracks_csv(out / "truth.csv")
    write_tracks_csv(truth, out / "tracks.csv")
    return out


def test_skeleton_is_drawn_where_the_joints_project(take):
    tracks = read_tracks_csv(take / "tracks.csv")
    cam = read_calibration(take / "calibration.json")["cam0"]
    blank = np.zeros((cam.size[1], cam.size[0], 3), np.uint8)
    img = draw_skeletons(blank, tracks, 1, cam, {1: (0, 0, 255)})
    head = tracks[(tracks.frame == 1) & (tracks.part == "head")][["X", "Y", "Z"]].to_numpy(float)
    u, v = np.rint(cam.project(head)[0]).astype(int)
    assert (img[v, u] == 255).all()  # a white joint dot on the head
    assert (img[..., 2] == 255).sum() > 200 and img[..., 0].max() == 255  # red bones, white dots
    assert draw_skeletons(blank, tracks, 99, cam).max() == 0  # no joints at a frame not tracked


def test_page_moves_a_joint_and_refits_from_that_frame(take):
    at = AppTest.from_file(str(PAGE), default_timeout=240)
    at.session_state["depth_take"] = str(take)
    at.run()
    assert not at.exception and not at.error
    assert at.text_input(key="depth_tracks").value == str(take / "tracks.csv")
    assert len(at.get("image")) == 4  # colour, depth, and both again with the skeleton
    at.slider(key="depth_frame").set_value(1).run()
    at.selectbox(key="skel_joint").set_value("right_hand").run()
    cam = read_calibration(take / "calibration.json")["cam0"]
    before = read_tracks_csv(take / "tracks.csv")
    old = before[(before.frame == 1) & (before.part == "right_hand")][["X", "Y", "Z"]].to_numpy(float)
    u0, v0 = cam.project(old)[0]
    at.number_input(key="skel_u:1:1:right_hand").set_value(float(round(u0)) + 6.0)
    at.number_input(key="skel_v:1:1:right_hand").set_value(float(round(v0)) - 4.0)
    at.button(key="skel_move").click().run()
    assert not at.exception and not at.error
    after = read_tracks_csv(take / "tracks.csv")
    row = after[(after.frame == 1) & (after.part == "right_hand")]
    assert row["source"].iloc[0] == "human"
    u, v = cam.project(row[["X", "Y", "Z"]].to_numpy(float))[0]
    assert (u, v) == pytest.approx((round(u0) + 6.0, round(v0) - 4.0), abs=0.05)
    assert 20.0 < np.linalg.norm(row[["X", "Y", "Z"]].to_numpy(float)[0] - old[0]) < 200.0
    at.button(key="skel_refit").click().run()
    assert not at.exception and not at.error
    refit = read_tracks_csv(take / "tracks.csv")
    assert (refit[refit.frame == 0]["source"] == "truth").all()  # before the frame: kept
    later = refit[refit.frame >= 1]
    assert len(later) == 14 and not (later["source"] == "truth").any()  # re-tracked: 2 frames x 7 joints
    # the re-fit starts from the moved hand: frame 1's hand is near where it was put
    hand = later[(later.frame == 1) & (later.part == "right_hand")][["X", "Y", "Z"]].to_numpy(float)[0]
    assert np.linalg.norm(hand - row[["X", "Y", "Z"]].to_numpy(float)[0]) < 60.0


def test_a_joint_moved_off_the_image_is_refused(take):
    from partlab.errors import UserError

    tracks = read_tracks_csv(take / "truth.csv")
    cam = read_calibration(take / "calibration.json")["cam0"]
    depth = np.full((cam.size[1], cam.size[0]), 2000.0, np.float32)
    with pytest.raises(UserError, match="outside the 320x240 depth image"):
        move_joint(tracks, 0, 1, "head", (400.0, 10.0), depth, cam)
