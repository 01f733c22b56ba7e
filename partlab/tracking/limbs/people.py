"""Where people are, for limb trackers started without ``--init`` (issue 13).

The head-and-hands paper starts its trackers from skin blobs inside the silhouettes of the people
its background subtraction finds (sec. 6.2), in a room where nothing else moves. Outdoors a
real background model also lets through skin-coloured walls, grass, road cones and parked cars
now and then (lighting, camera noise, its own warm-up); a skin blob there persists for a few
frames, starts a tracker, and the tracker's own support region then keeps it observable for
good. So, found automatically, limbs live only on people:

- **person regions** are the boxes of the foreground's connected components at least
  ``people.min_height`` of the frame tall (a walker's silhouette after a closing that joins its
  legs and body), or, under ``--tracker all``, the body tracker's person boxes of the frame;
- a tracker **starts** only from a skin blob inside a person region, is **labelled a head** only
  in the top ``people.head_top`` of one (a standing or sitting person's head is in the top third
  of their box), a hand only inside one;
- its rows are **written** only while it is on a person region (a head in its top part), and it
  **ends** after ``people.end_frames`` frames off every person region.

Found automatically, the skin and hue images are computed only over these regions and the targets'
neighbourhoods (:func:`merge_boxes`, :func:`on_regions`): nothing is started or kept elsewhere.

Boxes are ``(P, 4) float [x, y, w, h]`` in pixels; regions ``(R, 4) int [x1, y1, x2, y2]``.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np

from partlab.tracking.params import LimbParams


def foreground_people(foreground: np.ndarray, params: LimbParams) -> np.ndarray:
    """Person regions of a foreground mask ``(H, W)`` (non-zero = moving): ``(P, 4)`` boxes of its
    connected components at least ``people.min_height`` of the frame tall, after a closing of
    ``people.close`` of the frame height that joins a walker's legs, body and head.

    Found on the mask shrunk by ``people.shrink`` (a cell is foreground when any of its pixels
    is): a region's box needs no finer grain than a few pixels, and the full-size closing and
    labelling cost as much as the body tracker's whole frame on PETS09."""
    pp = params.people
    fg = np.asarray(foreground)
    hgt, wid = fg.shape
    f = max(int(pp.shrink), 1)
    small = (fg > 0).astype(np.uint8)
    if f > 1:  # max over f x f cells
        padded = np.zeros((-(-hgt // f) * f, -(-wid // f) * f), np.uint8)
        padded[:hgt, :wid] = small
        small = padded.reshape(padded.shape[0] // f, f, padded.shape[1] // f, f).max(axis=(1, 3))
    k = max(int(round(pp.close * hgt / f)) | 1, 3)
    small = cv2.morphologyEx(small, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k)))
    n, _, stats, _ = cv2.connectedComponentsWithStats(small, connectivity=8)
    boxes = stats[1:n, :4].astype(float) * f
    boxes[:, 2] = np.minimum(boxes[:, 0] + boxes[:, 2], wid) - boxes[:, 0]
    boxes[:, 3] = np.minimum(boxes[:, 1] + boxes[:, 3], hgt) - boxes[:, 1]
    return boxes[boxes[:, 3] >= pp.min_height * hgt]


def in_regions(points: np.ndarray, boxes: np.ndarray, top: float = 1.0, margin: float = 0.0) -> np.ndarray:
    """``(K,) bool``: which ``points (K, 2)`` lie inside some box ``(P, 4)``, within its top ``top``
    fraction of height, the box grown by ``margin`` pixels on every side."""
    pts = np.asarray(points, float).reshape(-1, 2)
    b = np.asarray(boxes, float).reshape(-1, 4)
    if len(pts) == 0 or len(b) == 0:
        return np.zeros(len(pts), bool)
    x, y = pts[:, None, 0], pts[:, None, 1]
    inside = ((x >= b[None, :, 0] - margin) & (x <= b[None, :, 0] + b[None, :, 2] + margin)
              & (y >= b[None, :, 1] - margin) & (y <= b[None, :, 1] + top * b[None, :, 3] + margin))
    return inside.any(axis=1)


def merge_boxes(boxes: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Boxes ``(B, 4) x, y, w, h`` as disjoint-ish regions ``(R, 4) int [x1, y1, x2, y2]`` clipped to
    a frame of ``shape (H, W)``: overlapping boxes are merged into their common bounding box (until
    none overlap), so no pixel is computed twice; empty boxes are dropped."""
    hgt, wid = shape
    b = np.asarray(boxes, float).reshape(-1, 4)
    r = np.column_stack([np.floor(b[:, 0]), np.floor(b[:, 1]), np.ceil(b[:, 0] + b[:, 2]),
                         np.ceil(b[:, 1] + b[:, 3])])
    r = np.clip(r, 0, [wid, hgt, wid, hgt]).astype(int)
    regions = [list(x) for x in r if x[2] > x[0] and x[3] > x[1]]
    merged = True
    while merged:
        merged = False
        for i in range(len(regions)):
            for j in range(i + 1, len(regions)):
                a, c = regions[i], regions[j]
                if a[0] < c[2] and c[0] < a[2] and a[1] < c[3] and c[1] < a[3]:
                    regions[i] = [min(a[0], c[0]), min(a[1], c[1]), max(a[2], c[2]), max(a[3], c[3])]
                    del regions[j]
                    merged = True
                    break
            if merged:
                break
    return np.array(regions, int).reshape(-1, 4)


def on_regions(fn: Callable[[np.ndarray], np.ndarray], frame: np.ndarray, regions: np.ndarray | None,
               fill: float, dtype, pad: int = 0) -> np.ndarray:
    """``fn`` (a per-pixel image function of a BGR frame, e.g. the skin probability) over ``regions``
    only, ``fill`` elsewhere: ``(H, W) dtype``. Each region is computed on a crop grown by ``pad``
    pixels (the reach of a blur inside ``fn``), so its pixels equal the whole frame's. ``regions``
    None: the whole frame."""
    if regions is None:
        return np.asarray(fn(frame)).astype(dtype, copy=False)
    hgt, wid = frame.shape[:2]
    out = np.full((hgt, wid), fill, dtype)
    for x1, y1, x2, y2 in np.asarray(regions, int).reshape(-1, 4):
        px1, py1, px2, py2 = max(x1 - pad, 0), max(y1 - pad, 0), min(x2 + pad, wid), min(y2 + pad, hgt)
        part = fn(np.ascontiguousarray(frame[py1:py2, px1:px2]))
        out[y1:y2, x1:x2] = part[y1 - py1:y2 - py1, x1 - px1:x2 - px1]
    return out
