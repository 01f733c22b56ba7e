from __future__ import annotations

import cv2
import numpy as np

from tracking.hue_histogram import back_projection, hue_bin_image, integral_histogram, reference_histogram
from tracking.limb_filter import Candidates, LimbFilter, blob_likelihood, candidate_modes, candidate_terms, silhouette_term
from tracking.params import LimbParams
from tracking.skin import SkinModel, find_blobs

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
    c = candidate_terms(blobs, fg, skin.probability(frame), LimbParams(sigma_s=4.0))
    assert set(c.terms) == {"silhouette", "skin"}
    np.testing.assert_allclose(c.priors, c.terms["silhouette"] * c.terms["skin"])
    order = np.argsort(c.centres[:, 0])
    assert c.priors[order[0]] == 1.0 and c.priors[order[1]] < 1e-3  # the disc off the silhouette


def test_filter_follows_a_moving_skin_disc_and_refines_onto_it():
    p = LimbParams(particles=200)
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
        bins = hue_bin_image(hsv, p.hue_bins, p.hue_min_saturation, p.hue_min_value)
        cands = candidate_terms(find_blobs(skin.mask(frame), 1, 1.5, 10), None, skin.probability(frame), p)
        if filt is None:
            filt = LimbFilter((cx, 30), (14, 14), reference_histogram(bins, (cx - 7, 23, 14, 14), p.hue_bins), p, rng)
            continue
        filt.predict(rng)
        filt.weigh(cands, integral_histogram(bins, p.hue_bins))
        filt.refine(back_projection(bins, filt.ref_hist))
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
