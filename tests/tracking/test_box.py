import numpy as np
import pytest

from partlab.tracking.core.box import Box, iou_xywh


def test_iou_area_intersection_centre():
    a = Box(0, 0, 10, 10)
    b = Box(5, 5, 10, 10)
    assert a.area == 100
    assert a.intersection(b) == 25
    assert a.iou(b) == pytest.approx(25 / 175)
    assert a.centre == (5.0, 5.0)
    assert Box(0, 0, 4, 4).iou(Box(10, 10, 4, 4)) == 0.0


def test_clip_and_union():
    assert Box(-5, -5, 20, 10).clip(8, 100) == Box(0, 0, 8, 5)
    assert Box(50, 50, 5, 5).clip(40, 40).area == 0
    assert Box(0, 0, 2, 2).union_box(Box(5, 1, 2, 4)) == Box(0, 0, 7, 5)


def test_negative_size_refused():
    with pytest.raises(ValueError, match="non-negative"):
        Box(0, 0, -1, 3)


def test_vectorised_iou_matches_scalar():
    rng = np.random.default_rng(1)
    a = rng.uniform(0, 50, (7, 4))
    b = rng.uniform(0, 50, (5, 4))
    m = iou_xywh(a, b)
    for i in range(7):
        for j in range(5):
            assert m[i, j] == pytest.approx(Box(*a[i]).iou(Box(*b[j])))


def test_transformed_scales_about_the_centre_and_shifts_by_own_size():
    b = Box(10, 20, 10, 20).transformed(2.0, 0.5, shift_x=0.5, shift_y=-0.25)
    assert b == Box(10, 20, 20, 10)  # centre (15, 30) -> (20, 25); size (20, 10)
