"""The compiled kernels give what the numpy + OpenCV path gives."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from partlab.tracking.core import kernels
from partlab.tracking.core.histogram import bhattacharyya_counts, equalization_map, fused_lut, level_histogram
from partlab.tracking.core.integral_histogram import particle_rectangles, rectangle_histograms, sampled_areas


def test_numba_is_there():  # a dependency: the kernels below must run compiled, not be skipped
    assert kernels.HAVE_NUMBA


def _scene(seed=3):
    rng = np.random.default_rng(seed)
    ycc = rng.integers(0, 256, (70, 90, 3), dtype=np.uint8)
    ycc[20:50, 30:60] = (120, 140, 110)  # a flat patch the target's model comes from
    mapping = equalization_map(level_histogram(ycc[15:55, 25:65]))
    target = np.bincount((mapping.astype(int) + 8 * np.arange(3)[:, None]).ravel(),
                         weights=level_histogram(ycc[20:50, 30:60]).ravel(), minlength=24)
    sqrt_target = np.sqrt(target.reshape(3, 8) / target.reshape(3, 8).sum(1, keepdims=True)).ravel()
    states = np.column_stack([rng.uniform(-5, 95, 300), rng.uniform(-5, 75, 300), rng.uniform(2, 35, 300),
                              rng.uniform(2, 35, 300), np.zeros(300), np.zeros(300)]).astype(np.float32)
    states[:3, :4] = [[44.5, 35.5, 30, 30], [45.5, 34.5, 11, 13], [88, 68, 10, 10]]  # ties round to even
    return ycc, mapping, sqrt_target, states


@pytest.mark.parametrize("stride", [1, 2])
def test_rectangle_rho_matches_numpy_path(stride):
    ycc, mapping, sqrt_target, states = _scene()
    rects = kernels.rectangles(states, 90, 70)
    assert np.array_equal(rects, particle_rectangles(states, 90, 70))
    rho, areas = kernels.rectangle_rho(ycc, mapping, rects, stride, sqrt_target)
    counts = rectangle_histograms(ycc, fused_lut(mapping), rects, stride)
    expect_areas = sampled_areas(rects, stride)
    assert np.array_equal(areas, expect_areas)
    assert rho == pytest.approx(bhattacharyya_counts(counts.astype(np.float64), expect_areas, sqrt_target),
                                abs=1e-6)  # numpy: float32 areas
    assert rho[0] == pytest.approx(1.0)  # the flat patch itself matches its model
    assert rho.min() >= 0.0 and rho[areas > 0].min() < 0.7  # random pixels elsewhere do not


def test_level_histogram_box_and_drift_match_numpy():
    ycc, _, _, states = _scene(5)
    got = kernels.level_histogram_box(ycc, 10, 5, 40, 33)
    pixels = ycc[5:33, 10:40].reshape(-1, 3)
    assert np.array_equal(got, np.stack([np.bincount(pixels[:, c], minlength=256) for c in range(3)]) / len(pixels))
    assert np.all(kernels.level_histogram_box(ycc, 10, 5, 10, 33) == 1 / 256)  # empty: uniform
    noise = np.random.default_rng(1).standard_normal(states.shape, dtype=np.float32)
    sigma = np.array([4, 3, 1, 1, 1, 0.5], np.float32)
    lo, hi = np.array([5, 6], np.float32), np.array([20, 21], np.float32)
    expect = states.copy()
    expect[:, 0:2] += expect[:, 4:6]
    expect += noise * sigma
    expect[:, 2:4] = np.minimum(np.maximum(expect[:, 2:4], lo), hi)
    kernels.drift(states, noise, sigma, lo, hi)
    assert np.array_equal(states, expect)


def test_weigh_equalize_similarity_resampling_match_numpy():
    from partlab.tracking.core.histogram import bhattacharyya, binned_histogram, likelihood
    from partlab.tracking.core.resampling import adaptive_particle_count, normalise_weights, systematic_resample

    ycc, mapping, sqrt_target, states = _scene(7)
    rects = kernels.rectangles(states, 90, 70)
    rho, areas = kernels.rectangle_rho(ycc, mapping, rects, 1, sqrt_target)
    w, state = kernels.weigh(states, rho, areas, 20.0, 45.0, 6.0, 0.0, 0.0)
    expect = likelihood(rho, 20.0) * np.exp(-0.5 * ((states[:, 0] - np.float64(45.0)) / 6.0) ** 2)
    expect = normalise_weights(np.where(areas < 4, 0.0, expect))
    assert w == pytest.approx(expect, rel=1e-9, abs=1e-15)
    assert state == pytest.approx((expect[:, None] * states).sum(0), rel=1e-9)
    assert np.all(kernels.weigh(states, rho, np.zeros(300), 20.0, 0.0, 0.0, 0.0, 0.0)[0] == 1 / 300)

    ref = level_histogram(ycc[15:55, 25:65])
    m, target, st = kernels.equalize(ref, ref, 8, 0.05)
    expect_map = equalization_map(ref, 8, smoothing=0.0, floor=0.05)
    assert np.array_equal(m, expect_map)
    assert target == pytest.approx(binned_histogram(ref, expect_map))
    observed = level_histogram(ycc[0:20, 0:20])
    assert kernels.similarity(observed, m, st) == pytest.approx(
        bhattacharyya(binned_histogram(observed, m), target), rel=1e-12)

    n = kernels.entropy_count(w, 1.2, 200, 1000)
    assert n == adaptive_particle_count(w, 1.2, 200, 1000)
    assert kernels.entropy_count(np.full(300, 1 / 300), 1.2, 200, 1000) == 360  # uniform: C N
    idx = kernels.systematic_indices(w, n, np.random.default_rng(9).random())
    assert np.array_equal(idx, systematic_resample(w, n, np.random.default_rng(9)))


def test_standard_normal_is_standard_normal_and_seeded():
    from scipy import stats

    z = kernels.standard_normal(np.random.default_rng(0), (20000, 6))
    assert z.dtype == np.float32 and z.shape == (20000, 6)
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1) < 0.01
    assert stats.kstest(z.ravel(), "norm").pvalue > 0.01
    assert 0.002 < (np.abs(z) > 3).mean() < 0.0035  # the tails are there (2 x 0.00135)
    assert np.array_equal(z, kernels.standard_normal(np.random.default_rng(0), (20000, 6)))
    ppf = stats.norm.ppf([0.001, 0.01, 0.3, 0.5, 0.9, 0.99])
    u = np.array([0.001, 0.01, 0.3, 0.5, 0.9, 0.99], np.float32) - np.float32(0.5 / 2**24)
    kernels._uniform_to_normal(u)
    assert u == pytest.approx(ppf, abs=1e-5)


def test_scatter_matches_numpy():
    states = np.zeros((50, 6), np.float32)
    state = np.array([10, 20, 8, 9, 1, -1], np.float32)
    noise = np.random.default_rng(2).standard_normal((50, 6), dtype=np.float32)
    sigma = np.array([4, 3, 1, 1, 1, 0.5], np.float32)
    lo, hi = np.array([7.5, 8], np.float32), np.array([8.5, 10], np.float32)
    kernels.scatter(states, state, noise, sigma, lo, hi)
    expect = state + noise * sigma
    expect[:, 2:4] = np.minimum(np.maximum(expect[:, 2:4], lo), hi)
    assert np.array_equal(states, expect)


def test_fused_resample_matches_the_two_steps():
    rng = np.random.default_rng(11)
    particles = rng.normal(0, 5, (300, 6)).astype(np.float32)
    w = rng.random(300) ** 8
    w /= w.sum()
    new, weights = kernels.resample(particles, w, 1.2, 200, 1000, 0.37)
    n = kernels.entropy_count(w, 1.2, 200, 1000)
    assert len(new) == n and 200 <= n < 360  # peaked weights: fewer than C N
    assert np.array_equal(new, particles[kernels.systematic_indices(w, n, 0.37)])
    assert np.all(weights == 1.0 / n)


def test_prepare_sets_up_numba_without_blas_or_cffi_and_leaves_them_importable():
    """``kernels.prepare`` keeps scipy's BLAS and cffi out of numba's set-up (start-up time), yet a
    later import of either works and the kernels compute as before (a fresh process: the set-up
    happens once per process)."""
    code = (
        "import sys\n"
        "import numpy as np\n"
        "from partlab.tracking.core import kernels\n"
        "kernels.prepare()\n"
        "assert 'scipy.linalg' not in sys.modules and 'cffi' not in sys.modules, sorted(sys.modules)\n"
        "from numba.np import arraymath\n"
        "assert arraymath._HAVE_BLAS is False\n"
        "import cffi, scipy.linalg.cython_blas, scipy.linalg\n"
        "print(scipy.linalg.solve(np.eye(2) * 2.0, np.ones(2)).tolist(), cffi.FFI().sizeof('int'))\n"
        "states = np.array([[10.4, 20.6, 5.0, 7.0], [0.0, 0.0, 50.0, 50.0]], np.float32)\n"
        "print(kernels.rectangles(states, 30, 30).tolist())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[0] == "[0.5, 0.5] 4"
    assert out[1] == "[[8, 17, 13, 24], [0, 0, 25, 25]]"
