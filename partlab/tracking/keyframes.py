"""Keyframe-guided tracking: boxes a person drew on some frames, a tracker in between.

Between two keyframes of a track (CVAT's track mode, with a tracker instead of a straight line)
the tracker runs forward from the first keyframe and backward (over the frames in reverse order)
from the second. Each run is shifted by what it reported at its own keyframe against the drawn
box (a tracker's box convention, e.g. the body tracker's minimum bounding rectangle of its parts,
is not the annotator's), so that it starts exactly on the keyframe. The two are blended with
weights ``(1 - a) c_f`` and ``a c_b``, where ``a`` goes linearly from 0 at the first keyframe to 1
at the second and ``c`` is each run's confidence (its ``score``, 0 for a failed or occluded box):
the proposal meets each keyframe exactly and, in between, leans on the run that is surer. Where
only one run has a box, that one is used; where neither, or where the two overlap so little that
one of them must be lost (IoU below ``FALLBACK_IOU``), the keyframes are interpolated. A
frame is flagged for review (``failure`` True, ``state`` "review") where the two runs disagree
(IoU below ``agree_iou``) or either run's failure detector fired.

:func:`track_between` is one track between two keyframes (what the app's Correct page calls);
:func:`track_with_keyframes` every track of a keyframes table over a take (``partlab track
--keyframes``). Both work with any tracker of the registry; only the parts both keyframes
have are blended (``person`` for person-only keyframes; the body tracker reports it).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pandas as pd

from partlab.errors import UserError
from partlab.tracking import registry
from partlab.tracking.frame import MemoryTake
from partlab.tracking.run import RunResult, track
from partlab.tracking.tracks import TracksCSVError, empty_tracks, normalise_tracks

XYWH = ["x", "y", "w", "h"]
AGREE_IOU = 0.5  # forward and backward boxes overlapping less than this: the frame needs a look
#: forward and backward boxes overlapping less than this cannot both be right and either may be the
#: lost one: the straight line between the keyframes is proposed instead (flagged for review). 0.3
#: on PETS09-S2L1 frames 0-199, keyframes every 25: edits 14.8 -> 9.6 per 100 truth boxes (linear
#: interpolation alone 19.8); 0.5 gave 10.6, 0.7 13.7
FALLBACK_IOU = 0.3
MIN_CONFIDENCE = 0.05  # a run's weight never drops to nothing while it still has a box


def _confidence(rows: pd.DataFrame) -> np.ndarray:
    score = rows["score"].to_numpy(float) if "score" in rows else np.ones(len(rows))
    score = np.where(np.isfinite(score), np.clip(score, 0.0, 1.0), 1.0)
    bad = rows["failure"].to_numpy(bool) | (rows["occluded"].to_numpy(float) >= 0.5)
    return np.where(bad, MIN_CONFIDENCE, np.maximum(score, MIN_CONFIDENCE))


def _run(frames: list[np.ndarray], boxes: pd.DataFrame, tracker: str, model: Any, seed: int,
         fps: float) -> pd.DataFrame:
    """One run over ``frames`` started at their first from ``boxes`` (one track, frame 0)."""
    init = boxes.assign(frame=0, track_id=1)
    result = track(MemoryTake(frames, fps), tracker, init=init, model=model, seed=seed)
    return result.tracks[result.tracks["track_id"] == 1]


def _aligned(run: pd.DataFrame, key: pd.Series, key_frame: int,
             frame_of: Callable[[np.ndarray], np.ndarray]) -> pd.DataFrame:
    """A run's rows of one part indexed by real frame, shifted so that its box at the keyframe it
    started from is the keyframe."""
    run = run.assign(frame=frame_of(run["frame"].to_numpy())).set_index("frame").sort_index()
    at_key = run.loc[key_frame] if key_frame in run.index else None
    if at_key is not None:
        shift = key[XYWH].to_numpy(float) - at_key[XYWH].to_numpy(float)
        run = run.copy()
        run[XYWH] = run[XYWH].to_numpy(float) + shift
    return run


def blend_runs(fwd: pd.DataFrame, bwd: pd.DataFrame, key_a: pd.Series, key_b: pd.Series, start: int, end: int,
               agree_iou: float = AGREE_IOU, fallback_iou: float = FALLBACK_IOU) -> pd.DataFrame:
    """Rows ``frame, x, y, w, h, score, failure, state`` for ``start..end`` from a forward and a
    backward run of one part (both indexed by real frame, already shifted onto their keyframes)."""
    frames = np.arange(start, end + 1)
    a = (frames - start) / max(end - start, 1)
    out = pd.DataFrame(index=frames)
    ka, kb = key_a[XYWH].to_numpy(float), key_b[XYWH].to_numpy(float)
    lin = (1 - a)[:, None] * ka + a[:, None] * kb
    f = fwd.reindex(frames)
    b = bwd.reindex(frames)
    has_f, has_b = f["x"].notna().to_numpy(), b["x"].notna().to_numpy()
    cf = np.zeros(len(frames))
    cb = np.zeros(len(frames))
    cf[has_f] = _confidence(f[has_f])
    cb[has_b] = _confidence(b[has_b])
    wf, wb = (1 - a) * cf, a * cb
    bf = np.nan_to_num(f[XYWH].to_numpy(float))
    bb = np.nan_to_num(b[XYWH].to_numpy(float))
    total = wf + wb
    with np.errstate(invalid="ignore", divide="ignore"):
        blended = (wf[:, None] * bf + wb[:, None] * bb) / total[:, None]
    only_f = has_f & ~has_b
    only_b = has_b & ~has_f
    blended[only_f] = bf[only_f]
    blended[only_b] = bb[only_b]
    neither = ~has_f & ~has_b | ~np.isfinite(blended).all(axis=1)
    blended[neither] = lin[neither]
    both = has_f & has_b
    iou = np.ones(len(frames))
    if both.any():
        iou[both] = _rowwise(bf[both], bb[both])
    fired = np.zeros(len(frames), bool)
    fired[has_f] |= f.loc[has_f, "failure"].to_numpy(bool)
    fired[has_b] |= b.loc[has_b, "failure"].to_numpy(bool)
    review = (both & (iou < agree_iou)) | fired
    lost = both & (iou < fallback_iou)
    blended[lost] = lin[lost]
    out[XYWH] = blended
    out["score"] = np.where(both, iou, np.where(has_f | has_b, np.maximum(cf, cb), 0.0))
    out["failure"] = review
    state = np.where(neither | lost, "interpolated", np.where(review, "review", "tracked"))
    state[0], state[-1] = "keyframe", "keyframe"
    out["state"] = state
    out.loc[start, XYWH] = ka
    out.loc[end, XYWH] = kb
    out.loc[[start, end], "failure"] = False
    out.loc[[start, end], "score"] = 1.0
    return out.rename_axis("frame").reset_index()


def _rowwise(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ix = np.clip(np.minimum(a[:, 0] + a[:, 2], b[:, 0] + b[:, 2]) - np.maximum(a[:, 0], b[:, 0]), 0, None)
    iy = np.clip(np.minimum(a[:, 1] + a[:, 3], b[:, 1] + b[:, 3]) - np.maximum(a[:, 1], b[:, 1]), 0, None)
    inter = ix * iy
    union = a[:, 2] * a[:, 3] + b[:, 2] * b[:, 3] - inter
    return np.where(union > 0, inter / np.where(union > 0, union, 1), 0.0)


def _keyframes_table(keyframes: pd.DataFrame) -> pd.DataFrame:
    try:
        return normalise_tracks(keyframes)
    except (TracksCSVError, ValueError, KeyError) as exc:
        raise UserError(f"bad keyframes table: {exc}") from None


def track_between(take, keyframes: pd.DataFrame, track_id: int, start: int | None = None, end: int | None = None, *,
                  tracker: str = "body", model: Any = None, seed: int = 0, agree_iou: float = AGREE_IOU,
                  frames: list[np.ndarray] | None = None, parts: list[str] | None = None) -> pd.DataFrame:
    """Proposals for track ``track_id`` from its keyframe at ``start`` to its keyframe at ``end``.

    ``keyframes``: a tracks table (any tracks, any parts) of boxes a person drew; ``start``/``end``:
    two keyframe frames of the track (default: the track's first two). Returns tracks rows
    (``frame, track_id, part, x, y, w, h, score, failure, state, source``) for every frame from
    ``start`` to ``end`` and every part both keyframes have: the keyframes exactly at their frames,
    the confidence blend of a forward and a backward run in between (see the module docstring).
    ``frames``: the decoded frames ``start..end`` if the caller already has them; ``parts``: blend
    only these parts (the tracker still starts from every part of the keyframes).
    """
    keys = _keyframes_table(keyframes)
    mine = keys[keys["track_id"] == track_id]
    at = np.sort(mine["frame"].unique())
    if len(at) < 2 and (start is None or end is None):
        raise UserError(f"track {track_id} has {len(at)} keyframe(s); tracking between keyframes needs two")
    start = int(at[0]) if start is None else int(start)
    end = int(at[at > start][0]) if end is None and (at > start).any() else end
    if end is None or start not in set(at) or int(end) not in set(at) or int(end) <= start:
        raise UserError(f"track {track_id}: frames {start} and {end} are not two keyframes of the track "
                        f"(its keyframes: {', '.join(map(str, at[:10]))}{' ...' if len(at) > 10 else ''})")
    end = int(end)
    a_rows = mine[mine["frame"] == start].set_index("part")
    b_rows = mine[mine["frame"] == end].set_index("part")
    parts = [p for p in a_rows.index if p in b_rows.index and (parts is None or p in parts)]
    if not parts:
        raise UserError(f"track {track_id}: the keyframes at {start} and {end} have no part in common")
    if frames is None:
        frames = [fs.first.color for fs in take.frames(start, end + 1)]
    fps = float(getattr(take, "fps", 25.0) or 25.0)
    if end - start >= 2:
        fwd = _run(frames, a_rows.reset_index(), tracker, model, seed, fps)
        bwd = _run(frames[::-1], b_rows.reset_index(), tracker, model, seed, fps)
    else:
        fwd = bwd = empty_tracks()
    out = []
    for part in parts:
        f = _aligned(fwd[fwd["part"] == part], a_rows.loc[part], start, lambda i: start + i)
        b = _aligned(bwd[bwd["part"] == part], b_rows.loc[part], end, lambda i: end - i)
        rows = blend_runs(f, b, a_rows.loc[part], b_rows.loc[part], start, end, agree_iou)
        out.append(rows.assign(track_id=track_id, part=part, source="tracker"))
    return normalise_tracks(pd.concat(out, ignore_index=True))


#: a stretch is tracked inside the keyframes' boxes of its track grown on every side by this many
#: times their largest side: the tracker's search (Zhao & Lee's lost-head window is one torso width
#: either side) and a path that bends away from the straight line between the keyframes stay
#: inside. On PETS09-S2L1 (people 75 px tall) 1.0 crops 768x576 to about 260x215.
ROI_PAD = 1.0


def stretch_region(boxes: pd.DataFrame, width: int, height: int, pad: float = ROI_PAD) -> tuple[int, int, int, int]:
    """``(x0, y0, x1, y1)``: the part of a ``width`` x ``height`` frame a stretch is tracked in, the
    bounding rectangle of ``boxes`` (the keyframes' rows) grown by ``pad`` times their largest side."""
    x, y = boxes["x"].to_numpy(float), boxes["y"].to_numpy(float)
    w, h = boxes["w"].to_numpy(float), boxes["h"].to_numpy(float)
    margin = pad * float(max(w.max(), h.max(), 1.0))
    x0, y0 = int(max(np.floor(x.min() - margin), 0)), int(max(np.floor(y.min() - margin), 0))
    x1 = int(min(np.ceil((x + w).max() + margin), width))
    y1 = int(min(np.ceil((y + h).max() + margin), height))
    return x0, y0, max(x1, x0 + 1), max(y1, y0 + 1)


def track_stretch(frames: list[np.ndarray], keyframes: pd.DataFrame, track_id: int, start: int, end: int, *,
                  parts: list[str] | None = None, pad: float = ROI_PAD, tracker: str = "body", model: Any = None,
                  seed: int = 0, fps: float = 25.0, agree_iou: float = AGREE_IOU) -> pd.DataFrame:
    """:func:`track_between` of one track inside its region only (:func:`stretch_region` of its
    keyframes at ``start`` and ``end``): what the Correct page runs when a keyframe moves, so that
    one stretch costs a crop's tracking, not the whole frame's. ``frames``: the decoded frames
    ``start..end``. Rows are in the whole frame's coordinates."""
    keys = _keyframes_table(keyframes)
    mine = keys[(keys["track_id"] == track_id) & keys["frame"].isin([start, end])]
    if not len(mine):
        raise UserError(f"track {track_id} has no keyframe at {start} or {end}")
    height, width = frames[0].shape[:2]
    x0, y0, x1, y1 = stretch_region(mine, width, height, pad)
    crops = [np.ascontiguousarray(f[y0:y1, x0:x1]) for f in frames]
    shifted = mine.assign(x=mine["x"] - x0, y=mine["y"] - y0)
    rows = track_between(MemoryTake(crops, fps), shifted, track_id, start, end, tracker=tracker, model=model,
                         seed=seed, agree_iou=agree_iou, frames=crops, parts=parts)
    return rows.assign(x=rows["x"] + x0, y=rows["y"] + y0)


def stretch_proposer(read: Callable[[int], np.ndarray], *, tracker: str = "body", model: Any = None, seed: int = 0,
                     fps: float = 25.0, pad: float = ROI_PAD) -> Callable[..., pd.DataFrame]:
    """A proposer for :func:`partlab.labelling.trackops.fill_between`: ``propose(keys, track_id,
    part, start, end)`` reads frames ``start..end`` with ``read(index)`` and returns
    :func:`track_stretch`'s rows of ``part`` strictly between the keyframes. A part ``tracker``
    does not report (hands for the body tracker) gets the straight line, marked "interpolated"."""
    reported = set(registry.get(tracker).parts)

    def propose(keys: pd.DataFrame, track_id: int, part: str, start: int, end: int) -> pd.DataFrame:
        if part in reported and end - start >= 2:
            frames = [read(i) for i in range(start, end + 1)]
            rows = track_stretch(frames, keys, track_id, start, end, parts=[part], pad=pad, tracker=tracker,
                                 model=model, seed=seed, fps=fps)
        else:
            k = _keyframes_table(keys)
            k = k[(k["track_id"] == track_id) & (k["part"] == part)].set_index("frame")
            rows = blend_runs(empty_tracks(), empty_tracks(), k.loc[start], k.loc[end], start, end)
        return rows[(rows["frame"] > start) & (rows["frame"] < end)].reset_index(drop=True)

    return propose


def warm_up(tracker: str = "body") -> None:
    """Run ``tracker`` once between two keyframes of a tiny drawn scene, so that its imports and
    compiled kernels (numba's on-disk cache is read at a kernel's first call, which also sets up
    numba's compiler: seconds on a busy machine) are loaded before a user waits for them."""
    rng = np.random.default_rng(0)
    frames = [rng.integers(0, 255, (64, 64, 3), dtype=np.uint8) for _ in range(3)]
    for f in frames:
        f[20:52, 24:40] = (40, 60, 200)
    keys = pd.DataFrame({"frame": [0, 2], "track_id": 1, "part": "person", "x": 24.0, "y": 20.0, "w": 16.0,
                         "h": 32.0})
    track_between(MemoryTake(frames), keys, 1, 0, 2, tracker=tracker, frames=frames)


class _FrameCache:
    """Frames of a take read in order once, kept while some stretch still needs them."""

    def __init__(self, take):
        self._it: Iterator = take.frames(0, None)
        self._next = 0
        self._frames: OrderedDict[int, np.ndarray] = OrderedDict()

    def get(self, start: int, end: int) -> list[np.ndarray]:
        while self._next <= end:
            fs = next(self._it)
            self._frames[fs.index] = fs.first.color
            self._next = fs.index + 1
        return [self._frames[i] for i in range(start, end + 1)]

    def forget_before(self, frame: int) -> None:
        for i in [i for i in self._frames if i < frame]:
            del self._frames[i]


def track_with_keyframes(take, keyframes: pd.DataFrame, *, tracker: str = "body", model: Any = None, seed: int = 0,
                         agree_iou: float = AGREE_IOU, progress: Callable[[int, int], None] | None = None) -> RunResult:
    """Every track of ``keyframes`` tracked between each pair of its consecutive keyframes
    (:func:`track_between`); a track's rows run from its first keyframe to its last. A track with
    a single keyframe keeps just that box. The take is decoded once, in order."""
    keys = _keyframes_table(keyframes)
    n = take.frame_count
    late = keys[keys["frame"] >= n]
    if len(late):
        raise UserError(f"keyframe at frame {int(late['frame'].iloc[0])} is outside the clip (0..{n - 1})")
    pairs = []  # (start, end, track_id, first stretch of its track?)
    singles = []
    for tid, g in keys.groupby("track_id"):
        at = np.sort(g["frame"].unique())
        if len(at) == 1:
            singles.append(g.assign(state="keyframe"))
        pairs.extend((int(s), int(e), int(tid), j == 0) for j, (s, e) in enumerate(zip(at[:-1], at[1:])))
    pairs.sort()
    cache = _FrameCache(take)
    out = list(singles)
    for k, (s, e, tid, first) in enumerate(pairs):
        cache.forget_before(s)
        rows = track_between(take, keys, tid, s, e, tracker=tracker, model=model, seed=seed, agree_iou=agree_iou,
                             frames=cache.get(s, e))
        if not first:  # the keyframe two stretches share is written once
            rows = rows[rows["frame"] != s]
        out.append(rows)
        if progress is not None:
            progress(k + 1, len(pairs))
    if not out:
        return RunResult(empty_tracks())
    tracks = normalise_tracks(pd.concat(out, ignore_index=True))
    tracks = tracks.sort_values(["frame", "track_id"], kind="stable").reset_index(drop=True)
    return RunResult(tracks)

