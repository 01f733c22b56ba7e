"""Carried objects: the colour of what lies around a hand (sec. 7.2-7.3 of *3D tracking of the hands
and head of interacting people from several cameras*).

Per view and frame, for each tracked hand (:func:`hand_colour`):

1. the region: a circle around the hand (sec. 7.2.1) cut by the body's silhouette, keeping only
   the silhouette region connected to the hand, without the skin-coloured pixels;
2. the hue histogram of what remains (180 two-degree bins, OpenCV's hue), smoothed by a Gaussian
   kernel density; its local maxima are the modes, and a mode is kept only if a connected region of
   at least ``n`` pixels lies within ``+- delta`` degrees of it (sec. 7.2.2: n = 10, delta ~ 3);
   modes near the hand's own skin hue are dropped;
3. the region's reliability, eq. 28, from the silhouette along the circle.

The text of eq. 28 reads ``rho = (n - sum v_c) / n + rho_min`` with ``v_c = 1`` for *background*
pixels of the circle, which would make a hand held inside the body's silhouette the most reliable
one, the opposite of what the paper explains with its Fig. 8 (a hand stretched out is reliable).
We read it as the share of the circle's boundary that lies *outside* the silhouette plus rho_min.

The kept histogram is normalised by the region's size, so a value is the share of the hand's
surroundings that has that hue: a held object covers a good part of it, stray pixels do not.
:func:`fuse` is eq. 29, the reliability-weighted average over frames and views.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

from partlab.tracking.activities.params import ActivityParams
from partlab.tracking.core.box import Box

HUE_BINS = 180  # OpenCV's 8-bit hue: two degrees a bin
DEGREES_PER_BIN = 2.0


@dataclass(frozen=True)
class HandColour:
    """One view of one hand at one frame: ``shares`` ``(180,)`` the share of the region per hue bin
    of the kept (non-skin, connected) modes; ``rho`` eq. 28's reliability; ``where``: per kept mode
    ``(hue bin, x, y)``, the image position (centroid) of its pixels, which tells an object that moves
    with the hand from one it passes by."""

    shares: np.ndarray
    rho: float
    where: tuple[tuple[int, float, float], ...] = ()
    view: str = ""  # the camera that saw it (a take of several views)
    visible: float = 1.0  # the share of the hand the tracker says is seen there (1 - its ``occluded``)


@lru_cache(maxsize=1)
def _skin_model():
    from partlab.tracking.core.skin import SkinModel

    return SkinModel.default()


def _circular_kde(hist: np.ndarray, sigma_bins: float) -> np.ndarray:
    """Gaussian kernel density of a circular histogram (hue wraps at 180 bins)."""
    half = int(np.ceil(3 * sigma_bins))
    k = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma_bins) ** 2)
    k /= k.sum()
    padded = np.concatenate([hist[-half:], hist, hist[:half]])
    return np.convolve(padded, k, mode="valid")


def _hue_distance(a, b) -> np.ndarray:
    """Circular distance between hue bins."""
    d = np.abs(np.asarray(a) - np.asarray(b)) % HUE_BINS
    return np.minimum(d, HUE_BINS - d)


def hue_modes(hues: np.ndarray, valid: np.ndarray, params: ActivityParams) -> list[int]:
    """Modes (hue bins) of the valid pixels' hue that form a connected region of at least
    ``min_pixels`` pixels within ``+- delta`` degrees (sec. 7.2.2)."""
    m = params.modes
    hist = np.bincount(hues[valid].ravel(), minlength=HUE_BINS).astype(np.float64)
    if hist.sum() < m.min_pixels:
        return []
    smooth = _circular_kde(hist, m.kde_sigma / DEGREES_PER_BIN)
    left, right = np.roll(smooth, 1), np.roll(smooth, -1)
    peaks = np.flatnonzero((smooth >= left) & (smooth > right) & (smooth * HUE_BINS > m.min_pixels * 0.5))
    kept = []
    width = m.delta / DEGREES_PER_BIN
    for peak in peaks:
        near = valid & (_hue_distance(hues, peak) <= max(width, 0.5))
        if int(near.sum()) < m.min_pixels:
            continue
        n, _, stats, _ = cv2.connectedComponentsWithStats(near.astype(np.uint8), connectivity=8)
        if n > 1 and int(stats[1:, cv2.CC_STAT_AREA].max()) >= m.min_pixels:
            kept.append(int(peak))
    return kept


def hand_colour(frame: np.ndarray, foreground: np.ndarray | None, hand: Box, params: ActivityParams) -> HandColour:
    """What is around ``hand`` in ``frame`` (BGR): see the module's steps 1-3."""
    r_hand = max(hand.w, hand.h) / 2.0
    R = max(3.0, params.region.radius * r_hand)
    cx, cy = hand.x + hand.w / 2.0, hand.y + hand.h / 2.0
    H, W = frame.shape[:2]
    x0, y0 = max(0, int(cx - R)), max(0, int(cy - R))
    x1, y1 = min(W, int(np.ceil(cx + R)) + 1), min(H, int(np.ceil(cy + R)) + 1)
    if x1 - x0 < 3 or y1 - y0 < 3:
        return HandColour(np.zeros(HUE_BINS), params.reliability.rho_min)
    crop = frame[y0:y1, x0:x1]
    yy, xx = np.mgrid[y0:y1, x0:x1]
    d2 = (xx + 0.5 - cx) ** 2 + (yy + 0.5 - cy) ** 2
    disk = d2 <= R * R
    boundary = disk & (d2 >= (R - 1.5) ** 2)
    fg = None if foreground is None else foreground[y0:y1, x0:x1] > 0
    hx0, hy0 = max(0, int(hand.x) - x0), max(0, int(hand.y) - y0)
    hx1, hy1 = min(x1 - x0, int(np.ceil(hand.x + hand.w)) - x0), min(y1 - y0, int(np.ceil(hand.y + hand.h)) - y0)
    if fg is not None and fg[hy0:hy1, hx0:hx1].mean() >= 0.3:
        inside = disk & fg
        n, labels = cv2.connectedComponents(inside.astype(np.uint8), connectivity=8)
        # the silhouette region holding the hand: the label most of the hand's box is in
        under = labels[hy0:hy1, hx0:hx1]
        under = under[under > 0]
        region = labels == np.bincount(under).argmax() if under.size else inside
        rho = float((~fg[boundary]).mean()) if boundary.any() else 1.0
    else:  # no silhouette here (a person standing still fades into the background model)
        region = disk
        rho = 0.5
    rho += params.reliability.rho_min
    hsv = cv2.cvtColor(crop, cv2.COLOR_BGR2HSV)
    hues, sat, val = hsv[..., 0], hsv[..., 1], hsv[..., 2]
    skin = _skin_model().mask(crop) > 0
    valid = region & ~skin & (sat >= params.region.min_saturation) & (val >= params.region.min_value)
    size = max(int(region.sum()), 1)
    modes = hue_modes(hues, valid, params)
    skin_hues = hues[region & skin]
    if skin_hues.size >= params.modes.min_pixels:  # the hand's own skin hue (circular mean)
        ang = skin_hues.astype(np.float64) * (2 * np.pi / HUE_BINS)
        skin_bin = (np.arctan2(np.sin(ang).mean(), np.cos(ang).mean()) % (2 * np.pi)) * HUE_BINS / (2 * np.pi)
        margin = params.modes.skin_margin / DEGREES_PER_BIN
        modes = [m for m in modes if _hue_distance(m, skin_bin) > margin]
    shares = np.zeros(HUE_BINS)
    where = []
    if modes:
        hist = np.bincount(hues[valid].ravel(), minlength=HUE_BINS).astype(np.float64) / size
        reach = params.decision.same_colour / DEGREES_PER_BIN
        keep = np.zeros(HUE_BINS, bool)
        for m in modes:
            keep |= _hue_distance(np.arange(HUE_BINS), m) <= reach
            px = valid & (_hue_distance(hues, m) <= reach)
            where.append((int(m), float(xx[px].mean() + 0.5), float(yy[px].mean() + 0.5)))
        shares = np.where(keep, hist, 0.0)
    return HandColour(shares, rho, tuple(where))


def body_colours(frame: np.ndarray, foreground: np.ndarray | None, head: Box, params: ActivityParams) -> np.ndarray:
    """``(180,)`` hue shares of the person's clothes: the silhouette's saturated, non-skin pixels in
    the region below the head (chest, arms and the top of the trousers, ``modes.clothes_reach``).
    A colour the person wears is not an object they hold: the paper removes the sleeve through
    eq. 28's boundary vector; we remove every colour of the clothes (an object of the shirt's own
    hue is then not seen, a limitation docs/ states)."""
    H, W = frame.shape[:2]
    x0, x1 = int(max(0, head.x - 0.8 * head.w)), int(min(W, head.x + 1.8 * head.w))
    y0, y1 = int(max(0, head.y + 1.1 * head.h)), int(min(H, head.y + params.modes.clothes_reach * head.h))
    if x1 - x0 < 3 or y1 - y0 < 3:
        return np.zeros(HUE_BINS)
    crop = frame[y0:y1, x0:x1]
    hsv = cv2.cvtColor(crop, cv2.COLOR_BGR2HSV)
    ok = (hsv[..., 1] >= params.region.min_saturation) & (hsv[..., 2] >= params.region.min_value)
    ok &= _skin_model().mask(crop) == 0
    if foreground is not None and (foreground[y0:y1, x0:x1] > 0).mean() >= 0.2:
        ok &= foreground[y0:y1, x0:x1] > 0
    counts = np.bincount(hsv[..., 0][ok].ravel(), minlength=HUE_BINS).astype(np.float64)
    return counts / max(crop.shape[0] * crop.shape[1], 1)


def _weight(o: HandColour) -> float:
    """An observation's weight in eq. 29: its reliability, times how much of the hand is seen there."""
    return o.rho * max(o.visible, 1e-3)


def fuse(observations: list[HandColour]) -> np.ndarray:
    """Eq. 29: the reliability-weighted average of the observations' shares (over frames and views)."""
    if not observations:
        return np.zeros(HUE_BINS)
    rho = np.array([_weight(o) for o in observations])
    return (rho[:, None] * np.stack([o.shares for o in observations])).sum(0) / rho.sum()


def fuse_views(observations: list[HandColour], params: ActivityParams) -> dict[int, float]:
    """The colours a hand holds over ``observations`` (frames and views): eq. 29 per view
    (:func:`fuse`, :func:`colour_masses`), then the views' colours averaged with the views'
    weights, a colour of one view matched to the nearest of another within ``view_hue_shift``
    degrees (its hue the weighted mean of theirs). Each camera renders a hue a little differently
    (its white balance): averaged bin by bin, a yellow object seen at 54, 58 and 70 degrees by
    three views splits into two colours of half its share each. Where more than ``min_views``
    views saw the hand, a colour needs ``min_views`` of them (at ``max_mass_absent`` or more): an
    object in the hand is seen from nearly every side, a shirt or a wall behind it only from the
    views it lies behind in. One view: eq. 29 as is."""
    views: dict[str, list[HandColour]] = {}
    for o in observations:
        views.setdefault(o.view, []).append(o)
    if len(views) <= 1:
        return colour_masses(fuse(observations), params)
    tol = params.modes.view_hue_shift / DEGREES_PER_BIN
    weights = {v: sum(_weight(o) for o in obs) for v, obs in views.items()}
    # every view's colours start as colours of their own; the two nearest in hue that share no view
    # join, until none are within ``view_hue_shift`` (nearest first, not strongest first: a view's
    # yellow at 35 bins joined another colour at 43 when it came before the other views' 29 and 28)
    groups: list[dict[str, tuple[int, float]]] = [{v: (h, m)} for v, obs in views.items()
                                                  for h, m in colour_masses(fuse(obs), params).items()]
    while True:
        hues = [_group_hue(g, weights) for g in groups]
        pairs = [(float(_hue_distance(hues[i], hues[j])), i, j) for i in range(len(groups))
                 for j in range(i + 1, len(groups)) if not set(groups[i]) & set(groups[j])]
        d, i, j = min(pairs, default=(np.inf, -1, -1))
        if d > tol:
            break
        groups[i] = {**groups[i], **groups.pop(j)}
    total = sum(weights.values())
    out: dict[int, float] = {}
    reach = params.decision.same_colour / DEGREES_PER_BIN
    need = params.modes.min_views if len(views) > params.modes.min_views else 1
    for g in groups:
        if sum(m >= params.decision.max_mass_absent for _, m in g.values()) < need:
            continue  # what lies behind the hand in one view (another person's shirt), not what it holds
        h, mass = _group_hue(g, weights), sum(weights[v] * m for v, (_, m) in g.items()) / total
        q = next((q for q in out if _hue_distance(h, q) <= reach), None)
        out[h if q is None else q] = mass if q is None else max(out[q], mass)
    return out


def _group_hue(group: dict[str, tuple[int, float]], weights: dict[str, float]) -> int:
    """The mean hue bin (circular, weighted by view weight and share) of one colour seen by several views."""
    ang = np.array([h for h, _ in group.values()], float) * (2 * np.pi / HUE_BINS)
    w = np.array([weights[v] * m for v, (_, m) in group.items()]) + 1e-12
    mean = np.arctan2((w * np.sin(ang)).sum(), (w * np.cos(ang)).sum()) % (2 * np.pi)
    return int(round(mean * HUE_BINS / (2 * np.pi))) % HUE_BINS


def colour_masses(fused: np.ndarray, params: ActivityParams) -> dict[int, float]:
    """The colours a fused distribution holds: ``{hue bin: share}`` for each of its local maxima,
    the share summed within ``same_colour`` degrees of it."""
    if not fused.any():
        return {}
    reach = params.decision.same_colour / DEGREES_PER_BIN
    smooth = _circular_kde(fused, params.modes.kde_sigma / DEGREES_PER_BIN)
    peaks = np.flatnonzero((smooth >= np.roll(smooth, 1)) & (smooth > np.roll(smooth, -1)) & (smooth > 0))
    out: dict[int, float] = {}
    bins = np.arange(HUE_BINS)
    for p in peaks:
        mass = float(fused[_hue_distance(bins, p) <= reach].sum())
        if mass > 0 and not any(_hue_distance(p, q) <= reach for q in out):
            out[int(p)] = mass
    return out


def hue_to_hex(hue_bin: int) -> str:
    """A saturated colour of that hue, as ``#rrggbb`` (for the events table and the app)."""
    bgr = cv2.cvtColor(np.uint8([[[hue_bin % HUE_BINS, 220, 220]]]), cv2.COLOR_HSV2BGR)[0, 0]
    return f"#{int(bgr[2]):02x}{int(bgr[1]):02x}{int(bgr[0]):02x}"
