"""Equalized histograms (seed 002 sec. 3.1) and integral-histogram batching."""

from __future__ import annotations

import numpy as np
import pytest

from partlab.tracking.core.histogram import (
    bhattacharyya,
    binned_histogram,
    equalization_map,
    fused_lut,
    level_histogram,
    onehot_lut,
    uniform_map,
    update_reference,
)
from partlab.tracking.core.integral_histogram import particle_rectangles, rectangle_histograms


def _patch(rng, means, sd=5.0, shape=(40, 30)):
    out = np.empty(shape + (3,), dtype=np.uint8)
    for c, m in enumerate(means):
        out[..., c] = np.clip(rng.normal(m, sd, shape), 0, 255).astype(np.uint8)
    return out


def test_equalization_map_spreads_reference_evenly():
    rng = np.random.default_rng(0)
    ref = level_histogram(_patch(rng, (120, 140, 110)))
    mapping = equalization_map(ref, bins=8)
    z = binned_histogram(ref, mapping).reshape(3, 8)
    # every bin of every channel holds a real share of the reference (uniform: 0.125)
    assert z.min() > 0.03
    assert z.max() < 0.3
    # the plain map puts almost all of it into one or two bins
    raw = binned_histogram(ref, uniform_map(8)).reshape(3, 8)
    assert raw.max() > 0.6


def test_equalization_separates_close_colours_better_than_raw_bins():
    """Sec. 5.1 in small: two regions whose colours differ slightly look alike with
    uniform bins and clearly different with the target's equalization map."""
    rng = np.random.default_rng(1)
    target = level_histogram(_patch(rng, (120, 140, 110)))
    same = level_histogram(_patch(rng, (120, 140, 110)))
    close = level_histogram(_patch(rng, (132, 146, 104)))
    eq = equalization_map(target)
    raw = uniform_map()
    def rho(h, m):
        return float(bhattacharyya(binned_histogram(h, m), binned_histogram(target, m)))

    assert rho(same, eq) > 0.95
    assert rho(close, raw) > 0.8           # raw bins: hardly distinguishable
    assert rho(close, eq) < 0.8            # equalized: clearly different
    gap_eq = rho(same, eq) - rho(close, eq)
    gap_raw = rho(same, raw) - rho(close, raw)
    assert gap_eq > 2 * gap_raw


def test_model_update_is_eq1():
    a = np.zeros((3, 256))
    a[:, 10] = 1
    b = np.zeros((3, 256))
    b[:, 20] = 1
    u = update_reference(a, b, 0.1)
    assert u[0, 10] == pytest.approx(0.9) and u[0, 20] == pytest.approx(0.1)
    assert u.sum(axis=1) == pytest.approx([1, 1, 1])


def test_integral_histograms_match_direct_counts():
    rng = np.random.default_rng(2)
    ycc = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
    mapping = equalization_map(level_histogram(ycc[10:30, 10:30]))
    lut = onehot_lut(mapping)
    states = np.array([[20, 20, 10, 12, 0, 0], [50, 30, 21, 30, 0, 0], [78, 58, 10, 10, 0, 0]], np.float32)
    rects = particle_rectangles(states, 80, 60)
    got = rectangle_histograms(ycc, lut, rects)
    for (x1, y1, x2, y2), row in zip(rects, got):
        direct = binned_histogram(level_histogram(ycc[y1:y2, x1:x2]) * (x2 - x1) * (y2 - y1), mapping)
        assert row == pytest.approx(direct)
    # the last box is clipped at the frame's corner: 3 x 3 pixels remain (73..76 -> clipped 73..80)
    assert rects[2].tolist() == [73, 53, 80, 60]
    assert got[2].sum() == pytest.approx(3 * 7 * 7)


def test_strided_integral_histograms_count_the_sampled_pixels():
    from partlab.tracking.core.integral_histogram import sampled_areas

    rng = np.random.default_rng(4)
    ycc = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
    mapping = equalization_map(level_histogram(ycc[10:30, 10:30]))
    lut = fused_lut(mapping)
    rects = np.array([[11, 13, 40, 41], [12, 14, 13, 15], [20, 30, 61, 60]], np.int32)
    got = rectangle_histograms(ycc, lut, rects, stride=2)
    sub = ycc[13::2, 11::2]  # the grid starts at the union's corner (11, 13)
    for (x1, y1, x2, y2), row, area in zip(rects, got, sampled_areas(rects, 2)):
        kx = slice(-((11 - x1) // 2), -((11 - x2) // 2))
        ky = slice(-((13 - y1) // 2), -((13 - y2) // 2))
        part = sub[ky, kx]
        assert area == part.shape[0] * part.shape[1]
        direct = binned_histogram(level_histogram(part) * area, mapping)
        assert row == pytest.approx(direct)
    # 29 x 28 pixels -> 15 x 14 samples; the 1 x 1 rectangle at an odd offset has none;
    # 41 x 30 pixels starting 9 and 17 px into the grid -> 20 x 15
    assert sampled_areas(rects, 2).tolist() == [210.0, 0.0, 300.0]
