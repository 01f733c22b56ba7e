from __future__ import annotations

import cv2
import numpy as np
import pytest

from partlab.tracking.core.hue_histogram import (
    back_projection,
    bhattacharyya_distance,
    box_histograms,
    hue_bin_image,
    hue_confidence,
    integral_histogram,
    local_box_histograms,
    local_mean_shift,
    mean_shift,
    reference_histogram,
)


def _frame():
    f = np.full((40, 60, 3), (90, 110, 70), np.uint8)  # green: hue ~ 40 (OpenCV scale)
    cv2.rectangle(f, (30, 10), (49, 29), (110, 150, 210), -1)  # skin: hue ~ 13
    f[0:5, 0:5] = (128, 128, 128)  # grey: no hue
    return cv2.cvtColor(f, cv2.COLOR_BGR2HSV)


def test_integral_histograms_match_direct_counts():
    hsv = _frame()
    bins = hue_bin_image(hsv, 16, 30, 40)
    assert (bins[0:5, 0:5] == -1).all()
    integ = integral_histogram(bins, 16)
    boxes = np.array([[25, 5, 30, 30], [0, 0, 10, 10], [-5, -5, 200, 200]], float)
    got = box_histograms(integ, boxes)
    for box, h in zip(boxes, got):
        x, y, w, hh = (int(v) for v in box)
        patch = bins[max(y, 0):y + hh, max(x, 0):x + w]
        ref = np.bincount(patch[patch >= 0], minlength=16) / (patch >= 0).sum()
        np.testing.assert_allclose(h, ref, atol=1e-6)


def test_bhattacharyya_distance_and_confidence_eq_1_2():
    ref = np.array([0.5, 0.5, 0.0, 0.0])
    hists = np.array([[0.5, 0.5, 0, 0], [0, 0, 0.5, 0.5], [1.0, 0, 0, 0], [0, 0, 0, 0]])
    d = bhattacharyya_distance(hists, ref)
    np.testing.assert_allclose(d, [0.0, 1.0, np.sqrt(1 - np.sqrt(0.5)), 1.0], atol=1e-9)
    np.testing.assert_allclose(hue_confidence(hists, ref, lam=1.0), np.exp(-d**2))


def test_mean_shift_climbs_to_the_skin_patch_on_the_back_projection():
    hsv = _frame()
    bins = hue_bin_image(hsv, 16, 30, 40)
    ref = reference_histogram(bins, (32, 12, 10, 10), 16)
    assert ref.max() == 1.0  # one hue bin
    bp = back_projection(bins, ref)
    assert bp[20, 40] == 255 and bp[20, 10] == 0
    x, y, w, h = mean_shift(bp, (24.0, 4.0, 20.0, 20.0), 20, 0.5)
    assert (w, h) == (20.0, 20.0)
    # the window settles on the 20 x 20 patch at (30, 10), to within the integer steps of cv2.meanShift
    assert abs(x - 30) <= 2 and abs(y - 10) <= 2
    # a window over no probability stays where it is
    assert mean_shift(bp, (0.0, 0.0, 8.0, 8.0), 20, 0.5) == (0.0, 0.0, 8.0, 8.0)


def test_local_mean_shift_equals_the_whole_frame_one_and_stops_at_its_margin():
    rng = np.random.default_rng(5)
    f = np.full((120, 160, 3), (90, 110, 70), np.uint8)
    for _ in range(6):  # skin patches scattered over the frame
        x, y = rng.integers(0, 140), rng.integers(0, 100)
        cv2.circle(f, (int(x), int(y)), int(rng.integers(4, 9)), (110, 150, 210), -1)
    bins = hue_bin_image(cv2.cvtColor(f, cv2.COLOR_BGR2HSV), 16, 30, 40)
    ref = reference_histogram(hue_bin_image(_frame(), 16, 30, 40), (32, 12, 10, 10), 16)  # skin only
    bp = back_projection(bins, ref)
    assert 0 < (bp > 0).mean() < 0.3
    for box in rng.uniform([0, 0, 8, 8], [150, 110, 20, 20], (40, 4)):
        whole = mean_shift(bp, tuple(box), 10, 1.0)
        local = local_mean_shift(bins, ref, tuple(box), 10, 1.0, margin=10.0)
        np.testing.assert_allclose(local, whole)
    # with a small margin a window far from any skin cannot climb out of its neighbourhood
    g = np.full((60, 200, 3), (90, 110, 70), np.uint8)
    cv2.rectangle(g, (150, 20), (169, 39), (110, 150, 210), -1)
    gb = hue_bin_image(cv2.cvtColor(g, cv2.COLOR_BGR2HSV), 16, 30, 40)
    assert local_mean_shift(gb, ref, (10.0, 20.0, 10.0, 10.0), 10, 1.0, margin=2.0) == (10.0, 20.0, 10.0, 10.0)
    x, _, _, _ = local_mean_shift(gb, ref, (135.0, 20.0, 20.0, 20.0), 10, 1.0, margin=2.0)
    assert abs(x - 150) <= 2


@pytest.mark.parametrize("compiled", [True, False])
def test_local_box_histograms_equal_the_whole_frame_integral_ones(compiled, monkeypatch):
    from partlab.tracking.core import kernels

    monkeypatch.setattr(kernels, "HAVE_NUMBA", compiled)
    rng = np.random.default_rng(2)
    bins = rng.integers(-1, 16, (50, 70)).astype(np.int16)
    boxes = np.vstack([rng.uniform([-10, -10, 0, 0], [75, 55, 30, 30], (200, 4)),
                       [[0, 0, 70, 50], [69.5, 10, 5, 5], [10.5, 11.5, 3.5, 2.5]]])
    expect = box_histograms(integral_histogram(bins, 16), boxes)
    np.testing.assert_allclose(local_box_histograms(bins, boxes, 16), expect, atol=1e-12)
    assert local_box_histograms(bins, np.zeros((0, 4)), 16).shape == (0, 16)
