"""Tracking-failure adjustment (seed 002 sec. 4.3), run when a failure detector flags parts.

* one failed part is rebuilt from the other two:
  - torso: eq. (4), centre and size the mean of head and hip-leg;
  - head: the inner rectangle (sec. 4.1) of the foreground in
    ``X_T - W_T <= x <= X_T + W_T``, ``Y_T - 0.5 H_T + 2 (Y_T - Y_L) <= y <= Y_T - 0.5 H_T``
    (above the torso; the paper writes the bounds the other way round, ``Y_T - Y_L`` being
    negative with y pointing down);
  - hip-leg: the same below the torso, keeping the upper half as in sec. 4.1;
  and its particles and appearance model are re-seeded from the new box;
  beyond the paper, a lost head or hip-leg is also looked for with its own model on the
  foreground around the torso (:func:`search_on_body`): where that matches better, the part
  moves there and keeps its model (a person bending forward, whom the upright geometry misses);
* two or three failed parts: the person is re-initialised from the foreground around its
  predicted position (sec. 4.3, first paragraph): the blob that overlaps the predicted
  person box most, decomposed by sec. 4.1. A ``multi`` verdict counts only when at least two
  part scores are negative too.

Without usable foreground the rebuilt part keeps its previous size and sits above (head)
or below (hip-leg) the torso, which is what the geometry alone says.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import cv2
import numpy as np

from partlab.tracking.body.decomposition import decompose, inner_rectangle, minimum_bounding_rectangle
from partlab.tracking.body.part_filter import box_to_state, state_to_box
from partlab.tracking.core.box import Box
from partlab.tracking.protocol import FailureVerdict

if TYPE_CHECKING:
    from partlab.tracking.body.tracker import BodyTracker, Person


def torso_from_head_and_hipleg(head: Box, hipleg: Box) -> Box:
    """Seed 002 eq. (4): ``{X, Y, W, H}_T = ({X, Y, W, H}_H + {X, Y, W, H}_L) / 2``."""
    return state_to_box((box_to_state(head) + box_to_state(hipleg)) / 2.0)


def _foreground(mask: np.ndarray | None, region: Box, W: int, H: int):
    r = region.clip(W, H)
    x1, y1, x2, y2 = int(r.x), int(r.y), int(np.ceil(r.x2)), int(np.ceil(r.y2))
    if mask is None or x2 - x1 < 2 or y2 - y1 < 2:
        return None, x1, y1
    return mask[y1:y2, x1:x2] > 0, x1, y1


def head_from_torso(torso: Box, hipleg: Box, previous: Box, mask: np.ndarray | None, W: int, H: int) -> Box:
    """A lost head from the foreground above the torso (sec. 4.3)."""
    xt, yt, wt, ht = box_to_state(torso)[:4]
    yl = box_to_state(hipleg)[1]
    top = yt - 0.5 * ht + 2.0 * (yt - yl)
    bottom = yt - 0.5 * ht
    region = Box(xt - wt, min(top, bottom), 2 * wt, abs(bottom - top))
    fg, x0, y0 = _foreground(mask, region, W, H)
    rect = None
    if fg is not None and fg.mean() > 0.05:
        # the region reaches down to the torso's inner rectangle, i.e. over the shoulders: the
        # head is the top of its foreground, about one previous head height (sec. 4.1's
        # height-ratio step applied to this region)
        rows = np.nonzero(fg.any(axis=1))[0]
        span = max(int(round(1.2 * previous.h)), 2)
        rect = inner_rectangle(fg[rows[0]:rows[0] + span], x0, y0 + rows[0])
    if rect is None:
        rect = Box(xt - previous.w / 2, bottom - previous.h, previous.w, previous.h)
    return rect


def hipleg_from_torso(torso: Box, hipleg: Box, previous: Box, mask: np.ndarray | None, W: int, H: int) -> Box:
    """A lost hip-leg from the foreground below the torso, upper half kept (sec. 4.1, 4.3)."""
    xt, yt, wt, ht = box_to_state(torso)[:4]
    top = yt + 0.5 * ht
    depth = max(2.0 * previous.h, ht)  # the hip-leg inner box is the upper half of the legs
    region = Box(xt - wt, top, 2 * wt, depth)
    fg, x0, y0 = _foreground(mask, region, W, H)
    rect = None
    if fg is not None and fg.mean() > 0.05:
        rows = np.nonzero(fg.any(axis=1))[0]
        half = max((rows[-1] + 1 - rows[0]) // 2, 2)
        rect = inner_rectangle(fg[rows[0]:rows[0] + half], x0, y0 + rows[0])
        if rect is not None:
            rect = Box(rect.x, y0 + rows[0], rect.w, float(half))
    if rect is None:
        rect = Box(xt - previous.w / 2, top, previous.w, previous.h)
    return rect


def reinitialise_box(predicted: Box, mask: np.ndarray | None, W: int, H: int, grow: float = 0.5) -> Box:
    """The foreground blob overlapping ``predicted`` most, searched in the box grown by
    ``grow`` of its size on every side; ``predicted`` itself when there is none."""
    search = Box(predicted.x - grow * predicted.w, predicted.y - grow * predicted.h,
                 (1 + 2 * grow) * predicted.w, (1 + 2 * grow) * predicted.h)
    fg, x0, y0 = _foreground(mask, search, W, H)
    if fg is None or not fg.any():
        return predicted
    n, labels, stats, _ = cv2.connectedComponentsWithStats(fg.astype(np.uint8), connectivity=8)
    best, best_overlap = None, 0.0
    for i in range(1, n):
        x, y, w, h, _ = (int(v) for v in stats[i])
        b = Box(float(x0 + x), float(y0 + y), float(w), float(h))
        ov = b.intersection(predicted)
        if ov > best_overlap:
            best, best_overlap = b, ov
    if best is None or best.h < 0.5 * predicted.h:
        return predicted
    return best


def adjust_person(tracker: BodyTracker, person: Person, verdict: FailureVerdict,
                  ycc: np.ndarray, mask: np.ndarray | None) -> None:
    """Repair the parts ``verdict`` flags (seed 002 sec. 4.3); re-seeds their filters."""
    H, W = ycc.shape[:2]
    f = person.filters
    velocity = person.velocity()  # the person's motion; a failed part's own velocity is not trusted
    boxes = {n: f[n].box for n in ("head", "torso", "hipleg")}
    failed = set(verdict.failed)
    # a multi-part verdict re-initialises the person only when at least two part SVMs say
    # failed this frame: the multi SVM alone is weak (it separates single from multi-part
    # failures at balanced accuracy ~0.75), and re-initialising a person who is not upright
    # decomposes the wrong shape (measured on the bending walker: head and hip-leg lost)
    scores = verdict.scores or {}
    negative = {n for n, v in scores.items() if v < 0} | failed
    if len(failed) >= 2 or (verdict.multi and len(negative) >= 2):
        predicted = minimum_bounding_rectangle(state_to_box(np.r_[person.prev[n][:2] + person.prev[n][4:6],
                                                                  person.prev[n][2:4]])
                                               for n in ("head", "torso", "hipleg"))
        region = reinitialise_box(predicted, mask, W, H)
        new = decompose(ycc, mask, region, tracker.params)
        for name in ("head", "torso", "hipleg"):
            _reseed(f[name], new[name], ycc, velocity)
        return
    if "torso" in failed:
        new = torso_from_head_and_hipleg(boxes["head"], boxes["hipleg"])
        _reseed(f["torso"], new, ycc, velocity)
    elif "head" in failed or "hipleg" in failed:
        name = "head" if "head" in failed else "hipleg"
        rebuild = head_from_torso if name == "head" else hipleg_from_torso
        new = rebuild(boxes["torso"], boxes["hipleg"], boxes[name], mask, W, H)
        found = search_on_body(f[name], f["torso"].state, new, ycc, mask, tracker.params.adjustment.search)
        if found is not None:
            # the part's own model found it on the body, away from where an upright body
            # would have it (a bent person): move there, keep the model that found it
            _reseed(f[name], found, ycc, velocity, keep_model=True)
        else:
            _reseed(f[name], new, ycc, velocity)


def _foreground_share(mask: np.ndarray, states: np.ndarray) -> np.ndarray:
    """Share of foreground pixels in each centre-size state's rectangle ``(N,)``."""
    H, W = mask.shape[:2]
    ii = cv2.integral((mask > 0).astype(np.uint8))
    s = np.asarray(states, dtype=np.float64)
    x1 = np.clip(np.rint(s[:, 0] - s[:, 2] / 2), 0, W).astype(int)
    y1 = np.clip(np.rint(s[:, 1] - s[:, 3] / 2), 0, H).astype(int)
    x2 = np.clip(np.rint(s[:, 0] + s[:, 2] / 2), 0, W).astype(int)
    y2 = np.clip(np.rint(s[:, 1] + s[:, 3] / 2), 0, H).astype(int)
    area = np.maximum((x2 - x1) * (y2 - y1), 1)
    return (ii[y2, x2] - ii[y1, x2] - ii[y2, x1] + ii[y1, x1]) / area


def search_on_body(pf, torso: np.ndarray, rebuilt: Box, ycc: np.ndarray, mask: np.ndarray | None,
                   spread: float, n: int = 300, margin: float = 0.05) -> Box | None:
    """Where a lost head or hip-leg's own appearance model finds it on the person's body.

    Sec. 4.3 rebuilds the part above or below the torso, which is wrong for a person who is
    not upright (the paper's stated limitation): a bending walker's head hangs in front of
    the torso. So ``n`` candidates of the part's size are also drawn around the torso's
    centre (``spread`` torso heights), those mostly on foreground (at least half) are scored
    against the part's model, and the best one is returned if it matches the model better
    than the rebuilt box by ``margin``; otherwise None (the rebuilt box stands).
    ``spread <= 0`` or no foreground mask: None.
    """
    if spread <= 0 or mask is None:
        return None
    cand = pf.candidates(spread * float(torso[3]), n, centre=(float(torso[0]), float(torso[1])))
    rho = pf.similarities(ycc, cand)
    rho[_foreground_share(mask, cand) < 0.5] = 0.0
    k = int(np.argmax(rho))
    size = pf.state[2:4].astype(np.float64)
    ref = box_to_state(rebuilt)
    ref[2:4] = size  # compare like with like: the model's size at the rebuilt place
    base = float(pf.similarities(ycc, ref[None, :])[0])
    if rho[k] <= base + margin:
        return None
    x, y = float(cand[k, 0]), float(cand[k, 1])
    return Box(x - size[0] / 2, y - size[1] / 2, float(size[0]), float(size[1]))


def _reseed(pf, box: Box, ycc: np.ndarray, velocity: np.ndarray | None, keep_model: bool = False) -> None:
    pf.reseed(Box(box.x, box.y, max(box.w, 2.0), max(box.h, 2.0)), ycc, n=pf.n, keep_velocity=True,
              keep_model=keep_model)
    if velocity is not None:
        pf.set_velocity(velocity)
