"""Depth as a picture: millimetres to a colour map (near = red, far = blue), missing depth black.

For showing depth beside colour (the app's Depth page, the benchmarks' figures); the numbers stay
in the take, this is only a view.
"""

from __future__ import annotations

import cv2
import numpy as np


def depth_colours(depth: np.ndarray, near: float | None = None, far: float | None = None) -> np.ndarray:
    """``(H, W, 3) uint8`` BGR of ``depth`` (mm, NaN = missing) through OpenCV's TURBO map:
    ``near`` (default: the 2nd percentile) is red, ``far`` (the 98th) blue, NaN black."""
    d = np.asarray(depth, np.float32)
    ok = np.isfinite(d)
    if not ok.any():
        return np.zeros(d.shape + (3,), np.uint8)
    lo = float(np.percentile(d[ok], 2)) if near is None else float(near)
    hi = float(np.percentile(d[ok], 98)) if far is None else float(far)
    scale = 255.0 / max(hi - lo, 1e-6)
    level = np.clip((hi - np.where(ok, d, hi)) * scale, 0, 255).astype(np.uint8)  # near -> 255
    out = cv2.applyColorMap(level, cv2.COLORMAP_TURBO)
    out[~ok] = 0
    return out
