"""Xu, Deng & Jia: Table 1's hand regions in millimetres, eq. 3 and the f/g weight, the filter's
second-order dynamics, and the elbow search of sec. 5."""

import numpy as np
import pytest

from partlab.tracking.camera import Camera
from partlab.tracking.depth.filter import HueFilter
from partlab.tracking.depth.params import DepthCue, Posture
from partlab.tracking.depth.posture import elbow, elbow_circle
from partlab.tracking.depth.regions import depth_foreground, face_depth, hand_regions, support_surfaces
from partlab.tracking.depth.sampling import icondensation_correction, importance_density, prior_density


def _room(h=120, w=160):
    d = np.full((h, w), 3000.0, np.float32)  # the wall
    d[30:120, 50:110] = 1500.0  # torso, at the face's depth
    d[8:30, 70:90] = 1500.0  # the face
    return d


def _blob(d, cx, cy, r, z_centre, slope=0.0):
    yy, xx = np.mgrid[: d.shape[0], : d.shape[1]]
    inside = (xx - cx) ** 2 + (yy - cy) ** 2 <= r * r
    # a rounded blob: nearest at its centre (plus a slope, as an arm reaching forward)
    d[inside] = (z_centre + 2.0 * ((xx - cx) ** 2 + (yy - cy) ** 2) ** 0.5 + slope * (xx - cx))[inside]


def test_hands_are_what_is_nearer_than_the_face_and_the_region_centres_on_the_nearest_part():
    d = _room()
    _blob(d, 40, 70, 9, 1150.0)  # a hand 350 mm in front of the face
    # a forearm and hand: a bar getting nearer to the right, ending in a hand at x = 130
    d[66:74, 100:125] = np.linspace(1400, 1250, 25)[None, :]
    _blob(d, 130, 70, 8, 1180.0)
    d[100:110, 5:15] = 3500.0  # something far: never a hand (the paper's d > ... is for disparity)
    d[0, 0] = np.nan  # unmeasured stays out
    face_box = (70, 8, 20, 22)
    fd = face_depth(d, face_box, fx=160.0)
    assert fd.mean == pytest.approx(1500.0) and fd.sd == pytest.approx(0.0)
    regions = hand_regions(d, fd, face_box, 160.0, DepthCue())
    assert len(regions) == 2
    centres = sorted((r.xc, r.yc) for r in regions)
    assert centres[0] == pytest.approx((40, 70), abs=1.5)
    # the coarse box spans the forearm too; step 4's iteration moves it onto the hand
    right = max(regions, key=lambda r: r.xc)
    assert right.coarse[0] < 110 and right.xc > 124  # the hand blob starts at x = 122
    fg = depth_foreground(d, fd, DepthCue())
    assert fg[50, 80] == 1 and fg[5, 5] == 0 and fg[0, 0] == 0


def test_components_of_improper_size_are_not_hands():
    d = _room()
    d[100:120, :] = 1200.0  # a desk top across the frame, in front of the person
    face_box = (70, 8, 20, 22)
    fd = face_depth(d, face_box, fx=160.0)
    assert hand_regions(d, fd, face_box, 160.0, DepthCue()) == []


def _desk_scene(h=120, w=160, f=160.0):
    """The room, a desk top (a horizontal plane 250 mm below the camera, from 900 mm to the person
    at 1500 mm) and a hand resting on it at its far edge, joined to it in the depth map."""
    d = _room(h, w)
    yy, xx = np.mgrid[:h, :w].astype(float)
    cy = h / 2
    with np.errstate(divide="ignore"):
        z_desk = 250.0 * f / (yy - cy)  # a ray through row v meets y = 250 mm at z = 250 f / (v - cy)
    desk = (yy > cy) & (z_desk >= 900) & (z_desk <= 1500)
    d[desk] = z_desk[desk]
    # a hand (radius 45 mm, 6 px) resting on it 1230 mm away: its centre 205 mm below the camera
    _blob(d, 40, 87, 6, 1230.0)
    return d, desk


def test_a_desk_top_is_a_support_surface_and_a_hand_on_it_stays_a_hand():
    d, desk = _desk_scene()
    K = np.array([[160.0, 0, 80], [0, 160.0, 60], [0, 0, 1]])
    face_box = (70, 8, 20, 22)
    fd = face_depth(d, face_box, fx=160.0)
    p = DepthCue()
    near = d < fd.mean - p.hand_gap * fd.width_mm
    # without the surface the hand's component is joined to the desk and rejected with it (too large)
    assert hand_regions(d, fd, face_box, 160.0, p) == []
    surf = support_surfaces(d, near, K, fd, 20 * 22, p, np.random.default_rng(0))
    assert surf is not None
    assert surf[desk & near].mean() > 0.95  # the desk top's pixels in front of the face
    yy, xx = np.mgrid[: d.shape[0], : d.shape[1]]
    upper = ((xx - 40) ** 2 + (yy - 87) ** 2 <= 36) & (yy <= 87)
    assert not surf[upper].any()  # the hand is not flat: only its rim next to the desk is within reach of it
    regions = hand_regions(d, fd, face_box, 160.0, p, surfaces=surf)
    assert len(regions) == 1 and abs(regions[0].xc - 40) < 4
    # nothing large and flat in front of the face: no surface (the room of the test above)
    d2 = _room()
    _blob(d2, 40, 70, 9, 1150.0)
    fd2 = face_depth(d2, face_box, fx=160.0)
    assert support_surfaces(d2, d2 < fd2.mean - 40, K, fd2, 20 * 22, p, np.random.default_rng(0)) is None


def test_a_long_streak_in_front_of_the_face_is_not_a_hand():
    d = _room()
    d[100:104, 20:140] = 1200.0  # 120 x 4 px: the size of a hand's component, six face widths long
    _blob(d, 40, 60, 7, 1150.0)
    face_box = (70, 8, 20, 22)
    fd = face_depth(d, face_box, fx=160.0)
    regions = hand_regions(d, fd, face_box, 160.0, DepthCue())
    assert [(round(r.xc), round(r.yc)) for r in regions] == [(40, 60)]


def test_importance_weight_is_f_over_g():
    u, sigma = np.array([50.0, 40.0]), np.array([4.0, 6.0])
    xy = np.array([[50.0, 40.0], [58.0, 40.0], [20.0, 10.0]])
    g = importance_density(xy, u, sigma)
    assert g[0] == pytest.approx(1 / (2 * np.pi * 24))
    assert g[1] == pytest.approx(g[0] * np.exp(-2.0))
    pred = np.array([[20.0, 10.0], [22.0, 10.0]])
    f = prior_density(xy, pred, noise=5.0, floor=0.05, area=1e4)
    assert np.allclose(icondensation_correction(xy, u, sigma, pred, 5.0, 0.05, 1e4), f / g)
    # a sample where the dynamics expect the hand gains, one where only the region is loses
    w = icondensation_correction(xy, u, sigma, pred, 5.0, 0.05, 1e4)
    assert w[2] > 1e3 * w[0]
    # the uniform floor keeps a region sample far from every prediction weighted, not zero
    assert w[0] >= 0.05 / 1e4 / g[0] * 0.999


def test_second_order_dynamics_carry_the_velocity():
    rng = np.random.default_rng(0)
    f = HueFilter((10.0, 20.0), (8, 8), np.ones(4) / 4, 50, rng)
    f.pos[:, 0] += 5.0
    f.vel[:, 0] = 5.0  # moved 5 px last frame
    f.propagate(decay=1.0, noise_xy=0.0, noise_alpha=0.0)
    assert np.allclose(f.pos[:, :2], [20.0, 20.0])  # x_t - x_{t-1} = x_{t-1} - x_{t-2}
    assert np.allclose(f.boxes()[0], [16.0, 16.0, 8.0, 8.0])  # centred window of the reference size


def test_elbow_found_on_the_depth_of_the_arm_and_fallback_when_hidden():
    cam = Camera("c", [[300, 0, 160], [0, 300, 120], [0, 0, 1]], (320, 240))
    shoulder, hand = np.array([0.0, 0.0, 1500.0]), np.array([100.0, 300.0, 1300.0])
    cands = elbow_circle(shoulder, hand, 300.0, 260.0, 36)
    assert np.allclose(np.linalg.norm(cands - shoulder, axis=1), 300.0)
    assert np.allclose(np.linalg.norm(cands - hand, axis=1), 260.0)
    true = cands[9]
    # a depth map of the two arm segments' surfaces (20 mm in front of their axes) over a far wall
    depth = np.full((240, 320), 3000.0, np.float32)
    for a, b in ((shoulder, true), (true, hand)):
        for s in np.linspace(0, 1, 200):
            p = a + s * (b - a)
            (u, v), = cam.project(p[None])
            depth[int(v) - 3:int(v) + 4, int(u) - 3:int(u) + 4] = p[2] - 20.0
    got, ok = elbow(cam, depth, shoulder, hand, 300.0, 260.0, 20.0, 60.0, 36)
    assert ok and np.linalg.norm(got - true) < 60.0
    hidden = np.full((240, 320), 600.0, np.float32)  # something right in front of the camera
    got, ok = elbow(cam, hidden, shoulder, hand, 300.0, 260.0, 20.0, 60.0, 36)
    assert not ok and np.allclose(got, hand + [0, 0, 260.0])  # (X_h, Y_h, Z_h + l_f)
    assert Posture().upper_arm > Posture().forearm


def test_hand_reference_with_its_other_bin_observes_the_scale():
    """A round hand on pixels outside the hand mask: with the fill-weighted reference the window
    of the hand's own size scores best; a pure-skin reference (fill 1) prefers the smallest."""
    from partlab.tracking.core.hue_histogram import box_histograms, hue_confidence, integral_histogram
    from partlab.tracking.depth.tracker import hand_reference

    nb = 16
    bins = np.full((80, 80), nb, np.int16)  # "other": not in front of the face
    yy, xx = np.mgrid[:80, :80]
    bins[(xx - 40) ** 2 + (yy - 40) ** 2 <= 10**2] = 2  # the hand, 20 px across, skin hue bin 2
    skin = np.full((10, 10), 2, np.int16)  # the face's inner part
    integral = integral_histogram(bins, nb + 1)
    alphas = np.array([0.7, 0.85, 1.0, 1.15, 1.4])
    boxes = np.stack([40 - 10 * alphas, 40 - 10 * alphas, 20 * alphas, 20 * alphas], axis=1)
    for fill, best in ((0.785, 1.0), (1.0, 0.7)):
        ref = hand_reference(skin, (0, 0, 10, 10), nb, fill)
        assert ref.shape == (nb + 1,) and ref.sum() == pytest.approx(1.0)
        conf = hue_confidence(box_histograms(integral, boxes), ref, 6.0)
        assert alphas[np.argmax(conf)] == best, (fill, conf)
    ref = hand_reference(skin, (0, 0, 10, 10), nb, 0.785)
    conf = hue_confidence(box_histograms(integral, boxes), ref, 6.0)
    assert conf[2] > 0.95 and conf[0] < conf[2] - 0.1 and conf[-1] < conf[2] - 0.1


def test_arm_lengths_are_fitted_to_the_depth_of_a_shorter_arm():
    """Arms 6 % shorter than the head's proportions: the stretched arm rules the longer factors
    out, the bent ones fit best at the true factor, and the elbow then lands on the true one."""
    from partlab.tracking.depth.posture import ArmFit

    cam = Camera("c", [[300, 0, 160], [0, 300, 120], [0, 0, 1]], (320, 240))
    p = Posture()
    upper, fore, true_scale = 300.0, 260.0, 0.94
    shoulder = np.array([0.0, 0.0, 1500.0])
    fit = ArmFit(p)
    for reach, turn in ((0.97, 0.0), (0.8, 0.5), (0.9, -0.4)):
        direction = np.array([np.sin(turn), np.cos(turn), -0.3])
        direction /= np.linalg.norm(direction)
        hand = shoulder + reach * true_scale * (upper + fore) * direction
        true = elbow_circle(shoulder, hand, true_scale * upper, true_scale * fore, 36)[9]
        depth = np.full((240, 320), 3000.0, np.float32)
        for a, b in ((shoulder, true), (true, hand)):
            for s in np.linspace(0, 1, 200):
                q = a + s * (b - a)
                (u, v), = cam.project(q[None])
                depth[int(v) - 4:int(v) + 5, int(u) - 4:int(u) + 5] = q[2] - 20.0
        fit.update(cam, depth, shoulder, hand, upper, fore, 20.0, 60.0, 36, lambda c: np.ones(len(c), bool), 8)
    assert fit.scale == true_scale, fit.cost
    got, ok = elbow(cam, depth, shoulder, hand, fit.scale * upper, fit.scale * fore, 20.0, 60.0, 36)
    assert ok and np.linalg.norm(got - true) < 40.0



def test_hands_bins_other_behind_the_hand_plane_or_on_a_surface_and_colour_decides_where_depth_is_missing():
    from partlab.tracking.depth.params import DepthParams
    from partlab.tracking.depth.regions import FaceDepth
    from partlab.tracking.depth.tracker import DepthTracker

    tracker = DepthTracker(DepthParams(), np.random.default_rng(0))
    nb = DepthParams().appearance.hue_bins
    bins = np.array([[3, 3, 3, -1]], np.int16)
    depth = np.array([[900.0, 1500.0, np.nan, 900.0]], np.float32)  # near, at the face, unmeasured, near
    got = tracker._hand_bins(bins, depth, FaceDepth(1500.0, 5.0, 160.0), None)
    assert got.tolist() == [[3, nb, 3, nb]]  # unmeasured depth is no evidence: its hue counts
    surface = np.array([[True, False, False, False]])
    assert tracker._hand_bins(bins, depth, FaceDepth(1500.0, 5.0, 160.0), surface).tolist() == [[nb, nb, 3, nb]]
    assert tracker._hand_bins(bins, depth, None, None).tolist() == [[3, 3, 3, nb]]  # colour alone: only hue counts
