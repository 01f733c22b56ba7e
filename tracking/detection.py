"""Person-size foreground blobs: where new people are found (seed 002 sec. 4, 5).

Connected components of the cleaned foreground mask, kept when they are at least
``min_person_height`` x ``min_person_width`` pixels (the paper's people are over
100 x 30 px; smaller defaults let distant walkers count), taller than wide within
``max_person_aspect`` (w <= aspect * h), filled at least ``blob_fill_min`` and clear of
the frame border (people still entering are not started half-seen).
"""

from __future__ import annotations

import cv2
import numpy as np

from tracking.box import Box
from tracking.params import BodyParams


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
        if h < p.min_person_height or w < p.min_person_width:
            continue
        if w > p.max_person_aspect * h or h > 0.95 * H:
            continue
        b = p.detection_border
        if x < b or y < b or x + w > W - b or y + h > H - b:
            continue
        if area < p.blob_fill_min * w * h:
            continue
        out.append((area, Box(float(x), float(y), float(w), float(h))))
    out.sort(key=lambda t: -t[0])
    return [b for _, b in out]
