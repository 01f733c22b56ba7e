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
from collections.abc import Mapping
from dataclasses import replace

import cv2
import numpy as np
import pandas as pd

from partlab.tracking.activities.objects import (
    DEGREES_PER_BIN,
    HUE_BINS,
    HandColour,
    body_colours,
    colour_masses,
    fuse,
    fuse_views,
    hand_colour,
    hue_to_hex,
)
from partlab.tracking.activities.params import ActivityParams
from partlab.tracking.activities.table import Verdict, absent, mass, one_hand, two_hands
from partlab.tracking.core.background import half_size, plate_silhouette
from partlab.tracking.frame import FrameSet
from partlab.tracking.tracks import TrackRecord

HAND_PARTS = ("left_hand", "right_hand")
ACTIVITY_COLUMNS: tuple[str, ...] = ("start_frame", "end_frame", "kind", "track_id_a", "part_a", "track_id_b",
                                     "part_b", "ended_by", "object_colour", "confidence")
KINDS = ("clap", "handshake", "exchange", "pick", "place", "hand_head")

Key = tuple[int, str]  # (track_id, part)
LOST = "lost"  # the state of a target the tracker no longer sees (limbs' state machine)


class ActivityTracker:
    """A tracker plus activity recognition over the hands it reports."""

    def __init__(self, inner, params: ActivityParams, backgrounds: Mapping[str, np.ndarray] | None = None):
        self.inner = inner
        self.activity_params = params
        # per stream the empty-scene plate at half resolution (a take's backgrounds, if it has them)
        self._plates = {s: half_size(b) for s, b in (backgrounds or {}).items() if b is not None}
        self.params = getattr(inner, "params", None)
        self._colours: dict[Key, dict[int, list[HandColour]]] = defaultdict(lambda: defaultdict(list))
        self._centres: dict[Key, dict[int, tuple[float, float, float]]] = defaultdict(dict)
        self._clothes: dict[int, np.ndarray] = defaultdict(lambda: np.zeros(HUE_BINS))
        self._clothes_n: dict[int, int] = defaultdict(int)
        self._where: dict[Key, dict[int, tuple]] = defaultdict(dict)
        self.events: pd.DataFrame | None = None

    def step(self, frames: FrameSet, foreground: Mapping[str, np.ndarray | None]) -> list[TrackRecord]:
        rows = self.inner.step(frames, foreground)
        foreground = {s: self._foreground(s, v.color, foreground.get(s)) for s, v in frames.views.items()}
        for r in rows:
            if r.part not in HAND_PARTS + ("head",) or r.box.w <= 0 or r.box.h <= 0 or r.state == LOST:
                continue  # a lost target's box is where it was last seen, not where it is
            stream = r.camera or next(iter(frames.views))
            view = frames.views.get(stream)
            if view is None or view.color is None:
                continue
            if r.part == "head":
                self._clothes[r.track_id] += body_colours(view.color, foreground.get(stream), r.box,
                                                          self.activity_params)
                self._clothes_n[r.track_id] += 1
                continue
            key = (r.track_id, r.part)
            seen = replace(hand_colour(view.color, foreground.get(stream), r.box, self.activity_params),
                           view=stream, visible=_visible(r.occluded))
            self._colours[key][r.frame].append(seen)
            if stream == next(iter(frames.views)):  # still moments are measured in the first view
                self._centres[key][r.frame] = (r.box.x + r.box.w / 2, r.box.y + r.box.h / 2, max(r.box.w, r.box.h))
                self._where[key][r.frame] = seen.where
        return rows

    def _foreground(self, stream: str, color: np.ndarray | None, mask: np.ndarray | None) -> np.ndarray | None:
        """The silhouettes of one view the colour analysis reads: the plate's where the take has an
        empty-scene image of the view (the person against the room, ``region.plate_threshold``),
        else the run loop's ``mask`` (its adaptive background model; None without one)."""
        plate = self._plates.get(stream)
        if color is None or plate is None or plate.shape != (color.shape[0] // 2, color.shape[1] // 2, 3):
            return mask
        sil = plate_silhouette(half_size(color), plate, self.activity_params.region.plate_threshold)
        return cv2.resize(sil, (color.shape[1], color.shape[0]), interpolation=cv2.INTER_NEAREST)

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        out = self.inner.table(records)
        joins = getattr(self.inner, "events", None)
        seen = out[out["state"] != LOST] if "state" in out.columns else out
        found = contacts(seen, self.activity_params)
        if self.activity_params.decision.held_out > 0:
            found = pd.concat([found, held_out_joins(seen, found, self.activity_params)], ignore_index=True)
        joins = found if joins is None or not len(joins) else pd.concat([joins, found], ignore_index=True)
        if self.activity_params.decision.meeting_reach > 0:
            joins = meeting_points(joins, seen, self.activity_params)
        clothes = {t: clothes_hues(self._clothes[t] / max(n, 1), self.activity_params)
                   for t, n in self._clothes_n.items()}
        centres = {k: bridge_gaps(c, self.activity_params) for k, c in self._centres.items()}
        self.events = recognise(joins, self._colours, centres, self.activity_params, clothes, self._where)
        return out


def bridge_gaps(centres: Mapping[int, tuple[float, float, float]], params: ActivityParams) -> dict[int, tuple]:
    """``centres`` with the short losses bridged: where a hand was unseen for at most
    ``bridge_frames`` frames and is seen again within ``bridge_size`` hand sides of where it was
    last seen, it is put where it was seen again over the unseen frames (a tracker loses a hand
    that moved away from its estimate, and finds it where it went). Longer or farther losses stay
    unseen."""
    d = params.decision
    out = dict(centres)
    frames = sorted(centres)
    for f0, f1 in zip(frames, frames[1:]):
        if not 1 < f1 - f0 <= d.bridge_frames + 1:
            continue
        (x0, y0, s0), (x1, y1, s1) = centres[f0], centres[f1]
        if np.hypot(x1 - x0, y1 - y0) <= d.bridge_size * max(s0, s1):
            out.update({f: centres[f1] for f in range(f0 + 1, f1)})
    return out


def _visible(occluded: float) -> float:
    """How much of a hand a record says is seen (trackers that do not say: all of it)."""
    return 1.0 if not np.isfinite(occluded) else float(np.clip(1.0 - occluded, 0.0, 1.0))


def clothes_hues(shares: np.ndarray, params: ActivityParams) -> np.ndarray:
    """Hue bins a person's clothes cover (their mean share below the head is at least ``clothes_share``),
    widened by ``same_colour`` degrees."""
    reach = int(round(params.decision.same_colour / DEGREES_PER_BIN))
    smooth = np.convolve(np.concatenate([shares[-reach:], shares, shares[:reach]]), np.ones(2 * reach + 1), "valid")
    return np.flatnonzero(smooth >= params.modes.clothes_share)


def _without(held: dict[int, float] | None, hues: np.ndarray) -> dict[int, float] | None:
    if held is None or not len(hues):
        return held
    return {h: m for h, m in held.items() if h not in set(hues.tolist())}


def _held(colours: dict[int, list[HandColour]], lo: int, hi: int, params: ActivityParams) -> dict[int, float] | None:
    """The colours a hand holds over frames ``lo..hi`` (eq. 29), or None when it was not seen there."""
    obs = [o for f in range(lo, hi + 1) for o in colours.get(f, ())]
    if len(obs) < max(2, params.decision.window // 3):
        return None
    return fuse_views(obs, params)


def _held_seen(colours: dict[int, list[HandColour]], lo: int, hi: int, away: int,
               params: ActivityParams) -> dict[int, float] | None:
    """:func:`_held` over ``lo..hi``, or, where the hand was unseen there (lost while it touched the
    other), over the window widened away from the activity (``away`` -1: earlier, +1: later) by up
    to ``apart_search`` frames until it has been seen often enough."""
    for extra in range(0, params.decision.apart_search + 1, max(1, params.decision.window // 2)):
        held = _held(colours, lo - extra if away < 0 else lo, hi + extra if away > 0 else hi, params)
        if held is not None:
            return held
    return None


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
    runs: list[list[int]] = []
    for a, b in zip(starts, stops):  # stops a jittering hand makes are merged, as joins are
        if runs and frames[a] - runs[-1][1] <= params.decision.still_gap:
            runs[-1][1] = int(frames[b])
        else:
            runs.append([int(frames[a]), int(frames[b])])
    return [(a, b) for a, b in runs if b - a + 1 >= params.decision.still_frames]


def _near(hands: pd.DataFrame, params: ActivityParams) -> tuple[np.ndarray, np.ndarray]:
    """Per hand row: its centre and how near another hand's centre must be to touch it. With 3D
    positions (``X, Y, Z`` mm, a multi-camera tracker) the centres are 3D and the reach is
    ``contact_mm``: two hands one behind the other in a view do not touch. Else the first view's
    box centres, ``contact_size`` hand sides."""
    if {"X", "Y", "Z"} <= set(hands.columns) and hands[["X", "Y", "Z"]].notna().all(axis=None):
        return hands[["X", "Y", "Z"]].to_numpy(float), np.full(len(hands), params.decision.contact_mm / 2)
    centre = np.stack([(hands["x"] + hands["w"] / 2).to_numpy(), (hands["y"] + hands["h"] / 2).to_numpy()], 1)
    return centre, params.decision.contact_size * 0.5 * np.maximum(hands["w"], hands["h"]).to_numpy()


def _pair_distances(hands: pd.DataFrame, params: ActivityParams) -> dict[tuple, dict[int, float]]:
    """Per pair of hands and frame where both are seen: their distance over the sum of their reaches
    (:func:`_near`): at most 1 is a touch."""
    centre, reach = _near(hands, params)
    frame, tid, part = hands["frame"].to_numpy(), hands["track_id"].to_numpy(), hands["part"].to_numpy()
    out: dict[tuple, dict[int, float]] = defaultdict(dict)
    order = np.argsort(frame, kind="stable")
    bounds = np.flatnonzero(np.diff(frame[order])) + 1
    for idx in np.split(order, bounds):
        for i in range(len(idx)):
            for j in range(i + 1, len(idx)):
                p, q = idx[i], idx[j]
                key = tuple(sorted(((int(tid[p]), str(part[p])), (int(tid[q]), str(part[q])))))
                out[key][int(frame[p])] = float(np.linalg.norm(centre[p] - centre[q]) / max(reach[p] + reach[q], 1e-9))
    return out


def touch_runs(ratio: Mapping[int, float], params: ActivityParams) -> list[tuple[int, int]]:
    """Frames two hands touch, with hysteresis: a touch starts where their distance ratio
    (:func:`_pair_distances`) is at most 1 and lasts until it exceeds ``release_ratio``; frames where
    either hand is unseen (a hand lost while the two are together, what a tracker of blobs does
    when two hands make one blob) do not end it, and it ends at its last frame not apart."""
    rel = params.decision.release_ratio
    runs, cur, last_ok = [], None, None
    for f in sorted(ratio):
        r = ratio[f]
        if cur is None:
            if r <= 1.0:
                cur, last_ok = f, f
            continue
        if r > rel:
            runs.append((cur, last_ok))
            cur = None
            if f - last_ok > 1:  # unseen in between: the touch ended somewhere there, at its middle
                runs[-1] = (runs[-1][0], (last_ok + f) // 2)
            continue
        last_ok = f
    if cur is not None:
        runs.append((cur, last_ok))
    return runs


def _contact_hands(tracks: pd.DataFrame) -> tuple[pd.DataFrame, bool]:
    """The hand rows touches are read from, and whether they carry 3D positions: with 3D, one row
    per hand and frame (a hand is where it is, whichever view saw it; one view may not see it),
    else the first view's rows."""
    hands = tracks[tracks["part"].isin(HAND_PARTS)]
    in_3d = {"X", "Y", "Z"} <= set(hands.columns) and bool(hands[["X", "Y", "Z"]].notna().all(axis=None))
    if "camera" in hands.columns and (hands["camera"] != "").any():
        if in_3d:
            hands = hands.drop_duplicates(["frame", "track_id", "part"])
        else:
            hands = hands[hands["camera"] == sorted(set(hands["camera"]) - {""})[0]]
    return hands, in_3d


def meeting_points(joins: pd.DataFrame | None, tracks: pd.DataFrame, params: ActivityParams) -> pd.DataFrame | None:
    """``joins`` with where each join of two hands met (``meet``: the midpoint of the two hands' 3D
    positions at its first frame both are seen, with the sum of their touching reaches,
    :func:`_near`; None where they are never both seen). Tracks without 3D positions: ``joins``
    as they are (one view's boxes of 15-30 px hands place a meeting too loosely: one camera,
    ``meeting_reach`` 1.5 split a handshake's touches 57-73 and 74-106, held-out seed 18)."""
    if joins is None or not len(joins):
        return joins
    hands, in_3d = _contact_hands(tracks)
    if not in_3d or hands.empty:
        return joins
    pos = _hand_positions(hands, params)
    meets = []
    for j in joins.itertuples(index=False):
        pa, pb = pos.get((int(j.track_id_a), str(j.part_a)), {}), pos.get((int(j.track_id_b), str(j.part_b)), {})
        f = next((f for f in range(int(j.start_frame), int(j.end_frame) + 1) if f in pa and f in pb), None)
        meets.append(None if f is None else ((pa[f][0] + pb[f][0]) / 2, pa[f][1] + pb[f][1]))
    return joins.assign(meet=meets)


def contacts(tracks: pd.DataFrame, params: ActivityParams) -> pd.DataFrame:
    """Touches of two hands (:func:`touch_runs`), as join rows: one per touch of a pair."""
    cols = ["start_frame", "end_frame", "kind", "track_id_a", "part_a", "track_id_b", "part_b", "ended_by"]
    hands, in_3d = _contact_hands(tracks)
    if hands.empty:
        return pd.DataFrame(columns=cols)
    ratios = _pair_distances(hands, params)
    alone = _hand_positions(hands, params) if in_3d else None
    if params.decision.stayed_hand and in_3d:
        runs = {pair: stayed_touch_runs(alone[pair[0]], alone[pair[1]], params) for pair in ratios}
    else:
        runs = {pair: touch_runs(ratio, params) for pair, ratio in ratios.items()}
    if in_3d and params.decision.meeting_reach > 0:
        runs = {(a, b): [at_the_meeting(run, alone[a], alone[b], params) for run in spans] if a[0] != b[0] else spans
                for (a, b), spans in runs.items()}
    rows = [(start, end, "clap" if a[0] == b[0] else "handshake", a[0], a[1], b[0], b[1], "contact")
            for (a, b), spans in runs.items() for start, end in spans]
    return pd.DataFrame(rows, columns=cols)


def _hand_positions(hands: pd.DataFrame, params: ActivityParams) -> dict[Key, dict[int, tuple[np.ndarray, float]]]:
    """Per hand and frame it is seen: its centre and touching reach (:func:`_near`)."""
    centre, reach = _near(hands, params)
    out: dict[Key, dict[int, tuple[np.ndarray, float]]] = defaultdict(dict)
    for i, (f, t, part) in enumerate(zip(hands["frame"].to_numpy(), hands["track_id"].to_numpy(),
                                         hands["part"].to_numpy())):
        out[(int(t), str(part))][int(f)] = (centre[i], float(reach[i]))
    return out


def stayed_touch_runs(pa: Mapping[int, tuple[np.ndarray, float]], pb: Mapping[int, tuple[np.ndarray, float]],
                      params: ActivityParams) -> list[tuple[int, int]]:
    """:func:`touch_runs` of two hands (per frame seen: centre and reach, :func:`_hand_positions`),
    read from the hand that stayed (``decision.stayed_hand``): while one of the two is unseen, or
    its estimate jumped away from the touch faster than a hand moves (more than ``stay_jump``
    touching distances in a frame, and not back), the touch lasts as long as the other hand stays
    within its reach of where it was at the last frame both touched. A multi-camera tracker that
    splits two joined hands wrongly leaves one at the meeting and throws the other a hand's length
    off in one frame (limbs3d, 3-camera handshake seed 2: 300 mm in a frame at 32 and 38, the
    other hand still at the meeting until 50, the touch read as 31-37, truth 27-48), or loses one
    (seed 3: the taker's hand lost at 80, the giver's held out there until 89, read as 76-79,
    truth 75-87)."""
    d = params.decision
    rel = d.release_ratio
    runs: list[tuple[int, int]] = []
    cur = last_ok = None
    anchor: dict[int, np.ndarray] = {}
    prev: dict[int, np.ndarray] = {}
    jumped: set[int] = set()
    for f in sorted(set(pa) | set(pb)):
        obs = {k: v[f] for k, v in ((0, pa), (1, pb)) if f in v}
        if cur is None:
            if len(obs) == 2 and _ratio(obs[0], obs[1]) <= 1.0:
                cur = last_ok = f
                anchor = {k: o[0] for k, o in obs.items()}
                jumped = set()
            prev.update({k: o[0] for k, o in obs.items()})
            continue
        for k, (c, r) in obs.items():
            if k in prev and np.linalg.norm(c - prev[k]) > d.stay_jump * 2 * r:
                jumped ^= {k}  # a jump away, or (already jumped) one back
        prev.update({k: o[0] for k, o in obs.items()})
        if len(obs) == 2 and _ratio(obs[0], obs[1]) <= rel:
            jumped = set()  # touching again, both
        usable = {k: o for k, o in obs.items() if k not in jumped}
        if len(usable) == 2:
            if _ratio(usable[0], usable[1]) > rel:
                runs.append((cur, last_ok if f - last_ok == 1 else (last_ok + f) // 2))
                cur = None
                continue
            last_ok = f
            anchor = {k: o[0] for k, o in usable.items()}
        elif len(usable) == 1:
            (k, (c, r)), = usable.items()
            if np.linalg.norm(c - anchor[k]) > r:
                runs.append((cur, last_ok))
                cur = None
                continue
            last_ok = f
    if cur is not None:
        runs.append((cur, last_ok))
    return runs


def held_out_joins(tracks: pd.DataFrame, touches: pd.DataFrame, params: ActivityParams) -> pd.DataFrame:
    """Touches a multi-camera tracker lost one hand of (3D positions; ``decision.held_out``): a
    person's hand held out towards another person, at least ``held_out`` of the way from their
    head to the other's (their heads' line), over at least ``still_frames`` frames with no touch
    read, while one of the other person's hands is unseen over at least half of them, is a touch
    of the two (``ended_by`` "held_out"): the hand reached for the other, and the tracker lost
    that one at the meeting (limbs3d, 3-camera handshake seed 0: person 2's right hand held out at
    (0, 10, 1140) mm, 0.49-0.56 of the way, over 35-62, person 1's right hand lost from 39; truth
    36-59). What Table 1 reads there is unsure (a hand unseen at both decision points: a handshake
    only where the hand seen holds no colour, ``unseen_confidence``)."""
    cols = ["start_frame", "end_frame", "kind", "track_id_a", "part_a", "track_id_b", "part_b", "ended_by"]
    hands, in_3d = _contact_hands(tracks)
    heads = tracks[tracks["part"] == "head"].drop_duplicates(["frame", "track_id"])
    if not in_3d or hands.empty or heads[["X", "Y", "Z"]].isna().any(axis=None):
        return pd.DataFrame(columns=cols)
    d = params.decision
    head = {(int(f), int(t)): np.array(xyz, float)
            for f, t, *xyz in heads[["frame", "track_id", "X", "Y", "Z"]].itertuples(index=False)}
    pos = {(int(t), str(p), int(f)): np.array(xyz, float)
           for f, t, p, *xyz in hands[["frame", "track_id", "part", "X", "Y", "Z"]].itertuples(index=False)}
    people = sorted({t for _, t in head})
    frames = sorted({f for f, _ in head})
    touched = defaultdict(list)
    for j in touches.itertuples(index=False):
        for k in ((int(j.track_id_a), str(j.part_a)), (int(j.track_id_b), str(j.part_b))):
            touched[k].append((int(j.start_frame), int(j.end_frame)))
    rows = []
    for p in people:
        for q in (q for q in people if q != p):
            for part in HAND_PARTS:
                out = []
                for f in frames:
                    hp, hq, at = head.get((f, p)), head.get((f, q)), pos.get((p, part, f))
                    if hp is None or hq is None or at is None or not np.any(hq != hp):
                        continue
                    if np.dot(at - hp, hq - hp) / np.dot(hq - hp, hq - hp) >= d.held_out:
                        out.append(f)
                runs, cur = [], None
                for f in out:
                    if cur is not None and f - cur[1] <= 2:
                        cur[1] = f
                    else:
                        cur = [f, f]
                        runs.append(cur)
                for a, b in runs:
                    if b - a + 1 < d.still_frames or any(s <= b and e >= a for s, e in touched[(p, part)]):
                        continue
                    unseen = {other: sum((q, other, f) not in pos for f in range(a, b + 1)) for other in HAND_PARTS}
                    other, n = max(unseen.items(), key=lambda kv: kv[1])
                    if n >= 0.5 * (b - a + 1):
                        rows.append((a, b, "handshake", p, part, q, other, "held_out"))
    return pd.DataFrame(rows, columns=cols)


def at_the_meeting(run: tuple[int, int], pa: Mapping[int, tuple[np.ndarray, float]],
                   pb: Mapping[int, tuple[np.ndarray, float]], params: ActivityParams) -> tuple[int, int]:
    """A touch of two people's hands (3D positions, :func:`_hand_positions`) ended at the last
    frame before both hands seen are farther than ``decision.meeting_reach`` touching distances
    from where they met (their midpoint at the touch's first frame): people who shake hands or
    pass an object meet between them, and a multi-camera tracker that carries the two joined
    estimates back to one person's side has lost the touch (limbs3d, 3-camera handshake seed 4:
    the pair joined at (-36, -221, 1106) mm over 96-108 and carried 340 mm to person 1's side by
    116, read 95-135 against the true exchange's 93-107). A hand the other's estimate was thrown
    from stays at the meeting, so the touch goes on (``stayed_hand``)."""
    start, end = run
    if start not in pa or start not in pb:
        return run
    meet = (pa[start][0] + pb[start][0]) / 2
    for f in range(start + 1, end + 1):
        seen = [p[f] for p in (pa, pb) if f in p]
        if seen and all(np.linalg.norm(c - meet) > params.decision.meeting_reach * 2 * r for c, r in seen):
            return (start, f - 1)
    return run


def _ratio(a: tuple[np.ndarray, float], b: tuple[np.ndarray, float]) -> float:
    return float(np.linalg.norm(a[0] - b[0]) / max(a[1] + b[1], 1e-9))


def merged_joins(joins: pd.DataFrame | None, params: ActivityParams) -> list[dict]:
    """The joins of each pair of targets, those less than ``merge_gap`` frames apart merged into one
    (claps come in bursts, a handshake touches a few times): ``start_frame`` of the first,
    ``end_frame`` of the last. Joins
    that met (``meet``, :func:`meeting_points`) farther apart than ``decision.meeting_reach``
    touching distances are two activities too: a handshake's or a clap's touches are at one
    place, and a hand that later passes the other's estimate elsewhere is not one of them."""
    if joins is None or not len(joins):
        return []
    groups: dict[tuple, list] = defaultdict(list)
    for j in joins.itertuples(index=False):
        a, b = (int(j.track_id_a), str(j.part_a)), (int(j.track_id_b), str(j.part_b))
        groups[tuple(sorted((a, b)))].append((int(j.start_frame), int(j.end_frame), str(j.kind), str(j.ended_by),
                                              getattr(j, "meet", None)))
    out = []
    for (a, b), items in groups.items():
        items.sort(key=lambda i: i[:4])
        cur = None
        for start, end, kind, ended, meet in items:
            if (cur is not None and start - cur["end_frame"] <= params.decision.merge_gap
                    and _met_near(cur["meet"], meet, params)):
                cur.update(end_frame=max(cur["end_frame"], end), ended_by=ended)
                continue
            cur = dict(start_frame=start, end_frame=end, kind=kind, a=a, b=b, ended_by=ended, meet=meet)
            out.append(cur)
    return out


def _met_near(m1, m2, params: ActivityParams) -> bool:
    """Whether two joins' meeting points (:func:`meeting_points`) are within ``meeting_reach``
    touching distances (True where either is unknown or the rule is off)."""
    k = params.decision.meeting_reach
    if k <= 0 or not isinstance(m1, tuple) or not isinstance(m2, tuple):
        return True
    return float(np.linalg.norm(np.asarray(m1[0]) - np.asarray(m2[0]))) <= k * 0.5 * (m1[1] + m2[1])


def apart_windows(ca: Mapping[int, tuple], cb: Mapping[int, tuple], start: int, end: int,
                  params: ActivityParams) -> tuple[tuple[int, int], tuple[int, int]]:
    """The two decision windows of a join: ending at the last frame before ``start`` and starting at
    the first frame after ``end`` where the hands are ``apart_size`` hand sides apart (the gap
    windows of :func:`_windows` where they never are). The activity itself lasts as long as the
    touch (:func:`touch_runs`): the decision points are where colour is read, not its ends.
    """
    d = params.decision

    def apart(f: int) -> bool:
        if f not in ca or f not in cb:
            return False
        (xa, ya, sa), (xb, yb, sb) = ca[f], cb[f]
        return np.hypot(xa - xb, ya - yb) >= d.apart_size * 0.5 * (sa + sb)

    (b0, b1), (a0, a1) = _windows(start, end, params)
    before = next((f for f in range(start - 1, start - d.apart_search, -1) if apart(f)), None)
    after = next((f for f in range(end + 1, end + d.apart_search) if apart(f)), None)
    if before is not None:
        b0, b1 = before - d.window, before
    if after is not None:
        a0, a1 = after, after + d.window
    return (b0, b1), (a0, a1)


def moved_windows(centres: Mapping[int, tuple], s0: int, s1: int,
                  params: ActivityParams) -> tuple[tuple[int, int], tuple[int, int]]:
    """The decision windows of a still moment ``s0..s1`` (a pick or a place): ending where the hand,
    coming in, was last ``apart_size`` hand sides from where it stopped, and starting where it is
    that far from where it left (searched up to ``apart_search`` frames; the gap windows of
    :func:`_windows` where it never is). Right after a place the hand is still beside the object it
    put down, which would read as still holding it; a hand's length away it no longer is."""
    d = params.decision
    (b0, b1), (a0, a1) = _windows(s0, s1, params)

    def away(f: int, ref: int) -> bool:
        if f not in centres or ref not in centres:
            return False
        (x, y, _), (rx, ry, side) = centres[f], centres[ref]
        return np.hypot(x - rx, y - ry) >= d.apart_size * side

    before = next((f for f in range(s0 - 1, s0 - d.apart_search, -1) if away(f, s0)), None)
    after = next((f for f in range(s1 + 1, s1 + d.apart_search) if away(f, s1)), None)
    if before is not None:
        b0, b1 = before - d.window, before
    if after is not None:
        a0, a1 = after, after + d.window
    return (b0, b1), (a0, a1)


def colour_at(where: Mapping[int, tuple], hue: int, lo: int, hi: int, params: ActivityParams) -> np.ndarray | None:
    """The median image position of colour ``hue`` around a hand over frames ``lo..hi``
    (:attr:`HandColour.where`, the first view), or None where it was not seen there."""
    reach = params.decision.same_colour / DEGREES_PER_BIN
    pts = [(x, y) for f in range(lo, hi + 1) for h, x, y in where.get(f, ())
           if min((h - hue) % HUE_BINS, (hue - h) % HUE_BINS) <= reach]
    return np.median(np.array(pts), axis=0) if pts else None


def _stayed_put(where, centres, giver: Key, taker: Key, hue: int, windows, params: ActivityParams) -> bool:
    """Whether the colour an exchange would pass from ``giver`` to ``taker`` is, after, where it was
    before (within one hand side): what a tracker that swapped the two hands' identities while they
    touched reports (each hand's surroundings, a sleeve or the trousers it hangs by, then seem to
    change hands), not an object that went from one person to the other."""
    (b0, b1), (a0, a1) = windows
    before = colour_at(where.get(giver, {}), hue, b0, b1, params)
    after = colour_at(where.get(taker, {}), hue, a0, a1, params)
    sides = [c[2] for k in (giver, taker) for f, c in centres.get(k, {}).items() if b0 <= f <= a1]
    if before is None or after is None or not sides:
        return False
    return bool(np.hypot(*(after - before)) < float(np.median(sides)))


def _two_hand_verdict(seen: list[dict], a: Key, b: Key, windows, centres, where, params: ActivityParams) -> Verdict:
    """Table 1 for two hands (:func:`~.table.two_hands`); an exchange whose colour stayed put
    (:func:`_stayed_put`) is a touch of hands whose tracks swapped, less sure."""
    ab, aa, bb, ba = seen
    v = two_hands(ab, bb, aa, ba, a[0] == b[0], params)
    if v.kind != "exchange" or v.colour is None:
        return v
    giver, taker = (a, b) if mass(ab, v.colour, params) >= mass(bb, v.colour, params) else (b, a)
    if not _stayed_put(where, centres, giver, taker, v.colour, windows, params):
        return v
    return replace(two_hands({}, {}, {}, {}, a[0] == b[0], params), margin=0.5)


def _join_rows(joins: pd.DataFrame | None, colours, centres, params: ActivityParams,
               clothes: Mapping[int, np.ndarray], where=None) -> tuple[list[dict], dict[Key, list]]:
    rows, busy = [], defaultdict(list)
    for j in merged_joins(joins, params):
        a, b, start, end = j["a"], j["b"], j["start_frame"], j["end_frame"]
        if a[1] in HAND_PARTS and b[1] in HAND_PARTS and end - start + 1 < params.decision.min_touch_frames:
            continue  # two hands near each other in a frame or two: no join (``min_touch_frames``)
        base = dict(start_frame=start, end_frame=end, kind=j["kind"], track_id_a=a[0], part_a=a[1],
                    track_id_b=b[0], part_b=b[1], ended_by=j["ended_by"], object_colour="", confidence=0.5)
        if a[1] in HAND_PARTS and b[1] in HAND_PARTS:
            (b0, b1), (a0, a1) = apart_windows(centres.get(a, {}), centres.get(b, {}), start, end, params)
            worn = np.union1d(clothes.get(a[0], np.zeros(0, int)), clothes.get(b[0], np.zeros(0, int)))
            seen = [_without(_held_seen(colours.get(k, {}), lo, hi, away, params), worn)
                    for k in (a, b) for lo, hi, away in ((b0, b1, -1), (a0, a1, 1))]
            if a[0] == b[0] and found_at_touch(centres.get(a, {}), centres.get(b, {}), start, params):
                seen[0] = seen[2] = None  # not seen coming together: the tracker found a hand there
            if all(s is not None for s in seen):
                ab, aa, bb, ba = seen
                v = _two_hand_verdict(seen, a, b, ((b0, b1), (a0, a1)), centres, where or {}, params)
                if v.kind == "exchange" and a[0] == b[0]:
                    continue  # an object moved from one of a person's hands to the other: no activity of Table 1
                if v.kind in ("clap", "handshake") and params.decision.object_at_touch:
                    touch = [_without(_held(colours.get(k, {}), start, end, params), worn) for k in (a, b)]
                    if object_at_touch(seen, touch, params) is not None:
                        v = replace(v, margin=0.3)  # an object in hand: not row 1 of Table 1
                base.update(kind=v.kind, confidence=round(v.margin, 3),
                            object_colour="" if v.colour is None else hue_to_hex(v.colour))
            else:  # a hand unseen at a decision point: the state machine's guess, less sure
                v = _unseen_exchange(seen, params) if a[0] != b[0] else None
                if v is not None:
                    base.update(kind="exchange", confidence=params.decision.unseen_confidence,
                                object_colour=hue_to_hex(v.colour))
                else:
                    base.update(kind="clap" if a[0] == b[0] else "handshake",
                                confidence=0.3 if a[0] == b[0] else _unseen_confidence(seen, params))
        rows.append(base)
        # a touch is its hands' activity even when it is not reported (a hand unseen at a decision
        # point): reading their still moments on their own instead found one more limbs3d exchange
        # (3-camera handshake seed 6) and 6 more false picks and places with the one-camera limb
        # tracker (seeds 0-9)
        busy[a].append((start, end))
        busy[b].append((start, end))
    return rows, busy


def found_at_touch(ca: Mapping[int, tuple], cb: Mapping[int, tuple], start: int, params: ActivityParams) -> bool:
    """Whether one of two hands was unseen over the ``decision.clap_found_frames`` frames before
    their touch began (0: never): a hand the tracker found again beside the other (one person's
    two lost hands found on their own body in one frame), not two hands seen coming together."""
    k = params.decision.clap_found_frames
    return k > 0 and any(all(f not in c for f in range(start - k, start)) for c in (ca, cb))


def object_at_touch(seen: list[dict], touch: list[dict | None], params: ActivityParams) -> int | None:
    """The colour (hue bin) of an object held at a touch of two hands, or None: a colour one of the
    four decision points (``seen``) holds (``min_mass``) that is also held round either hand over
    the touch itself (``touch``: the two hands' colours fused over it, None where unseen). Table 1
    calls a touch a handshake or a clap only when *no* hand holds an object before or after (row
    1); a colour that stays with one hand through the touch (no exchange read) is an object still
    in hand, and the touch is none of the table's activities. A colour only near a hand at rest
    (the trousers a hanging hand is next to) is not at the meeting, so it does not count (one
    camera, handshake seeds 6 and 9: hue 110-112 0.10-0.31 round a resting hand, none at the
    touch; exchange seed 0: the object 0.30 round both hands at the touch, read as a handshake
    because the tracker split the hands before it was passed)."""
    d = params.decision
    for held in seen:
        for hue, m in (held or {}).items():
            if m >= d.min_mass and any(t is not None and mass(t, hue, params) >= d.min_mass for t in touch):
                return hue
    return None


def _unseen_exchange(seen: list[dict | None], params: ActivityParams) -> Verdict | None:
    """Table 1's exchange row read with one hand unseen after the separation (``decision.unseen_exchange``):
    both hands seen before, one of them holding a colour the other does not; after, either the
    giver is seen without it and the taker unseen (the object went away with a hand the tracker
    lost, e.g. taken back behind the taker's body), or the taker is seen with it and the giver
    unseen. None otherwise (``seen``: a before, a after, b before, b after)."""
    d = params.decision
    if not d.unseen_exchange:
        return None
    ab, aa, bb, ba = seen
    if ab is None or bb is None:
        return None
    for give_b, give_a, take_b, take_a in ((ab, aa, bb, ba), (bb, ba, ab, aa)):
        if (give_a is None) == (take_a is None):  # both seen is Table 1's case, neither is no case
            continue
        for hue, m in give_b.items():
            if m < d.min_mass or not absent(mass(take_b, hue, params), m, params):
                continue
            if take_a is None and absent(mass(give_a, hue, params), m, params):
                return Verdict("exchange", hue, d.unseen_confidence)
            if give_a is None and mass(take_a, hue, params) >= d.min_mass:
                return Verdict("exchange", hue, d.unseen_confidence)
    return None


def _unseen_confidence(seen: list[dict | None], params: ActivityParams) -> float:
    """How sure a touch of two people's hands with a hand unseen at a decision point is a
    handshake: 0.3 (not reported), or ``decision.unseen_confidence`` where every decision point
    that was seen shows no colour held (``min_mass``) and at least ``decision.unseen_min_seen``
    were seen: no object is around, so none changed hands (a hand the tracker lost as it went back
    behind its person's body after a handshake). Not for claps: a person's hand hidden behind
    their body has a track that wanders onto their other hand, which would read as claps."""
    d = params.decision
    known = [s for s in seen if s is not None]
    if len(known) < d.unseen_min_seen or any(m >= d.min_mass for s in known for m in s.values()):
        return 0.3
    return d.unseen_confidence


def _distinct(rows: list[dict]) -> list[dict]:
    """One activity where several pairs of hands report the same one: of rows of one kind that share
    a hand and overlap by more than half of the shorter (:func:`_overlap`), the most confident (a person's right hand
    meets the other's right and left hand in the same exchange)."""
    kept: list[dict] = []
    for r in sorted(rows, key=lambda r: -r["confidence"]):
        hands = {(r["track_id_a"], r["part_a"]), (r["track_id_b"], r["part_b"])} - {(0, "")}
        span = (r["start_frame"], r["end_frame"])
        if not any(k["kind"] == r["kind"] and hands & {(k["track_id_a"], k["part_a"]), (k["track_id_b"], k["part_b"])}
                   and _overlap(span, (k["start_frame"], k["end_frame"])) > 0.5 for k in kept):
            kept.append(r)
    return kept


def _overlap(a: tuple[int, int], b: tuple[int, int]) -> float:
    """Frames in common over the frames of the shorter span: one activity reported over 45-52 and
    45-89 by two pairs of hands is one (their IoU is only 0.18)."""
    inter = min(a[1], b[1]) - max(a[0], b[0]) + 1
    return max(inter, 0) / min(a[1] - a[0] + 1, b[1] - b[0] + 1)


def stays_behind(where: Mapping[int, tuple], centres: Mapping[int, tuple], hue: int, s0: int, s1: int,
                 params: ActivityParams) -> bool | None:
    """Whether colour ``hue`` stayed where the hand stood still over ``s0..s1`` while the hand moved
    on (True: an object left there, or one it only passed), moved with it (False: held), or cannot
    be told (None: the hand never moved ``follow_move`` hand sides away within ``apart_search``
    frames while the colour was seen). Positions from :attr:`HandColour.where` (the first view)."""
    d = params.decision
    reach = d.same_colour / DEGREES_PER_BIN

    def at(f):
        pts = [(x, y) for h, x, y in where.get(f, ()) if min((h - hue) % HUE_BINS, (hue - h) % HUE_BINS) <= reach]
        return pts[0] if pts else None

    # where the colour was last seen while the hand stood still (an object put down during the still
    # moment has moved from the hand to where it rests)
    ref = [at(f) for f in range(s0, s1 + 1) if at(f) is not None][-max(1, d.window // 2):]
    if not ref or s1 not in centres:
        return None
    rx, ry = np.median(np.array(ref), axis=0)
    hx, hy, side = centres[s1]
    ratios = []
    for f in range(s1 + 1, s1 + d.apart_search):
        p = at(f)
        if p is None or f not in centres:
            continue
        dx, dy = centres[f][0] - hx, centres[f][1] - hy
        moved = np.hypot(dx, dy)
        if moved >= d.follow_move * side:  # the colour's displacement along the hand's, in units of it
            ratios.append(((p[0] - rx) * dx + (p[1] - ry) * dy) / moved**2)
    if len(ratios) < d.follow_frames:
        return None
    return bool(np.median(ratios) < d.follow_ratio)


def recognise(joins: pd.DataFrame | None, colours: Mapping[Key, Mapping[int, list[HandColour]]],
              centres: Mapping[Key, Mapping[int, tuple[float, float, float]]], params: ActivityParams,
              clothes: Mapping[int, np.ndarray] | None = None,
              where: Mapping[Key, Mapping[int, tuple]] | None = None) -> pd.DataFrame:
    """The activities table (:data:`ACTIVITY_COLUMNS`) from the join events and what each hand held;
    ``clothes``: per track, the hue bins the person wears (never taken for objects); ``where``: per
    hand and frame, the positions of the colours around it (:func:`stays_behind`)."""
    clothes, where = clothes or {}, where or {}
    rows, busy = _join_rows(joins, colours, centres, params, clothes, where)
    d = params.decision
    last = max((f for cs in colours.values() for f in cs), default=0)  # the run's last frame seen
    for key, cs in centres.items():
        for s0, s1 in still_moments(cs, params):
            if any(s0 <= e + d.gap + d.window and s1 >= b - d.gap - d.window for b, e in busy.get(key, ())):
                continue  # part of a two-hand activity
            far_before, far_after = moved_windows(cs, s0, s1, params)
            v = _still_verdict(key, cs, s0, s1, (far_before, far_after), colours, clothes, where, last, params)
            if v is None and d.held_near:
                # a pick read with the window right after the still moment (``held_near``), where
                # the colour is seen to leave with the hand
                v = _still_verdict(key, cs, s0, s1, (far_before, _windows(s0, s1, params)[1]), colours, clothes,
                                   where, last, params, "pick")
                if v is not None and stays_behind(where.get(key, {}), cs, v.colour, s0, s1, params) is not False:
                    v = None
            if v is not None:
                rows.append(dict(start_frame=s0, end_frame=s1, kind=v.kind, track_id_a=key[0], part_a=key[1],
                                 track_id_b=0, part_b="", ended_by="still", object_colour=hue_to_hex(v.colour),
                                 confidence=round(v.margin, 3), hue=v.colour, at=_stood(cs, s0, s1)))
    rows = [r for r in _distinct(rows) if r["confidence"] >= params.decision.min_confidence or r["kind"] == "hand_head"]
    rows = picked_once(rows, params)
    rows += other_sides(rows, colours, clothes, params)
    out = pd.DataFrame(_exchange_touches_dropped(handovers(rows, params)), columns=list(ACTIVITY_COLUMNS))
    return out.sort_values(["start_frame", "track_id_a", "part_a"], kind="stable").reset_index(drop=True)


def _still_verdict(key: Key, cs, s0: int, s1: int, windows, colours, clothes, where, last: int,
                   params: ActivityParams, only: str | None = None) -> Verdict | None:
    """Rows 4-5 of Table 1 for the still moment ``s0..s1`` of hand ``key`` read at ``windows``
    (before, after); ``only``: the one kind wanted (None: either)."""
    d = params.decision
    (b0, b1), (a0, a1) = windows
    worn = clothes.get(key[0], np.zeros(0, int))
    before, after = (_without(_held(colours.get(key, {}), lo, hi, params), worn) for lo, hi in ((b0, b1), (a0, a1)))
    if before is not None and after is None and a1 <= last and only in (None, "place"):
        # unseen where it should have moved on (a giver's hand lost as the taker pulls the
        # object away): what it held at the end of its still moment tells a place, nothing else
        after, only = _without(_held(colours.get(key, {}), s1 - d.window, s1, params), worn), "place"
        a0, a1 = s1 - d.window, s1
    if before is None or after is None:
        return None
    v = one_hand(before, after, params,
                 lambda hue: stays_behind(where.get(key, {}), cs, hue, s0, s1, params))
    if v is None or (only is not None and v.kind != only):
        return None
    if v.colour is not None:
        # the side where the colour is gone (after a place, before a pick): a view that still
        # shows it as much as the views together showed it held saw no change there
        lo, hi, held = (a0, a1, before) if v.kind == "place" else (b0, b1, after)
        if _one_view_mass(colours.get(key, {}), lo, hi, v.colour, params) >= mass(held, v.colour, params):
            return None
    return v


def picked_once(rows: list[dict], params: ActivityParams) -> list[dict]:
    """``rows`` with each run of picks (places) of one colour by one hand, each starting at most
    ``decision.merge_gap`` frames after the previous one ends and with no other activity of that
    hand in between, made one pick (place) from the first's start to the last's end: a hand
    cannot pick up what it already holds, and two still moments of one pick are a stop the
    tracker broke in two (one camera, pick_place seed 6: the tracked hand jumped 36 px onto the
    arm and back over frames 38-44, two picks 25-40 and 45-56 of the one 25-57). The merged row
    keeps the less sure confidence."""
    d = params.decision
    reach = d.same_colour / DEGREES_PER_BIN
    order = sorted(range(len(rows)), key=lambda i: rows[i]["start_frame"])
    out: list[dict] = []
    last: dict[Key, int] = {}  # per hand, the index in ``out`` of its latest activity
    for i in order:
        r = rows[i]
        hands = [k for k in ((r["track_id_a"], r["part_a"]), (r["track_id_b"], r["part_b"])) if k != (0, "")]
        prev = out[last[hands[0]]] if len(hands) == 1 and hands[0] in last else None
        if (prev is not None and r["kind"] in ("pick", "place") and prev["kind"] == r["kind"]
                and prev.get("hue") is not None and r.get("hue") is not None
                and min((prev["hue"] - r["hue"]) % HUE_BINS, (r["hue"] - prev["hue"]) % HUE_BINS) <= reach
                and r["start_frame"] - prev["end_frame"] <= d.merge_gap):
            prev.update(end_frame=max(prev["end_frame"], r["end_frame"]),
                        confidence=min(prev["confidence"], r["confidence"]))
            continue
        out.append(dict(r))
        for k in hands:
            last[k] = len(out) - 1
    return out


def _exchange_touches_dropped(rows: list[dict]) -> list[dict]:
    """``rows`` without the handshakes of two people that overlap an exchange between them by more
    than half of the shorter (:func:`_overlap`): the touch of the exchange, read by another pair of
    their hands (the giver's other hand, a hand whose track wandered onto the meeting; limb
    tracker, exchange seed 5: an exchange 34-86 by the right hands and a handshake 37-90)."""
    exchanges = [r for r in rows if r["kind"] == "exchange"]

    def touch(r: dict) -> bool:
        return r["kind"] == "handshake" and any(
            {r["track_id_a"], r["track_id_b"]} == {e["track_id_a"], e["track_id_b"]}
            and _overlap((r["start_frame"], r["end_frame"]), (e["start_frame"], e["end_frame"])) > 0.5
            for e in exchanges)

    return [r for r in rows if not touch(r)]


def other_sides(rows: list[dict], colours: Mapping[Key, Mapping[int, list[HandColour]]],
                clothes: Mapping[int, np.ndarray], params: ActivityParams) -> list[dict]:
    """The other side of a handover no still moment shows: for each pick (place) that no place
    (pick) of its colour by another person's hand pairs with (:func:`handovers`), the place (pick)
    of another person's hand that held (did not hold) that colour just before the still moment and
    did not (did) just after, over the same frames. A giver's hand that moves while it lets go, or
    that the tracker loses right after, stands still nowhere (limbs3d, handshake seed 5: the giver
    let go over 85-91 while moving; the taker stood still over 92-108). Rows of one-hand
    activities carry their colour as ``hue``."""
    d = params.decision
    reach = d.same_colour / DEGREES_PER_BIN
    out = []
    for r in rows:
        if r["kind"] not in ("pick", "place") or r.get("hue") is None:
            continue
        other = "place" if r["kind"] == "pick" else "pick"
        if any(q["kind"] == other and q["track_id_a"] != r["track_id_a"] and q.get("hue") is not None
               and min((q["hue"] - r["hue"]) % HUE_BINS, (r["hue"] - q["hue"]) % HUE_BINS) <= reach
               and _gap(q, r) <= d.handover_gap for q in rows):
            continue
        (b0, b1), (a0, a1) = _windows(r["start_frame"], r["end_frame"], params)
        best = None
        for key, cs in colours.items():
            if key[0] == r["track_id_a"] or key[1] not in HAND_PARTS:
                continue
            worn = clothes.get(key[0], np.zeros(0, int))
            before = _without(_held_seen(cs, b0, b1, -1, params), worn)
            after = _without(_held_seen(cs, a0, a1, 1, params), worn)
            if before is None or after is None:
                continue
            was, now = mass(before, r["hue"], params), mass(after, r["hue"], params)
            held, gone = (was, now) if other == "place" else (now, was)
            if held < d.min_mass or gone > max(d.max_mass_absent, d.absent_ratio * held):
                continue
            conf = round(min(r["confidence"], 1.0 - gone / max(held, 1e-9)), 3)
            if conf >= d.min_confidence and (best is None or conf > best["confidence"]):
                best = dict(r, kind=other, track_id_a=key[0], part_a=key[1], confidence=conf, at=None)
        if best is not None:
            out.append(best)
    return out


def _one_view_mass(colours: Mapping[int, list[HandColour]], lo: int, hi: int, hue: int,
                   params: ActivityParams) -> float:
    """The largest share of colour ``hue`` any single view shows around a hand over ``lo..hi``
    (eq. 29 per view), 0 where fewer than two views saw it. A view that sees the hand against
    the person's trousers shows them all along, while another sees them only as the hand passes
    (3-camera handshake seed 6, limbs3d hands: one view 0.26-0.43 throughout, another 0.19 -> 0,
    a false place and a false pick as the views' agreement came and went)."""
    views: dict[str, list[HandColour]] = {}
    for f in range(lo, hi + 1):
        for o in colours.get(f, ()):
            views.setdefault(o.view, []).append(o)
    if len(views) < 2:
        return 0.0
    return max(mass(colour_masses(fuse(obs), params), hue, params) for obs in views.values())


def _stood(centres: Mapping[int, tuple[float, float, float]], s0: int, s1: int) -> tuple[float, float, float] | None:
    """Where a hand stood still over ``s0..s1``: the median of its centres and sides."""
    seen = [centres[f] for f in range(s0, s1 + 1) if f in centres]
    return tuple(float(v) for v in np.median(np.array(seen, float), axis=0)) if seen else None


def _stood_near(a: dict, b: dict, reach: float) -> bool:
    """Whether two one-hand rows' hands stood within ``reach`` hand sides of each other (True when
    ``reach`` is 0 or a row has no place)."""
    pa, pb = a.get("at"), b.get("at")
    if reach <= 0 or pa is None or pb is None:
        return True
    return float(np.hypot(pa[0] - pb[0], pa[1] - pb[1])) <= reach * max(pa[2], pb[2], 1.0)


def _gap(a: dict, b: dict) -> int:
    """Frames between two rows' spans (0 or less where they overlap), in either order."""
    return max(b["start_frame"] - a["end_frame"], a["start_frame"] - b["end_frame"])


def handovers(rows: list[dict], params: ActivityParams) -> list[dict]:
    """``rows`` (activity rows; one-hand ones with the object's hue bin as ``hue``) with each
    object given from one person to another read as one exchange: a *place* by one person's hand
    followed, at most ``handover_gap`` frames after it ends, by a *pick* of the same colour
    (``same_colour``) by another person's hand. Where a tracker never brings the two hands together
    (nor within ``contact_mm`` of each other in 3D) Table 1's two-hand rows are never read, and the
    object seems to rest for a moment where nobody holds it. The taker's still moment may also end
    up to ``handover_gap`` frames *before* the giver's starts: its pick is read after it, where the
    hand moved on to take the object (limbs3d, handshake seed 3: the taker stood still over 59-67,
    took the object at 71-78 and was lost; the giver stood still over 77-87). The exchange starts
    with the giver's still moment and ends with the later of the two (the giver's where the
    taker's began after it ended, ``handover_giver``), goes from the placing hand
    (``a``) to the picking one (``b``), with the less sure of the two confidences; a handshake of
    the two people overlapping it is dropped (the touch of the handover). The two hands must have
    stood still within ``handover_reach`` hand sides of each other (rows' ``at``, where known).
    Each place and each pick gives at most one exchange, the nearest in time first; an exchange
    that shares a hand with another and overlaps it by more than half of the shorter is the same
    one, the more confident kept (``one_exchange``)."""
    d = params.decision
    reach = d.same_colour / DEGREES_PER_BIN

    def same(h1, h2) -> bool:
        return h1 is not None and h2 is not None and min((h1 - h2) % HUE_BINS, (h2 - h1) % HUE_BINS) <= reach

    places = [i for i, r in enumerate(rows) if r["kind"] == "place"]
    picks = [i for i, r in enumerate(rows) if r["kind"] == "pick"]
    pairs = sorted((_gap(rows[i], rows[j]), i, j) for i in places for j in picks
                   if rows[j]["track_id_a"] != rows[i]["track_id_a"]
                   and _gap(rows[i], rows[j]) <= d.handover_gap
                   and same(rows[i].get("hue"), rows[j].get("hue"))
                   and _stood_near(rows[i], rows[j], d.handover_reach))
    used: set[int] = set()
    exchanges = []
    for _, i, j in pairs:
        if i in used or j in used:
            continue
        used |= {i, j}
        give, take = rows[i], rows[j]
        end = max(give["end_frame"], take["end_frame"])
        if d.handover_giver and take["start_frame"] > give["end_frame"]:
            end = give["end_frame"]  # the taker stood still with the object after it was passed
        exchanges.append(dict(start_frame=give["start_frame"], end_frame=end,
                              kind="exchange", track_id_a=give["track_id_a"], part_a=give["part_a"],
                              track_id_b=take["track_id_a"], part_b=take["part_a"], ended_by="still",
                              object_colour=give["object_colour"], hue=give.get("hue"),
                              confidence=min(give["confidence"], take["confidence"])))

    def covered(r: dict) -> bool:
        people = {r["track_id_a"], r["track_id_b"]}
        return r["kind"] == "handshake" and any(
            people == {e["track_id_a"], e["track_id_b"]} and _overlap((r["start_frame"], r["end_frame"]),
                                                                     (e["start_frame"], e["end_frame"])) > 0
            for e in exchanges)

    out = [r for k, r in enumerate(rows) if k not in used and not covered(r)] + exchanges
    # one object given by one hand is one exchange: a handover's and one read from a touch of the
    # giver's hand with another of the taker's (``decision.one_exchange``; :func:`_distinct`)
    return _distinct(out) if d.one_exchange else out
