"""Xu, Deng & Jia sec. 2 (depth foreground) and sec. 4, Table 1 (hand candidate regions).

Depth here is millimetres along the optical axis (partlab's :class:`~partlab.tracking.frame.Frame`
convention), NaN where unmeasured. The paper's depth maps are stereo *disparities*, which grow as
things come nearer, and Table 1 is written for them: step 2 keeps ``d > d_f + lambda sd_f`` (nearer
than the face) and step 4 a) weights the centroid by ``d`` (pulling it to the nearest pixels). In
millimetres both flip: step 2 keeps ``d < d_f - lambda sd_f`` and step 4 weights each kept pixel by
how far it lies in front of the threshold, ``ds_thre - d`` (0 at the threshold, largest at the
fingertips), which is what the disparity weight does up to an offset.

*Our addition*, :func:`support_surfaces`: a desk top (or any large flat surface) in front of the
person passes step 2's test like a hand. Step 3 rejects its component by size, but a hand resting on
it (or joined to it by a stereo pair's blurred edges) is then rejected with it, and the hands'
observation (which keeps every pixel in front of the face, sec. 4) lets a skin-hued desk pull the
hands onto its front edge. Large planes among the pixels in front of the face are found by RANSAC
(Fischler & Bolles) in 3D and their pixels taken out of both; a hand is not flat over several face
areas, so it stays.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from partlab.tracking.depth.params import DepthCue


@dataclass(frozen=True)
class FaceDepth:
    """Table 1 step 1: mean ``d_f`` and standard deviation ``sd_f`` (mm) of the face box's depth."""

    mean: float
    sd: float
    width_mm: float  # the face box's width at that depth (the unit of the size thresholds)


def face_depth(depth: np.ndarray, box, fx: float) -> FaceDepth | None:
    """Step 1 over the face box ``x, y, w, h``; None when the box holds no measured depth."""
    x, y, w, h = (int(round(v)) for v in box)
    hgt, wid = depth.shape
    patch = depth[max(y, 0):min(y + h, hgt), max(x, 0):min(x + w, wid)]
    vals = patch[np.isfinite(patch)]
    if vals.size < 4:
        return None
    # the face box also holds some background at its corners: keep the near half's spread
    med = float(np.median(vals))
    vals = vals[np.abs(vals - med) < 0.5 * med * w / max(fx, 1e-6) + 1.0]  # within a face width
    mean = float(vals.mean()) if vals.size else med
    sd = float(vals.std()) if vals.size else 0.0
    return FaceDepth(mean, sd, max(w, 1) * mean / max(fx, 1e-6))


def depth_foreground(depth: np.ndarray, face: FaceDepth, p: DepthCue) -> np.ndarray:
    """Sec. 2: ``(H, W) float32`` 1 where the depth is nearer than the face plus a margin (the
    person and what is in front of them), 0 elsewhere and where depth is missing."""
    thre = face.mean + p.foreground_margin * face.width_mm
    with np.errstate(invalid="ignore"):
        return (depth < thre).astype(np.float32)


@dataclass(frozen=True)
class HandRegion:
    """Table 1 step 4 d): the region ``R = (x_c, y_c, w, h)`` (centre and size, pixels)."""

    xc: float
    yc: float
    w: float
    h: float
    coarse: tuple[int, int, int, int]  # step 3's bounding rectangle x, y, w, h


def support_surfaces(depth: np.ndarray, near: np.ndarray, K: np.ndarray, face: FaceDepth, face_px: float,
                     p: DepthCue, rng: np.random.Generator) -> np.ndarray | None:
    """``(H, W) bool``: the pixels of ``near`` (in front of the face, depth measured) that lie on a
    plane covering at least ``p.surface_area`` face areas (up to ``p.surface_planes`` planes, each
    within ``p.surface_tol`` face widths); None when there is none.

    RANSAC, vectorised: ``p.surface_hypotheses`` planes through 3 random points of a grid subsample
    (every ``p.surface_step``-th pixel each way) are scored at once by their inliers; the best is
    refitted to its inliers by least squares (the smallest singular vector) and tested on every pixel."""
    step = p.surface_step
    need = p.surface_area * face_px / step ** 2  # grid points a large enough plane holds
    sub = near[::step, ::step]
    if sub.sum() < need:
        return None
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    hgt, wid = depth.shape
    vv, uu = np.mgrid[0:hgt:step, 0:wid:step]
    z = depth[::step, ::step][sub].astype(np.float64)
    pts = np.stack([(uu[sub] - cx) * z / fx, (vv[sub] - cy) * z / fy, z], 1)
    tol = p.surface_tol * face.width_mm
    out = np.zeros_like(near)
    left = np.ones(len(pts), bool)
    for _ in range(p.surface_planes):
        cand = np.flatnonzero(left)
        if len(cand) < need:
            break
        tri = pts[cand[rng.integers(0, len(cand), (p.surface_hypotheses, 3))]]  # (M, 3, 3)
        normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        norm = np.linalg.norm(normal, axis=1)
        good = norm > 1e-9
        if not good.any():
            break
        normal = normal[good] / norm[good, None]
        offset = np.einsum("mk,mk->m", normal, tri[good, 0])
        inl = np.abs(pts[cand] @ normal.T - offset) < tol  # (n, M)
        best = int(np.argmax(inl.sum(0)))
        if inl[:, best].sum() < need:
            break
        # least squares on the inliers: the plane through their mean, normal = least spread
        q = pts[cand[inl[:, best]]]
        centre = q.mean(0)
        normal = np.linalg.svd(q - centre, full_matrices=False)[2][-1]
        on = np.abs((pts - centre) @ normal) < tol
        left &= ~on
        out |= _on_plane(depth, near, K, centre, normal, tol)
    return out if out.any() else None


def _on_plane(depth, near, K, centre, normal, tol) -> np.ndarray:
    """Every pixel of ``near`` whose 3D point lies within ``tol`` of the plane (centre, normal)."""
    hgt, wid = depth.shape
    vv, uu = np.nonzero(near)
    z = depth[vv, uu].astype(np.float64)
    pts = np.stack([(uu - K[0, 2]) * z / K[0, 0], (vv - K[1, 2]) * z / K[1, 1], z], 1)
    out = np.zeros((hgt, wid), bool)
    out[vv, uu] = np.abs((pts - centre) @ normal) < tol
    return out


def hand_regions(depth: np.ndarray, face: FaceDepth, face_box, fx: float, p: DepthCue,
                 max_regions: int = 2, surfaces: np.ndarray | None = None) -> list[HandRegion]:
    """Table 1 steps 2-4: up to ``max_regions`` hand candidate regions, largest first (pixels on
    ``surfaces``, :func:`support_surfaces`, are not hands)."""
    # step 2 (in mm; see the module docstring): nearer than the face by lambda sd_f
    gap = max(p.lam * face.sd, p.min_gap * face.width_mm)
    thre = face.mean - gap
    with np.errstate(invalid="ignore"):
        keep = depth < thre
    if surfaces is not None:
        keep &= ~surfaces
    weight = np.where(keep, thre - depth, 0.0).astype(np.float32)
    # step 3: connected components of proper size (in face areas)
    face_px = max(float(face_box[2]) * float(face_box[3]), 1.0)
    n, _, stats, _ = cv2.connectedComponentsWithStats(keep.view(np.uint8), connectivity=8)
    area = stats[1:, cv2.CC_STAT_AREA].astype(float)
    ok = np.flatnonzero((area >= p.min_area * face_px) & (area <= p.max_area * face_px)) + 1
    ok = ok[np.argsort(-stats[ok, cv2.CC_STAT_AREA])]
    if not len(ok):
        return []
    # step 4: integral images of d', x d', y d' make each iteration's centroid four lookups
    hgt, wid = weight.shape
    xs = np.arange(wid, dtype=np.float64)[None, :]
    ys = np.arange(hgt, dtype=np.float64)[:, None]
    w64 = weight.astype(np.float64)
    integ = [cv2.integral(a) for a in (w64, w64 * xs, w64 * ys)]
    out = []
    longest = p.max_extent * float(face_box[2])
    for k in ok:
        x, y, w, h = (int(v) for v in stats[k, :4])
        box = _refine(integ, float(x), float(y), float(x + w - 1), float(y + h - 1), p)
        xl, yl, xu, yu = box
        region = HandRegion((xl + xu) / 2, (yl + yu) / 2, max(xu - xl + 1, 1.0), max(yu - yl + 1, 1.0), (x, y, w, h))
        if max(region.w, region.h) <= longest:  # not a long streak (a stereo pair's noise on a desk's edge)
            out.append(region)
        if len(out) == max_regions:
            break
    return out


def _sums(integ, xl, yl, xu, yu):
    x1, y1, x2, y2 = int(np.floor(xl)), int(np.floor(yl)), int(np.floor(xu)) + 1, int(np.floor(yu)) + 1
    return [float(ii[y2, x2] - ii[y1, x2] - ii[y2, x1] + ii[y1, x1]) for ii in integ]


def _refine(integ, xl, yl, xu, yu, p: DepthCue):
    """Step 4 a)-c): move the edge on the far side of the centroid until the rectangle's centre
    is its depth-weighted centroid (a local minimum of depth)."""
    for _ in range(p.max_iterations):
        s, sx, sy = _sums(integ, xl, yl, xu, yu)
        if s <= 0:
            break
        cxp, cyp = sx / s, sy / s  # a) the centroid
        xc, yc = (xl + xu) / 2, (yl + yu) / 2
        if abs(xc - cxp) < p.eps and abs(yc - cyp) < p.eps:
            break
        if abs(xu - xl) < p.eps_size and abs(yu - yl) < p.eps_size:
            break
        # b) the edge away from the centroid moves in so the centre coincides with it
        if cxp > xc:
            xl = 2 * cxp - xu
        elif cxp < xc:
            xu = 2 * cxp - xl
        if cyp > yc:
            yl = 2 * cyp - yu
        elif cyp < yc:
            yu = 2 * cyp - yl
        xl, xu = min(xl, xu), max(xl, xu)
        yl, yu = min(yl, yu), max(yl, yu)
    return xl, yl, xu, yu
