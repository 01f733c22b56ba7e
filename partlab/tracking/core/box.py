"""Axis-aligned boxes in pixels: (x, y) is the top-left corner, (w, h) the size.

``Box`` is the scalar type used at the edges (CSV rows, the store, the editor);
the ``*_xywh`` functions are the same geometry over ``(N, 4)`` arrays for the hot
loops and for evaluation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class Box:
    x: float
    y: float
    w: float
    h: float

    def __post_init__(self) -> None:
        if self.w < 0 or self.h < 0:
            raise ValueError(f"box size must be non-negative, got w={self.w}, h={self.h}")

    @property
    def x2(self) -> float:
        return self.x + self.w

    @property
    def y2(self) -> float:
        return self.y + self.h

    @property
    def area(self) -> float:
        return self.w * self.h

    @property
    def centre(self) -> tuple[float, float]:
        return (self.x + self.w / 2.0, self.y + self.h / 2.0)

    def intersection(self, other: Box) -> float:
        """Area of overlap with ``other`` (0 when disjoint)."""
        iw = min(self.x2, other.x2) - max(self.x, other.x)
        ih = min(self.y2, other.y2) - max(self.y, other.y)
        return max(iw, 0.0) * max(ih, 0.0)

    def iou(self, other: Box) -> float:
        """Intersection over union; 0 for two empty boxes."""
        inter = self.intersection(other)
        union = self.area + other.area - inter
        return inter / union if union > 0 else 0.0

    def contains_point(self, px: float, py: float) -> bool:
        return self.x <= px <= self.x2 and self.y <= py <= self.y2

    def clip(self, width: int, height: int) -> Box:
        """The part of the box inside a ``width`` x ``height`` frame (may be empty)."""
        x1 = min(max(self.x, 0.0), width)
        y1 = min(max(self.y, 0.0), height)
        x2 = min(max(self.x2, 0.0), width)
        y2 = min(max(self.y2, 0.0), height)
        return Box(x1, y1, x2 - x1, y2 - y1)

    def union_box(self, other: Box) -> Box:
        """Minimum bounding rectangle of both boxes."""
        x1, y1 = min(self.x, other.x), min(self.y, other.y)
        x2, y2 = max(self.x2, other.x2), max(self.y2, other.y2)
        return Box(x1, y1, x2 - x1, y2 - y1)

    def transformed(self, scale_w: float, scale_h: float, shift_x: float = 0.0, shift_y: float = 0.0) -> Box:
        """The box scaled about its centre and moved by fractions of its own size."""
        cx, cy = self.centre
        cx += shift_x * self.w
        cy += shift_y * self.h
        w, h = self.w * scale_w, self.h * scale_h
        return Box(cx - w / 2.0, cy - h / 2.0, w, h)

    def as_tuple(self) -> tuple[float, float, float, float]:
        return (self.x, self.y, self.w, self.h)


def intersection_xywh(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pairwise overlap areas of boxes ``a (N, 4)`` and ``b (M, 4)`` -> ``(N, M)``."""
    a = np.asarray(a, dtype=float).reshape(-1, 4)
    b = np.asarray(b, dtype=float).reshape(-1, 4)
    x1 = np.maximum(a[:, None, 0], b[None, :, 0])
    y1 = np.maximum(a[:, None, 1], b[None, :, 1])
    x2 = np.minimum(a[:, None, 0] + a[:, None, 2], b[None, :, 0] + b[None, :, 2])
    y2 = np.minimum(a[:, None, 1] + a[:, None, 3], b[None, :, 1] + b[None, :, 3])
    return np.clip(x2 - x1, 0, None) * np.clip(y2 - y1, 0, None)


def iou_xywh(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pairwise IoU of boxes ``a (N, 4)`` and ``b (M, 4)`` -> ``(N, M)``."""
    a = np.asarray(a, dtype=float).reshape(-1, 4)
    b = np.asarray(b, dtype=float).reshape(-1, 4)
    inter = intersection_xywh(a, b)
    union = (a[:, 2] * a[:, 3])[:, None] + (b[:, 2] * b[:, 3])[None, :] - inter
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(union > 0, inter / union, 0.0)
