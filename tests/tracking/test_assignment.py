"""The trackers' own Hungarian method gives SciPy's pairs, ties included (so tracks are the same
as with ``scipy.optimize.linear_sum_assignment``, which it replaces on the tracking path)."""

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment as scipy_lsa

from partlab.tracking.core.assignment import linear_sum_assignment


def matrices(seed: int, count: int):
    rng = np.random.default_rng(seed)
    for k in range(count):
        r, c = (int(v) for v in rng.integers(1, 10, 2))
        kind = k % 4
        if kind == 0:
            yield rng.random((r, c))
        elif kind == 1:  # integer costs: many ties between equal assignments
            yield rng.integers(0, 3, (r, c)).astype(float)
        elif kind == 2:  # gated pairs as associate() builds them
            yield np.where(rng.random((r, c)) < 0.5, 1e6, rng.random((r, c)))
        else:
            yield -np.round(rng.random((r, c)), 1)


@pytest.mark.parametrize("maximize", [False, True])
def test_same_pairs_as_scipy_on_square_rectangular_and_tied_matrices(maximize):
    for m in matrices(7, 1500):
        want, got = scipy_lsa(m, maximize=maximize), linear_sum_assignment(m, maximize=maximize)
        assert np.array_equal(want[0], got[0]) and np.array_equal(want[1], got[1]), m


def test_a_known_optimum_empty_matrices_and_bad_input():
    cost = np.array([[4.0, 1.0, 3.0], [2.0, 0.0, 5.0], [3.0, 2.0, 2.0]])
    rows, cols = linear_sum_assignment(cost)
    assert rows.tolist() == [0, 1, 2] and cols.tolist() == [1, 0, 2] and cost[rows, cols].sum() == 5.0
    rows, cols = linear_sum_assignment(np.zeros((0, 4)))
    assert rows.shape == cols.shape == (0,)
    with pytest.raises(ValueError, match="invalid"):
        linear_sum_assignment(np.array([[np.nan, 1.0]]))
    with pytest.raises(ValueError, match="infeasible"):
        linear_sum_assignment(np.array([[np.inf, np.inf], [1.0, 2.0]]))
