from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.core.hue_histogram import hue_bin_image, reference_histogram
from partlab.tracking.core.skin import SkinModel, find_blobs
from partlab.tracking.limbs.filter import (
    Candidates,
    LimbFilter,
    blob_likelihood,
    blob_points,
    blob_tips,
    candidate_modes,
    candidate_terms,
    nearest_per_parent,
    silhouette_term,
    tip_candidates,
)
from partlab.tracking.params import LimbParams

SKIN = (110, 150, 210)
BG = (90, 110, 70)


def _cands(centres, priors):
    c = np.asarray(centres, float)
    return Candidates(c, np.zeros((len(c), 4)), np.ones(len(c)), {"x": np.asarray(priors, float)},
                      np.asarray(priors, float))


def test_blob_likelihood_is_the_prior_weighted_gaussian_sum_of_eq_17():
    cands = _cands([[0, 0], [10, 0]], [1.0, 0.5])
    got = blob_likelihood(np.array([[0, 0], [10, 0], [5, 0]]), cands, sigma_xy=5.0)
    g = np.exp(-100 / 50)
    np.testing.assert_allclose(got, [1 + 0.5 * g, g + 0.5, 1.5 * np.exp(-25 / 50)])
    assert blob_likelihood(np.zeros((3, 2)), _cands(np.zeros((0, 2)), []), 5.0).tolist() == [0, 0, 0]


def test_silhouette_term_decays_with_distance_to_the_foreground_eq_27():
    fg = np.zeros((20, 40), np.uint8)
    fg[:, :10] = 255
    t = silhouette_term(np.array([[5, 10], [18, 10], [30, 10]]), fg, sigma_s=8.0)
    # distances 0, ~8.x, ~20.x from the silhouette edge at x = 9
    assert t[0] == 1.0
    assert 0.5 < t[1] < 0.65 and t[2] < 0.05
    assert silhouette_term(np.array([[5, 5]]), None, 8.0).tolist() == [1.0]


def test_candidate_prior_is_the_product_of_named_terms():
    frame = np.full((40, 60, 3), BG, np.uint8)
    cv2.circle(frame, (15, 20), 6, SKIN, -1)
    cv2.circle(frame, (45, 20), 6, SKIN, -1)
    fg = np.zeros((40, 60), np.uint8)
    fg[:, :30] = 255
    skin = SkinModel.default()
    blobs = find_blobs(skin.mask(frame), 1, 1.5, 10)
    c = candidate_terms(blobs, fg, skin.probability(frame), LimbParams().updated({"priors.sigma_s": 4.0}))
    assert set(c.terms) == {"silhouette", "skin"}
    np.testing.assert_allclose(c.priors, c.terms["silhouette"] * c.terms["skin"])
    order = np.argsort(c.centres[:, 0])
    assert c.priors[order[0]] == 1.0 and c.priors[order[1]] < 1e-3  # the disc off the silhouette


def test_filter_follows_a_moving_skin_disc_and_refines_onto_it():
    p = LimbParams().updated({"dynamics.particles": 200})
    rng = np.random.default_rng(3)
    skin = SkinModel.default()
    filt = None
    errors = []
    for t in range(25):
        cx = 20 + 3 * t
        frame = np.full((60, 120, 3), BG, np.uint8)
        cv2.circle(frame, (cx, 30), 7, SKIN, -1)
        cv2.circle(frame, (100, 50), 4, (40, 40, 200), -1)  # a red distractor (not skin)
        hsv = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)
        bins = hue_bin_image(hsv, p.appearance.hue_bins, p.appearance.hue_min_saturation, p.appearance.hue_min_value)
        cands = candidate_terms(find_blobs(skin.mask(frame), 1, 1.5, 10), None, skin.probability(frame), p)
        if filt is None:
            ref = reference_histogram(bins, (cx - 7, 23, 14, 14), p.appearance.hue_bins)
            filt = LimbFilter((cx, 30), (14, 14), ref, p, rng)
            continue
        filt.predict(rng)
        filt.weigh(cands, bins)
        filt.refine(bins)
        filt.resample(rng)
        errors.append(np.hypot(filt.estimate[0] - cx, filt.estimate[1] - 30))
    assert max(errors) < 4.0
    assert filt.confidence > 0.5


def test_candidate_modes_are_the_strong_nearby_components():
    rng = np.random.default_rng(0)
    pts = np.vstack([rng.normal([0, 0], 3, (100, 2)), rng.normal([30, 0], 3, (100, 2))])
    w = np.full(200, 1 / 200)
    cands = _cands([[0, 0], [30, 0], [200, 0], [15, 0]], [1.0, 0.8, 1.0, 0.01])
    m = candidate_modes(pts, w, cands, sigma_xy=5.0, radius=40.0)
    np.testing.assert_allclose(m, [[0, 0], [30, 0]])  # far one out of reach, weak one below 10 %


def _blob(draw) -> np.ndarray:
    mask = np.zeros((120, 160), np.uint8)
    draw(mask)
    (pts,) = blob_points(find_blobs(mask, 1, 1.0, 10))
    return pts


def test_an_arm_long_blob_gives_its_two_hand_sized_ends_and_a_hand_its_centre():
    def arm(m):  # forearm (width 12) from an elbow at (30, 60) to a hand of radius 8 at (100, 60)
        cv2.line(m, (30, 60), (100, 60), 255, 12)
        cv2.circle(m, (100, 60), 8, 255, -1)
    tips = blob_tips(_blob(arm), side=16, span=1.6, far=2.5, radius=0.8)
    assert tips.shape == (2, 2)
    tips = tips[np.argsort(tips[:, 0])]
    assert np.allclose(tips[1], (100, 60), atol=3.0)  # the hand's centre, not the blob's (~67, 60)
    assert abs(tips[0, 0] - 30) < 8 and abs(tips[0, 1] - 60) < 1
    hand = _blob(lambda m: cv2.circle(m, (80, 50), 8, 255, -1))
    assert np.allclose(blob_tips(hand, 16, 1.6, 2.5, 0.8), [[80, 50]], atol=0.5)


def test_a_blob_cut_by_the_observed_regions_edge_gives_its_end_away_from_the_cut():
    def arm(m):  # a hand of radius 8 at (100, 60) and its forearm, cut square at x = 70
        cv2.line(m, (70, 60), (100, 60), 255, 12)
        cv2.circle(m, (100, 60), 8, 255, -1)
    pts = _blob(arm)
    cut = pts[:, 0] <= 71  # the pixels next to skin that is not observed
    plain = blob_tips(pts, side=16, span=1.6, far=2.5, radius=0.8)
    assert len(plain) == 2 and plain[:, 0].min() < 80  # without the cut: the cut is an end too
    tips = blob_tips(pts, side=16, span=1.6, far=2.5, radius=0.8, cut=cut)
    assert tips.shape == (1, 2) and np.allclose(tips[0], (100, 60), atol=3.0)
    # a shorter piece (under tip_span): its centre lies towards the cut, the end away from it is the hand
    short = _blob(lambda m: (cv2.line(m, (88, 60), (100, 60), 255, 12), cv2.circle(m, (100, 60), 8, 255, -1)))
    assert blob_tips(short, 16, 1.6, 2.5, 0.8)[0, 0] < 97
    assert np.allclose(blob_tips(short, 16, 1.6, 2.5, 0.8, cut=short[:, 0] <= 89)[0], (100, 60), atol=2.5)


def test_two_forearms_meeting_at_a_clap_give_the_meeting_point_as_a_third_end():
    def v(m):
        cv2.line(m, (20, 100), (80, 40), 255, 12)
        cv2.line(m, (140, 100), (80, 40), 255, 12)
    tips = blob_tips(_blob(v), side=16, span=1.6, far=2.5, radius=0.8)
    assert len(tips) == 3
    assert np.min(np.hypot(*(tips - np.array([80, 44])).T)) < 6.0


def test_tip_candidates_keep_their_blob_and_prior_and_one_end_per_blob_is_chosen():
    mask = np.zeros((120, 160), np.uint8)
    cv2.line(mask, (20, 30), (90, 30), 255, 12)  # an arm
    cv2.circle(mask, (130, 90), 8, 255, -1)  # a hand alone
    blobs = find_blobs(mask, 1, 1.0, 10)
    cands = Candidates(blobs.centres, blobs.boxes, blobs.areas, {"x": np.array([0.9, 0.5])}, np.array([0.9, 0.5]))
    tc = tip_candidates(cands, blob_points(blobs), 16, LimbParams())
    assert len(tc) == 3 and list(np.bincount(tc.parents)) == [2, 1]
    assert np.allclose(tc.priors, [0.9, 0.9, 0.5]) and np.allclose(tc.terms["x"], tc.priors)
    keep = nearest_per_parent(tc, (95, 35))
    assert keep.sum() == 2
    assert tc.centres[keep & (tc.parents == 0)][0, 0] > 70  # the arm's end near (95, 35)
