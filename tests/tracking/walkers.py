"""Tiny drawn walkers for the body-tracker tests (no video files, a few ms per frame)."""

from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.core.box import Box
from partlab.tracking.measures import right_box_one

SKIN = (90, 140, 200)


def background(rng: np.random.Generator, width: int, height: int) -> np.ndarray:
    """A fixed, blotchy grey-green background (the same every frame)."""
    small = rng.integers(60, 180, (height // 8 + 1, width // 8 + 1, 3), dtype=np.uint8)
    big = cv2.resize(small, (width, height), interpolation=cv2.INTER_LINEAR)
    return cv2.GaussianBlur(big, (0, 0), 2)


def draw_walker(frame: np.ndarray, cx: float, top: float, height: float, shirt, trousers, phase: float = 0.0):
    """Draw a walker of ``height`` px with feet centred at ``cx``; returns truth part boxes."""
    h = height
    head_r = 0.075 * h
    hx, hy = cx, top + head_r
    cv2.circle(frame, (int(round(hx)), int(round(hy))), int(round(head_r)), SKIN, -1)
    tw, tt, tb = 0.26 * h, top + 0.15 * h, top + 0.5 * h
    cv2.rectangle(frame, (int(cx - tw / 2), int(tt)), (int(cx + tw / 2), int(tb)), shirt, -1)
    lw = 0.1 * h
    swing = 0.08 * h * np.sin(phase)
    for side, s in ((-1, swing), (1, -swing)):
        x_hip = cx + side * lw * 0.6
        pts = np.array([[x_hip - lw / 2, tb], [x_hip + lw / 2, tb],
                        [x_hip + s + lw / 2, top + h], [x_hip + s - lw / 2, top + h]], np.int32)
        cv2.fillConvexPoly(frame, pts, trousers)
    return {
        "head": Box(hx - head_r, top, 2 * head_r, 2 * head_r),
        "torso": Box(cx - tw / 2, tt, tw, tb - tt),
        "hipleg": Box(cx - lw * 1.1 - abs(swing), tb, 2.2 * lw + 2 * abs(swing), top + h - tb),
        "person": Box(cx - max(tw / 2, lw * 1.1 + abs(swing)), top, max(tw, 2.2 * lw + 2 * abs(swing)), h),
    }


def correct(box: Box, truth: Box) -> bool:
    """The right-box rule (:func:`partlab.tracking.measures.right_box`) for two boxes."""
    return right_box_one(box, truth)
