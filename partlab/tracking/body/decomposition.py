"""Three-part decomposition of a person's foreground region (seed 002 sec. 4.1).

1. Two horizontal separation lines cut the person's foreground rows by the height ratios
   ``BodyParams.decomposition.height_ratios`` (head : torso : hip-leg; the paper gives none, so adult
   proportions are used, see the parameter's comment).
2. Each line moves up or down while the mean colours (YCrCb) of the two sections it
   separates grow more different; a line that wanders further than
   ``separation_search`` x height is reset to its initial place (the paper's rule, so a
   line between two similar parts stays where the ratios put it).
3. Each section shrinks to its *inner rectangle*: centre at the mass centre of its
   foreground pixels, half-sizes their standard deviations in x and y. The hip-leg
   rectangle keeps only the upper half of its section (lower legs swing too much).

:func:`inner_rectangle` is also what the adjustment of sec. 4.3 uses on the foreground
above or below a torso to rebuild a lost head or hip-leg.
"""

from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.core.box import Box
from partlab.tracking.measures import person_box
from partlab.tracking.params import BodyParams

#: below this share of foreground in the person's box the mask is not trusted (first frames
#: of the background model, a person standing still): the box's colour contrast with its
#: surroundings stands in for it (:func:`contrast_foreground`), else the whole box.
MIN_FOREGROUND_SHARE = 0.15


def inner_rectangle(fg: np.ndarray, x0: float = 0.0, y0: float = 0.0, min_size: float = 2.0) -> Box | None:
    """Inner rectangle of the foreground pixels of ``fg (h, w) bool``: mass centre plus or
    minus the standard deviation in x and y, offset by ``(x0, y0)``; None when empty."""
    ys, xs = np.nonzero(fg)
    if len(xs) == 0:
        return None
    cx, cy = xs.mean() + 0.5, ys.mean() + 0.5
    sx, sy = max(xs.std(), min_size / 2), max(ys.std(), min_size / 2)
    return Box(x0 + cx - sx, y0 + cy - sy, 2 * sx, 2 * sy)


def contrast_foreground(ycc: np.ndarray, x1: int, y1: int, x2: int, y2: int, ring: float = 0.3,
                        levels: int = 16) -> np.ndarray:
    """Foreground of the box ``[x1, x2) x [y1, y2)`` without a background model: pixels whose
    colour (YCrCb quantised to ``levels`` per channel) is more frequent inside the box than
    in a ring of ``ring`` x the box size around it. Used when a person box is given (an
    init row) before the background model has learnt anything. ``(y2 - y1, x2 - x1) bool``."""
    H, W = ycc.shape[:2]
    bw, bh = x2 - x1, y2 - y1
    rx1, ry1 = max(x1 - int(ring * bw), 0), max(y1 - int(ring * bh * 0.5), 0)
    rx2, ry2 = min(x2 + int(ring * bw), W), min(y2 + int(ring * bh * 0.5), H)
    shift = int(np.log2(256 // levels))
    q = (ycc[ry1:ry2, rx1:rx2] >> shift).astype(np.int32)
    codes = (q[..., 0] * levels + q[..., 1]) * levels + q[..., 2]
    inside = np.zeros(codes.shape, dtype=bool)
    inside[y1 - ry1:y2 - ry1, x1 - rx1:x2 - rx1] = True
    n = levels ** 3
    h_in = np.bincount(codes[inside], minlength=n).astype(np.float64)
    h_out = np.bincount(codes[~inside], minlength=n).astype(np.float64)
    if h_out.sum() == 0:
        return np.ones((bh, bw), dtype=bool)
    p_in = h_in / max(h_in.sum(), 1.0)
    p_out = h_out / h_out.sum()
    fg = (p_in > p_out)[codes[inside].reshape(bh, bw)]
    return cv2.medianBlur(fg.astype(np.uint8) * 255, 3) > 0


def _region(ycc: np.ndarray, mask: np.ndarray | None, box: Box):
    H, W = ycc.shape[:2]
    x1, y1 = max(int(round(box.x)), 0), max(int(round(box.y)), 0)
    x2, y2 = min(int(round(box.x2)), W), min(int(round(box.y2)), H)
    if x2 - x1 < 2 or y2 - y1 < 3:
        raise ValueError(f"person box {box.as_tuple()} has less than 2 x 3 pixels inside the {W}x{H} frame")
    colours = ycc[y1:y2, x1:x2].astype(np.float64)
    fg = None if mask is None else mask[y1:y2, x1:x2] > 0
    if fg is None or fg.mean() < MIN_FOREGROUND_SHARE:
        fg = contrast_foreground(ycc, x1, y1, x2, y2)
        if fg.mean() < MIN_FOREGROUND_SHARE:
            fg = np.ones_like(fg)
    return x1, y1, colours, fg


def separation_lines(colours: np.ndarray, fg: np.ndarray, top: int, bottom: int,
                     params: BodyParams) -> tuple[int, int]:
    """Rows (relative to the region) of the head/torso and torso/hip-leg separation lines."""
    counts = fg.sum(axis=1).astype(np.float64)                       # (h,)
    sums = (colours * fg[..., None]).sum(axis=1)                      # (h, 3)
    cum_n = np.concatenate([[0.0], np.cumsum(counts)])
    cum_s = np.concatenate([np.zeros((1, 3)), np.cumsum(sums, axis=0)])

    def mean(a: int, b: int) -> np.ndarray:
        n = cum_n[b] - cum_n[a]
        return (cum_s[b] - cum_s[a]) / max(n, 1.0)

    height = bottom - top
    r = np.asarray(params.decomposition.height_ratios, dtype=np.float64)
    r = r / r.sum()
    init1 = top + int(round(r[0] * height))
    init2 = top + int(round((r[0] + r[1]) * height))
    limit = max(1, int(round(params.decomposition.separation_search * height)))
    step = max(1, height // 50)

    def climb(line: int, lo_bound: int, hi_bound: int, upper: int, lower: int, initial: int) -> int:
        def diff(at: int) -> float:
            return float(np.linalg.norm(mean(upper, at) - mean(at, lower)))
        best = diff(line)
        while True:
            cands = [c for c in range(line - step, line + step + 1) if c != line and lo_bound < c < hi_bound]
            if not cands:
                return line
            scores = [diff(c) for c in cands]
            k = int(np.argmax(scores))
            if scores[k] <= best:
                return line
            line, best = cands[k], scores[k]
            if abs(line - initial) > limit:
                return initial

    l1, l2 = init1, init2
    for _ in range(2):
        l1 = climb(l1, top + 1, l2 - 1, top, l2, init1)
        l2 = climb(l2, l1 + 1, bottom - 1, l1, bottom, init2)
    return l1, l2


def decompose(ycc: np.ndarray, mask: np.ndarray | None, box: Box, params: BodyParams | None = None) -> dict[str, Box]:
    """Head, torso and hip-leg inner rectangles of the person in ``box``.

    ``ycc (H, W, 3) uint8`` is the frame in YCrCb, ``mask (H, W)`` the foreground (or None:
    the box's colour contrast with its surroundings decides, :func:`contrast_foreground`).
    Returns ``{"head", "torso", "hipleg"} -> Box``.
    """
    p = params or BodyParams()
    x0, y0, colours, fg = _region(ycc, mask, box)
    rows = np.nonzero(fg.sum(axis=1) >= max(1, 0.05 * fg.shape[1]))[0]
    if len(rows) < 3:
        rows = np.arange(fg.shape[0])
    top, bottom = int(rows[0]), int(rows[-1]) + 1
    if bottom - top < 6:
        top, bottom = 0, fg.shape[0]
    l1, l2 = separation_lines(colours, fg, top, bottom, p)
    out: dict[str, Box] = {}
    for name, a, b in (("head", top, l1), ("torso", l1, l2), ("hipleg", l2, bottom)):
        section = fg[a:b]
        if name == "hipleg":  # only the upper half: thighs are stable, lower legs swing
            half = max((b - a) // 2, 2)
            section = fg[a:a + half]
            rect = inner_rectangle(section, x0, y0 + a)
            if rect is not None:
                rect = Box(rect.x, y0 + a, rect.w, float(half))
        else:
            rect = inner_rectangle(section, x0, y0 + a)
        if rect is None:  # no foreground in the section: its full width and height
            rect = Box(float(x0), float(y0 + a), float(fg.shape[1]), float(max(b - a, 2)))
        out[name] = rect
    return out


def shrink_part(ycc: np.ndarray, mask: np.ndarray | None, box: Box, part: str) -> Box:
    """The inner rectangle of a given part box (an init row): the box is taken as the part's
    section ``R`` of sec. 4.1 and shrunk the same way (mass centre +- standard deviation of
    its foreground; the hip-leg keeps the upper half of its foreground rows), so that a
    tight box drawn around legs or arms is tracked by its stable, mostly-foreground core."""
    x0, y0, _, fg = _region(ycc, mask, box)
    if part == "hipleg":
        rows = np.nonzero(fg.any(axis=1))[0]
        if len(rows) >= 4:
            half = max((rows[-1] + 1 - rows[0]) // 2, 2)
            rect = inner_rectangle(fg[rows[0]:rows[0] + half], x0, y0 + rows[0])
            if rect is not None:
                return Box(rect.x, y0 + rows[0], rect.w, float(half))
    rect = inner_rectangle(fg, x0, y0)
    return rect if rect is not None else box


#: The MBR of boxes: the person box of the three-part tracker (sec. 5.3), defined in one place.
minimum_bounding_rectangle = person_box
