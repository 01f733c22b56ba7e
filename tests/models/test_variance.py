import numpy as np
import pandas as pd
import pytest

from partlab.models.variance import (
    comparison_figure,
    comparison_table,
    fit_body_noise,
    fit_constant_velocity,
    fit_limb_sigmas,
)
from partlab.tracking.params import BodyParams, LimbParams
from partlab.tracking.tracks import normalise_tracks


def _simulate(rng, n, s_pos, s_vel, x0=100.0):
    x, v, out = x0, rng.normal(0, 1), np.empty(n)
    for t in range(n):
        out[t] = x
        x, v = x + v + rng.normal(0, s_pos), v + rng.normal(0, s_vel)
    return out


def test_constant_velocity_fit_recovers_known_noise():
    rng = np.random.default_rng(7)
    paths = [_simulate(rng, 300, 3.0, 0.6) for _ in range(8)]
    s_pos, s_vel, n = fit_constant_velocity(paths)
    assert n == 8 * 298
    assert abs(s_pos - 3.0) / 3.0 < 0.1
    assert abs(s_vel - 0.6) / 0.6 < 0.1


def test_body_fit_from_a_tracks_table_recovers_noise_and_size_steps():
    rng = np.random.default_rng(1)
    rows = []
    for tid in (1, 2, 3):
        cx = _simulate(rng, 400, 2.0, 0.5)
        cy = _simulate(rng, 400, 1.5, 0.3)
        w = 40 + np.cumsum(rng.normal(0, 1.2, 400))
        for f in range(400):
            if f == 200:
                continue  # a gap: segments are split there
            rows.append(dict(frame=f, track_id=tid, part="torso", x=cx[f] - w[f] / 2, y=cy[f] - 30, w=w[f], h=60.0))
    truth = normalise_tracks(pd.DataFrame(rows))
    body, table = fit_body_noise([truth], keep_defaults_as_floor=False)
    n = body.dynamics.noise["torso"]
    assert abs(n.x - 2.0) / 2.0 < 0.1 and abs(n.vx - 0.5) / 0.5 < 0.1
    assert abs(n.y - 1.5) / 1.5 < 0.1 and abs(n.vy - 0.3) / 0.3 < 0.1
    assert abs(n.w - 1.2) / 1.2 < 0.1
    assert n.h == 1.0  # constant height: floored at 1 px
    assert n.lam == BodyParams().dynamics.noise["torso"].lam  # not fitted
    # parts without data keep their defaults
    assert body.dynamics.noise["head"] == BodyParams().dynamics.noise["head"]
    t = table.set_index(["part", "parameter"])
    assert np.isnan(t.loc[("head", "x"), "fitted"]) and t.loc[("torso", "x"), "n"] == 3 * (198 + 197)
    assert "torso" in comparison_table(table)
    fig = comparison_figure(table)
    assert len(fig.data) == 3 and len(fig.data[0].x) == len(table)
    # default policy: a fit only widens the defaults (torso default x = 4, vx = 1, w = 1)
    body2, table2 = fit_body_noise([truth])
    n2 = body2.dynamics.noise["torso"]
    assert n2.x == 4.0 and n2.vx == 1.0 and n2.w == pytest.approx(n.w)
    t2 = table2.set_index(["part", "parameter"])
    assert t2.loc[("torso", "x"), "fitted"] == pytest.approx(n.x) and t2.loc[("torso", "x"), "applied"] == 4.0


def test_limb_sigmas_from_known_residuals():
    rng = np.random.default_rng(2)
    rows = []
    for f in range(500):
        # hand: straight line plus isotropic noise of 3 px -> prediction error std per axis 3*sqrt(6)
        hx, hy = 100 + 2 * f + rng.normal(0, 3), 200 + rng.normal(0, 3)
        rows.append(dict(frame=f, track_id=1, part="left_hand", x=hx - 5, y=hy - 5, w=10, h=10))
        rows.append(dict(frame=f, track_id=1, part="person", x=hx - 40, y=100, w=60, h=200))
    limb, table = fit_limb_sigmas([normalise_tracks(pd.DataFrame(rows))], keep_defaults_as_floor=False)
    assert abs(limb.priors.sigma_d - 3 * np.sqrt(6)) / (3 * np.sqrt(6)) < 0.1
    assert abs(limb.priors.sigma_v - 3 * np.sqrt(2)) / (3 * np.sqrt(2)) < 0.1
    assert limb.priors.sigma_s == 1.0  # always inside its person box: floored
    assert set(table["parameter"]) == {"sigma_d", "sigma_v", "sigma_s"}
    # saved, but no one-camera tracker reads sigma_v / sigma_d: the table does not call them applied
    t = table.set_index("parameter")
    assert np.isnan(t.loc["sigma_d", "applied"]) and np.isnan(t.loc["sigma_v", "applied"])
    assert t.loc["sigma_s", "applied"] == 1.0 and "not read" in t.loc["sigma_d", "source"]
    assert LimbParams().priors.sigma_d == 20.0
    floored, _ = fit_limb_sigmas([normalise_tracks(pd.DataFrame(rows))])
    assert (floored.priors.sigma_d, floored.priors.sigma_v, floored.priors.sigma_s) == (20.0, 12.0, 8.0)


def test_noise_from_the_trackers_prediction_errors():
    from partlab.models.variance import prediction_residuals

    rng = np.random.default_rng(4)
    truth_rows, tracked_rows = [], []
    for f in range(600):
        cx, cy = 100 + 2.0 * f, 200.0
        truth_rows.append(dict(frame=f, track_id=1, part="torso", x=cx - 20, y=cy - 30, w=40, h=60))
        ex = rng.normal(0, 2.0)
        tracked_rows.append(dict(frame=f, track_id=1, part="torso", x=cx + ex - 15, y=cy - 25, w=30, h=50))
    truth, tracked = normalise_tracks(pd.DataFrame(truth_rows)), normalise_tracks(pd.DataFrame(tracked_rows))
    r = prediction_residuals(tracked, truth, "torso")
    assert r["cx"].size == 598
    # truth moves exactly linearly: residual = -(2 e_{t-1} - e_{t-2}), std 2 * sqrt(5)
    assert abs(np.std(r["cx"]) - 2 * np.sqrt(5)) / (2 * np.sqrt(5)) < 0.1
    body, table = fit_body_noise([truth], tracked=[tracked], keep_defaults_as_floor=False)
    n = body.dynamics.noise["torso"]
    assert abs(n.x - 2 * np.sqrt(5)) / (2 * np.sqrt(5)) < 0.1
    assert n.w == 1.0 and n.y == 1.0           # constant offsets are not noise: floored
    assert n.vx == 0.1                         # the truth's velocity never changes: floored
    src = table.set_index(["part", "parameter"])["source"]
    assert src[("torso", "x")] == "tracker" and src[("torso", "vx")] == "truth" and src[("head", "x")] == "truth"
