"""People detection as a tracking cue: OpenCV's HOG people detector run only where people can be.

Dalal & Triggs' HOG + linear SVM (``cv2.HOGDescriptor_getDefaultPeopleDetector``, ships with
OpenCV, nothing to download) scanned over a whole frame at every scale costs about 0.4-1.5 s a
frame; a tracker only needs it where a person can be: around foreground blobs (a newcomer) and
around its own tracks (re-acquiring, re-sizing, ending them). Each such *region* is cropped with a
margin and resized so that the people expected in it (about the region's height) fill the
detector's window, then scanned over a few scales only; what the detector finds is mapped back to
the frame, its window shrunk to the body (the 64 x 128 window holds a person of about 0.6 x 0.75 of
it) and suppressed to one box per person (non-maximum suppression).

:func:`associate` pairs detections with tracks by the Hungarian method on IoU
(:mod:`partlab.tracking.core.assignment`, SciPy's algorithm without importing ``scipy.optimize``),
as SORT (Bewley et al. 2016) and Breitenstein et al.
(2009, "Robust tracking-by-detection using a detector confidence particle filter") do.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from partlab.tracking.core.assignment import linear_sum_assignment
from partlab.tracking.core.box import Box, iou_xywh

#: the default detector's window (width, height) in pixels
WINDOW = (64, 128)


@dataclass(frozen=True)
class RegionScan:
    """How a region is scanned (the defaults live in the tracker's parameters, e.g.
    ``BodyParams().detector``): ``fill``: the region's reference height is resized to this many
    times the height of the body in the window (above 1, people up to about 1/fill of the region's
    height are still found; the pyramid finds the larger ones); ``margin``: the crop reaches this
    many reference heights beyond the region on every side; ``scale_step``: HOG's pyramid factor;
    ``min_score``: the SVM margin a window needs; ``nms``: IoU above which the weaker of two
    detections is dropped; ``shrink``: (width, height) of the body in the window;
    ``max_upscale``: regions are never enlarged more than this (tiny far blobs are noise)."""

    fill: float
    margin: float
    scale_step: float
    min_score: float
    nms: float
    shrink: tuple[float, float]
    max_upscale: float
    finer: float = 1.0


class PeopleDetector:
    """HOG people detection restricted to regions of a frame."""

    def __init__(self, scan: RegionScan):
        self.scan = scan
        self.hog = cv2.HOGDescriptor()
        self.hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())

    def crops(self, regions: list[Box], W: int, H: int) -> list[tuple[Box, float]]:
        """Merged crops ``(box, reference height)``: each region widened by the margin (and to at
        least a window's shape around it), overlapping crops joined (one scan, the smaller
        reference height, so that nobody in either is too small to be found)."""
        s = self.scan
        out: list[list] = []
        for r in regions:
            h = max(r.h, 1.0)
            win_w = h / s.shrink[1] * WINDOW[0] / WINDOW[1]
            half_w = max(r.w / 2, win_w / 2) + s.margin * h
            cx, cy = r.centre
            half_h = h / s.shrink[1] / 2 + s.margin * h
            crop = Box(cx - half_w, cy - half_h, 2 * half_w, 2 * half_h).clip(W, H)
            if crop.w < 8 or crop.h < 8:
                continue
            out.append([crop, h])
        merged = True
        while merged:  # join until no two crops overlap (a handful of crops: quadratic is fine)
            merged = False
            for i in range(len(out)):
                for j in range(i + 1, len(out)):
                    if out[i][0].intersection(out[j][0]) > 0:
                        out[i] = [out[i][0].union_box(out[j][0]), min(out[i][1], out[j][1])]
                        del out[j]
                        merged = True
                        break
                if merged:
                    break
        return [(c, h) for c, h in out]

    def detect(self, frame: np.ndarray, regions: list[Box]) -> np.ndarray:
        """``(N, 5)`` float64 ``x, y, w, h, score`` of the people found in ``regions`` of ``frame``
        (BGR), body boxes in frame pixels, sorted by score (highest first; ties by position, so
        the order never depends on threads)."""
        s = self.scan
        H, W = frame.shape[:2]
        rects, scores = [], []
        for crop, ref_h in self.crops(regions, W, H):
            f = min(s.fill * WINDOW[1] * s.shrink[1] / ref_h, s.max_upscale)
            r, w = self._scan(frame, crop, f)
            if len(r) and s.finer < 1 and f < s.max_upscale:
                r, w = self._finer(frame, r, w, f)
            if len(r):
                rects.append(r)
                scores.append(w)
        if not rects:
            return np.zeros((0, 5))
        r, w = np.concatenate(rects), np.concatenate(scores)
        keep = w >= s.min_score
        r, w = r[keep], w[keep]
        if len(r) == 0:
            return np.zeros((0, 5))
        order = np.lexsort((r[:, 1], r[:, 0], -np.round(w, 6)))
        r, w = r[order], w[order]
        cx, cy = r[:, 0] + r[:, 2] / 2, r[:, 1] + r[:, 3] / 2
        bw, bh = r[:, 2] * s.shrink[0], r[:, 3] * s.shrink[1]
        boxes = np.stack([cx - bw / 2, cy - bh / 2, bw, bh], axis=1)
        keep = _nms(boxes, w, s.nms)
        return np.concatenate([boxes[keep], w[keep, None]], axis=1)

    def _scan(self, frame: np.ndarray, crop: Box, f: float) -> tuple[np.ndarray, np.ndarray]:
        """Windows ``(N, 4)`` (frame pixels) and scores HOG finds in ``crop`` of ``frame`` resized by ``f``."""
        x0, y0 = int(crop.x), int(crop.y)
        x1, y1 = int(np.ceil(crop.x2)), int(np.ceil(crop.y2))
        img = frame[y0:y1, x0:x1]
        img = cv2.resize(img, None, fx=f, fy=f, interpolation=cv2.INTER_LINEAR if f > 1 else cv2.INTER_AREA)
        if img.shape[0] < WINDOW[1] or img.shape[1] < WINDOW[0]:
            img = cv2.copyMakeBorder(img, 0, max(WINDOW[1] - img.shape[0], 0), 0,
                                     max(WINDOW[0] - img.shape[1], 0), cv2.BORDER_REPLICATE)
        r, w = self.hog.detectMultiScale(img, winStride=(8, 8), padding=(8, 8), scale=self.scan.scale_step)
        if len(r) == 0:
            return np.zeros((0, 4)), np.zeros(0)
        r = np.asarray(r, np.float64) / f
        r[:, 0] += x0
        r[:, 1] += y0
        return r, np.asarray(w, np.float64).ravel()

    def _finer(self, frame: np.ndarray, r: np.ndarray, w: np.ndarray, f: float) -> tuple[np.ndarray, np.ndarray]:
        """The windows of the scan's smallest scale (the person may be smaller than any window
        it tried: a walker going away from the camera inside a track's box) scanned again, each
        around itself, ``finer`` times smaller; their windows join the scan's."""
        s = self.scan
        H, W = frame.shape[:2]
        smallest = WINDOW[1] / f * s.scale_step ** 0.5
        at_min = r[:, 3] <= smallest
        if not at_min.any() or w[at_min].max() < s.min_score:
            return r, w
        f2 = min(f / s.finer, s.max_upscale)
        out_r, out_w = [r], [w]
        for x, y, ww, hh in r[at_min & (w >= s.min_score)]:
            m = s.margin * hh
            crop = Box(x - m, y - m, ww + 2 * m, hh + 2 * m).clip(W, H)
            if crop.w < 8 or crop.h < 8:
                continue
            r2, w2 = self._scan(frame, crop, f2)
            small = r2[:, 3] < hh / s.scale_step ** 0.5 if len(r2) else np.zeros(0, bool)
            out_r.append(r2[small])
            out_w.append(w2[small])
        return np.concatenate(out_r), np.concatenate(out_w)


def _nms(boxes: np.ndarray, scores: np.ndarray, threshold: float) -> np.ndarray:
    """Greedy non-maximum suppression over ``boxes`` already sorted by score: indexes kept.
    A box is also dropped when it lies mostly (> 0.7) inside a stronger one (a detection of the
    upper body inside the whole person's)."""
    kept: list[int] = []
    for i in range(len(boxes)):
        if kept:
            k = boxes[kept]
            iou = iou_xywh(boxes[i:i + 1], k)[0]
            ix = np.clip(np.minimum(boxes[i, 0] + boxes[i, 2], k[:, 0] + k[:, 2]) - np.maximum(boxes[i, 0], k[:, 0]),
                         0, None)
            iy = np.clip(np.minimum(boxes[i, 1] + boxes[i, 3], k[:, 1] + k[:, 3]) - np.maximum(boxes[i, 1], k[:, 1]),
                         0, None)
            inside = ix * iy / max(boxes[i, 2] * boxes[i, 3], 1e-9)
            if (iou > threshold).any() or (inside > 0.7).any():
                continue
        kept.append(i)
    return np.asarray(kept, dtype=int)


def associate(tracks: np.ndarray, detections: np.ndarray, iou_min: float, affinity: np.ndarray | None = None,
              affinity_min: float = 0.0, affinity_weight: float = 0.0) -> list[tuple[int, int]]:
    """``(track index, detection index)`` pairs of the assignment maximising the total IoU
    (Hungarian method), only pairs with IoU at least ``iou_min``. ``tracks``, ``detections``:
    ``(N, >=4)`` x, y, w, h.

    ``affinity`` ``(tracks, detections)``, e.g. how well each detection matches each track's
    colour model (a walker's box overlaps the neighbour it walks beside as much as its own
    person): pairs below ``affinity_min`` are never made, and the assignment maximises
    ``IoU + affinity_weight * affinity`` (appearance and motion gating, as in DeepSORT, Wojke et
    al. 2017, with colour in place of a learnt embedding)."""
    if len(tracks) == 0 or len(detections) == 0:
        return []
    iou = iou_xywh(np.asarray(tracks, float)[:, :4], np.asarray(detections, float)[:, :4])
    if affinity is None:  # IoU alone: assign over every pair, then keep those overlapping enough
        rows, cols = linear_sum_assignment(-iou)
        return [(int(t), int(d)) for t, d in zip(rows, cols) if iou[t, d] >= iou_min]
    # gated first (IoU and affinity), then assigned among the pairs left
    a = np.nan_to_num(np.asarray(affinity, float), nan=-np.inf)
    ok = (iou >= iou_min) & (a >= affinity_min)
    score = np.where(ok, iou + affinity_weight * np.where(ok, a, 0.0), -1e6)
    rows, cols = linear_sum_assignment(-score)
    return [(int(t), int(d)) for t, d in zip(rows, cols) if ok[t, d]]


def associate_near(previous: np.ndarray, detections: np.ndarray, max_distance: float) -> list[tuple[int, int]]:
    """``(previous index, detection index)`` pairs of the assignment minimising the total distance
    between box centres, in units of the detection's height, only pairs at most ``max_distance``
    apart and of heights within a factor 1.5 (a person seen a few frames apart: a fast walker's
    boxes no longer overlap, its size hardly changes)."""
    if len(previous) == 0 or len(detections) == 0:
        return []
    a, b = np.asarray(previous, float)[:, :4], np.asarray(detections, float)[:, :4]
    ca, cb = a[:, :2] + a[:, 2:4] / 2, b[:, :2] + b[:, 2:4] / 2
    d = np.hypot(*(ca[:, None, :] - cb[None, :, :]).transpose(2, 0, 1)) / np.maximum(b[None, :, 3], 1e-6)
    ratio = a[:, None, 3] / np.maximum(b[None, :, 3], 1e-6)
    cost = np.where((ratio <= 1.5) & (ratio >= 1 / 1.5), d, 1e6)
    rows, cols = linear_sum_assignment(cost)
    return [(int(i), int(j)) for i, j in zip(rows, cols) if cost[i, j] <= max_distance]
