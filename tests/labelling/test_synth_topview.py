"""Synthetic top-view takes: a take folder the take reader opens, with depth, truth and labels."""

import json

import numpy as np
import pandas as pd
import pytest

from partlab.cli import main
from partlab.labelling.synth.topview import make_topview
from partlab.labelling.take import open_take
from partlab.tracking.topview.model import JOINTS, joints
from partlab.tracking.topview.tracker import Geometry


def test_cli_writes_a_take_with_depth_calibration_and_truth(tmp_path, capsys):
    out = tmp_path / "s3"
    assert main(["synth", str(out), "--scenario", "topview_s3", "--seed", "5", "--frames", "3"]) == 0
    take = open_take(out)
    assert take.frame_count == 3 and take.has_depth and take.cameras["cam0"] is not None
    fs = next(take.frames())
    view = fs.first
    assert view.depth.shape == (240, 320) and view.color.shape == (240, 320, 3)
    d = view.depth[np.isfinite(view.depth)]
    assert 800 <= d.min() and d.max() <= 3500
    cam = take.cameras["cam0"]
    assert 2850 <= cam.centre[2] <= 2950
    t3 = pd.read_csv(out / "truth3d.csv")
    assert list(t3.columns) == ["frame", "track_id", "part", "X", "Y", "Z"]
    assert len(t3) == 3 * 2 * len(JOINTS)
    labels = np.load(out / "labels.npz")
    assert labels["person"].shape == (3, 240, 240 * 4 // 3) and set(np.unique(labels["person"])) == {0, 1, 2}
    angles = pd.read_csv(out / "angles.csv")
    assert angles.shape == (6, 19)
    meta = json.loads((out / "scene.json").read_text())
    assert meta["tracks"] == 2 and len(meta["people"]) == 2


def test_depth_of_a_labelled_pixel_back_projects_onto_that_person():
    s = make_topview("topview_s1", seed=9, n_frames=1)
    g = Geometry(s.camera)
    idx = np.flatnonzero((s.person[0] == 1).ravel() & np.isfinite(s.depth[0]).ravel())
    pts = g.points(s.depth[0], idx)
    head = joints(s.people[0].states[0][None], s.people[0].body)[0, 0]
    # the highest labelled points are the top of the head, within the sensor's quantisation
    assert pts[:, 2].max() == pytest.approx(head[2] + s.people[0].body.head_radius, abs=15.0)
    # the floor is at Z = 0
    floor = np.flatnonzero((s.person[0] == 0).ravel() & np.isfinite(s.depth[0]).ravel())
    assert np.median(g.points(s.depth[0], floor)[:, 2]) == pytest.approx(0.0, abs=30.0)


def test_scenes_differ_by_seed_and_dark_clothes_are_dark():
    a, b = make_topview("topview_s1", 0, 1), make_topview("topview_s1", 1, 1)
    assert a.people[0].body != b.people[0].body
    bright = make_topview("topview_s2", 0, 1)
    assert max(a.people[0].colours["torso"]) < 90 < max(bright.people[0].colours["torso"])


def test_unknown_topview_scenario_is_refused(tmp_path, capsys):
    assert main(["synth", str(tmp_path / "x"), "--scenario", "topview_s9"]) == 2
    assert "unknown scenario 'topview_s9'" in capsys.readouterr().err


def test_group_scenes_vary_the_number_of_people_camera_height_and_noise():
    scenes = [make_topview("topview_group", seed=s, n_frames=1, width=160, height=120) for s in range(6)]
    counts = [len(s.people) for s in scenes]
    assert set(counts) <= {1, 2, 3} and len(set(counts)) >= 2
    heights = [s.camera.centre[2] for s in scenes]
    assert all(2700 <= h <= 3200 for h in heights) and max(heights) - min(heights) > 100
    for s in scenes:
        # every person is seen (labelled pixels of their own) and nobody else is labelled
        assert set(np.unique(s.person[0])) == set(range(len(s.people) + 1))
        assert min((s.person[0] == k + 1).sum() for k in range(len(s.people))) > 100


def test_no_forearm_goes_into_its_own_torso_and_other_frames_are_left_alone():
    from partlab.labelling.synth.topview import CAMERA_HEIGHT_MM, _out_of_the_body, _people
    from partlab.tracking.topview.likelihood import self_intersection
    from partlab.tracking.topview.model import Body, neutral_state, primitives

    body = Body()
    free = neutral_state(0.0, 0.0, body)
    inside = free.copy()
    inside[13], inside[15] = -0.2, 1.6  # left arm against the body, elbow bent: the forearm goes in
    assert self_intersection(primitives(inside[None], body), 1000.0).max() > 10.0
    fixed = _out_of_the_body(np.stack([free, inside]), body)
    assert self_intersection(primitives(fixed, body), 1000.0).max() == 0.0
    assert np.array_equal(fixed[0], free)  # nothing went in: untouched
    moved = np.flatnonzero(fixed[1] != inside)
    assert set(moved) <= {13, 15} and np.abs(fixed[1] - inside).max() <= 1.5
    # S1 seed 7's left forearm went 25 mm into the torso before the motions were kept out of it
    rng = np.random.default_rng([7, 17])
    rng.uniform(*CAMERA_HEIGHT_MM.get("topview_s1", (2850.0, 2950.0)))
    person = _people("topview_s1", rng, 25)[0]
    assert self_intersection(primitives(person.states, person.body), 1000.0).max() == 0.0
