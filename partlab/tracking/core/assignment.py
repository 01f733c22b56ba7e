"""The linear assignment problem (the Hungarian method) for the trackers' small matrices.

The shortest augmenting path method of Crouse (2016, "On implementing 2D rectangular assignment
algorithms", IEEE Trans. Aerospace and Electronic Systems 52(4)), step for step as SciPy's
``scipy.optimize.linear_sum_assignment`` implements it, ties included, so it returns the same pairs.
It is here because importing ``scipy.optimize`` costs a 5-frame ``partlab track`` more than its
frames do (its package imports the whole optimiser); the trackers assign tens of tracks to tens of
detections a frame, where plain Python takes microseconds.
"""

from __future__ import annotations

import math

import numpy as np


def _augmenting_path(cost: list[list[float]], u: list[float], v: list[float], path: list[int],
                     row4col: list[int], spc: list[float], i: int, sr: list[bool],
                     sc: list[bool]) -> tuple[int, float]:
    """The sink column of the shortest augmenting path from row ``i`` and its length."""
    nc = len(v)
    remaining = list(range(nc - 1, -1, -1))
    num_remaining = nc
    for j in range(nc):
        sc[j] = False
        spc[j] = math.inf
    for r in range(len(sr)):
        sr[r] = False
    min_val = 0.0
    sink = -1
    while sink == -1:
        index = -1
        lowest = math.inf
        sr[i] = True
        row, ui = cost[i], u[i]
        for it in range(num_remaining):
            j = remaining[it]
            r = min_val + row[j] - ui - v[j]
            if r < spc[j]:
                path[j] = i
                spc[j] = r
            if spc[j] < lowest or (spc[j] == lowest and row4col[j] == -1):
                lowest = spc[j]
                index = it
        min_val = lowest
        if min_val == math.inf:  # no column left that row i may take
            return -1, min_val
        j = remaining[index]
        if row4col[j] == -1:
            sink = j
        else:
            i = row4col[j]
        sc[j] = True
        num_remaining -= 1
        remaining[index] = remaining[num_remaining]
    return sink, min_val


def linear_sum_assignment(cost_matrix, maximize: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``(rows, cols)`` of the assignment of least (``maximize``: greatest) total cost, rows
    ascending; as ``scipy.optimize.linear_sum_assignment``. Raises ValueError for NaN or an
    infeasible matrix."""
    cost = np.asarray(cost_matrix, dtype=np.float64)
    if cost.ndim != 2:
        raise ValueError(f"expected a matrix (2-D array), got a {cost.ndim}-D array")
    if cost.size == 0:
        return np.empty(0, dtype=np.intp), np.empty(0, dtype=np.intp)
    transpose = cost.shape[1] < cost.shape[0]
    if transpose:
        cost = cost.T
    if maximize:
        cost = -cost
    if np.isnan(cost).any() or (cost == -np.inf).any():
        raise ValueError("matrix contains invalid numeric entries")
    nr, nc = cost.shape
    rows = cost.tolist()
    u, v = [0.0] * nr, [0.0] * nc
    spc = [math.inf] * nc
    path, col4row, row4col = [-1] * nc, [-1] * nr, [-1] * nc
    sr, sc = [False] * nr, [False] * nc
    for cur in range(nr):
        sink, min_val = _augmenting_path(rows, u, v, path, row4col, spc, cur, sr, sc)
        if sink < 0:
            raise ValueError("cost matrix is infeasible")
        u[cur] += min_val  # update the dual variables
        for i in range(nr):
            if sr[i] and i != cur:
                u[i] += min_val - spc[col4row[i]]
        for j in range(nc):
            if sc[j]:
                v[j] -= min_val - spc[j]
        j = sink  # augment the previous solution
        while True:
            i = path[j]
            row4col[j] = i
            col4row[i], j = j, col4row[i]
            if i == cur:
                break
    if transpose:
        order = sorted(range(nr), key=col4row.__getitem__)
        return np.array([col4row[k] for k in order], dtype=np.intp), np.array(order, dtype=np.intp)
    return np.arange(nr, dtype=np.intp), np.array(col4row, dtype=np.intp)
