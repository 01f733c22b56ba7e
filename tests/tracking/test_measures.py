"""The one definition of each measure, against answers worked out by hand."""

import numpy as np
import pandas as pd
import pytest

from partlab.tracking import measures
from partlab.tracking.core.box import Box
from partlab.tracking.tracks import normalise_tracks

TRUTH = (10.0, 10.0, 20.0, 20.0)  # x 10..30, y 10..30


@pytest.mark.parametrize("box, cover, right", [
    ((10, 10, 20, 20), 1.0, True),        # the true box itself
    ((20, 10, 20, 20), 0.5, True),        # half on it, centre (30, 20) on its right edge: edges count
    ((21, 10, 20, 20), 0.45, False),      # 9/20 on it: more than half covers other things
    ((0, 0, 40, 40), 0.25, False),        # centre inside, but three quarters of it is elsewhere
    ((12, 12, 4, 4), 1.0, True),          # a small box inside
    ((28, 28, 4, 4), 0.25, False),        # a corner: a quarter on it
    ((10, 10, 0, 20), 0.0, False),        # no area
    ((np.nan, 10, 20, 20), 0.0, False),   # no box
])
def test_right_box_by_hand(box, cover, right):
    b, t = np.array([box], float), np.array([TRUTH])
    if not np.isnan(box[0]):
        assert measures.cover_fraction(b, t)[0] == pytest.approx(cover)
    assert measures.right_box(b, t)[0] == right


def test_right_box_needs_the_centre_inside():
    # a tall thin box mostly on the truth (12/20 of it) but with its centre below the truth's edge
    thin = np.array([[15.0, 18.0, 2.0, 20.0]])  # y 18..38, centre y 28 inside: right
    assert measures.right_box(thin, np.array([TRUTH]))[0]
    # any box with >= half of its area on a rectangle has its centre in it, closed: the rule's
    # second test can only fail together with the first; check the two together on a grid
    rng = np.random.default_rng(0)
    boxes = np.column_stack([rng.uniform(-10, 40, 500), rng.uniform(-10, 40, 500), rng.uniform(1, 30, (500, 2))])
    truth = np.repeat(np.array([TRUTH]), 500, axis=0)
    right = measures.right_box(boxes, truth)
    assert (right == (measures.cover_fraction(boxes, truth) >= 0.5) & measures.centre_inside(boxes, truth)).all()
    assert 20 < right.sum() < 480  # the grid has both kinds


def test_box_objects_and_arrays_agree():
    assert measures.right_box_one(Box(20, 10, 20, 20), Box(*TRUTH))
    assert not measures.right_box_one(Box(21, 10, 20, 20), Box(*TRUTH))


def test_person_box_is_the_mbr_of_its_parts():
    parts = [Box(4, 0, 4, 4), Box(2, 4, 8, 8), Box(2, 12, 8, 10)]
    assert measures.person_box(parts).as_tuple() == (2.0, 0.0, 8.0, 22.0)
    rows = [(0, 1, "head", 4, 0, 4, 4), (0, 1, "torso", 2, 4, 8, 8), (0, 1, "hipleg", 2, 12, 8, 10),
            (1, 1, "head", 4, 0, 4, 4)]  # frame 1: one part only, no person box
    df = normalise_tracks(pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h"]))
    got = measures.person_boxes(df)
    assert got[["frame", "track_id", "x", "y", "w", "h"]].values.tolist() == [[0, 1, 2.0, 0.0, 8.0, 22.0]]


def _table(rows):
    return normalise_tracks(pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h"]))


def test_tracking_rate_curve_and_average_by_hand():
    # person 1 from frame 0 to 3, person 2 from frame 2 to 4 (offsets 0..2)
    truth = _table([(f, 1, "head", 10 * f, 0, 10, 10) for f in range(4)]
                   + [(f, 2, "head", 100, 50, 10, 10) for f in range(2, 5)])
    tracks = _table([(0, 1, "head", 0, 0, 10, 10), (1, 1, "head", 12, 0, 10, 10),    # right, right (80 %)
                     (2, 1, "head", 27, 0, 10, 10), (3, 1, "head", 60, 0, 10, 10),   # wrong (30 %), wrong
                     (2, 2, "head", 100, 50, 10, 10), (4, 2, "head", 101, 51, 10, 10)])  # right, missing, right
    judged = measures.with_offsets(measures.judge(truth, tracks), truth)
    assert judged.sort_values(["track_id", "frame"]).right.tolist() == [True, True, False, False, True, False, True]
    curve = measures.rate_curve(judged)
    assert curve.tolist() == [1.0, 0.5, 0.5, 0.0]  # offsets 0..3: 2/2, 1/2, 1/2, 0/1
    assert measures.rate_at(curve, 1) == 0.5 and np.isnan(measures.rate_at(curve, 9))
    assert measures.averaged_rate(curve) == pytest.approx(1 / 3)  # offsets 1..3; 0 is the start
    assert measures.part_rates(tracks, truth, ("head", "torso")) == {"head": pytest.approx(1 / 3),
                                                                     "torso": pytest.approx(np.nan, nan_ok=True)}
    assert measures.part_rates(tracks, truth, ("head",), at=2) == {"head": 0.5}
