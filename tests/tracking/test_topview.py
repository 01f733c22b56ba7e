"""The top-view tracker (Migniot & Ababsa): model geometry, likelihood, resampling, exclusion."""

import numpy as np
import pandas as pd
import pytest

from partlab.errors import UserError
from partlab.labelling.synth.topview import make_topview, ray_cast, topview_camera
from partlab.tracking.frame import FrameSet
from partlab.tracking.protocol import TrackContext
from partlab.tracking.run import build_tracker
from partlab.tracking.topview.filter import PersonFilter
from partlab.tracking.topview.likelihood import (
    bhattacharyya,
    free_space,
    nearest,
    nearest_primitive,
    self_intersection,
    weigh,
)
from partlab.tracking.topview.model import (
    JOINTS,
    KINDS,
    N_DOF,
    PART_DOFS,
    WEIGHT_PARTS,
    Body,
    fit_state,
    joints,
    neutral_state,
    primitives,
)
from partlab.tracking.topview.params import DynamicsParams, ExclusionParams, ResamplingParams, TopViewParams
from partlab.tracking.topview.tracker import Geometry, TopViewTracker


@pytest.fixture(scope="module")
def s1():
    return make_topview("topview_s1", seed=4, n_frames=15)


@pytest.fixture(scope="module")
def s3():
    return make_topview("topview_s3", seed=2, n_frames=8)


def test_table1_gives_every_degree_of_freedom_to_one_part():
    owned = sorted(i for p in WEIGHT_PARTS for i in PART_DOFS[p])
    assert owned == list(range(N_DOF)) and N_DOF == 17


def test_kinematics_of_the_neutral_pose():
    b = Body()
    j = joints(neutral_state(100.0, -50.0, b, yaw=0.0)[None], b)[0]
    head, rs, ls, re, le = j[0], j[1], j[2], j[3], j[4]
    assert head[2] == pytest.approx(b.stature - b.head_radius)
    assert rs[0] - 100.0 == pytest.approx(b.shoulder_offset) and ls[0] - 100.0 == pytest.approx(-b.shoulder_offset)
    # arms hang 0.15 rad away from the body: each elbow is below and outside its shoulder
    assert np.linalg.norm(re - rs) == pytest.approx(b.upper_arm_length)
    assert re[2] < rs[2] - 280 and re[0] > rs[0] and le[0] < ls[0]
    # raising the right arm forward by 90 degrees puts the elbow in front (+y at yaw 0)
    s = neutral_state(0.0, 0.0, b)
    s[7], s[8] = np.pi / 2, 0.0
    e = joints(s[None], b)[0, 3] - joints(s[None], b)[0, 1]
    assert e == pytest.approx([0.0, b.upper_arm_length, 0.0], abs=1e-6)


def test_rendered_surface_lies_on_the_model_and_distance_is_exact_for_spheres_and_cylinders():
    b = Body()
    state = neutral_state(0.0, 0.0, b, yaw=0.3)
    state[[7, 10]] = 1.0, 0.8
    prims = primitives(state[None], b)[0]
    cam = topview_camera(160, 120, 2900.0)
    g = Geometry(cam)
    hit = np.full(160 * 120, np.inf)
    for k, prim in enumerate(prims):
        hit = np.minimum(hit, ray_cast(cam.centre, g.rays, prim, int(KINDS[k])))
    on = np.flatnonzero(np.isfinite(hit))
    assert len(on) > 500
    pts = cam.centre + hit[on, None] * g.rays[on]
    d, _ = nearest(pts, prims)
    assert np.percentile(d, 99) < 0.5  # the ray caster and the distance agree on the surface
    # a point 30 mm above the top of the head is 30 mm from the model
    top = joints(state[None], b)[0, 0] + [0, 0, b.head_radius + 30.0]
    assert nearest(top[None], prims)[0][0] == pytest.approx(30.0, abs=0.01)
    # a point beside the raised forearm's axis, 60 mm from it: 60 - radius from the surface
    fore = prims[4]
    side = fore[0:3] + 0.5 * fore[14] * fore[9:12] + 60.0 * fore[3:6]
    d, part = nearest(side[None], prims)
    assert d[0] == pytest.approx(60.0 - b.forearm_radius, abs=0.01) and part[0] == WEIGHT_PARTS.index("right_arm")


def test_eq1_prefers_the_true_pose_and_eq3_gives_each_point_to_its_nearest_part(s1):
    person = s1.people[0]
    g = Geometry(s1.camera)
    idx = np.flatnonzero((s1.person[5] == 1).ravel() & np.isfinite(s1.depth[5]).ravel())
    pts = g.points(s1.depth[5], idx)
    true = person.states[5]
    off = true.copy()
    off[10] += 0.5  # the right elbow bent half a radian more
    sums, counts, _ = weigh(pts, primitives(np.stack([true, off]), person.body))
    mean = sums.sum(1) / counts.sum(1)
    assert mean[0] < 2.0 < mean[1]
    right = WEIGHT_PARTS.index("right_arm")
    assert sums[0, right] / counts[0, right] < 0.5 * sums[1, right] / counts[1, right]
    # the nearest part of each point is its true part for nearly all points
    _, part = nearest(pts, primitives(true[None], person.body)[0])
    assert np.mean(part + 1 == s1.part[5].ravel()[idx]) > 0.95


def test_bhattacharyya_distance():
    a = np.array([1.0, 0, 0, 0])
    assert bhattacharyya(a, a) == pytest.approx(0.0)
    assert bhattacharyya(a, np.array([0, 1.0, 0, 0])) == pytest.approx(1.0)
    assert bhattacharyya(np.array([1.0, 1, 0, 0]), a) == pytest.approx(np.sqrt(1 - np.sqrt(0.5)))


def test_free_space_charges_an_arm_over_the_floor_only(s1):
    person = s1.people[0]
    true = person.states[3]
    off = true.copy()
    off[12] = true[12] + 1.2  # left arm swung far forward, over what the sensor sees as floor
    pen = free_space(primitives(np.stack([true, off]), person.body), s1.depth[3], s1.camera, 100.0)
    left = WEIGHT_PARTS.index("left_arm")
    assert pen[0].max() < 10.0
    assert pen[1, left] > 40.0 and pen[1, WEIGHT_PARTS.index("head")] == pytest.approx(pen[0, 0])


def test_self_intersection_charges_a_forearm_folded_into_the_torso_only():
    b = Body()
    hanging = neutral_state(0.0, 0.0, b)
    folded = hanging.copy()
    folded[9], folded[10] = 1.2, 1.0  # right upper arm twisted in, elbow bent: the forearm crosses the belly
    pen = self_intersection(primitives(np.stack([hanging, folded]), b), 100.0)
    right, left = WEIGHT_PARTS.index("right_arm"), WEIGHT_PARTS.index("left_arm")
    assert pen[0].max() == 0.0
    assert pen[1, right] > 20.0 and pen[1, left] == 0.0 and pen[1, :3].max() == 0.0
    assert self_intersection(primitives(folded[None], b), 10.0)[0, right] <= 10.0  # capped


def test_a_hidden_forearm_random_walks_slower_and_speeds_up_when_seen_again(s1):
    p = TopViewParams(dynamics=DynamicsParams(hidden_scale=0.25, hidden_points=8.0))
    person = s1.people[0]
    f = PersonFilter(p, np.random.default_rng(0), person.body, person.states[0])
    full = f.step_scales()
    f.seen[:] = (0.0, 4.0)  # right forearm not seen, the left half seen
    slow = f.step_scales()
    assert slow[[9, 10, 11]] == pytest.approx(0.25 * full[[9, 10, 11]])
    assert slow[[14, 15, 16]] == pytest.approx(0.625 * full[[14, 15, 16]])
    assert slow[[7, 8, 12, 13]] == pytest.approx(full[[7, 8, 12, 13]])  # the upper arms: seen from above
    # the true pose's points: at least those on each forearm and hand are counted
    pts = Geometry(s1.camera).points(s1.depth[0], np.flatnonzero((s1.person[0] == 1).ravel()
                                                                  & np.isfinite(s1.depth[0]).ravel()))
    f.estimate = person.states[0].copy()
    f.observe_forearms(pts)
    _, prim = nearest_primitive(pts, primitives(person.states[0][None], person.body)[0])
    on = [np.isin(prim, (4, 5)).sum(), np.isin(prim, (7, 8)).sum()]
    assert min(on) > 0 and np.all(f.seen >= 0.9 * np.array(on)) and f.seen.sum() < 0.5 * len(pts)
    f.estimate[0] += 2000.0  # the model 2 m away: every point unexplained, each on one side
    f.observe_forearms(pts)
    assert f.seen.sum() == len(pts)


def test_part_based_resampling_recombines_parts_and_measures_survival():
    p = TopViewParams(resampling=ResamplingParams(n_particles=8))
    f = PersonFilter(p, np.random.default_rng(0), Body(), neutral_state(0, 0, Body()))
    f.particles = np.tile(np.arange(8.0)[:, None], (1, N_DOF))
    w = np.full((8, 5), 1e-12)
    w[2, :] = 1.0                     # particle 2 wins every part but the right arm ...
    w[2, 3], w[5, 3] = 1e-12, 1.0     # ... where particle 5 wins
    f.weights = w / w.sum(0)
    f.resample()
    assert np.all(f.particles[:, PART_DOFS["right_arm"]] == 5.0)
    assert np.all(f.particles[:, PART_DOFS["head"]] == 2.0)
    assert f.survival == pytest.approx(np.full(5, 1 / 8))
    g = PersonFilter(TopViewParams(resampling=ResamplingParams(mode="global", n_particles=8)),
                     np.random.default_rng(0), Body(), neutral_state(0, 0, Body()))
    g.particles = np.tile(np.arange(8.0)[:, None], (1, N_DOF))
    g.weights = np.full((8, 5), 1 / 8)
    g.resample()
    assert g.survival == pytest.approx(np.ones(5))


def test_fit_state_recovers_a_pose_from_its_joints(s1):
    person = s1.people[0]
    js = dict(zip(JOINTS, joints(person.states[7][None], person.body)[0]))
    got = joints(fit_state(js, person.body)[None], person.body)[0]
    assert np.abs(got - np.array(list(js.values()))).max() < 15.0


def _run(scene, tracker):
    rows = []
    for f in range(len(scene.depth)):
        rows += tracker.step(FrameSet.single(f, scene.color[f], scene.depth[f], camera=scene.camera), {})
    return tracker.table(rows)


def _errors(tab, scene):
    m = tab.merge(scene.truth3d, on=["frame", "track_id", "part"], suffixes=("", "_t"))
    return m.assign(err=np.sqrt((m.X - m.X_t) ** 2 + (m.Y - m.Y_t) ** 2 + (m.Z - m.Z_t) ** 2))


def test_tracks_one_person_from_init_and_same_seed_same_output(s1):
    ctx = TrackContext(init=s1.init, cameras={"cam0": s1.camera})
    few = TopViewParams(resampling=ResamplingParams(n_particles=100))
    tab = _run(s1, build_tracker("topview", model=few, seed=3, context=ctx))
    assert set(tab["part"]) == set(JOINTS) and tab["frame"].nunique() == 15
    m = _errors(tab, s1)
    arm = m[m.part.str.contains("elbow|hand")]
    assert arm["err"].median() < 60.0 and (arm["err"] < 80).mean() > 0.8
    assert m[m.part == "head"]["err"].median() < 40.0
    again = _run(s1, build_tracker("topview", model=few, seed=3, context=ctx))
    pd.testing.assert_frame_equal(tab, again)


def test_exclusion_assigns_pixels_to_the_right_person_and_auto_start_finds_both(s3):
    few = TopViewParams(resampling=ResamplingParams(n_particles=60))
    tr = TopViewTracker(few, np.random.default_rng(1), init=s3.init, cameras={"cam0": s3.camera})
    rates = []
    for f in range(len(s3.depth)):
        tr.step(FrameSet.single(f, s3.color[f], s3.depth[f], camera=s3.camera))
        roi = tr.assignment > 0
        rates.append(np.mean(tr.assignment[roi] == s3.person[f][roi]))
    assert np.mean(rates) > 0.98
    # the second pass (nearest fitted model) against eq. 5 alone on the same frames and seeds
    alone = TopViewParams(resampling=ResamplingParams(n_particles=60), exclusion=ExclusionParams(second_pass=False))
    tr1 = TopViewTracker(alone, np.random.default_rng(1), init=s3.init, cameras={"cam0": s3.camera})
    first = []
    for f in range(len(s3.depth)):
        tr1.step(FrameSet.single(f, s3.color[f], s3.depth[f], camera=s3.camera))
        roi = tr1.assignment > 0
        first.append(np.mean(tr1.assignment[roi] == s3.person[f][roi]))
    assert np.mean(rates) >= np.mean(first) - 0.002
    auto = TopViewTracker(few, np.random.default_rng(1), cameras={"cam0": s3.camera})
    auto.step(FrameSet.single(0, s3.color[0], s3.depth[0], camera=s3.camera))
    assert len(auto.targets) == 2
    heads = sorted(np.linalg.norm(joints(t.filter.estimate[None], t.filter.body)[0, 0, :2]) for t in auto.targets)
    true = sorted(np.linalg.norm(joints(p.states[0][None], p.body)[0, 0, :2]) for p in s3.people)
    assert np.allclose(heads, true, atol=60.0)


def test_init_without_3d_joints_is_refused():
    init = pd.DataFrame({"frame": [0], "track_id": [1], "part": ["head"], "x": [1.0], "y": [1.0], "w": [4.0],
                         "h": [4.0], "X": [np.nan], "Y": [np.nan], "Z": [np.nan]})
    with pytest.raises(UserError, match="X,Y,Z"):
        TopViewTracker(TopViewParams(), np.random.default_rng(0), init=init)


def test_params_round_trip():
    p = TopViewParams(resampling=ResamplingParams(mode="global", n_particles=50))
    assert TopViewParams.from_dict(p.to_dict()) == p
    with pytest.raises(ValueError, match="topview.resampling.mode"):
        TopViewParams(resampling=ResamplingParams(mode="both"))


def _cast(state, body, cam):
    g = Geometry(cam)
    prims = primitives(state[None], body)[0]
    hit = np.full(len(g.rays), np.inf)
    for k, prim in enumerate(prims):
        hit = np.minimum(hit, ray_cast(cam.centre, g.rays, prim, int(KINDS[k])))
    on = np.isfinite(hit)
    return cam.centre + hit[on, None] * g.rays[on]


def test_start_fits_the_bend_and_stature_that_joints_alone_leave_open():
    from partlab.tracking.topview.start import fit_person

    body = Body().scaled(1800.0)
    state = neutral_state(150.0, -80.0, body, yaw=0.7)
    state[4] = 0.5                      # bent over a shelf
    state[2] = body.pelvis_height - 15  # the hips sink a little
    state[[7, 10, 12, 15]] = 0.6, 0.9, 0.2, 0.4
    js = dict(zip(JOINTS, joints(state[None], body)[0]))
    pts = _cast(state, body, topview_camera(160, 120, 2900.0))
    fitted, got = fit_person(js, pts)
    assert got[4] == pytest.approx(0.5, abs=0.08)
    assert fitted.stature == pytest.approx(1800.0, rel=0.03)
    assert np.hypot(*(got[:2] - state[:2])) < 40.0
    assert np.abs(joints(got[None], fitted)[0] - np.array(list(js.values()))).max() < 20.0


def test_eq5_prediction_extrapolates_the_last_two_estimates():
    p = TopViewParams(resampling=ResamplingParams(n_particles=8))
    f = PersonFilter(p, np.random.default_rng(0), Body(), neutral_state(0.0, 0.0, Body()))
    f.previous = neutral_state(0.0, 0.0, Body(), yaw=np.pi - 0.05)
    f.estimate = neutral_state(30.0, 0.0, Body(), yaw=-np.pi + 0.05)  # across the wrap: +0.1 rad
    f.previous[10], f.estimate[10] = 0.3, 0.5
    pred = f.predicted(1.0)
    assert pred[0] == pytest.approx(60.0) and pred[10] == pytest.approx(0.7)
    assert pred[3] == pytest.approx(-np.pi + 0.15)
    assert f.predicted(0.0) == pytest.approx(f.estimate)
    f.estimate[10] = 2.45  # clipped at the elbow's limit
    assert f.predicted(1.0)[10] == pytest.approx(2.5)


def test_eq5_colour_term_gives_a_point_to_the_person_whose_nearest_part_shows_its_colour(s3):
    tr = TopViewTracker(TopViewParams(resampling=ResamplingParams(n_particles=20)), np.random.default_rng(0),
                        init=s3.init, cameras={"cam0": s3.camera})
    for f in range(2):
        fs = FrameSet.single(f, s3.color[f], s3.depth[f], camera=s3.camera)
        tr.step(fs)
    assert all(t.colour is not None and np.allclose(t.colour.sum(1)[t.colour.sum(1) > 0], 1.0) for t in tr.targets)
    roi = tr.roi(fs.first)
    a, b = tr.targets
    # the second person moved half-way to the first: many points are then within 70 mm of both
    b.filter.estimate[:2] += 0.5 * (a.filter.estimate[:2] - b.filter.estimate[:2])
    geometric = TopViewTracker(TopViewParams(exclusion=ExclusionParams(colour_mm=0.0)), np.random.default_rng(0))
    geometric.targets = tr.targets
    by_distance = geometric.assign(roi, fitted=True)
    # every point's colour is bin 5; only the first person ever showed it (on every primitive)
    roi.bins = np.full(len(roi.points), 5)
    a.colour = np.zeros_like(a.colour)
    a.colour[:, 5] = 1.0
    b.colour = np.zeros_like(b.colour)
    b.colour[:, 7] = 1.0
    owner = tr.assign(roi, fitted=True)
    d = np.stack([nearest(roi.points, primitives(t.filter.estimate[None], t.filter.body)[0])[0] for t in tr.targets])
    margin = d[0] - d[1]  # how much nearer the second person is
    # the colour term: ln(1.02 / 0.02) * 20 mm = 79 mm in the first person's favour
    assert np.all(owner[(margin < 70) & (by_distance >= 0)] == 0)
    assert np.all(owner[(margin > 90) & (d[1] <= 250)] == 1)
    near_b = (margin > 0) & (margin < 70) & (d[1] <= 250)  # without colour: the second person's
    assert (by_distance[near_b] == 1).all() and near_b.sum() > 20
