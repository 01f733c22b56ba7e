"""The multi-camera tracker's geometry, priors, merging, 3D state machine and a short run."""

import cv2
import numpy as np
import pytest

from partlab.labelling.synth.multiview import look_at, make_multiview_scene
from partlab.tracking.frame import Frame, FrameSet
from partlab.tracking.limbs.state_machine import LimbState, LimbStateMachine, Observation
from partlab.tracking.limbs3d.filter import TargetFilter
from partlab.tracking.limbs3d.geometry import midpoints, pair_candidates
from partlab.tracking.limbs3d.params import Limbs3DDynamics, Limbs3DParams, Limbs3DPriors, Limbs3DStates
from partlab.tracking.limbs3d.priors import blob_keys, candidate_prior, observe_view, prune_and_merge
from partlab.tracking.limbs3d.tracker import Limbs3DTracker, triangulate


def _two_cameras():
    a = look_at("cam0", [3000.0, 0.0, 2200.0], [0.0, 0.0, 1000.0], 550.0, (640, 480))
    b = look_at("cam1", [0.0, -3000.0, 2000.0], [0.0, 0.0, 1000.0], 600.0, (640, 480))
    return a, b


def test_midpoint_of_skew_lines_known_by_hand():
    # the x axis and the line x = 0, z = 10 along y: the common perpendicular is the z axis 0..10
    z, d = midpoints(np.array([[5.0, 0, 0]]), np.array([[1.0, 0, 0]]), np.array([[0, 3.0, 10]]),
                     np.array([[0, 1.0, 0]]))
    np.testing.assert_allclose(z[0], [0, 0, 5], atol=1e-9)
    assert d[0] == pytest.approx(5.0)


def test_midpoint_agrees_with_cv2_triangulate_points():
    rng = np.random.default_rng(0)
    a, b = _two_cameras()
    X = rng.uniform([-600, -600, 600], [600, 600, 1800], (50, 3))
    ua = a.project(X) + rng.normal(0, 0.7, (50, 2))
    ub = b.project(X) + rng.normal(0, 0.7, (50, 2))
    pa, va = a.centre[None].repeat(50, 0), a.rays(ua)
    pb, vb = b.centre[None].repeat(50, 0), b.rays(ub)
    z, d = midpoints(pa, va, pb, vb)
    h = cv2.triangulatePoints(a.P, b.P, ua.T, ub.T)
    cv = (h[:3] / h[3]).T
    assert np.max(np.linalg.norm(z - cv, axis=1)) < 10.0  # within 1 cm (DESIGN: they agree within 1 cm)
    assert np.median(np.linalg.norm(z - X, axis=1)) < 8.0
    assert 0 < np.median(d) < 5.0
    # noise-free: both exact
    z0, d0 = midpoints(pa, a.rays(a.project(X)), pb, b.rays(b.project(X)))
    np.testing.assert_allclose(z0, X, atol=1e-6)
    assert np.max(d0) < 1e-6
    np.testing.assert_allclose(triangulate([a, b], [a.project(X[:1]), b.project(X[:1])]), X[0], atol=1e-4)


def test_true_pairs_get_a_high_prior_and_false_pairs_a_low_one():
    a, b = _two_cameras()
    X = np.array([[0.0, 0.0, 1600.0], [350.0, -250.0, 1000.0]])  # a head and a hand
    params = Limbs3DParams()
    views, centres = [], []
    for cam in (a, b):
        uv = cam.project(X)
        sil = np.zeros((480, 640), np.uint8)
        for (u, v), r in zip(uv, (25, 10)):
            cv2.circle(sil, (int(u), int(v)), r, 1, -1)
        foot = cam.project(np.array([[0.0, 0.0, 0.0]]))[0]
        cv2.line(sil, tuple(map(int, uv[0])), tuple(map(int, foot)), 1, 30)  # the body below the head
        centres.append(uv)
        views.append(observe_view(sil, uv))
    cands = pair_candidates([a, b], centres)
    assert len(cands) == 4  # eq. 18: 2 x 2
    prior, raw = candidate_prior(cands, [a, b], views, params)
    true = cands.blobs[:, 0] == cands.blobs[:, 1]
    assert np.all(prior.value[true] > 0.9)
    assert np.all(prior.value[~true] < 0.1)
    np.testing.assert_allclose(cands.points[true][np.argsort(cands.blobs[true, 0])], X, atol=1e-6)
    assert np.all(raw["d"][~true] > 100)  # a false pair's lines of sight pass far apart here


def test_prune_and_merge_drops_weak_and_merges_close_candidates():
    params = Limbs3DParams(priors=Limbs3DPriors(merge_distance=45.0, merge_boost=0.5, prior_threshold=0.1))
    pts = np.array([[0.0, 0, 1000], [20.0, 0, 1000], [300.0, 0, 1000], [600.0, 0, 1000], [0, 0, -50]])
    pr = np.array([0.6, 0.3, 0.5, 0.05, 0.9])
    out, w = prune_and_merge(pts, pr, params)
    assert len(out) == 2  # the weak one and the one under the floor are gone, two merged
    np.testing.assert_allclose(w, [0.75, 0.5])  # 0.6 + 0.5 * 0.3
    np.testing.assert_allclose(out[0], [20 / 3, 0, 1000])  # prior-weighted mean (merge_average)
    out, w = prune_and_merge(pts, pr, Limbs3DParams(priors=Limbs3DPriors(merge_average=False)))
    np.testing.assert_allclose(out[0], [0, 0, 1000])  # the paper: the stronger point is kept


def test_a_hand_cut_off_from_its_body_is_measured_from_its_persons_top():
    sil = np.zeros((120, 160), np.uint8)
    sil[10:110, 40:70] = 1  # the person: top at row 10
    sil[60:70, 90:100] = 1  # a hand reaching over a table, a component of its own (100 px of 3100)
    centres = np.array([[95.0, 65.0], [55.0, 30.0]])
    assert observe_view(sil, centres).below.tolist() == [5.0, 20.0]  # the paper's: its own top
    assert observe_view(sil, centres, fragment=0.25).below.tolist() == [55.0, 20.0]
    sil[60:70, 120:130] = 1  # no larger component is nearer: the nearest one horizontally is taken
    assert observe_view(sil, np.array([[125.0, 65.0]]), fragment=0.25).below.tolist() == [55.0]
    both = observe_view(sil, centres, fragment=0.25, either=True)  # both references kept
    assert both.below.tolist() == [5.0, 20.0] and both.below_person.tolist() == [55.0, 20.0]


def test_a_fragment_is_measured_from_the_top_of_its_persons_stacked_components():
    """A silhouette broken into a head (top row 10) and a belly (top row 50) component, with a hand
    at the hip in a fragment of its own: the nearest larger component is the belly's (8 px away,
    the head's 13), so the hand is 43 rows below its person's top instead of 83; with ``stack`` the
    highest of the components whose columns overlap the belly's, the head's, is taken. Another
    person beside them (higher, top row 2, columns that overlap neither) is not taken."""
    sil = np.zeros((120, 200), np.uint8)
    sil[10:30, 40:70] = 1  # head: 600 px
    sil[50:110, 35:75] = 1  # belly: 2400 px
    sil[90:97, 80:87] = 1  # the hand, a fragment
    sil[2:60, 120:150] = 1  # another person (its head and chest)
    hand = np.array([[83.0, 93.0]])
    assert observe_view(sil, hand, fragment=0.25).below.tolist() == [43.0]
    assert observe_view(sil, hand, fragment=0.25, stack=True).below.tolist() == [83.0]
    both = observe_view(sil, hand, fragment=0.25, either=True, stack=True)
    assert both.below.tolist() == [3.0] and both.below_person.tolist() == [83.0]  # its own top: row 90


def test_with_fragment_either_p_o_takes_the_better_of_the_two_references():
    from partlab.tracking.limbs3d.priors import ViewObservation

    a, b = _two_cameras()
    X = np.array([[100.0, 50.0, 1000.0]])
    cands = pair_candidates([a, b], [a.project(X), b.project(X)])
    za, zb = a.to_camera(X)[0, 2], b.to_camera(X)[0, 2]
    rows_b = 600.0 * b.K[1, 1] / zb  # 600 mm below its person's top in cam1
    dist = np.zeros((480, 640), np.float32)

    def p_o(own_mm, person_mm):
        va = ViewObservation(a.project(X), np.array([own_mm * a.K[1, 1] / za]), dist, True, 1.0,
                             None if person_mm is None else np.array([person_mm * a.K[1, 1] / za]))
        vb = ViewObservation(b.project(X), np.array([rows_b]), dist, True, 1.0)
        return float(candidate_prior(cands, [a, b], [va, vb], Limbs3DParams())[0].p_o[0])

    assert p_o(0.0, None) < 0.001  # a fragment measured from its own top: 600 mm off, sigma_v 150
    assert p_o(0.0, 600.0) == pytest.approx(1.0, abs=1e-6)  # from its person's top it agrees
    assert p_o(600.0, 0.0) == pytest.approx(1.0, abs=1e-6)  # and the other way round
    assert p_o(450.0, 0.0) == pytest.approx(np.exp(-0.5), rel=1e-6)  # the better one: 150 mm off


def test_ghost_pairs_of_two_hands_are_dropped_and_a_shared_blob_is_kept():
    params = Limbs3DParams()  # ghost_factor 0: a ghost is dropped
    # two views, two hands: true pairs (0-0, 1-1) and the two ghosts crossing them (0-1, 1-0)
    pts = np.array([[0.0, 0, 1000], [400.0, 0, 1000], [200.0, 300, 900], [200.0, -300, 1100]])
    views = np.array([[0, 1]] * 4)
    blobs = np.array([[0, 0], [1, 1], [0, 1], [1, 0]])
    out, w = prune_and_merge(pts, np.array([0.9, 0.8, 0.7, 0.6]), params, blob_keys(views, blobs))
    np.testing.assert_allclose(out, pts[:2])  # each ghost's two blobs belong to the true hands
    np.testing.assert_allclose(w, [0.9, 0.8])
    out, _ = prune_and_merge(pts, np.array([0.9, 0.8, 0.7, 0.6]), Limbs3DParams(priors=Limbs3DPriors(ghost_factor=1.0)),
                             blob_keys(views, blobs))
    assert len(out) == 4  # off: the paper's candidates
    # the hands are one blob in view 0: each still owns its blob in view 1, both are kept
    out, _ = prune_and_merge(pts[:2], np.array([0.9, 0.8]), params, blob_keys(views[:2], np.array([[0, 0], [0, 1]])))
    assert len(out) == 2


def test_with_equal_priors_the_pairs_nearest_the_predictions_own_their_blobs():
    # two views, two hands, every pair with prior 1 (as with two cameras in a clap): the ghosts come
    # first, so by prior alone they take all four blobs and the true pairs are dropped
    pts = np.array([[200.0, 300, 900], [200.0, -300, 1100], [0.0, 0, 1000], [400.0, 0, 1000]])
    keys = blob_keys(np.array([[0, 1]] * 4), np.array([[0, 1], [1, 0], [0, 0], [1, 1]]))
    ones = np.ones(4)
    alone = Limbs3DParams().updated({"priors.ghost_anchor": 0.0})
    np.testing.assert_allclose(prune_and_merge(pts, ones, alone, keys, pts[2:] + 30.0)[0], pts[:2])
    # the tracked hands' predictions (30 mm off their true pairs) decide: the ghosts are dropped
    np.testing.assert_allclose(prune_and_merge(pts, ones, Limbs3DParams(), keys, pts[2:] + 30.0)[0], pts[2:])
    # a tie-breaker only: a true pair stronger by more than the anchor's weight keeps its blobs even
    # when the filter's prediction sits on the ghost
    out, _ = prune_and_merge(pts, np.array([0.8, 0.8, 1.0, 1.0]), Limbs3DParams(), keys, pts[:2])
    np.testing.assert_allclose(out, pts[2:])


def test_the_jump_mixture_lets_a_filter_reach_a_candidate_200_mm_off():
    def reach(dyn):
        out = []
        for seed in range(10):
            f = TargetFilter(np.array([0.0, 0, 1000]), dyn, np.random.default_rng(seed))
            for _ in range(5):  # a still hand
                f.predict()
                f.update(np.array([[0.0, 0, 1000]]), np.array([0.9]))
            f.predict()  # the clap starts: its only candidate is 200 mm along x
            out.append(f.update(np.array([[200.0, 0, 1000]]), np.array([0.9]))[0])
        return float(np.mean(out))

    assert reach(Limbs3DDynamics()) > 115  # defaults: 128 mm of the 200 in one frame
    assert reach(Limbs3DDynamics(jump_mix=0.0, weight_floor=1e-3)) < 100  # before: 88


def test_state_machine_combines_and_splits_3d_targets_by_direction():
    m = LimbStateMachine(Limbs3DParams(states=Limbs3DStates(combine_distance=80.0, split_distance=120.0)))
    for t in (0, 1):
        m.add(t, LimbState.UNLABELLED)
        m._status[t].state = LimbState.NORMAL
    # two hands approach along x (0 on the left), join, and part again
    for f, gap in enumerate((400, 300, 200, 100, 60)):
        m.update(f, {0: Observation((-gap / 2, 0.0, 1000.0), 0.9), 1: Observation((gap / 2, 0.0, 1000.0), 0.9)})
    assert m.state(0) == m.state(1) == LimbState.COMBINED
    # the modes part: the one at +x is listed first, the left tracker must still get the left mode
    out = m.update(5, {0: Observation((0.0, 0.0, 1000.0), 0.9, modes=((90.0, 0.0, 1000.0), (-90.0, 0.0, 1000.0)))})
    split = {t.tracker: t.position for t in out if t.reason == "split"}
    assert split[0][0] == -90.0 and split[1][0] == 90.0


def test_tracker_follows_head_and_hands_of_a_standing_person():
    scene = make_multiview_scene("standing", 4, seed=4, n_frames=25)
    cams = {c.name: c for c in scene.cameras}
    tr = Limbs3DTracker(Limbs3DParams(), np.random.default_rng(0), cams, init=scene.init,
                        backgrounds=scene.backgrounds)
    recs = []
    for i in range(25):
        views = {c: Frame(i, scene.frames[c][i], None, c, cams[c]) for c in cams}
        recs += tr.step(FrameSet(i, views), {c: None for c in cams})
    df = tr.table(recs)
    assert set(df["camera"]) == set(cams)  # a box in every view
    est = df.drop_duplicates(["frame", "track_id", "part"]).merge(scene.truth3d, on=["frame", "track_id", "part"])
    err = np.linalg.norm(est[["X_x", "Y_x", "Z_x"]].to_numpy() - est[["X_y", "Y_y", "Z_y"]].to_numpy(), axis=1)
    est["err"] = err
    med = est.groupby("part")["err"].median()
    assert med["head"] < 80  # the face's centroid lies ~4-5 cm before the head's centre
    assert med["left_hand"] < 40 and med["right_hand"] < 40
    # the back-projected box of the head in each view overlaps the true head box
    t = scene.truth[(scene.truth["frame"] == 24) & (scene.truth["part"] == "head")].set_index("camera")
    d = df[(df["frame"] == 24) & (df["part"] == "head")].set_index("camera")
    for cam in cams:
        cx, cy = d.loc[cam, "x"] + d.loc[cam, "w"] / 2, d.loc[cam, "y"] + d.loc[cam, "h"] / 2
        r = t.loc[cam]
        assert r.x <= cx <= r.x + r.w and r.y <= cy <= r.y + r.h


def test_single_view_candidates_lie_on_the_blob_line_nearest_the_prediction_and_respect_others():
    a, b = _two_cameras()
    tr = Limbs3DTracker(Limbs3DParams(), np.random.default_rng(0), {"cam0": a, "cam1": b})
    pred = np.array([100.0, 50.0, 1200.0])
    seen = pred + [0.0, 40.0, -30.0]  # where the hand really is: 50 mm off the prediction
    blob = a.project(seen[None])[0]
    far = a.project((pred + [0.0, 400.0, 0.0])[None])[0]  # 400 mm off: beyond the 100 mm gate
    [point] = tr._single_view(pred, [np.array([blob, far]), np.zeros((0, 2))], np.zeros((0, 3)))
    v = a.rays(blob[None])[0]
    np.testing.assert_allclose(np.cross(point - a.centre, v), 0, atol=1e-6)  # on the blob's line of sight
    assert abs((point - pred) @ v) < 1e-6  # the line's point nearest the prediction
    assert np.linalg.norm(point - seen) < 60  # the depth stays the prediction's: ~ the offset across the line
    # a blob nearer another target's projection is that target's; nothing beyond the gate is taken
    assert len(tr._single_view(pred, [np.array([blob]), np.zeros((0, 2))], seen[None] + [0.0, 5.0, 0.0])) == 0
    assert len(tr._single_view(pred, [np.array([far]), np.zeros((0, 2))], np.zeros((0, 3)))) == 0


def test_a_hand_uses_only_candidates_within_reach_of_its_own_head():
    a, b = _two_cameras()
    tr = Limbs3DTracker(Limbs3DParams(), np.random.default_rng(0), {"cam0": a, "cam1": b})
    from partlab.tracking.limbs3d.tracker import _Target

    head = np.array([0.0, 0.0, 1600.0])
    points = np.array([[300.0, 0.0, 900.0], [1200.0, 0.0, 1000.0]])  # 760 mm and 1340 mm from the head
    hand, face = _Target(1, "left_hand"), _Target(1, "head")
    assert tr._usable(hand, points, None, None, head).tolist() == [True, False]
    assert tr._usable(face, points, None, None, head).tolist() == [True, True]  # a head has no reach limit
    assert tr._usable(hand, points, None, None, None).tolist() == [True, True]  # no head estimate: no limit


def test_a_single_view_candidate_takes_the_depth_where_the_other_view_sees_a_body_in_front_of_it():
    a, b = _two_cameras()
    params = Limbs3DParams().updated({"dynamics.single_view_support": 8.0})
    tr = Limbs3DTracker(params, np.random.default_rng(0), {"cam0": a, "cam1": b})
    hand = np.array([100.0, 50.0, 1200.0])  # seen as a blob by cam0 only: cam1 sees a body in front of it
    blob = a.project(hand[None])[0]
    v = a.rays(blob[None])[0]
    pred = hand + 300.0 * v + np.array([0.0, 0.0, 20.0])  # the prediction 300 mm too deep along cam0's line
    sil = np.zeros((480, 640), np.uint8)
    u, w = b.project(hand[None])[0]
    cv2.circle(sil, (int(u), int(w)), 10, 1, -1)  # the body hiding the hand from cam1: a 10 px disc
    views = [observe_view(np.zeros((480, 640), np.uint8), np.array([blob])), observe_view(sil, np.zeros((0, 2)))]
    [free] = tr._single_view(pred, [np.array([blob]), np.zeros((0, 2))], np.zeros((0, 3)))  # no views given
    assert np.linalg.norm(free - hand) > 250  # on the line, at the prediction's depth
    [point] = tr._single_view(pred, [np.array([blob]), np.zeros((0, 2))], np.zeros((0, 3)), views)
    np.testing.assert_allclose(np.cross(point - a.centre, v), 0, atol=1e-6)  # still on the blob's line of sight
    uv = b.project(point[None])[0]
    assert np.hypot(uv[0] - u, uv[1] - w) <= 10 + 8 + 1  # hidden by cam1's silhouette (within the support)
    # ~ the disc's edge nearest the prediction (18 px ~ 100 mm at 3.3 m in cam1), not 300 mm off
    assert np.linalg.norm(point - hand) < 120
    # a view without any silhouette (a covered lens) does not constrain the depth
    dark = [views[0], observe_view(np.zeros((480, 640), np.uint8), np.zeros((0, 2)))]
    [same] = tr._single_view(pred, [np.array([blob]), np.zeros((0, 2))], np.zeros((0, 3)), dark)
    np.testing.assert_allclose(same, free, atol=1e-6)


def test_one_camera_of_a_2_camera_take_hidden_for_30_frames_loses_fewer_targets():
    """The issue's "one camera of a take hidden for 30 frames does not lose a target", with two
    cameras: while camera 0 is black (frames 60-89) only camera 1 sees skin, nothing can be
    triangulated, and every target lives on single-view candidates. Before 2026-12-03 (a 100 mm
    single-view gate in that case too: a hand that moves 100-150 mm a frame leaves it) a hand of
    this seated take was lost with each of the tracker seeds 0-5 and ended 430-500 mm off with four
    of them. Now (``single_view_gate_alone``) seeds 0, 1 and 3 lose nothing and end within 25 mm;
    2, 4 and 5 still lose the right hand (its depth on camera 1's line of sight drifts ~170 mm, and
    when camera 0 is back a false pair nearer that drifted estimate takes it): not met in full."""
    scene = make_multiview_scene("seated", 2, seed=0, n_frames=101)
    cams = {c.name: c for c in scene.cameras}
    kept = []
    for rng in range(6):
        tr = Limbs3DTracker(Limbs3DParams(), np.random.default_rng(rng), cams, init=scene.init,
                            backgrounds=scene.backgrounds)
        recs = []
        for i in range(101):
            views = {}
            for c in cams:
                image = scene.frames[c][i]
                views[c] = Frame(i, np.zeros_like(image) if c == "cam0" and 60 <= i < 90 else image, None, c, cams[c])
            recs += tr.step(FrameSet(i, views), {c: None for c in cams})
        df = tr.table(recs).drop_duplicates(["frame", "track_id", "part"])
        end = df[df["frame"] == 100].merge(scene.truth3d, on=["frame", "track_id", "part"])
        err = np.linalg.norm(end[["X_x", "Y_x", "Z_x"]].to_numpy() - end[["X_y", "Y_y", "Z_y"]].to_numpy(), axis=1)
        if not ((df["frame"] >= 60) & (df["state"] == "lost")).any() and len(err) == 3 and err.max() < 60:
            kept.append(rng)  # nothing lost, and all three back on their parts once the camera is back
    assert len(kept) >= 3  # before: none of the six


def test_frames_in_which_one_camera_of_two_is_dark_do_not_lose_a_target():
    """Standing, 2 cameras (rendered with 2, seed 5, 100 frames), camera 0 black for frames 60-89:
    the clap, seen by camera 1 alone, where nothing can be triangulated. With c50abb3's parameters
    (no ``dynamics.hold_unseen``, no ``gate_growth_dark``, no ``observations.blind_fill``) both hands
    are lost at frame 69; with the defaults none is, nor with either dynamics change alone once the
    black view is recognised as blind (the skin model finds a blob in it here, so without
    ``blind_fill`` camera 0 still counts as seeing)."""
    scene = make_multiview_scene("standing", 2, seed=5, n_frames=100)
    cams = {c.name: c for c in scene.cameras}

    def lost(params: Limbs3DParams) -> set:
        tr = Limbs3DTracker(params, np.random.default_rng(0), cams, init=scene.init, backgrounds=scene.backgrounds)
        recs = []
        for i in range(100):
            views = {c: Frame(i, np.zeros_like(scene.frames[c][i]) if c == "cam0" and 60 <= i < 90
                              else scene.frames[c][i], None, c, cams[c]) for c in cams}
            recs += tr.step(FrameSet(i, views), {c: None for c in cams})
        df = tr.table(recs)
        return set(df[(df["frame"] >= 60) & (df["state"] == "lost")]["part"])

    before = {"dynamics.hold_unseen": False, "dynamics.gate_growth_dark": 0.0, "observations.blind_fill": 1.0}
    assert lost(Limbs3DParams().updated(before)) == {"left_hand", "right_hand"}
    assert lost(Limbs3DParams()) == set()
    blind = {**before, "observations.blind_fill": 0.9}
    assert lost(Limbs3DParams().updated({**blind, "dynamics.hold_unseen": True})) == set()
    assert lost(Limbs3DParams().updated({**blind, "dynamics.gate_growth_dark": 0.5})) == set()


def test_two_peoples_hands_that_split_go_back_to_their_own_sides():
    """The direction cue (sec. 7.1) from drifted estimates gave each hand the other's mode after
    handshake seed 3's exchange (3 cameras, frame 90: a swap); with ``states.split_heads`` a pair of
    different people's hands whose modes point against their heads by more than 60 degrees is
    swapped back, and one person's two hands (a clap) keep the direction cue's modes."""
    a, b = _two_cameras()
    tr = Limbs3DTracker(Limbs3DParams(), np.random.default_rng(0), {"cam0": a, "cam1": b})
    for tid, part in [(1, "left_hand"), (2, "right_hand"), (1, "right_hand")]:
        tr._add(tid, part, 0, np.zeros(3), LimbState.NORMAL)
    heads = {1: np.array([0.0, 0.0, 1600.0]), 2: np.array([1000.0, 0.0, 1600.0])}
    near_1, near_2 = (450.0, 30.0, 1100.0), (570.0, -20.0, 1120.0)  # 120 mm apart, each nearer its head
    wrong = {0: near_2, 1: near_1}  # person 1's hand given the mode on person 2's side
    assert tr._split_sides(wrong, heads) == {0: near_1, 1: near_2}
    assert tr._split_sides({0: near_1, 1: near_2}, heads) == {0: near_1, 1: near_2}  # already right
    across = {0: (520.0, 60.0, 1100.0), 1: (500.0, -60.0, 1100.0)}  # mostly across the heads' line: kept
    assert tr._split_sides(across, heads) == across
    assert tr._split_sides({0: near_2, 2: near_1}, heads) == {0: near_2, 2: near_1}  # one person: kept
    off = Limbs3DTracker(Limbs3DParams().updated({"states.split_heads": 1.0}), np.random.default_rng(0),
                         {"cam0": a, "cam1": b})
    off.targets = tr.targets
    assert off._split_sides(wrong, heads) == wrong


def test_a_pair_of_two_peoples_hands_finds_a_hand_that_left_it_unseen():
    """Handshake seed 8, 4 cameras: the right hand left the handshake while hidden and came back
    390 mm from the pair (prior 0.93), out of ``states.mode_search`` (300 mm): the pair kept one mode
    and later split onto a false one (a swap). A candidate beyond it, within ``mode_search_heads``
    split distances and nearer one of the two heads than the pair, is its second mode; not one of
    prior below ``mode_heads_prior`` (a false one of 0.67 split seed 6's exchange), nor one that is
    no nearer either head."""
    a, b = _two_cameras()
    tr = Limbs3DTracker(Limbs3DParams(), np.random.default_rng(0), {"cam0": a, "cam1": b})
    t = tr.targets[tr._add(1, "right_hand", 0, np.zeros(3), LimbState.NORMAL)]
    est = np.array([0.0, 0.0, 1000.0])
    heads = [np.array([400.0, 0.0, 1400.0]), np.array([-400.0, 0.0, 1400.0])]
    back = np.array([350.0, 0.0, 900.0])  # 350 mm from the pair, 502 from head 1 (the pair: 566)
    aside = np.array([0.0, 350.0, 1000.0])  # 350 mm from the pair, 665 from both heads

    def modes(point, w, params=tr.params, pair_heads=heads):
        tr.params = params
        pts, ws = np.array([est, point]), np.array([1.0, w])
        return tr._combined_modes(t, est, np.arange(2), pts, ws, [], np.zeros((0, 3)), pair_heads)

    assert modes(back, 0.93) == (tuple(est), tuple(back))
    assert modes(back, 0.67) == (tuple(est),)
    assert modes(aside, 0.93) == (tuple(est),)
    assert modes(back, 0.93, pair_heads=[]) == (tuple(est),)  # one person's hands: the usual search
    assert modes(back, 0.93, Limbs3DParams().updated({"states.mode_search_heads": 2.5})) == (tuple(est),)


def test_frames_that_cannot_see_a_target_do_not_lose_it():
    m = LimbStateMachine(Limbs3DParams())
    m.add(0, LimbState.NORMAL)
    m._status[0].state = LimbState.NORMAL
    for f in range(3):  # three frames without confidence
        m.update(f, {0: Observation(position=(0.0, 0.0, 0.0), likelihood=0.0)})
    for f in range(3, 40):  # nothing can be triangulated: no evidence either way
        m.update(f, {0: Observation(position=(0.0, 0.0, 0.0), likelihood=0.0, unseen=True)})
    assert m.state(0) == LimbState.NORMAL
    for f in range(40, 44):  # seen again without confidence: the count starts again (4 < lost_frames 5)
        m.update(f, {0: Observation(position=(0.0, 0.0, 0.0), likelihood=0.0)})
    assert m.state(0) == LimbState.NORMAL
    m.update(44, {0: Observation(position=(0.0, 0.0, 0.0), likelihood=0.0)})
    assert m.state(0) == LimbState.LOST


def test_a_view_that_differs_from_its_plate_everywhere_gives_no_blobs():
    """A dark or covered camera: its frame differs from the empty-scene plate everywhere, so its
    silhouette is the whole view and any blob in it (a skin-coloured patch; the 3-camera standing
    seed 5 skin model found one in a black frame) is not a person's (``observations.blind_fill``)."""
    a, b = _two_cameras()
    plate = np.full((480, 640, 3), 90, np.uint8)
    skin = (120, 150, 215)  # BGR
    seen = plate.copy()
    cv2.circle(seen, (320, 200), 14, skin, -1)
    dark = np.zeros_like(plate)
    cv2.circle(dark, (320, 200), 14, skin, -1)
    tr = Limbs3DTracker(Limbs3DParams(), np.random.default_rng(0), {"cam0": a, "cam1": b},
                        backgrounds={"cam0": plate, "cam1": plate})
    frames = FrameSet(0, {"cam0": Frame(0, dark, None, "cam0", a), "cam1": Frame(0, seen, None, "cam1", b)})
    centres, _ = tr.observe(frames, {"cam0": None, "cam1": None})
    assert len(centres[1]) == 1 and np.linalg.norm(centres[1][0] - (320, 200)) < 2  # the patch, in a person
    assert len(centres[0]) == 0  # the same patch in a view that is all "person": dropped
    tr = Limbs3DTracker(Limbs3DParams().updated({"observations.blind_fill": 1.0}), np.random.default_rng(0),
                        {"cam0": a, "cam1": b}, backgrounds={"cam0": plate, "cam1": plate})
    assert len(tr.observe(frames, {"cam0": None, "cam1": None})[0][0]) == 1  # off: kept


def test_a_wider_gate_lets_the_filter_reach_a_candidate_beyond_the_default_one():
    def reach(gate):
        out = []
        for seed in range(10):
            f = TargetFilter(np.array([0.0, 0, 1000]), Limbs3DDynamics(), np.random.default_rng(seed))
            f.predict()  # its only candidate is 270 mm off, beyond the 250 mm candidate_gate
            out.append(f.update(np.array([[0.0, 270, 1000]]), np.array([0.99]), gate)[1])
        return float(np.mean(out))

    assert reach(None) < 40  # 10 mm of the 270: the particles only diffuse towards it
    assert reach(375.0) > 150  # 233 mm: one missed frame with dynamics.gate_growth 0.5


def _handshake_distance(scene, params: Limbs3DParams) -> np.ndarray:
    """The two people's tracked right hands' 3D distance (mm) at every frame of the scene's handshake."""
    cams = {c.name: c for c in scene.cameras}
    tr = Limbs3DTracker(params, np.random.default_rng(0), cams, init=scene.init, backgrounds=scene.backgrounds)
    recs = []
    for i in range(len(scene.frames["cam0"])):
        recs += tr.step(FrameSet(i, {c: Frame(i, scene.frames[c][i], None, c, cams[c]) for c in cams}),
                        {c: None for c in cams})
    pos = tr.table(recs).drop_duplicates(["frame", "track_id", "part"]).set_index(["frame", "track_id", "part"])
    ev = scene.events[scene.events["kind"] == "handshake"].iloc[0]
    frames = range(int(ev.start_frame), int(ev.end_frame) + 1)
    a = pos.reindex([(f, 1, "right_hand") for f in frames])[["X", "Y", "Z"]].to_numpy(float)
    b = pos.reindex([(f, 2, "right_hand") for f in frames])[["X", "Y", "Z"]].to_numpy(float)
    return np.linalg.norm(a - b, axis=1)


def test_the_hand_seen_by_one_camera_meets_the_other_in_a_handshake():
    """Handshake, 3 cameras: one person's right hand, in front of its own body, is seen by one camera
    only while it reaches out, mostly along that camera's line of sight, so its depth stays where it
    was (before 2026-12-03 it ended ~450 mm behind and never met the other hand: the one candidate
    of the two touching hands went to the other's, nearer, prediction). With ``dynamics.line_of_sight``
    it takes the candidate another view makes with the blob it follows, the two combine, and the
    tracked hands are within the recognition's contact distance (135 mm) during the grasp."""
    scene = make_multiview_scene("handshake", 3, seed=3, n_frames=50)
    before = _handshake_distance(scene, Limbs3DParams().updated({"dynamics.line_of_sight": False}))
    after = _handshake_distance(scene, Limbs3DParams())
    assert np.median(before) > 300  # main before the change: apart all along
    assert np.median(after) < 60 and (after < 135).mean() > 0.8


def test_a_hand_that_finds_nothing_after_a_split_goes_back_where_it_came_from():
    """Handshake, 3 cameras (the first three of the benchmark's 4-camera render of seed 8): the
    combined right hands split at frame 63 on a second mode where neither hand is; person 1's right
    hand, given it, had nothing there and drifted with its particles 300-390 mm off in frames 64-67
    (before 2026-12-03) until it was lost. Having found nothing for two frames, it is now put where
    it came from relative to its head (``home``), 13-25 mm from its truth."""
    scene = make_multiview_scene("handshake", 4, seed=8, n_frames=150)
    cams = {c.name: c for c in scene.cameras[:3]}
    tr = Limbs3DTracker(Limbs3DParams(), np.random.default_rng(8), cams, init=scene.init,
                        backgrounds=scene.backgrounds)
    recs = []
    for i in range(69):
        recs += tr.step(FrameSet(i, {c: Frame(i, scene.frames[c][i], None, c, cams[c]) for c in cams}),
                        {c: None for c in cams})
    e = tr.table(recs).drop_duplicates(["frame", "track_id", "part"]).merge(
        scene.truth3d, on=["frame", "track_id", "part"], suffixes=("", "_t"))
    e = e[(e["track_id"] == 1) & (e["part"] == "right_hand") & e["frame"].between(64, 68)]
    err = np.linalg.norm(e[["X", "Y", "Z"]].to_numpy(float) - e[["X_t", "Y_t", "Z_t"]].to_numpy(float), axis=1)
    assert len(err) == 5 and err.max() < 60  # main before: 301, 360, 390, 388, 260 mm


def _lost_hand_error(scene, params: Limbs3DParams, offset=(500.0, 0.0, 0.0)) -> list[float]:
    """The right hand's 3D error at frames 6-8 of ``scene`` when it is put in the lost state after
    frame 5, ``offset`` mm from where it was (a hand lost after drifting off)."""
    cams = {c.name: c for c in scene.cameras}
    tr = Limbs3DTracker(params, np.random.default_rng(0), cams, init=scene.init, backgrounds=scene.backgrounds)
    truth = scene.truth3d.set_index(["frame", "track_id", "part"])[["X", "Y", "Z"]]
    key = next(k for k, t in tr.targets.items() if t.part == "right_hand")
    out = []
    for i in range(9):
        tr.step(FrameSet(i, {c: Frame(i, scene.frames[c][i], None, c, cams[c]) for c in cams}), {c: None for c in cams})
        t = tr.targets[key]
        if i == 5:
            tr.machine._status[key].state = LimbState.LOST
            t.position = t.position + np.asarray(offset)
        elif i > 5:
            out.append(float(np.linalg.norm(t.position - truth.loc[(i, t.track_id, t.part)].to_numpy(float))))
    return out


def test_a_lost_hand_is_held_where_it_was_relative_to_its_head():
    """A lost hand is held, and looked for, at its home (where it was relative to its head when last
    tracked alone from pairs of views), not where it was lost (``states.lost_home``; before
    2026-12-06 only a hand that had left a combined pair was). Standing, 2 cameras: the right hand,
    put in the lost state 500 mm from where it was, stays 500 mm off with the rule off; with it, it is
    held at its home and found again there."""
    scene = make_multiview_scene("standing", 2, seed=0, n_frames=9)
    before = _lost_hand_error(scene, Limbs3DParams())  # the default: off
    after = _lost_hand_error(scene, Limbs3DParams().updated({"states.lost_home": True}))
    assert min(before) > 450
    assert max(after) < 60


def _head_error(scene, params: Limbs3DParams, n_cams: int, track_id: int, frames: range) -> np.ndarray:
    """Person ``track_id``'s head 3D error (mm) at ``frames`` with the scene's first ``n_cams`` cameras."""
    return _part_error(scene, params, n_cams, track_id, "head", frames, seed=8)


def _errors(scene, params: Limbs3DParams, n_cams: int, stop: int, seed: int):
    """Every target's estimate merged with its truth (``err``, mm) for frames 0 .. ``stop`` - 1 with
    the scene's first ``n_cams`` cameras (the random generator seeded with ``seed``, as the benchmark
    seeds it with the scene's)."""
    cams = {c.name: c for c in scene.cameras[:n_cams]}
    tr = Limbs3DTracker(params, np.random.default_rng(seed), cams, init=scene.init, backgrounds=scene.backgrounds)
    recs = []
    for i in range(stop):
        recs += tr.step(FrameSet(i, {c: Frame(i, scene.frames[c][i], None, c, cams[c]) for c in cams}),
                        {c: None for c in cams})
    e = tr.table(recs).drop_duplicates(["frame", "track_id", "part"]).merge(
        scene.truth3d, on=["frame", "track_id", "part"], suffixes=("", "_t"))
    e["err"] = np.linalg.norm(e[["X", "Y", "Z"]].to_numpy(float) - e[["X_t", "Y_t", "Z_t"]].to_numpy(float), axis=1)
    return e


def _select(e, track_id: int, part: str, frames: range) -> np.ndarray:
    e = e[(e["track_id"] == track_id) & (e["part"] == part) & e["frame"].between(frames.start, frames.stop - 1)]
    return e["err"].to_numpy(float)


def _part_error(scene, params: Limbs3DParams, n_cams: int, track_id: int, part: str, frames: range,
                seed: int) -> np.ndarray:
    """Person ``track_id``'s ``part`` 3D error (mm) at ``frames`` (:func:`_errors`)."""
    return _select(_errors(scene, params, n_cams, frames.stop, seed), track_id, part, frames)


def test_a_head_does_not_take_a_ghost_made_from_the_other_persons_head_blob():
    """Handshake, 3 cameras (the first three of the benchmark's 4-camera render of seed 8): from
    frame ~20 person 1's face is seen by camera 1 only (camera 2 sees the back of the head, and in
    camera 0 person 2's head, nearer, hides it on one line of sight). Camera 0's blob of person 2's
    head, which person 2's 3-view candidate uses, paired with camera 1's blob of person 1's face
    makes a ghost ~200 mm below person 1's head, inside every silhouette: the head slid onto it and
    stayed (170-217 mm off in frames 25-39 with ``dynamics.head_own_blobs`` off, the default). With
    the rule the head leaves that pair to the head that claims its blob and keeps its single-view
    candidate: 77-92 mm (the depth along camera 1's line of sight still drifts)."""
    scene = make_multiview_scene("handshake", 4, seed=8, n_frames=150)
    before = _head_error(scene, Limbs3DParams(), 3, 1, range(25, 40))
    after = _head_error(scene, Limbs3DParams().updated({"dynamics.head_own_blobs": True}), 3, 1, range(25, 40))
    assert len(before) == len(after) == 15
    assert before.min() > 160
    assert after.max() < 100


def test_a_hand_lost_with_its_combined_pair_is_held_at_its_home():
    """Handshake, 2 cameras (the first two of the benchmark's 4-camera render of seed 7): person 1's
    left hand and person 2's right hand are combined in the exchange (frames 79-100) and lost
    together at frame 101, their modes never parting. Held where the pair was lost (rule off),
    the left hand stays 379-424 mm off in frames 102-130, near person 2's right hand (the
    benchmark's swap); with ``states.combined_lost_home`` it is held at its home, relative to
    its head, as a hand that left the pair by a split is: 279-323 mm off (that home is where it
    was last tracked alone, already reaching for the exchange, so still far from where it rests)."""
    scene = make_multiview_scene("handshake", 4, seed=7, n_frames=150)
    frames = range(102, 131)
    before = _part_error(scene, Limbs3DParams().updated({"states.combined_lost_home": False}), 2, 1, "left_hand",
                         frames, seed=7)
    after = _part_error(scene, Limbs3DParams().updated({"states.combined_lost_home": True}), 2, 1, "left_hand",
                        frames, seed=7)
    assert len(before) == len(after) == 29
    assert before.min() > 370
    assert after.max() < 330
    assert (before - after).min() > 60


def test_a_hand_at_the_hip_of_a_fragmented_silhouette_keeps_its_true_pair():
    """Standing, 2 cameras (the first two of the benchmark's 4-camera render of seed 5): camera 0's
    plate silhouette of the person breaks into head, chest and belly components, and the right hand
    at the hip is a fragment of its own whose nearest larger component is the belly's. Measured
    from the belly's top its Dv differs from camera 1's by 640-800 mm, its true pair gets p_o 0,
    and the hand, lost at frame 103, is held 277-419 mm off in frames 100-130. With
    ``priors.fragment_stack`` (the highest of the components stacked over the belly's: the head's)
    the true pair is kept."""
    scene = make_multiview_scene("standing", 4, seed=5, n_frames=150)
    frames = range(100, 131)
    before = _part_error(scene, Limbs3DParams().updated({"priors.fragment_stack": False}), 2, 1, "right_hand",
                         frames, seed=5)
    after = _part_error(scene, Limbs3DParams().updated({"priors.fragment_stack": True}), 2, 1, "right_hand",
                        frames, seed=5)
    assert len(before) == len(after) == 31
    assert before.min() > 250
    assert after.max() < 30  # 4-18 mm


def test_with_two_views_a_clapping_hand_leaves_the_ghost_and_is_found_again():
    """Standing, 2 cameras (the first two of the benchmark's 4-camera render of seed 3): at the
    clap's release the left hand leaves at ~140 mm a frame; at frame 90 its true pair is beyond the
    250 mm gate, and from 92 camera 0 no longer sees it. With the defaults it then sits on the ghost
    made of camera 0's blob of the right hand (which the right hand's true pair uses) and camera 1's
    blob of the left hand: 395-492 mm off in frames 91-110. ``dynamics.hand_own_blobs`` (a hand's
    candidate sharing a blob with its other hand's claim 150 mm away is a ghost) keeps it off the
    ghost (232-289 mm: its depth along camera 1's line is still the lagging one), and
    ``dynamics.refind_gate`` puts it on its true pair at frame 90 (220 -> 23 mm off), so its
    single-view depth starts from there (frames 90-121: mean 233 -> 148 mm)."""
    scene = make_multiview_scene("standing", 4, seed=3, n_frames=150)
    base = {"priors.fragment_stack": True}
    ghost = _part_error(scene, Limbs3DParams().updated(base), 2, 1, "left_hand", range(89, 122), seed=3)
    own = {**base, "dynamics.hand_own_blobs": 150.0}
    kept = _part_error(scene, Limbs3DParams().updated(own), 2, 1, "left_hand", range(89, 122), seed=3)
    found = _part_error(scene, Limbs3DParams().updated({**own, "dynamics.refind_gate": 500.0}), 2, 1, "left_hand",
                        range(89, 122), seed=3)
    assert len(ghost) == len(kept) == len(found) == 33
    assert ghost[2:22].min() > 390 and kept[2:22].max() < 300  # frames 91-110
    assert kept[1] > 200 and found[1] < 50  # frame 90
    assert kept.mean() > 220 and found.mean() < 160


def test_a_pair_of_two_peoples_hands_far_on_one_persons_side_sends_the_other_hand_home():
    """Handshake, 4 cameras (seed 7): when the hands parted, person 2's right hand took person 1's
    (person 1's tracker lagged 230-360 mm off), followed it to person 1 and was combined with it
    from frame 75 to 131, 930-1040 mm from person 2's head and ~230 mm nearer person 1's: on person
    1's hand, 584-745 mm from its own in frames 90-130 (the benchmark's hand on another hand). With
    ``states.foreign_pair_frames`` the pair splits and the hand goes back to its home (not taken
    from the frames it spent nearer person 1's head by more than ``states.foreign_home_margin``, 150
    mm): 300-315 mm off in frames 90-94 (245-257 with a margin of 0); its home is where it was
    before the handshake and its hand is not seen there, so it drifts back to 530-590 mm off, no
    longer on person 1's hand."""
    scene = make_multiview_scene("handshake", 4, seed=7, n_frames=150)
    frames = range(90, 131)
    before = _part_error(scene, Limbs3DParams().updated({"states.foreign_pair_frames": 0}), 4, 2, "right_hand",
                         frames, seed=7)
    after = _part_error(scene, Limbs3DParams().updated({"states.foreign_pair_frames": 5,
                                                        "states.foreign_home_margin": 150.0}), 4, 2, "right_hand",
                        frames, seed=7)
    assert len(before) == len(after) == 41
    assert before.min() > 580
    assert after[:5].max() < 330
    assert before.mean() - after.mean() > 80


def test_a_hand_reaching_for_an_exchange_keeps_its_home_when_the_other_head_is_off():
    """Handshake, 4 cameras (seed 16, held out from the benchmark's seeds 0-9): person 1's head
    is ~300 mm off, and person 2's right hand, reaching for the exchange with person 1's left, is a
    little nearer that head estimate than its own. With ``states.foreign_pair_frames`` and no
    margin its home is not taken from those frames, and when the pair of the exchange splits
    (frame 95) it is sent back to the stale one (frames 97-109: 272-293 mm off, lost). With
    ``states.foreign_home_margin`` 150 mm the home follows the reach: 3-118 mm. Both with distances to
    the heads in 3D; measured horizontally (``states.foreign_horizontal``, on since session hs3d5) the
    home follows the reach even with no margin (3-118 mm)."""
    scene = make_multiview_scene("handshake", 4, seed=16, n_frames=150)
    frames = range(97, 110)
    on = {"states.foreign_pair_frames": 5, "states.foreign_horizontal": False}
    stale = _part_error(scene, Limbs3DParams().updated({**on, "states.foreign_home_margin": 0.0}), 4, 2,
                        "right_hand", frames, seed=16)
    kept = _part_error(scene, Limbs3DParams().updated({**on, "states.foreign_home_margin": 150.0}), 4, 2,
                       "right_hand", frames, seed=16)
    across = _part_error(scene, Limbs3DParams().updated({**on, "states.foreign_horizontal": True,
                                                         "states.foreign_home_margin": 0.0}), 4, 2,
                         "right_hand", frames, seed=16)
    assert len(stale) == len(kept) == len(across) == 13
    assert stale.min() > 250
    assert kept.max() < 130
    assert across.max() < 130


def test_a_lost_hand_takes_the_strong_candidate_on_its_side_that_nobody_tracks():
    """Handshake, 4 cameras (seed 4): person 2's right hand took person 1's lagging hand's candidate
    when the hands parted (frame 61), was lost at 68 and held ~600 mm off, looking for itself only
    ``dynamics.lost_search`` about that point, while its true candidate (prior 0.9-1.0, 3-4 views
    from frame 113) lay within 40 mm of it. Person 2's left hand, drifting on single-view
    candidates, then took that candidate through its line of sight (frame 134) and stayed on it to
    the end (the benchmark's hand on another hand). With ``states.lost_claim_frames`` the lost hand
    takes that candidate, on its side and within no tracked target's gate, after 3 frames (115), and
    the left hand, its line of sight's candidate now the right hand's, comes back to its own."""
    scene = make_multiview_scene("handshake", 4, seed=4, n_frames=150)
    off = _errors(scene, Limbs3DParams().updated({"states.lost_claim_frames": 0}), 4, 150, seed=4)
    on = _errors(scene, Limbs3DParams().updated({"states.lost_claim_frames": 3}), 4, 150, seed=4)
    right = range(116, 135)
    assert _select(off, 2, "right_hand", right).min() > 550
    assert _select(on, 2, "right_hand", right).max() < 80
    left = range(135, 150)
    assert _select(off, 2, "left_hand", left).min() > 450  # on person 2's right hand, ~30 mm from it
    assert _select(on, 2, "left_hand", left).max() < 60


def test_a_hand_seen_by_one_view_does_not_join_two_other_hands_that_meet():
    """Handshake, 3 cameras (seed 14, held out from the benchmark's seeds 0-9): person 2's left
    hand, hidden from every pair of views and 75 mm off, was put by its line of sight (frame 88) on
    the exchange of person 1's left hand and person 2's right, 540 mm from its own hand; it was
    combined with person 1's left hand, and when the pair split person 2's right hand went to
    person 1 and the left hand to the right one (two hands on another hand). With
    ``dynamics.sight_meeting`` a candidate where two other tracked hands already are is not taken:
    the left hand stays 12-102 mm off and the right hand comes back from the exchange."""
    scene = make_multiview_scene("handshake", 4, seed=14, n_frames=150)
    off = _errors(scene, Limbs3DParams().updated({"dynamics.sight_meeting": False}), 3, 150, seed=14)
    on = _errors(scene, Limbs3DParams().updated({"dynamics.sight_meeting": True}), 3, 150, seed=14)
    left, right = range(89, 101), range(110, 150)
    assert _select(off, 2, "left_hand", left).min() > 500
    assert _select(on, 2, "left_hand", left).max() < 130
    assert _select(off, 2, "right_hand", right).min() > 400
    assert _select(on, 2, "right_hand", right).max() < 80


def test_a_pair_of_two_peoples_hands_at_one_persons_hip_is_told_apart_horizontally():
    """Handshake, 3 cameras (seed 15, held out): when the hands parted, person 1's right hand was
    recovered and combined with person 2's again (frame 60), and the pair followed person 1's hand
    down to its hip: 780 mm from person 1's head and 910 from person 2's, within
    ``states.foreign_margin`` (200 mm) in 3D, so person 2's right hand stayed on person 1's (within
    13 mm of it in frames 70-128). Measured horizontally (``states.foreign_horizontal``: ~330 against
    ~700 mm) the pair splits and person 2's hand goes home: 290+ mm from person 1's hand."""
    scene = make_multiview_scene("handshake", 4, seed=15, n_frames=150)
    frames = range(70, 129)
    for flag, low, high in ((False, 0.0, 20.0), (True, 250.0, np.inf)):
        e = _errors(scene, Limbs3DParams().updated({"states.foreign_horizontal": flag}), 3, 129, seed=15)
        a = e[(e["track_id"] == 2) & (e["part"] == "right_hand") & e["frame"].between(70, 128)]
        b = e[(e["track_id"] == 1) & (e["part"] == "right_hand") & e["frame"].between(70, 128)]
        d = np.linalg.norm(a[["X", "Y", "Z"]].to_numpy(float) - b[["X_t", "Y_t", "Z_t"]].to_numpy(float), axis=1)
        assert len(d) == len(frames)
        assert low <= d.min() and d.max() <= high


def test_the_distance_to_a_head_is_horizontal_with_foreign_horizontal():
    a, b = _two_cameras()
    hip = np.array([[150.0, 0.0, 860.0]])  # person 1's hand at the hip, 150 mm towards person 2
    own, other = np.array([0.0, 0.0, 1600.0]), np.array([720.0, 0.0, 1600.0])
    for flag, gap in ((False, 179.0), (True, 420.0)):
        tr = Limbs3DTracker(Limbs3DParams().updated({"states.foreign_horizontal": flag}), np.random.default_rng(0),
                            {"cam0": a, "cam1": b})
        assert tr._to_head(hip, other)[0] - tr._to_head(hip, own)[0] == pytest.approx(gap, abs=1.0)
        assert tr._to_head(hip[0], other) - tr._to_head(hip[0], own) == pytest.approx(gap, abs=1.0)
