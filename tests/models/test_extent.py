import pandas as pd
import pytest

from partlab.models.extent import fit_output_extent


def _truth(n=40):
    rows = []
    for f in range(n):
        rows.append(dict(frame=f, track_id=1, part="torso", x=100 + 2 * f, y=80.0, w=40.0, h=60.0, occluded=0.0))
        rows.append(dict(frame=f, track_id=1, part="head", x=110 + 2 * f, y=60.0, w=20.0, h=20.0, occluded=0.0))
    return pd.DataFrame(rows)


def test_fit_recovers_the_widening_that_maps_reported_boxes_onto_corrections():
    truth = _truth()
    # the tracker's inner torso rectangle: half the true size, centred 3 px above the true centre;
    # reported with the current extent (1.5 x 1.5, no shift)
    inner_w, inner_h = 20.0, 30.0
    rep = truth[truth.part == "torso"].copy()
    cx, cy = rep.x + 20, rep.y + 30 - 3
    rep["w"], rep["h"] = inner_w * 1.5, inner_h * 1.5
    rep["x"], rep["y"] = cx - rep.w / 2, cy - rep.h / 2
    current = {"torso": (1.5, 1.5, 0.0, 0.0), "head": (1.6, 1.6, 0.0, -0.1)}
    fitted = fit_output_extent([rep], [truth], current)
    sw, sh, dx, dy = fitted["torso"]
    assert (sw, sh) == pytest.approx((2.0, 2.0), abs=1e-3)
    assert (dx, dy) == pytest.approx((0.0, 3 / inner_h), abs=1e-3)
    assert fitted["head"] == current["head"]  # no head rows tracked: kept


def test_too_few_pairs_keep_the_current_extent():
    truth = _truth(n=5)
    rep = truth.assign(w=truth.w / 2)
    current = {"torso": (1.5, 1.5, 0.0, 0.0)}
    assert fit_output_extent([rep], [truth], current)["torso"] == (1.5, 1.5, 0.0, 0.0)
