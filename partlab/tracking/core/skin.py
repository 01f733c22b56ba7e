"""Skin-colour observations of the limb tracker (seed 000 sec. 6.1-6.2).

A pixel's skin probability comes from a histogram table over YCrCb: chroma (Cr, Cb)
separates skin from most backgrounds under changing brightness, which the luma
channel carries. The default model is the classic rectangular rule Cr in [133, 173],
Cb in [77, 127] (Chai & Ngan 1999), brightness-free, which holds for ordinary webcam
skin of light to dark tones and for the synthetic scenes. A model is trained from
boxes users corrected (or the ``--init`` boxes) as the ratio of the colour histogram
inside the boxes to the histogram of the whole frames (a Bayes skin classifier),
with coarse luma bins, blended with the rule so that colours never seen keep their
prior. Models are plain arrays: saved as JSON or ``.npz``, never pickles.

Skin pixels are intersected with the foreground mask (skin-coloured background is
not a limb), split into connected blobs, and the ``ceil(3 * alpha * people)``
largest kept after dropping tiny ones (seed 000 sec. 6.2).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import cv2
import numpy as np

#: the default rule's chroma ranges (Chai & Ngan 1999), inclusive, 0..255 scale.
DEFAULT_CR: tuple[int, int] = (133, 173)
DEFAULT_CB: tuple[int, int] = (77, 127)


@dataclass(frozen=True)
class SkinModel:
    """P(skin | Y, Cr, Cb) as a ``(ybins, bins, bins) float32`` table in [0, 1].

    The default rule ignores brightness (``ybins = 1``). A trained model splits luma
    coarsely too (8 bins): skin-coloured wood differs from a face in chroma by less
    than the noise on some scenes but is much darker or lighter.

    ``blur``: odd Gaussian kernel size applied to the frame before the lookup (1 = none).
    Camera noise scatters a skin region's chroma over neighbouring bins (std ~2-3 levels
    on the synthetic scenes and on webcams); a 5 x 5 blur cuts it by ~3x and turns a
    speckled skin mask into solid blobs.
    """

    table: np.ndarray
    blur: int = 5

    def __post_init__(self) -> None:
        t = np.asarray(self.table, dtype=np.float32)
        if t.ndim == 2:
            t = t[None]
        if (t.ndim != 3 or t.shape[1] != t.shape[2] or t.shape[1] < 2 or 256 % t.shape[1]
                or 256 % t.shape[0]):
            raise ValueError("skin table must be square (bins, bins) or (ybins, bins, bins) with bins "
                             f"dividing 256, got {np.shape(self.table)}")
        if not np.all(np.isfinite(t)) or t.min() < 0 or t.max() > 1:
            raise ValueError("skin table values must be finite probabilities in [0, 1]")
        object.__setattr__(self, "table", t)
        if int(self.blur) < 1 or int(self.blur) % 2 == 0:
            raise ValueError(f"skin blur must be an odd kernel size >= 1, got {self.blur}")
        object.__setattr__(self, "blur", int(self.blur))

    @property
    def bins(self) -> int:
        return int(self.table.shape[1])

    @property
    def ybins(self) -> int:
        return int(self.table.shape[0])

    @classmethod
    def default(cls, bins: int = 32, blur: int = 5) -> SkinModel:
        """The rectangular YCrCb rule as a table: 1 inside the ranges, 0 outside."""
        centres = (np.arange(bins) + 0.5) * (256 / bins)
        cr_in = (centres >= DEFAULT_CR[0]) & (centres <= DEFAULT_CR[1] + 1)
        cb_in = (centres >= DEFAULT_CB[0]) & (centres <= DEFAULT_CB[1] + 1)
        return cls((cr_in[:, None] & cb_in[None, :]).astype(np.float32)[None], blur)

    def with_ybins(self, ybins: int) -> SkinModel:
        """The same model over ``ybins`` luma bins (a 1-bin table is repeated)."""
        if ybins == self.ybins:
            return self
        if self.ybins != 1:
            raise ValueError(f"cannot change a model with {self.ybins} luma bins to {ybins}")
        return SkinModel(np.repeat(self.table, ybins, axis=0), self.blur)

    def chroma(self, frame: np.ndarray) -> np.ndarray:
        """``(H, W, 3) uint8`` YCrCb of the frame after the model's blur."""
        frame = _check_frame(frame)
        if self.blur > 1:
            frame = cv2.GaussianBlur(frame, (self.blur, self.blur), 0)
        return cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb)

    def probability(self, frame: np.ndarray) -> np.ndarray:
        """``(H, W) float32`` skin probability of a BGR ``(H, W, 3) uint8`` frame."""
        ycrcb = self.chroma(frame)
        shift = int(round(math.log2(256 // self.bins)))
        yshift = int(round(math.log2(256 // self.ybins)))
        return self.table[ycrcb[..., 0] >> yshift, ycrcb[..., 1] >> shift, ycrcb[..., 2] >> shift]

    def mask(self, frame: np.ndarray, foreground: np.ndarray | None = None, threshold: float = 0.5) -> np.ndarray:
        """``(H, W) uint8`` mask, 255 where skin probability >= ``threshold`` and (if given) foreground."""
        skin = self.probability(frame) >= threshold
        if foreground is not None:
            fg = np.asarray(foreground)
            if fg.shape != skin.shape:
                raise ValueError(f"foreground mask shape {fg.shape} does not match the frame {skin.shape}")
            skin &= fg > 0
        return skin.astype(np.uint8) * 255

    # -- persistence: plain arrays only ---------------------------------------------------
    def to_dict(self) -> dict:
        return {"kind": "skin_ycrcb_table", "bins": self.bins, "ybins": self.ybins, "blur": self.blur,
                "table": np.round(self.table, 5).tolist()}

    @classmethod
    def from_dict(cls, data: dict) -> SkinModel:
        if data.get("kind") != "skin_ycrcb_table":
            raise ValueError(f"not a skin model (kind={data.get('kind')!r})")
        return cls(np.asarray(data["table"], dtype=np.float32), int(data.get("blur", 5)))

    def save(self, path: str | PathLike) -> None:
        """Write as ``.json`` or ``.npz`` (chosen by the suffix)."""
        path = Path(path)
        if path.suffix == ".npz":
            np.savez(path, table=self.table, blur=np.int64(self.blur))
        else:
            path.write_text(json.dumps(self.to_dict()))

    @classmethod
    def load(cls, path: str | PathLike) -> SkinModel:
        path = Path(path)
        if path.suffix == ".npz":
            with np.load(path, allow_pickle=False) as z:
                return cls(z["table"], int(z["blur"]) if "blur" in z else 5)
        return cls.from_dict(json.loads(path.read_text()))


def _check_frame(frame: np.ndarray) -> np.ndarray:
    frame = np.asarray(frame)
    if frame.ndim != 3 or frame.shape[2] != 3 or frame.dtype != np.uint8:
        raise ValueError(f"expected a BGR (H, W, 3) uint8 frame, got shape {frame.shape} dtype {frame.dtype}")
    return frame


def train_skin_model(frames, boxes, bins: int = 32, ybins: int = 8, prior: SkinModel | None = None,
                     prior_weight: float = 20.0, inner: float = 1.0, keep_mass: float = 0.0,
                     keep_recall: float = 0.5, threshold: float = 0.5, keep_min_side: float = 0.0,
                     keep_spread: float = 0.0, kept: list[bool] | None = None,
                     keepable: list[bool] | None = None) -> SkinModel:
    """Fit P(skin | Y, Cr, Cb) from corrected head/hand boxes (the prior's blur is kept).

    ``frames``: BGR frames; ``boxes``: for each frame a ``(K, 4)`` array of ``x, y, w, h``
    skin boxes (head and hands users corrected). Only the ellipse inscribed in each box,
    scaled by ``inner`` (1: the whole inscribed ellipse; tight boxes such as the synthetic
    truth need all of it, a smaller hand loses a third of its pixels at 0.8), counts as
    skin: the box corners are background. The estimate ``n_skin / n_all`` per colour bin is shrunk towards
    ``prior`` (default: the rule) with ``prior_weight`` pseudo-counts, so colours seen
    rarely keep the prior's answer while colours that fill the scene (a wooden desk)
    get the low probability they earn.

    ``keep_mass``, ``keep_recall``: a box of which the fitted model calls less than
    ``keep_recall`` of the ellipse skin (probability >= ``threshold``) gets its colour bins
    holding ``keep_mass`` of its pixels (most common first) raised to the prior's
    probability (``keep_mass = 0``: off). The ratio alone undercounts a box's own colour
    when the same colour fills more of the frame elsewhere: on the synthetic desk (seeds
    2, 9) the forearms and the desk top next to the hands share the hands' bins, the ratio
    fell to ~0.4 and the refit model saw under 6% of each hand. Boxes the ratio already
    sees keep the ratio's answer. Boxes with a side under ``keep_min_side`` pixels are not
    kept: a distant walker's 8-pixel hand is mostly edge pixels blurred with the background,
    whose bins would turn the floor into skin.

    ``keep_spread`` (0: off): ... but then only those of their bins with at least
    ``1 / keep_spread`` of the bin's pixels in the frames inside the box: a hand's own colour,
    shared with its bare forearm (a bin's pixels 3-30 times the box's), not the floor's, a
    wall's or the sleeve's at the box's edge (hundreds to thousands of times): a small box is
    kept by what its own colours are in the frame, not refused for its size.

    ``kept``: a list that receives, for every box with both sides at least 2 pixels (frame by
    frame, in order), whether its bins were kept (a box whose colour is shared by what is around
    it, such as its bare forearm). ``keepable``: for the same boxes, whether each may be kept
    at all (default: all); a box that is a skin sample but not kept is, say, a hand its user
    marked hidden behind the body, whose box shows clothes.
    """
    if not 0.0 <= keep_mass <= 1.0:
        raise ValueError(f"keep_mass must be in [0, 1], got {keep_mass}")
    prior = (prior or SkinModel.default(bins)).with_ybins(ybins)
    if prior.bins != bins:
        raise ValueError(f"prior has {prior.bins} bins, expected {bins}")
    skin = np.zeros((ybins, bins, bins), np.float64)
    total = np.zeros((ybins, bins, bins), np.float64)
    box_hists: list[tuple[np.ndarray, bool] | None] = []  # (histogram, small: kept only by the spread test)
    n_frames = 0
    hist_args = ([0, 1, 2], [ybins, bins, bins], [0, 256, 0, 256, 0, 256])
    for frame, fboxes in zip(frames, boxes):
        n_frames += 1
        ycrcb = prior.chroma(frame)
        total += cv2.calcHist([ycrcb], hist_args[0], None, *hist_args[1:])
        mask = np.zeros(frame.shape[:2], np.uint8)
        for x, y, w, h in np.asarray(fboxes, dtype=float).reshape(-1, 4):
            if w < 2 or h < 2:
                continue
            one = np.zeros_like(mask)
            cv2.ellipse(one, (int(round(x + w / 2)), int(round(y + h / 2))),
                        (max(int(inner * w / 2), 1), max(int(inner * h / 2), 1)), 0, 0, 360, 255, -1)
            mask |= one
            small = min(w, h) < keep_min_side
            may_keep = keepable is None or bool(keepable[len(box_hists)])
            box_hists.append((cv2.calcHist([ycrcb], hist_args[0], one, *hist_args[1:]).ravel(), small)
                             if may_keep and keep_mass > 0 and (not small or keep_spread > 0) else None)
        skin += cv2.calcHist([ycrcb], hist_args[0], mask, *hist_args[1:])
    if n_frames == 0:
        raise ValueError("train_skin_model needs at least one frame")
    if skin.sum() == 0:
        raise ValueError("no skin pixels inside the given boxes")
    table = (skin + prior_weight * prior.table) / (total + prior_weight)
    keep = np.zeros(table.size, bool)
    seen = table.ravel() >= threshold
    for item in box_hists:
        if kept is not None:
            kept.append(False)
        if item is None:
            continue
        hist, small = item
        if hist.sum() == 0 or hist[seen].sum() >= keep_recall * hist.sum():
            continue
        order = np.argsort(-hist, kind="stable")
        n = int(np.searchsorted(np.cumsum(hist[order]), keep_mass * hist.sum())) + 1
        bins_kept = order[:n]
        if small:  # only the bins the box holds a share of: its own colour, not the floor's
            bins_kept = bins_kept[total.ravel()[bins_kept] <= keep_spread * hist[bins_kept]]
            if not (~seen[bins_kept]).any():
                continue
        keep[bins_kept] = True
        if kept is not None:
            kept[-1] = True
    table = np.where(keep.reshape(table.shape), np.maximum(table, prior.table), table)
    return SkinModel(np.clip(table, 0.0, 1.0).astype(np.float32), prior.blur)


@dataclass(frozen=True)
class Blobs:
    """Skin blobs of one frame, largest first.

    ``centres (K, 2)`` centres of mass, ``boxes (K, 4)`` ``x, y, w, h``, ``areas (K,)`` pixels,
    ``labels (H, W) int32`` the component image with blob k drawn as ``ids[k]``.
    """

    centres: np.ndarray
    boxes: np.ndarray
    areas: np.ndarray
    ids: np.ndarray
    labels: np.ndarray

    def __len__(self) -> int:
        return int(self.areas.size)


def find_blobs(mask: np.ndarray, people: int, alpha: float = 1.5, min_area: float = 30.0,
               regions: np.ndarray | None = None) -> Blobs:
    """Connected skin blobs of a ``(H, W) uint8`` mask (seed 000 sec. 6.2).

    Ideally each person gives 3 blobs (head, two hands); occlusion, shadows and
    joined limbs change that, so the ``ceil(3 * alpha * people)`` largest are kept
    (``alpha > 1`` keeps spares) after those smaller than ``min_area`` are dropped.

    ``regions``: ``(R, 4) int [x1, y1, x2, y2]`` boxes, not overlapping, outside which the mask
    is empty (the limb tracker's person regions): the components are labelled region by region,
    which on a large frame with a few people costs a fraction of labelling it whole.
    """
    if people < 0:
        raise ValueError(f"people must be >= 0, got {people}")
    labels, stats, centroids = _components((np.asarray(mask) > 0).astype(np.uint8), regions)
    areas = stats[1:, cv2.CC_STAT_AREA].astype(float)
    ids = np.arange(1, len(stats))
    keep = areas >= min_area
    ids, areas = ids[keep], areas[keep]
    order = np.argsort(-areas, kind="stable")[: max(int(math.ceil(3 * alpha * max(people, 1))), 0)]
    ids = ids[order]
    return Blobs(
        centres=centroids[ids].astype(float).reshape(-1, 2),
        boxes=stats[ids, :4].astype(float).reshape(-1, 4),
        areas=stats[ids, cv2.CC_STAT_AREA].astype(float),
        ids=ids,
        labels=labels,
    )


def _components(mask: np.ndarray, regions: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``cv2.connectedComponentsWithStats`` (8-connected) of the whole mask, or of each region with
    the labels numbered on across regions: labels ``(H, W) int32``, stats ``(n, 5)`` and centroids
    ``(n, 2)`` with row 0 the background."""
    if regions is None:
        _, labels, stats, centroids = cv2.connectedComponentsWithStats(mask, 8)
        return labels, stats, centroids
    labels = np.zeros(mask.shape, np.int32)
    stats, centroids = [np.zeros((1, 5), np.int32)], [np.zeros((1, 2))]
    n = 1
    for x1, y1, x2, y2 in np.asarray(regions, int).reshape(-1, 4):
        k, lab, st, ce = cv2.connectedComponentsWithStats(mask[y1:y2, x1:x2], 8)
        if k <= 1:
            continue
        own = lab > 0
        labels[y1:y2, x1:x2][own] = lab[own] + (n - 1)
        st = st[1:].copy()
        st[:, 0] += x1
        st[:, 1] += y1
        stats.append(st)
        centroids.append(ce[1:] + np.array([x1, y1]))
        n += k - 1
    return labels, np.vstack(stats), np.vstack(centroids)
