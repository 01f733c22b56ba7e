"""Weighting (Migniot & Ababsa sec. 2.3.1-2.4): how well a model state fits the depth points.

For a particle ``i`` and every ROI point (a depth pixel back-projected to the world), the point's
distance to the model is the distance to its nearest primitive, and the point belongs to that
primitive's weighting part (Fig. 3, eq. 3). :func:`weigh` returns, per particle and part, the sum
of these distances, the number of points and a colour histogram of those points, from which

* eq. (1): ``omega_i = exp(-d_ch_i / s)``, ``d_ch_i`` the mean 3D distance of the points to the
  model (the text lost the minus sign; ``s`` makes millimetres unitless), and
* eq. (2): ``omega_i = exp(-(d_ch_i / s + lambda * d_bh_i))``, ``d_bh_i`` the sum over parts of the
  Bhattacharyya distances of each part's histogram to the previous estimate's,

are computed either once per particle (the global "3D model") or once per part with only the
points nearest that part (the part-based model, eq. 3). The hot loop (particles x points x
primitives) is one compiled numba kernel; :func:`nearest` is the same distance for a single model,
for the exclusion principle (eq. 5) and for the evaluation's epsilon.
"""

from __future__ import annotations

import math

import numpy as np

from partlab.tracking.core.kernels import _jit
from partlab.tracking.topview.model import KINDS, N_PARTS, PART_OF, RECTANGLE, SPHERE


@_jit(inline="always", fastmath=True)
def _distance(px, py, pz, prim, kind):
    """Unsigned distance (mm) of point ``p`` to the surface of one packed primitive."""
    dx, dy, dz = px - prim[0], py - prim[1], pz - prim[2]
    if kind == SPHERE:
        return abs(math.sqrt(dx * dx + dy * dy + dz * dz) - prim[12])
    q1 = dx * prim[3] + dy * prim[4] + dz * prim[5]
    q2 = dx * prim[6] + dy * prim[7] + dz * prim[8]
    q3 = dx * prim[9] + dy * prim[10] + dz * prim[11]
    a, b, L = prim[12], prim[13], prim[14]
    if kind == RECTANGLE:
        ex = max(abs(q1) - a, 0.0)
        ez = max(abs(q3) - L, 0.0)
        return math.sqrt(q2 * q2 + ex * ex + ez * ez)
    # (elliptic) cylinder: radial distance along the ray from the axis (exact when a == b)
    rho = math.sqrt(q1 * q1 + q2 * q2)
    rn = math.sqrt((q1 / a) ** 2 + (q2 / b) ** 2)
    dr = rho - rho / rn if rn > 1e-9 else -min(a, b)
    if q3 < 0.0:
        da = -q3
    elif q3 > L:
        da = q3 - L
    else:
        if dr >= 0.0:
            return dr
        return min(-dr, q3, L - q3)
    if dr <= 0.0:
        return da
    return math.sqrt(dr * dr + da * da)


@_jit(fastmath=True)
def _weigh(points, bins, prims, kinds, part_of, n_parts, n_bins):
    n_p, n_k = prims.shape[0], prims.shape[1]
    m = points.shape[0]
    sums = np.zeros((n_p, n_parts))
    counts = np.zeros((n_p, n_parts))
    hist = np.zeros((n_p, n_parts, max(n_bins, 1)))
    for i in range(n_p):
        for j in range(m):
            px, py, pz = points[j, 0], points[j, 1], points[j, 2]
            best = 1e30
            part = 0
            for k in range(n_k):
                d = _distance(px, py, pz, prims[i, k], kinds[k])
                if d < best:
                    best = d
                    part = part_of[k]
            sums[i, part] += best
            counts[i, part] += 1.0
            if n_bins > 0:
                hist[i, part, bins[j]] += 1.0
    return sums, counts, hist


@_jit(fastmath=True)
def _nearest(points, prims, kinds):
    m, n_k = points.shape[0], prims.shape[0]
    dist = np.empty(m, np.float32)
    prim = np.empty(m, np.int64)
    for j in range(m):
        best = 1e30
        bp = 0
        for k in range(n_k):
            d = _distance(points[j, 0], points[j, 1], points[j, 2], prims[k], kinds[k])
            if d < best:
                best = d
                bp = k
        dist[j] = best
        prim[j] = bp
    return dist, prim


def weigh(points: np.ndarray, prims: np.ndarray, bins: np.ndarray | None = None, n_bins: int = 0):
    """Per particle and weighting part: ``sums (P, 5)`` of point-to-model distances (mm),
    ``counts (P, 5)`` of points nearest that part, ``hist (P, 5, n_bins)`` colour counts.

    ``points``: ``(M, 3)`` world mm; ``prims``: ``(P, K, 16)`` from
    :func:`partlab.tracking.topview.model.primitives`; ``bins``: ``(M,)`` colour bin of each point
    (None: no colour, ``hist`` is all zero)."""
    pts = np.ascontiguousarray(points, np.float32)
    b = np.zeros(len(pts), np.int64) if bins is None else np.ascontiguousarray(bins, np.int64)
    nb = 0 if bins is None else int(n_bins)
    return _weigh(pts, b, np.ascontiguousarray(prims, np.float32), KINDS, PART_OF, N_PARTS, nb)


def nearest(points: np.ndarray, prims: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For one model (``prims (K, 16)``): each point's distance to it ``(M,)`` mm and its nearest
    weighting part ``(M,)``."""
    dist, prim = nearest_primitive(points, prims)
    return dist, PART_OF[prim]


def nearest_primitive(points: np.ndarray, prims: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """As :func:`nearest`, with each point's nearest primitive ``(M,)`` (index into
    :data:`partlab.tracking.topview.model.PRIMITIVES`) instead of its part."""
    pts = np.ascontiguousarray(points, np.float32).reshape(-1, 3)
    return _nearest(pts, np.ascontiguousarray(prims, np.float32).reshape(-1, 16), KINDS)


def bhattacharyya(hist: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Bhattacharyya distance ``sqrt(1 - sum sqrt(h r))`` of normalised histograms along the last
    axis (Nummiaro et al.); an empty histogram is at distance 1."""
    h = hist / np.maximum(hist.sum(-1, keepdims=True), 1e-12)
    r = reference / np.maximum(reference.sum(-1, keepdims=True), 1e-12)
    bc = np.sqrt(h * r).sum(-1)
    return np.sqrt(np.clip(1.0 - bc, 0.0, 1.0))


def colour_bins(bgr: np.ndarray, levels: int) -> np.ndarray:
    """The colour bin of each ``(M, 3) uint8`` BGR colour: ``levels`` levels per channel."""
    q = (np.asarray(bgr, np.int64) * levels) >> 8
    return (q[:, 0] * levels + q[:, 1]) * levels + q[:, 2]


# -- partlab's addition: the free-space check --------------------------------------------------
#
# Eq. 1 measures the data against the model only: a part placed where nothing is seen claims no
# points and pays nothing, and with per-part weights (eq. 3) an arm that slides off the real arm
# keeps a low mean over the few points it still claims while the points it gave up raise the
# *torso's* cost. The check below closes that gap the usual way of depth trackers: points on the
# top surface of each primitive (what a camera above sees) are projected into the depth image,
# and where the sensor sees *farther* than the model (the model would hide what is seen: floor
# where an arm should be), the difference, capped, is charged to the primitive's part. Where the
# sensor sees nearer (the part is hidden under another) or nothing, it costs nothing.

def surface_samples(prims: np.ndarray, kinds: np.ndarray = KINDS) -> tuple[np.ndarray, np.ndarray]:
    """``(P, S, 3)`` world points on the upper surfaces of ``(P, K, 16)`` primitives and the
    weighting part ``(S,)`` of each."""
    O, e1, e2, e3 = prims[..., 0:3], prims[..., 3:6], prims[..., 6:9], prims[..., 9:12]
    a, b, L = prims[..., 12:13], prims[..., 13:14], prims[..., 14:15]
    up = np.array([0.0, 0.0, 1.0], np.float32)
    out, parts = [], []
    for k, kind in enumerate(kinds):
        if kind == SPHERE:
            for dx, dy, dz in ((0, 0, 1), (0.6, 0, 0.8), (-0.6, 0, 0.8), (0, 0.6, 0.8), (0, -0.6, 0.8)):
                out.append(O[:, k] + a[:, k] * np.array([dx, dy, dz], np.float32))
        elif kind == RECTANGLE:
            for f in (-0.6, 0.0, 0.6):
                out.append(O[:, k] + f * L[:, k] * e3[:, k])
        elif k in (1,):  # the shoulders' slab: its top cap
            top = O[:, k] + L[:, k] * e3[:, k]
            for da, db in ((0, 0), (0.6, 0), (-0.6, 0), (0, 0.6), (0, -0.6)):
                out.append(top + da * a[:, k] * e1[:, k] + db * b[:, k] * e2[:, k])
        else:  # a cylinder: along the axis, on the side that faces up
            u = up - (e3[:, k] @ up)[:, None] * e3[:, k]
            u = u / np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-6)
            r = np.minimum(a[:, k], b[:, k])
            for f in (0.2, 0.5, 0.8):
                out.append(O[:, k] + f * L[:, k] * e3[:, k] + r * u)
        parts.extend([PART_OF[k]] * (len(out) - len(parts)))
    return np.stack(out, axis=1), np.array(parts, np.int64)


def free_space(prims: np.ndarray, depth: np.ndarray, camera, cap_mm: float) -> np.ndarray:
    """``(P, 5)`` mean free-space violation (mm, capped at ``cap_mm``) of each part's surface
    samples: how much farther than the model the sensor sees along the samples' lines of sight."""
    pts, part = surface_samples(prims)
    n_p, n_s = pts.shape[:2]
    flat = pts.reshape(-1, 3).astype(np.float64)
    uv = np.rint(camera.project(flat)).astype(np.int64)
    z_model = camera.to_camera(flat)[:, 2]
    h, w = depth.shape
    inside = (uv[:, 0] >= 0) & (uv[:, 0] < w) & (uv[:, 1] >= 0) & (uv[:, 1] < h)
    z_obs = np.full(len(flat), np.nan)
    z_obs[inside] = depth[uv[inside, 1], uv[inside, 0]]
    pen = np.nan_to_num(np.clip(z_obs - z_model, 0.0, cap_mm), nan=0.0).reshape(n_p, n_s)
    out = np.zeros((n_p, N_PARTS))
    np.add.at(out.T, part, pen.T)
    return out / np.maximum(np.bincount(part, minlength=N_PARTS), 1)


# -- partlab's addition: the body's own volume -----------------------------------------------
#
# Seen from above, a forearm or hand under the person's own torso or head is hidden: eq. 1 finds
# its surface near the torso's points and the free-space check sees the sensor *nearer* than the
# model, so neither charges a hand pushed *into* the torso, where it explains the torso's points
# at almost no distance. A body cannot pass through itself: the axis points of each forearm and
# hand are checked against the torso's elliptic cylinder and the head's sphere, and how deep the
# segment's surface goes into them (capped) is charged to the arm's part.

_ARM_SAMPLES = ((4, 0.0), (4, 0.5), (4, 1.0), (5, 0.0), (7, 0.0), (7, 0.5), (7, 1.0), (8, 0.0))


def self_intersection(prims: np.ndarray, cap_mm: float) -> np.ndarray:
    """``(P, 5)`` mean depth (mm, capped at ``cap_mm``) by which the forearms and hands of ``(P, K,
    16)`` primitives go into their own torso or head, in the arms' columns (0 elsewhere)."""
    torso, slab, head = prims[:, 2], prims[:, 1], prims[:, 0]
    O, e1, e2, e3 = torso[:, None, 0:3], torso[:, None, 3:6], torso[:, None, 6:9], torso[:, None, 9:12]
    a, b = torso[:, None, 12], torso[:, None, 13]
    length = torso[:, None, 14] + slab[:, None, 14]
    k = np.array([s[0] for s in _ARM_SAMPLES])
    f = np.array([s[1] for s in _ARM_SAMPLES], np.float32)
    seg = prims[:, k]
    pts = seg[..., 0:3] + (f * seg[..., 14])[..., None] * seg[..., 9:12]  # (P, S, 3) on the axes
    radius = np.where(k % 3 == 2, 0.5 * seg[..., 12], seg[..., 12])  # a hand: half its half-width
    q = pts - O
    q1, q2, q3 = (q * e1).sum(-1), (q * e2).sum(-1), (q * e3).sum(-1)
    rn = np.sqrt((q1 / a) ** 2 + (q2 / b) ** 2)
    along = np.minimum(q3, length - q3)  # how far inside the cylinder's length the point is
    into_torso = np.minimum(radius - (rn - 1.0) * np.minimum(a, b), radius + along)
    into_head = radius + head[:, None, 12] - np.linalg.norm(pts - head[:, None, 0:3], axis=-1)
    pen = np.clip(np.maximum(into_torso, into_head), 0.0, cap_mm)
    out = np.zeros((len(prims), N_PARTS))
    half = len(_ARM_SAMPLES) // 2
    out[:, PART_OF[4]] = pen[:, :half].mean(1)
    out[:, PART_OF[7]] = pen[:, half:].mean(1)
    return out
