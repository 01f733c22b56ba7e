import numpy as np

from partlab.tracking.core.resampling import adaptive_particle_count, systematic_resample


def test_systematic_resample_follows_weights():
    rng = np.random.default_rng(0)
    w = np.array([0.0, 0.5, 0.25, 0.25])
    idx = systematic_resample(w, 400, rng)
    counts = np.bincount(idx, minlength=4)
    assert counts[0] == 0
    assert counts.tolist() == [0, 200, 100, 100]  # exact: samples are 1/n apart


def test_entropy_count_bounds():
    uniform = np.full(500, 1 / 500)
    assert adaptive_particle_count(uniform) == 600          # C * N for uniform weights
    assert adaptive_particle_count(np.full(900, 1 / 900)) == 1000  # capped
    peaked = np.zeros(500)
    peaked[3] = 1.0
    assert adaptive_particle_count(peaked) == 200           # floor
    mid = np.r_[np.full(10, 0.09), np.full(490, 0.1 / 490)]
    n = adaptive_particle_count(mid)
    assert 200 < n < 600
