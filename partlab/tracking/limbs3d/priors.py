"""How good is a candidate point: its prior ``p(Z) = p_o(Z) p_t(Z) p_b(Z)`` (eq. 19, 25-27), then
pruning and merging (sec. 6.4).

- ``p_o`` (eq. 25) compares the two blobs in their own images: how far below the top of its
  person's silhouette each blob lies, ``Dv``, should agree, because with every camera upright a
  higher point has a smaller row in every view. The paper divides the rows by the silhouette's
  height; that range is not the same person in every view when a table hides the legs from some
  cameras and not others (seated, the true hand pairs got p_o 0.00-0.18 with sigma_v = 0.08), so
  here the offset from the silhouette's top (the top of the head, which every camera above the
  people sees) is turned into millimetres at the candidate's depth in that camera
  (``rows * depth / f``) and ``sigma_v`` is in mm;
- ``p_t`` (eq. 26) is the reconstruction error ``d`` of eq. 24;
- ``p_b`` (eq. 27) projects the candidate into every view and measures its distance ``Ds`` (pixels)
  to that view's silhouette: a false pair of two limbs on one line of sight in one camera lands
  off the people in another. A view with no silhouette at all (a covered lens) says nothing and
  is left out of the product.

Each term measures something the pair of blobs does not already guarantee (the silhouettes are
the background model's, not the skin mask the blobs were cut from). Terms are kept by name
(:class:`Prior`) so that the app and training can show and fit them one by one.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from partlab.tracking.camera import Camera
from partlab.tracking.limbs3d.geometry import PairCandidates
from partlab.tracking.limbs3d.params import Limbs3DParams


@dataclass(frozen=True, eq=False)
class ViewObservation:
    """One view at one frame: skin-blob ``centres (K, 2)``, ``below (K,)`` image rows from the top of
    each blob's silhouette to the blob, and ``distance (H, W) float32``: pixels to the nearest silhouette pixel
    (0 inside); ``has_silhouette`` False when the view sees nobody at all."""

    centres: np.ndarray
    below: np.ndarray
    distance: np.ndarray
    has_silhouette: bool
    scale: float = 1.0  # image pixels per silhouette pixel (silhouettes may be found at lower resolution)
    #: ``(K,)`` rows from the top of each blob's person (the nearest larger component for a blob in
    #: a fragment, see :func:`observe_view`); None: the same as ``below``
    below_person: np.ndarray | None = None


def observe_view(silhouette: np.ndarray, centres: np.ndarray, scale: float = 1.0,
                 fragment: float = 0.0, either: bool = False, stack: bool = False) -> ViewObservation:
    """The silhouette measures of one view (``silhouette``: ``(H, W)`` mask, nonzero = person;
    ``centres`` in silhouette pixels; ``scale``: image pixels per silhouette pixel). A blob in a
    component smaller than ``fragment`` times the largest (a hand reaching across a table, cut
    off from its body in this view) is measured from the top of the nearest larger component
    (horizontally), its person's; 0 = from its own component's top. With ``either``, ``below`` is
    from its own component's top and ``below_person`` from its person's (p_o takes the better).
    With ``stack``, a fragment's person is the highest of the larger components whose columns
    overlap those of the nearest one: a person whose clothes match the background breaks into a
    head, a chest and a belly component stacked one above the other, and the nearest of them to a
    hand at the hip may be the belly's, whose top is far below the person's; two people side by
    side do not overlap."""
    sil = (np.asarray(silhouette) > 0).astype(np.uint8)
    centres = np.asarray(centres, float).reshape(-1, 2)
    h, w = sil.shape
    if not sil.any():
        return ViewObservation(centres, np.zeros(len(centres)), np.zeros((h, w), np.float32), False, scale)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(sil, 8)
    distance = cv2.distanceTransform(1 - sil, cv2.DIST_L2, 3)
    top_all = float(stats[1:, cv2.CC_STAT_TOP].min())
    below, person = np.empty(len(centres)), np.empty(len(centres))
    area = stats[:, cv2.CC_STAT_AREA].astype(float)
    big = np.flatnonzero(area[1:] >= fragment * area[1:].max()) + 1
    for k, (x, y) in enumerate(centres):
        lab = own = labels[int(np.clip(round(y), 0, h - 1)), int(np.clip(round(x), 0, w - 1))]
        if lab > 0 and fragment > 0 and lab not in big:
            left, width = stats[big, cv2.CC_STAT_LEFT], stats[big, cv2.CC_STAT_WIDTH]
            lab = big[np.argmin(np.maximum(np.maximum(left - x, x - (left + width)), 0))]
            if stack:  # the highest of the larger components whose columns overlap the nearest one's
                lo, hi = stats[lab, cv2.CC_STAT_LEFT], stats[lab, cv2.CC_STAT_LEFT] + stats[lab, cv2.CC_STAT_WIDTH]
                over = big[(left < hi) & (left + width > lo)]
                lab = over[np.argmin(stats[over, cv2.CC_STAT_TOP])]
        top = float(stats[lab, cv2.CC_STAT_TOP]) if lab > 0 else top_all
        top_own = float(stats[own, cv2.CC_STAT_TOP]) if own > 0 else top_all
        below[k] = (y - (top_own if either else top)) * scale
        person[k] = (y - top) * scale
    return ViewObservation(centres, below, distance * np.float32(scale), True, scale,
                           person if either else None)


def silhouette_distance(camera: Camera, view: ViewObservation, points: np.ndarray) -> np.ndarray:
    """``Ds``: pixels from each point's projection to the view's silhouette (eq. 27); outside the
    image, the distance at the border plus how far outside."""
    uv = camera.project(points) / view.scale
    h, w = view.distance.shape
    cu = np.clip(uv[:, 0], 0, w - 1)
    cv_ = np.clip(uv[:, 1], 0, h - 1)
    inside = view.distance[cv_.astype(int), cu.astype(int)]
    out = np.hypot(uv[:, 0] - cu, uv[:, 1] - cv_) * view.scale
    ds = inside + out
    return np.where(np.isfinite(ds), ds, 1e6)


@dataclass(frozen=True)
class Prior:
    """The named terms of eq. 19 for every candidate, each ``(C,)`` in [0, 1]."""

    p_o: np.ndarray
    p_t: np.ndarray
    p_b: np.ndarray

    @property
    def value(self) -> np.ndarray:
        return self.p_o * self.p_t * self.p_b


def _below_mm(cands: PairCandidates, cameras: list[Camera], views: list[ViewObservation], side: int,
              person: bool = False) -> np.ndarray:
    """``Dv`` of each candidate's blob in its ``side`` (0, 1) view: rows below the silhouette's top
    at the candidate's depth in that camera, in mm (``rows * depth / f_y``)."""
    out = np.empty(len(cands))
    for m in np.unique(cands.views[:, side]):
        sel = cands.views[:, side] == m
        depth = cameras[m].to_camera(cands.points[sel])[:, 2]
        rows = views[m].below_person if person and views[m].below_person is not None else views[m].below
        out[sel] = rows[cands.blobs[sel, side]] * depth / cameras[m].K[1, 1]
    return out


def candidate_prior(cands: PairCandidates, cameras: list[Camera], views: list[ViewObservation],
                    params: Limbs3DParams) -> tuple[Prior, dict]:
    """Eq. 25-27 for every candidate; also returns the raw errors (``dv``, ``d``, ``ds``), which
    training (sec. 6.4) fits the sigmas from."""
    if len(cands) == 0:
        z = np.zeros(0)
        return Prior(z, z, z), {"dv": z, "d": z, "ds": np.zeros((0, len(views)))}
    ddv = _below_mm(cands, cameras, views, 0) - _below_mm(cands, cameras, views, 1)
    if any(v.below_person is not None for v in views):  # priors.fragment_either: the better reference
        alt = _below_mm(cands, cameras, views, 0, True) - _below_mm(cands, cameras, views, 1, True)
        ddv = np.where(np.abs(alt) < np.abs(ddv), alt, ddv)
    p_o = np.exp(-ddv**2 / (2 * params.priors.sigma_v**2))
    p_t = np.exp(-cands.error**2 / (2 * params.priors.sigma_d**2))
    ds = np.stack([silhouette_distance(c, v, cands.points) if v.has_silhouette else np.zeros(len(cands))
                   for c, v in zip(cameras, views)], axis=1)
    p_b = np.exp(-(ds**2).sum(axis=1) / (2 * params.priors.sigma_s**2))
    return Prior(p_o, p_t, p_b), {"dv": ddv, "d": cands.error, "ds": ds}


def prune_and_merge(points: np.ndarray, prior: np.ndarray, params: Limbs3DParams,
                    blobs: np.ndarray | None = None,
                    anchors: np.ndarray | None = None, with_members: bool = False):
    """Drop candidates below ``prior_threshold`` or outside the room, then merge close ones (sec.
    6.4): strongest first, every weaker candidate within ``merge_distance`` is eliminated and adds
    ``merge_boost`` times its prior to the one that absorbs it (capped at 1). With ``blobs (C, 2)``
    (each candidate's two blobs as view-blob keys, see :func:`blob_keys`), a merged candidate all
    of whose blobs are already used by stronger ones is a ghost (:func:`suppress_ghosts`); with
    ``anchors (T, 3)`` (the tracked targets' predictions), "stronger" is by prior times nearness to
    the nearest prediction (``priors.ghost_anchor``), after the number of views a candidate's
    pairs span (a point seen by three views outranks a pair of two). Returns ``points (K, 3)``
    and ``prior (K,)``, strongest first; ``with_members``: also the view-blob keys each merged
    candidate's pairs came from (``K`` sets, empty without ``blobs``)."""
    keep = (prior >= params.priors.prior_threshold) & np.isfinite(points).all(axis=1)
    keep &= (points[:, 2] > 0) & (points[:, 2] < params.priors.max_height)
    pts, pr = points[keep], prior[keep]
    order = np.argsort(-pr, kind="stable")
    pts, pr = pts[order], pr[order]
    keys = blobs[keep][order] if blobs is not None else None
    alive = np.ones(len(pr), bool)
    out_p, out_w, out_k = [], [], []
    if len(pr):
        dist = np.linalg.norm(pts[:, None] - pts[None], axis=-1)
    for i in range(len(pr)):
        if not alive[i]:
            continue
        near = alive & (dist[i] < params.priors.merge_distance)
        near[i] = False
        absorbed = np.flatnonzero(near)
        alive[absorbed] = False
        value = min(1.0, pr[i] + params.priors.merge_boost * float(pr[absorbed].sum()))
        idx = np.concatenate([[i], absorbed]).astype(int)
        if params.priors.merge_average and len(absorbed):
            p = (pts[idx] * pr[idx, None]).sum(0) / pr[idx].sum()
        else:
            p = pts[i]
        out_p.append(p)
        out_w.append(value)
        if keys is not None:
            out_k.append(set(keys[idx].ravel().tolist()))
    out_p, out_w = np.array(out_p).reshape(-1, 3), np.array(out_w)
    if not out_k:
        out_k = [set() for _ in out_w]
    if keys is not None and params.priors.ghost_factor < 1 and len(out_w):
        out_p, out_w, out_k = suppress_ghosts(out_p, out_w, out_k, params.priors.ghost_factor,
                                              _ghost_rank(out_p, out_w, out_k, params, anchors))
    return (out_p, out_w, out_k) if with_members else (out_p, out_w)


def _ghost_rank(points: np.ndarray, prior: np.ndarray, members: list[set], params: Limbs3DParams,
                anchors: np.ndarray | None) -> np.ndarray:
    """The order in which merged candidates claim their blobs (:func:`suppress_ghosts`): by prior,
    or with ``anchors`` by the number of views, then prior times nearness to a prediction."""
    if anchors is None or not len(anchors) or params.priors.ghost_anchor <= 0:
        return prior
    d = np.linalg.norm(points[:, None] - np.asarray(anchors, float).reshape(-1, 3)[None], axis=-1).min(axis=1)
    views = np.array([len({k // _VIEW_KEY for k in m}) for m in members], float)
    w = params.priors.ghost_anchor_weight
    return views + prior * (1 - w + w * np.exp(-0.5 * (d / params.priors.ghost_anchor) ** 2))


def blob_keys(views: np.ndarray, blobs: np.ndarray) -> np.ndarray:
    """``(C, 2)`` integer keys of each candidate's two blobs (view and blob index in one number)."""
    return np.asarray(views, np.int64) * _VIEW_KEY + np.asarray(blobs, np.int64)


_VIEW_KEY = 100000


def split_key(key: int) -> tuple[int, int]:
    """The view and blob index of a key of :func:`blob_keys`."""
    m, j = divmod(int(key), _VIEW_KEY)
    return m, j


def suppress_ghosts(points: np.ndarray, prior: np.ndarray, members: list[set], factor: float,
                    rank: np.ndarray | None = None):
    """Every skin blob is the image of one head or hand (our addition, not the paper's): from the
    strongest merged candidate down, one whose blobs (``members``: the view-blob keys of the pairs
    it merged) are all already used by stronger candidates is a ghost, the crossing of two lines of
    sight through two different limbs (a left hand in one view paired with the right hand in
    another), and its prior is scaled by ``factor`` (0 drops it). A true point seen by three views
    merges three pairs and owns blobs no other point uses; two hands that are one blob in one view
    still each own their blobs in the other views. ``rank`` (default the prior) orders the
    candidates. With two views, a ghost pair and a true pair can have the same prior (both 1): the
    order then picks one of two crossings of the same four blobs, and ranked by prior alone a
    clapping hand's true pairs were dropped for ghosts 200 mm away (standing seed 0 with camera 0
    of 3 hidden); ranked by nearness to the targets' predictions as well, the pair the dynamics
    expect owns its blobs first. Returns points, priors and members, strongest first."""
    order = np.argsort(-(prior if rank is None else rank), kind="stable")
    used: set = set()
    value = prior.copy()
    for i in order:
        if members[i] <= used:
            value[i] *= factor
        else:
            used |= members[i]
    keep = np.flatnonzero(value >= 1e-9)
    order = keep[np.argsort(-value[keep], kind="stable")]
    return points[order], value[order], [members[i] for i in order]
