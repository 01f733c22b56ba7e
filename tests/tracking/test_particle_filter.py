"""One part's colour particle filter (seed 002 sec. 3) on small drawn frames."""

from __future__ import annotations

import numpy as np
import pytest

from partlab.tracking.body.part_filter import PartFilter, box_to_state, state_to_box
from partlab.tracking.core.box import Box
from partlab.tracking.core.histogram import to_ycc
from partlab.tracking.params import BodyParams, PartNoise

W, H = 160, 120


def _frame(rng, cx, cy, colour=(40, 60, 200), size=(16, 24)):
    """Noisy grey background with a red-ish rectangle centred at (cx, cy)."""
    f = np.clip(rng.normal(128, 20, (H, W, 3)), 0, 255).astype(np.uint8)
    w, h = size
    x1, y1 = int(cx - w / 2), int(cy - h / 2)
    f[max(y1, 0):y1 + h, max(x1, 0):x1 + w] = np.clip(
        rng.normal(colour, 8, (h, w, 3))[: H - max(y1, 0), : W - max(x1, 0)], 0, 255)
    return f


def test_state_box_round_trip():
    b = Box(10, 20, 30, 40)
    s = box_to_state(b)
    assert s.tolist() == [25, 40, 30, 40, 0, 0]
    assert state_to_box(s) == b


@pytest.mark.parametrize("compiled", [True, False], ids=["numba", "numpy"])
def test_filter_follows_a_moving_rectangle(compiled, monkeypatch):
    from partlab.tracking.core import kernels
    from partlab.tracking.core.lazy_ycc import LazyYcc

    assert kernels.HAVE_NUMBA  # a dependency; False below is the fallback kept for platforms without it
    monkeypatch.setattr(kernels, "HAVE_NUMBA", compiled)  # False: the numpy + OpenCV fallback
    rng = np.random.default_rng(0)
    params = BodyParams().updated({"particles.initial": 300})
    noise = PartNoise(x=3, y=3, w=0.5, h=0.5, vx=0.5, vy=0.5, lam=20)
    cx, cy = 40.0, 60.0
    pf = PartFilter(Box(cx - 8, cy - 12, 16, 24), to_ycc(_frame(rng, cx, cy)), params, noise,
                    np.random.default_rng(1))
    errors = []
    for t in range(40):
        cx += 2.0  # 2 px per frame to the right
        cy += 0.5 * np.sin(t / 5)
        ycc = LazyYcc(_frame(rng, cx, cy))  # converted where the particles are (all of it without numba)
        pf.predict()
        pf.measure(ycc)
        pf.update_model(pf.appearance(ycc))
        pf.resample()
        errors.append(np.hypot(pf.state[0] - cx, pf.state[1] - cy))
    assert max(errors) < 6.0
    assert np.mean(errors[-10:]) < 3.0
    assert pf.state[4] == pytest.approx(2.0, abs=1.0)  # the velocity was learnt
    assert 200 <= pf.n <= 1000


def test_entropy_adapts_particle_count_within_bounds():
    rng = np.random.default_rng(3)
    params = BodyParams().updated({"particles.initial": 500})
    noise = PartNoise(x=3, y=3, w=0.5, h=0.5, vx=0.5, vy=0.5, lam=20)
    pf = PartFilter(Box(32, 48, 16, 24), to_ycc(_frame(rng, 40, 60)), params, noise, np.random.default_rng(4))
    # lost: the target vanishes, weights flatten, the count grows (by C = 1.2 at most) to the cap 1000
    counts = []
    empty = to_ycc(np.clip(rng.normal(128, 20, (H, W, 3)), 0, 255).astype(np.uint8))
    for _ in range(8):
        before = pf.n
        pf.predict()
        pf.measure(empty)
        pf.resample()
        assert pf.n <= round(1.2 * before)
        counts.append(pf.n)
    assert counts[-1] == 1000
    assert counts[0] > 500
    # found again, and sharply: few particles carry the weight, the count falls towards 200
    pf2 = PartFilter(Box(32, 48, 16, 24), to_ycc(_frame(rng, 40, 60)), params,
                     PartNoise(x=6, y=6, w=0.5, h=0.5, vx=0.5, vy=0.5, lam=200), np.random.default_rng(5))
    for _ in range(8):
        ycc = to_ycc(_frame(rng, 40, 60))
        pf2.predict()
        pf2.measure(ycc)
        pf2.resample()
    assert 200 <= pf2.n < 400


def test_coast_moves_by_velocity_without_measuring():
    rng = np.random.default_rng(6)
    pf = PartFilter(Box(32, 48, 16, 24), to_ycc(_frame(rng, 40, 60)), BodyParams(), PartNoise(),
                    np.random.default_rng(7))
    pf.set_velocity(np.array([3.0, -1.0]))
    for _ in range(10):
        pf.coast()
    assert pf.state[0] == pytest.approx(70.0) and pf.state[1] == pytest.approx(50.0)
    assert np.abs(pf.particles[:, 0].mean() - 70.0) < 1.0


def test_tiny_box_is_refused():
    with pytest.raises(ValueError, match="at least 2 x 2"):
        PartFilter(Box(0, 0, 1, 5), np.zeros((10, 10, 3), np.uint8), BodyParams(), PartNoise(),
                   np.random.default_rng(0))


@pytest.mark.parametrize("compiled", [True, False], ids=["numba", "numpy"])
def test_a_background_weighted_model_tells_a_thin_person_in_a_loose_box_from_the_background(compiled, monkeypatch):
    """A thin red figure (6 px) in a loose 24 px box on grey: the plain model is three quarters grey,
    so a box of pure background matches it well; weighted against the ring around the person
    (``appearance.surround``, Comaniciu et al. / Ning et al.) the grey bins count less, and the
    figure matches far better than the background does. Off (the camera still), the model is the
    plain one again."""
    from partlab.tracking.body.part_filter import surround_counts
    from partlab.tracking.core import kernels

    monkeypatch.setattr(kernels, "HAVE_NUMBA", compiled)
    rng = np.random.default_rng(3)
    frame = _frame(rng, 80, 60, size=(6, 24))
    ycc = to_ycc(frame)
    box = Box(68, 48, 24, 24)
    params = BodyParams()
    noise = PartNoise(x=3, y=3, w=0.5, h=0.5, vx=0.5, vy=0.5, lam=20)
    ring = surround_counts(ycc, box, params.appearance.surround)
    assert ring is not None and ring.sum(axis=1).tolist() == [ring.sum() / 3] * 3
    pf = PartFilter(box, ycc, params, noise, np.random.default_rng(1), surround=ring)
    on_person = np.array([[80, 60, 24, 24, 0, 0]], np.float32)
    on_grass = np.array([[30, 60, 24, 24, 0, 0]], np.float32)  # background only
    plain = pf.similarities(ycc, on_person)[0], pf.similarities(ycc, on_grass)[0]
    pf.weigh_by_background(True)
    weighted = pf.similarities(ycc, on_person)[0], pf.similarities(ycc, on_grass)[0]
    assert plain[1] > 0.85  # the plain model: background scores nearly as well as the person
    assert weighted[1] < plain[1] - 0.05 and weighted[0] - weighted[1] > 1.5 * (plain[0] - plain[1])
    pf.weigh_by_background(False)
    assert pf.similarities(ycc, on_grass)[0] == pytest.approx(plain[1])
