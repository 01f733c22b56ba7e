"""Person-size foreground blobs: where new people are found (seed 002 sec. 4, 5).

Connected components of the cleaned foreground mask, kept when they are at least
``min_person_height`` x ``min_person_width`` pixels (the paper's people are over
100 x 30 px; smaller defaults let distant walkers count), taller than wide within
``max_person_aspect`` (w <= aspect * h), filled at least ``blob_fill_min`` and clear of
the frame border (people still entering are not started half-seen).

``edge_contrast`` tells a person from a "ghost": a background model that learnt a person
standing in the first frames keeps reporting foreground where they stood after they leave,
but what the camera sees there now is plain background, so the blob's outline lies on no
image edge.
"""

from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.core.box import Box
from partlab.tracking.params import BodyParams


def person_blobs(mask: np.ndarray, params: BodyParams | None = None) -> list[Box]:
    """Boxes of person-size blobs of ``mask (H, W) uint8``, largest first."""
    p = params or BodyParams()
    if mask is None or not mask.any():
        return []
    n, _, stats, _ = cv2.connectedComponentsWithStats((mask > 0).astype(np.uint8), connectivity=8)
    H, W = mask.shape[:2]
    out: list[tuple[int, Box]] = []
    for i in range(1, n):
        x, y, w, h, area = (int(v) for v in stats[i])
        if h < p.detection.min_person_height or w < p.detection.min_person_width:
            continue
        if w > p.detection.max_person_aspect * h or h > 0.95 * H:
            continue
        b = p.detection.border
        if x < b or y < b or x + w > W - b or y + h > H - b:
            continue
        if area < p.detection.fill_min * w * h:
            continue
        out.append((area, Box(float(x), float(y), float(w), float(h))))
    out.sort(key=lambda t: -t[0])
    return [b for _, b in out]


def _disc(size: int) -> np.ndarray:
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size))


def edge_contrast(frame: np.ndarray, mask: np.ndarray, box: Box) -> float:
    """Mean gradient magnitude of ``frame`` (BGR) in a band of +-4 px around the outline of the
    foreground in ``box``, over the mean in a ring 6-12 px outside it (the background's own
    texture). About 1 for a ghost; 2-3 for a person on the synthetic scenes."""
    H, W = mask.shape[:2]
    pad = 14
    x0, y0 = max(int(box.x) - pad, 0), max(int(box.y) - pad, 0)
    x1, y1 = min(int(np.ceil(box.x2)) + pad, W), min(int(np.ceil(box.y2)) + pad, H)
    if x1 - x0 < 3 or y1 - y0 < 3:
        return 0.0
    gray = cv2.cvtColor(frame[y0:y1, x0:x1], cv2.COLOR_BGR2GRAY).astype(np.float32)
    mag = cv2.magnitude(cv2.Sobel(gray, cv2.CV_32F, 1, 0), cv2.Sobel(gray, cv2.CV_32F, 0, 1))
    fg = (mask[y0:y1, x0:x1] > 0).astype(np.uint8)
    band = (cv2.dilate(fg, _disc(9)) - cv2.erode(fg, _disc(9))) > 0
    ring = (cv2.dilate(fg, _disc(25)) - cv2.dilate(fg, _disc(13))) > 0
    if not band.any() or not ring.any():
        return float("inf")  # the ring falls outside the frame: no reference, do not reject
    return float(mag[band].mean() / max(float(mag[ring].mean()), 1.0))
