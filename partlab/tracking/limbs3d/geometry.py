"""Candidate 3D points from pairs of views (sec. 6.1 and 6.3, eq. 16, 18, 20-24).

A blob's centre of mass in camera ``m`` defines a line of sight ``(v, p)`` in the world frame
(eq. 20-21: the paper intersects two planes of the projection matrix; with a calibrated
:class:`~partlab.tracking.camera.Camera` the line is its optical centre ``p`` and the ray direction
``v`` through the undistorted pixel, the same line). Two lines from two cameras almost never meet:
the candidate point is the midpoint of their common perpendicular (eq. 22), with ``c = (c1, c2, c3)``
solving ``[v_m, -v_m', v_m x v_m'] c = p_m' - p_m`` (eq. 23; the text's version is garbled), and half
the length of that perpendicular is the reconstruction error ``d`` (eq. 24). Every pair of blobs of
every pair of cameras gives one candidate (eq. 16), ``sum_{m < m'} N_m N_m'`` of them (eq. 18).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from partlab.tracking.camera import Camera


def lines_of_sight(camera: Camera, pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(N, 2)`` pixels -> points ``p (N, 3)`` and unit directions ``v (N, 3)`` (eq. 20-21)."""
    v = camera.rays(pixels)
    return np.repeat(camera.centre[None], len(v), axis=0), v


def midpoints(p1: np.ndarray, v1: np.ndarray, p2: np.ndarray, v2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Midpoints ``Z (N, 3)`` of the common perpendiculars of ``N`` pairs of lines and their
    errors ``d (N,)`` (eq. 22-24). Parallel lines give NaN."""
    n = np.cross(v1, v2)
    A = np.stack([v1, -v2, n], axis=-1)  # columns v_m, -v_m', v_m x v_m'
    b = p2 - p1
    ok = np.abs(np.linalg.det(A)) > 1e-12
    c = np.full((len(A), 3), np.nan)
    if ok.any():
        c[ok] = np.linalg.solve(A[ok], b[ok][..., None])[..., 0]
    a1 = p1 + v1 * c[:, :1]
    a2 = p2 + v2 * c[:, 1:2]
    return (a1 + a2) / 2, np.linalg.norm(a1 - a2, axis=1) / 2


@dataclass(frozen=True)
class PairCandidates:
    """Candidates of one frame (eq. 16): ``points (C, 3)`` mm, ``error (C,)`` eq. 24's ``d`` (mm),
    and for each the two views and blobs it came from: ``views (C, 2)`` indexes into the view
    list, ``blobs (C, 2)`` indexes into each view's blobs."""

    points: np.ndarray
    error: np.ndarray
    views: np.ndarray
    blobs: np.ndarray

    def __len__(self) -> int:
        return int(self.error.size)


def pair_candidates(cameras: list[Camera], centres: list[np.ndarray]) -> PairCandidates:
    """Every blob of every view paired with every blob of every later view (eq. 16, 18)."""
    lines = [lines_of_sight(c, np.asarray(x, float).reshape(-1, 2)) for c, x in zip(cameras, centres)]
    P, E, V, B = [], [], [], []
    for m in range(len(cameras)):
        for m2 in range(m + 1, len(cameras)):
            n1, n2 = len(lines[m][0]), len(lines[m2][0])
            if n1 == 0 or n2 == 0:
                continue
            i, j = np.meshgrid(np.arange(n1), np.arange(n2), indexing="ij")
            i, j = i.ravel(), j.ravel()
            z, d = midpoints(lines[m][0][i], lines[m][1][i], lines[m2][0][j], lines[m2][1][j])
            P.append(z)
            E.append(d)
            V.append(np.stack([np.full(i.size, m), np.full(i.size, m2)], 1))
            B.append(np.stack([i, j], 1))
    if not P:
        return PairCandidates(np.zeros((0, 3)), np.zeros(0), np.zeros((0, 2), int), np.zeros((0, 2), int))
    return PairCandidates(np.concatenate(P), np.concatenate(E), np.concatenate(V), np.concatenate(B))
