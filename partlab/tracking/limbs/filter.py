"""One particle filter per head or hand, weighted against every skin blob (seed 000 sec. 4-5).

Low layer of seed 000 (sec. 3): parallel filters with no interaction except the
shared observations. A filter's particles are ``(N, 4) float64 [cx, cy, vx, vy]``
(box centre and velocity, pixels); the box size is the target's fixed reference size
(seed 003 sec. 3). Dynamics are second order, ``x_t - x_{t-1} = d (x_{t-1} - x_{t-2}) + w_t``
(seed 003 sec. 3; ``d`` = ``velocity_decay``, 1 in the paper).

The weight of particle i is the blob likelihood of seed 000 eq. (17) with every
indicator set to one (all-neighbours association, sec. 5),

    p(z | x_i) ~ sum_c p(x_i | Z_c) p(Z_c),   p(x_i | Z_c) = exp(-|x_i - Z_c|^2 / (2 sigma_xy^2)),

times the hue-histogram confidence of seed 003 eq. (1). The candidate prior ``p(Z_c)``
is a product of named terms (eq. 19); in one camera the silhouette term (eq. 27 in 2D)
and the blob's mean skin probability (the observation-quality role of ``p_o``) apply.
More cameras add their terms to :func:`candidate_terms` and nothing else changes.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from partlab.tracking.core.hue_histogram import hue_confidence, local_box_histograms, local_mean_shift
from partlab.tracking.core.resampling import systematic_resample
from partlab.tracking.core.skin import Blobs
from partlab.tracking.params import LimbParams


@dataclass(frozen=True)
class Candidates:
    """Candidate points of one frame: ``centres (K, 2)``, ``boxes (K, 4)``, ``areas (K,)``,
    their named prior terms ``terms[name] (K,)`` and the product ``priors (K,)`` (seed 000 eq. 19);
    ``parents (K,)``: the blob (index into the frame's :class:`Blobs`) each candidate comes from
    (None: candidate k is blob k); ``ends (K,) bool``: candidates that are a blob's end even where
    the blob gives only one (the end of a blob cut by the edge of the observable region, away from
    the cut; None: an end is one of two or more candidates of a blob)."""

    centres: np.ndarray
    boxes: np.ndarray
    areas: np.ndarray
    terms: dict[str, np.ndarray]
    priors: np.ndarray
    parents: np.ndarray | None = None
    ends: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.priors.size)


def silhouette_term(centres: np.ndarray, foreground: np.ndarray | None, sigma_s: float) -> np.ndarray:
    """``exp(-Ds^2 / (2 sigma_s^2))`` with ``Ds`` the distance of each centre to the foreground
    silhouette (seed 000 eq. 27, one camera); all ones without a foreground mask.

    ``Ds`` is measured within ``4 sigma_s`` of each centre (farther, the term is under 3e-4 and
    is taken as 0): a centre on the silhouette costs one lookup, not a distance transform of the
    frame."""
    centres = np.asarray(centres, dtype=float).reshape(-1, 2)
    if foreground is None or centres.size == 0:
        return np.ones(len(centres))
    fg = np.asarray(foreground) > 0
    hgt, wid = fg.shape
    xs = np.clip(np.round(centres[:, 0]).astype(int), 0, wid - 1)
    ys = np.clip(np.round(centres[:, 1]).astype(int), 0, hgt - 1)
    reach = max(int(np.ceil(4 * sigma_s)), 1)
    out = np.zeros(len(centres))
    for k, (x, y) in enumerate(zip(xs, ys)):
        if fg[y, x]:
            out[k] = 1.0
            continue
        x1, y1 = max(x - reach, 0), max(y - reach, 0)
        win = fg[y1:min(y + reach + 1, hgt), x1:min(x + reach + 1, wid)]
        if win.any():
            d = cv2.distanceTransform((~win).astype(np.uint8), cv2.DIST_L2, 3)[y - y1, x - x1]
            out[k] = np.exp(-(d * d) / (2.0 * sigma_s**2)) if d <= reach else 0.0
    return out


def skin_term(blobs: Blobs, skin_probability: np.ndarray | None) -> np.ndarray:
    """Mean skin probability over each blob's pixels: how good the observation is (role of p_o)."""
    if skin_probability is None or len(blobs) == 0:
        return np.ones(len(blobs))
    prob = np.asarray(skin_probability)
    out = np.empty(len(blobs))
    for k, ((x, y, w, h), i) in enumerate(zip(blobs.boxes.astype(int), blobs.ids)):
        own = blobs.labels[y:y + h, x:x + w] == i
        out[k] = float(prob[y:y + h, x:x + w][own].sum())
    return np.clip(out / np.maximum(blobs.areas, 1.0), 0.0, 1.0)


def candidate_terms(blobs: Blobs, foreground: np.ndarray | None, skin_probability: np.ndarray | None,
                    params: LimbParams) -> Candidates:
    """Candidates from one camera's blobs, with the prior as a product of named terms."""
    terms = {
        "silhouette": silhouette_term(blobs.centres, foreground, params.priors.sigma_s),
        "skin": skin_term(blobs, skin_probability),
    }
    priors = np.ones(len(blobs))
    for t in terms.values():
        priors = priors * t
    return Candidates(blobs.centres, blobs.boxes, blobs.areas, terms, priors)


def blob_points(blobs: Blobs) -> list[np.ndarray]:
    """``(n, 2) float [x, y]`` pixel coordinates of each blob, in the blobs' order."""
    out = []
    for (x, y, w, h), i in zip(blobs.boxes.astype(int), blobs.ids):
        ys, xs = np.nonzero(blobs.labels[y:y + h, x:x + w] == i)
        out.append(np.column_stack([xs + x, ys + y]).astype(float))
    return out


def blob_tips(points: np.ndarray, side: float, span: float, far: float, radius: float,
              max_tips: int = 4, cut: np.ndarray | None = None) -> np.ndarray:
    """Hand-sized ends of one blob: ``(T, 2)`` points, or the blob's centre when it is compact.

    With short sleeves a hand and its forearm share one colour and form one blob (a desk
    scene's arm is ~3-4 hand widths long); its centre lies mid-forearm, which pulls a hand
    filter up the arm. The hand is an end of that blob. A blob whose farthest pixels are at
    least ``span`` sides apart is split into ends: points of its outline that stick out (local
    maxima of the distance to the blob's centre along the outline), the two farthest apart
    first, then more (the tip of a V where two forearms meet at a clap) while one lies at
    least ``far`` sides from every end found. The middle of a long straight arm's side is
    no end: its distance to the centre is a minimum along the outline. Each end's point is
    the centroid of the blob pixels within ``radius`` sides of it: a hand's centre when the
    end is a hand.

    ``cut (n,) bool``: the blob's pixels at a cut, where it goes on as skin beyond the region
    that is observed (a still person whom the background absorbed is seen only in a box round
    each tracked target, which cuts their forearm square; :attr:`LimbBlobs.cut_ends`). An end
    at a cut is no end of the arm, and the centre of a cut blob lies towards the cut: a blob
    with cut pixels gives its ends away from the cut, or, where it has none (a short blob),
    the centroid round its pixel farthest from the cut.
    """
    pts = np.asarray(points, float).reshape(-1, 2)
    centre = pts.mean(axis=0)
    t1 = pts[np.argmax(((pts - centre) ** 2).sum(axis=1))]  # the pixel farthest from the centre
    long = bool(np.hypot(*(pts - t1).T).max() >= span * side)
    if cut is not None and np.any(cut) and not np.all(cut):
        raw = _tip_points(pts, centre, t1, side, span, far, max_tips) if long else None
        return _uncut_tips(pts, np.asarray(cut, bool), raw, side, radius)
    if not long:
        return centre[None]
    tips = _tip_points(pts, centre, t1, side, span, far, max_tips)
    return np.array([pts[np.hypot(*(pts - t).T) <= radius * side].mean(axis=0) for t in tips])


def _tip_points(pts: np.ndarray, centre: np.ndarray, t1: np.ndarray, side: float, span: float, far: float,
                max_tips: int) -> np.ndarray:
    """The outline points :func:`blob_tips` takes its ends round (of a blob at least ``span``
    sides long; ``centre`` its centroid, ``t1`` its pixel farthest from it)."""
    ends = _outline_maxima(pts, centre, max(int(side / 2), 2))
    tips = [t1]
    mind = np.hypot(*(ends - t1).T)
    while len(tips) < max_tips and len(ends):
        k = int(np.argmax(mind))
        if mind[k] < (span if len(tips) == 1 else far) * side:
            break
        tips.append(ends[k])
        mind = np.minimum(mind, np.hypot(*(ends - ends[k]).T))
    if len(tips) == 1:  # no outline end far enough (a ragged blob): its farthest pixel
        tips.append(pts[np.argmax(np.hypot(*(pts - t1).T))])
    return np.array(tips)


def _uncut_tips(pts: np.ndarray, cut: np.ndarray, raw: np.ndarray | None, side: float, radius: float) -> np.ndarray:
    """:func:`blob_tips` of a blob with ``cut`` pixels (``raw``: its ends' outline points,
    :func:`_tip_points`, None for a short blob): its ends whose outline point lies farther than
    ``CUT_GAP`` pixels from every cut pixel; none such (a short blob, or every end at the cut),
    the centroid round its pixel farthest from the cut."""
    x0, y0 = pts.min(axis=0).astype(int)
    xy = pts.astype(int) - np.array([x0, y0])
    img = np.ones((xy[:, 1].max() + 1, xy[:, 0].max() + 1), np.uint8)
    img[xy[cut, 1], xy[cut, 0]] = 0
    dist = cv2.distanceTransform(img, cv2.DIST_L2, 3)  # pixels to the nearest cut pixel

    def centroid(q: np.ndarray) -> np.ndarray:
        return pts[np.hypot(*(pts - q).T) <= radius * side].mean(axis=0)

    if raw is not None:
        rxy = np.clip(raw.astype(int) - np.array([x0, y0]), 0, np.array(img.shape[::-1]) - 1)
        keep = dist[rxy[:, 1], rxy[:, 0]] > CUT_GAP
        if keep.any():
            return np.array([centroid(t) for t in raw[keep]])
    return centroid(pts[int(np.argmax(dist[xy[:, 1], xy[:, 0]]))])[None]


def _outline_maxima(pts: np.ndarray, centre: np.ndarray, half_window: int) -> np.ndarray:
    """Points of a blob's outer outline farther from ``centre`` than every outline point
    within ``half_window`` steps along it: ``(M, 2)``."""
    x0, y0 = pts.min(axis=0).astype(int)
    mask = np.zeros((int(pts[:, 1].max()) - y0 + 3, int(pts[:, 0].max()) - x0 + 3), np.uint8)
    mask[pts[:, 1].astype(int) - y0 + 1, pts[:, 0].astype(int) - x0 + 1] = 1
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not contours:
        return np.zeros((0, 2))
    c = max(contours, key=len).reshape(-1, 2).astype(float) + np.array([x0 - 1, y0 - 1])
    r = np.hypot(*(c - centre[None, :]).T)
    n = len(r)
    w = min(half_window, (n - 1) // 2)
    shifted = np.stack([np.roll(r, s) for s in range(-w, w + 1)])
    return c[r >= shifted.max(axis=0)]


def tip_candidates(cands: Candidates, points: list[np.ndarray], side: float, params: LimbParams,
                   cuts: list[np.ndarray] | None = None, span: float | None = None) -> Candidates:
    """Candidates of a hand of box side ``side``: each elongated blob replaced by its ends
    (:func:`blob_tips`), which inherit the blob's prior terms. ``cuts``: per blob, its pixels at
    a cut (``blob_tips``' ``cut``); the tips of a blob with some are ends however many.
    ``span``: instead of ``blobs.tip_span`` (infinite: blob centres, but a cut blob's end away
    from the cut, for hands that see blob centres)."""
    if len(cands) == 0:
        return cands
    centres, parents, ends = [], [], []
    b = params.blobs
    for k, pts in enumerate(points):
        cut = None if cuts is None else cuts[k]
        tips = blob_tips(pts, side, b.tip_span if span is None else span, b.tip_far, b.tip_radius, cut=cut)
        centres.append(tips)
        parents += [k] * len(tips)
        ends += [cut is not None and bool(np.any(cut)) and not bool(np.all(cut))] * len(tips)
    out = _expand(cands, np.concatenate(centres), np.asarray(parents, int), side)
    return out if cuts is None else Candidates(out.centres, out.boxes, out.areas, out.terms, out.priors,
                                               out.parents, np.asarray(ends, bool))


def nearest_part_candidates(cands: Candidates, points: list[np.ndarray], near, side: float,
                            params: LimbParams) -> Candidates:
    """One candidate per blob: the centroid of its pixels within ``tip_radius`` sides of its
    pixel nearest to ``near``. A combined pair of hands looks for its modes with these: where
    two arms meet in a V the meeting point is no end of the blob's long axis, and as the hands
    part each arm's part nearest the pair is its hand."""
    if len(cands) == 0:
        return cands
    near = np.asarray(near, float)
    centres = []
    for pts in points:
        d = np.hypot(*(pts - near[None, :]).T)
        q = pts[int(np.argmin(d))]
        centres.append(pts[np.hypot(*(pts - q).T) <= params.blobs.tip_radius * side].mean(axis=0))
    return _expand(cands, np.asarray(centres).reshape(-1, 2), np.arange(len(points)), side)


def nearest_per_parent(cands: Candidates, point) -> np.ndarray:
    """``(K,) bool``: of the candidates sharing a parent blob, the one nearest ``point``."""
    if cands.parents is None or len(cands) == 0:
        return np.ones(len(cands), bool)
    d = np.hypot(*(cands.centres - np.asarray(point, float)[None, :]).T)
    keep = np.zeros(len(cands), bool)
    for k in np.unique(cands.parents):
        idx = np.flatnonzero(cands.parents == k)
        keep[idx[np.argmin(d[idx])]] = True
    return keep


#: pixels: an end whose outline point lies this near a blob's cut pixels is the cut (blob_tips)
CUT_GAP = 2.0


def _expand(cands: Candidates, centres: np.ndarray, parents: np.ndarray, side: float) -> Candidates:
    boxes = np.column_stack([centres - side / 2, np.full((len(centres), 2), side)])
    return Candidates(centres, boxes, cands.areas[parents], {k: v[parents] for k, v in cands.terms.items()},
                      cands.priors[parents], parents)


def blob_likelihood(points: np.ndarray, candidates: Candidates, sigma_xy: float) -> np.ndarray:
    """``sum_c exp(-|x - Z_c|^2 / (2 sigma^2)) p(Z_c)`` for ``points (N, 2)`` -> ``(N,)`` (seed 000 eq. 17)."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(candidates) == 0:
        return np.zeros(len(points))
    d2 = ((points[:, None, :] - candidates.centres[None, :, :]) ** 2).sum(axis=2)
    return (np.exp(-d2 / (2.0 * sigma_xy**2)) * candidates.priors[None, :]).sum(axis=1)


class LimbFilter:
    """SIR particle filter of one target (a head, a hand, or two combined targets)."""

    def __init__(self, centre, size, ref_hist: np.ndarray | None, params: LimbParams, rng: np.random.Generator):
        self.params = params
        self.size = (float(size[0]), float(size[1]))
        # no reference yet (the caller fills it in): flat until then
        self.ref_hist = (np.full(params.appearance.hue_bins, 1.0 / params.appearance.hue_bins) if ref_hist is None
                         else np.asarray(ref_hist, dtype=float))
        self.particles = np.zeros((params.dynamics.particles, 4))
        self.reset(centre, rng)
        self.confidence = 1.0
        self.weights = np.full(params.dynamics.particles, 1.0 / params.dynamics.particles)

    def reset(self, centre, rng: np.random.Generator, spread: float | None = None) -> None:
        """Particles around ``centre`` with zero velocity (start, recovery, split)."""
        s = self.params.dynamics.noise_xy if spread is None else spread
        n = self.params.dynamics.particles
        self.particles = np.zeros((n, 4))
        self.particles[:, :2] = np.asarray(centre, dtype=float)[None, :] + rng.normal(0.0, s, (n, 2))
        self.estimate = np.asarray(centre, dtype=float).copy()

    def box(self, centre=None) -> tuple[float, float, float, float]:
        cx, cy = self.estimate if centre is None else centre
        w, h = self.size
        return (float(cx - w / 2), float(cy - h / 2), w, h)

    def predict(self, rng: np.random.Generator, scale: float = 1.0) -> None:
        """Second-order dynamics (seed 003 sec. 3): position += velocity, both with white noise."""
        p, n = self.params, len(self.particles)
        d = p.dynamics
        self.particles[:, 2:] = d.velocity_decay * self.particles[:, 2:] + rng.normal(0.0, d.noise_v * scale, (n, 2))
        self.particles[:, :2] += self.particles[:, 2:] + rng.normal(0.0, d.noise_xy * scale, (n, 2))

    def particle_boxes(self) -> np.ndarray:
        w, h = self.size
        return np.column_stack([self.particles[:, 0] - w / 2, self.particles[:, 1] - h / 2,
                                np.full(len(self.particles), w), np.full(len(self.particles), h)])

    def weigh(self, candidates: Candidates, bin_image: np.ndarray) -> np.ndarray:
        """Weights = blob likelihood (eq. 17) x hue confidence (seed 003 eq. 1) + a floor; the hue
        histograms of the particles' boxes over ``bin_image`` (hue bins of skin pixels, -1 elsewhere).

        The floor is added, not multiplied by the hue term: a filter whose blob vanished
        then diffuses around its last place instead of being drawn to another limb's skin.

        ``confidence`` becomes the best particle's unnormalised score in [0, 1], the
        likelihood level the state machine thresholds.
        """
        p = self.params
        blob = np.minimum(blob_likelihood(self.particles[:, :2], candidates, p.priors.sigma_xy), 1.0)
        hist = local_box_histograms(bin_image, self.particle_boxes(), p.appearance.hue_bins)
        hue = hue_confidence(hist, self.ref_hist, p.appearance.lam)
        score = blob * hue
        self.confidence = float(score.max()) if score.size else 0.0
        w = score + p.priors.blob_floor
        total = w.sum()
        self.weights = w / total if total > 0 else np.full(len(w), 1.0 / len(w))
        self.estimate = (self.weights[:, None] * self.particles[:, :2]).sum(axis=0)
        return self.weights

    def refine(self, bin_image: np.ndarray | None) -> None:
        """Mean shift from the PF mean on the back-projection of the reference over the hue bins
        ``bin_image`` (skin pixels; -1 elsewhere), then shift the samples by the same amount (seed 003
        sec. 3: "redistribute the samples")."""
        p = self.params
        if bin_image is None or p.appearance.mean_shift_iterations <= 0:
            return
        x, y, w, h = local_mean_shift(bin_image, self.ref_hist, self.box(), p.appearance.mean_shift_iterations,
                                      p.appearance.mean_shift_eps)
        self.shift_to((x + w / 2, y + h / 2))

    def shift_to(self, centre) -> None:
        """Move the estimate to ``centre`` and every sample by the same amount (a refinement)."""
        new = np.asarray(centre, dtype=float)
        self.particles[:, :2] += new - self.estimate
        self.estimate = new.copy()

    def resample(self, rng: np.random.Generator) -> None:
        idx = systematic_resample(self.weights, len(self.particles), rng)
        self.particles = self.particles[idx]
        self.weights = np.full(len(self.particles), 1.0 / len(self.particles))

    def update_reference(self, hist: np.ndarray | None) -> None:
        """``h_ref = (1 - a) h_ref + a h`` with ``a`` = ``model_update``, when the estimate is confident."""
        if hist is None or hist.sum() <= 0:
            return
        a = self.params.appearance.model_update
        self.ref_hist = (1 - a) * self.ref_hist + a * hist


def candidate_modes(points: np.ndarray, weights: np.ndarray, candidates: Candidates, sigma_xy: float,
                    radius: float) -> np.ndarray:
    """Modes of a (combined) filter's posterior: ``(M, 2)`` candidate centres, strongest first.

    The posterior is the mixture of eq. (17); its components are the candidates, and the
    mass of component c is ``sum_i w_i p(x_i | Z_c) p(Z_c)``. Candidates with mass at least a
    tenth of the largest and within ``radius`` of the particle mean are the modes.
    """
    if len(candidates) == 0:
        return np.zeros((0, 2))
    points = np.asarray(points, float).reshape(-1, 2)
    w = np.asarray(weights, float)
    mean = (w[:, None] * points).sum(axis=0) / max(w.sum(), 1e-12)
    d2 = ((points[:, None, :] - candidates.centres[None, :, :]) ** 2).sum(axis=2)
    mass = (w[:, None] * np.exp(-d2 / (2.0 * sigma_xy**2))).sum(axis=0) * candidates.priors
    near = np.hypot(*(candidates.centres - mean[None, :]).T) <= radius
    mass = np.where(near, mass, 0.0)
    if mass.max() <= 0:
        return np.zeros((0, 2))
    keep = np.flatnonzero(mass >= 0.1 * mass.max())
    keep = keep[np.argsort(-mass[keep], kind="stable")]
    return candidates.centres[keep]
