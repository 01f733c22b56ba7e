"""Activities of tracked hands (sec. 7 of *3D tracking of the hands and head of interacting people
from several cameras*): clap, handshake, exchange, pick up, place.

:class:`ActivityTracker` wraps a tracker that reports hands (``limbs``, ``all``, ``limbs3d``): every
frame it looks at the colour around each reported hand in each view (:mod:`.objects`); when the
run ends it takes the tracker's join/separation events (sec. 5.2, the climax points of two-hand
activities) and the hands' still moments (the climax points of picks and places, the paper's
"ballistic movements"), fuses the colour around each hand over a window before and after the
climax (eq. 29) and reads the activity from Table 1 (:mod:`.table`). The tracks are unchanged.

Events carry :data:`ACTIVITY_COLUMNS`: start and end frame, kind, the two tracks and parts
(``track_id_b = 0`` and ``part_b`` empty for one-hand activities), how the join ended, the
object's colour (``#rrggbb``) and a confidence in [0, 1].
"""

from __future__ import annotations

from collections import defaultdict
from typing import Mapping

import numpy as np
import pandas as pd

from partlab.tracking.activities.objects import HandColour, colour_masses, fuse, hand_colour, hue_to_hex
from partlab.tracking.activities.params import ActivityParams
from partlab.tracking.activities.table import one_hand, two_hands
from partlab.tracking.frame import FrameSet
from partlab.tracking.tracks import TrackRecord

HAND_PARTS = ("left_hand", "right_hand")
ACTIVITY_COLUMNS: tuple[str, ...] = ("start_frame", "end_frame", "kind", "track_id_a", "part_a", "track_id_b",
                                     "part_b", "ended_by", "object_colour", "confidence")
KINDS = ("clap", "handshake", "exchange", "pick", "place", "hand_head")

Key = tuple[int, str]  # (track_id, part)


class ActivityTracker:
    """A tracker plus activity recognition over the hands it reports."""

    def __init__(self, inner, params: ActivityParams):
        self.inner = inner
        self.activity_params = params
        self.params = getattr(inner, "params", None)
        self._colours: dict[Key, dict[int, list[HandColour]]] = defaultdict(lambda: defaultdict(list))
        self._centres: dict[Key, dict[int, tuple[float, float, float]]] = defaultdict(dict)
        self.events: pd.DataFrame | None = None

    def step(self, frames: FrameSet, foreground: Mapping[str, np.ndarray | None]) -> list[TrackRecord]:
        rows = self.inner.step(frames, foreground)
        for r in rows:
            if r.part not in HAND_PARTS or r.box.w <= 0 or r.box.h <= 0:
                continue
            stream = r.camera or next(iter(frames.views))
            view = frames.views.get(stream)
            if view is None or view.color is None:
                continue
            key = (r.track_id, r.part)
            self._colours[key][r.frame].append(
                hand_colour(view.color, foreground.get(stream), r.box, self.activity_params))
            if stream == next(iter(frames.views)):  # still moments are measured in the first view
                self._centres[key][r.frame] = (r.box.x + r.box.w / 2, r.box.y + r.box.h / 2, max(r.box.w, r.box.h))
        return rows

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        out = self.inner.table(records)
        joins = getattr(self.inner, "events", None)
        self.events = recognise(joins, self._colours, self._centres, self.activity_params)
        return out


def _held(colours: dict[int, list[HandColour]], lo: int, hi: int, params: ActivityParams) -> dict[int, float] | None:
    """The colours a hand holds over frames ``lo..hi`` (eq. 29), or None when it was not seen there."""
    obs = [o for f in range(lo, hi + 1) for o in colours.get(f, ())]
    if len(obs) < max(2, params.decision.window // 3):
        return None
    return colour_masses(fuse(obs), params)


def _windows(start: int, end: int, params: ActivityParams) -> tuple[tuple[int, int], tuple[int, int]]:
    d = params.decision
    return (start - d.gap - d.window, start - d.gap), (end + d.gap, end + d.gap + d.window)


def still_moments(centres: dict[int, tuple[float, float, float]], params: ActivityParams) -> list[tuple[int, int]]:
    """Stretches of at least ``still_frames`` frames in which the hand moves less than
    ``still_speed`` hand sizes per frame (centres smoothed over three frames)."""
    if len(centres) < 3:
        return []
    frames = np.array(sorted(centres))
    xyz = np.array([centres[f] for f in frames], dtype=float)
    k = np.ones(3) / 3
    sx = np.convolve(np.pad(xyz[:, 0], 1, mode="edge"), k, "valid")
    sy = np.convolve(np.pad(xyz[:, 1], 1, mode="edge"), k, "valid")
    gaps = np.diff(frames)
    step = np.hypot(np.diff(sx), np.diff(sy)) / np.maximum(gaps, 1) / np.maximum(xyz[1:, 2], 1.0)
    ok = np.concatenate([[False], (step < params.decision.still_speed) & (gaps == 1), [False]]).astype(np.int8)
    edges = np.diff(ok)
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)  # a run of k steps spans k + 1 frames
    return [(int(frames[a]), int(frames[b])) for a, b in zip(starts, stops)
            if b - a + 1 >= params.decision.still_frames]


def _join_rows(joins: pd.DataFrame | None, colours, params: ActivityParams) -> tuple[list[dict], dict[Key, list]]:
    rows, busy = [], defaultdict(list)
    if joins is None or not len(joins):
        return rows, busy
    for j in joins.itertuples(index=False):
        a, b = (int(j.track_id_a), str(j.part_a)), (int(j.track_id_b), str(j.part_b))
        start, end = int(j.start_frame), int(j.end_frame)
        busy[a].append((start, end))
        busy[b].append((start, end))
        base = dict(start_frame=start, end_frame=end, kind=str(j.kind), track_id_a=a[0], part_a=a[1],
                    track_id_b=b[0], part_b=b[1], ended_by=str(j.ended_by), object_colour="", confidence=0.5)
        if a[1] in HAND_PARTS and b[1] in HAND_PARTS:
            (b0, b1), (a0, a1) = _windows(start, end, params)
            seen = [_held(colours.get(k, {}), lo, hi, params) for k in (a, b) for lo, hi in ((b0, b1), (a0, a1))]
            if all(s is not None for s in seen):
                ab, aa, bb, ba = seen
                v = two_hands(ab, bb, aa, ba, a[0] == b[0], params)
                base.update(kind=v.kind, confidence=round(v.margin, 3),
                            object_colour="" if v.colour is None else hue_to_hex(v.colour))
            else:  # a hand unseen at a decision point: the state machine's guess, less sure
                base.update(kind="clap" if a[0] == b[0] else "handshake", confidence=0.3)
        rows.append(base)
    return rows, busy


def recognise(joins: pd.DataFrame | None, colours: Mapping[Key, Mapping[int, list[HandColour]]],
              centres: Mapping[Key, Mapping[int, tuple[float, float, float]]], params: ActivityParams) -> pd.DataFrame:
    """The activities table (:data:`ACTIVITY_COLUMNS`) from the join events and what each hand held."""
    rows, busy = _join_rows(joins, colours, params)
    d = params.decision
    for key, cs in centres.items():
        for s0, s1 in still_moments(cs, params):
            if any(s0 <= e + d.gap + d.window and s1 >= b - d.gap - d.window for b, e in busy.get(key, ())):
                continue  # part of a two-hand activity
            (b0, b1), (a0, a1) = _windows(s0, s1, params)
            before, after = (_held(colours.get(key, {}), lo, hi, params) for lo, hi in ((b0, b1), (a0, a1)))
            if before is None or after is None:
                continue
            v = one_hand(before, after, params)
            if v is not None:
                rows.append(dict(start_frame=s0, end_frame=s1, kind=v.kind, track_id_a=key[0], part_a=key[1],
                                 track_id_b=0, part_b="", ended_by="still", object_colour=hue_to_hex(v.colour),
                                 confidence=round(v.margin, 3)))
    out = pd.DataFrame(rows, columns=list(ACTIVITY_COLUMNS))
    return out.sort_values(["start_frame", "track_id_a", "part_a"], kind="stable").reset_index(drop=True)
