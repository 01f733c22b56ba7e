"""The limb tracker: head, left hand and right hand of every person in one camera (seed 000, 003).

Per frame (``LimbTracker.step``):

1. observations: skin pixels (``partlab.tracking.core.skin``; with ``--init`` the skin model is refit
   on the init boxes against the whole frame) within the foreground and the
   neighbourhood of tracked targets, connected blobs, candidates with a prior that is a
   product of named terms (``partlab.tracking.limbs.filter``);
2. low layer: every active filter predicts, is weighted against the candidates no other
   target sits on and its hue histogram over skin pixels (seed 000 eq. 17, seed 003
   eq. 1-2), refined by mean shift on the skin hue back-projection and resampled;
3. high layer: the per-tracker state machine (``partlab.tracking.limbs.state_machine``) combines,
   splits, loses and recovers targets; this module acts on its transitions (one filter
   for a combined pair, one filter per mode after a split, labels by the direction
   cue), labels auto-started trackers (face detector for heads, side of the head for
   hands) and re-acquires a head with the face detector (seed 003 sec. 3).

A tracker's output row has ``track_id`` = the person, ``part`` in head/left_hand/right_hand,
``state`` = its state-machine state and ``score`` = the filter's confidence.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from partlab.tracking.core.box import Box
from partlab.tracking.core.hue_histogram import hue_bin_image, reference_histogram
from partlab.tracking.core.skin import Blobs, SkinModel, find_blobs, train_skin_model
from partlab.tracking.limbs.filter import (
    Candidates,
    LimbFilter,
    blob_points,
    candidate_modes,
    candidate_terms,
    nearest_part_candidates,
    nearest_per_parent,
    tip_candidates,
)
from partlab.tracking.limbs.people import foreground_people, in_regions, merge_boxes, on_regions
from partlab.tracking.limbs.state_machine import (
    JoinEvent,
    LimbState,
    LimbStateMachine,
    Observation,
    assign_by_direction,
    distance_threshold,
)
from partlab.tracking.params import LimbParams
from partlab.tracking.parts import LIMB_PARTS
from partlab.tracking.tracks import TrackRecord, normalise_tracks

EVENT_COLUMNS: tuple[str, ...] = ("start_frame", "end_frame", "kind", "track_id_a", "part_a",
                                  "track_id_b", "part_b", "ended_by")

FACE_CASCADE_FILE = "haarcascade_frontalface_default.xml"
#: side of the frontal-face cascade's window (pixels): it finds no smaller face
FACE_WINDOW = 24
#: smallest head box (pixels) whose face the cascade can find: a face's skin fills about 0.75 of
#: the cascade's box, so a smaller head's face is under its window (PETS09's heads, 8-16 px)
FACE_MIN_SIDE = 0.75 * FACE_WINDOW


def load_face_detector() -> cv2.CascadeClassifier | None:
    """OpenCV's bundled frontal-face cascade, or None if this OpenCV build lacks it
    (then heads are started and re-acquired from skin blobs only)."""
    data = getattr(cv2, "data", None)
    if data is None:
        return None
    path = Path(data.haarcascades) / FACE_CASCADE_FILE
    if not path.exists():
        return None
    det = cv2.CascadeClassifier(str(path))
    return None if det.empty() else det


def event_kind(part_a: str | None, track_a: int | None, part_b: str | None, track_b: int | None) -> str:
    """Activity class of a join (seed 000 sec. 7.1): two hands of one person -> clap (or an
    exchange between the hands), hands of two people -> handshake, a hand and a head -> hand_head."""
    hands = {"left_hand", "right_hand"}
    if part_a in hands and part_b in hands:
        return "clap" if track_a == track_b else "handshake"
    if {part_a, part_b} & hands and "head" in (part_a, part_b):
        return "hand_head"
    return "join"


def write_events(events: pd.DataFrame, path: str | PathLike) -> None:
    """Write the join/separation events as ``EVENTS.csv`` (columns :data:`EVENT_COLUMNS`)."""
    missing = [c for c in EVENT_COLUMNS if c not in events.columns]
    if missing:
        raise ValueError(f"events table lacks column(s) {', '.join(missing)}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    events.loc[:, list(EVENT_COLUMNS)].sort_values(["start_frame", "track_id_a"], kind="stable").to_csv(
        path, index=False, lineterminator="\n")


@dataclass
class _Target:
    """What the tracker knows of one head or hand beyond its state."""

    track_id: int | None = None
    part: str | None = None
    filter: LimbFilter | None = None
    size: tuple[float, float] = (0.0, 0.0)
    ref_hist: np.ndarray | None = None
    last: np.ndarray | None = None  # last confident position (lost-state search centre)
    low_frames: int = 0  # frames below reacquire_confidence (heads)
    unlabelled_frames: int = 0
    candidate: np.ndarray | None = None  # uninitialized: the candidate it would start from
    candidate_box: np.ndarray | None = None
    missed: int = 0  # uninitialized: frames without its candidate
    shown: np.ndarray | None = None  # combined: the position written for this member
    anchor: np.ndarray | None = None  # the person's head estimate when ``last`` was taken
    prev: np.ndarray | None = None  # normal: the estimate one frame before (the hand's velocity)
    off: int = 0  # found automatically: frames in a row off every person region

    @property
    def labelled(self) -> bool:
        return self.track_id is not None and self.part is not None


def _check_frame(frame: np.ndarray, foreground: np.ndarray | None) -> np.ndarray:
    frame = np.asarray(frame)
    if frame.ndim != 3 or frame.shape[2] != 3 or frame.dtype != np.uint8:
        raise ValueError(f"expected a BGR (H, W, 3) uint8 frame, got shape {frame.shape} dtype {frame.dtype}")
    if foreground is not None and np.asarray(foreground).shape != frame.shape[:2]:
        raise ValueError(f"foreground mask shape {np.asarray(foreground).shape} does not match the frame "
                         f"{frame.shape[:2]}")
    return frame


@dataclass(frozen=True)
class _View:
    """One frame's observations: skin ``blobs``, their candidates ``cands``, the hue bin of every
    skin pixel ``skin_bins (H, W) int16`` (-1 elsewhere); found automatically, the person regions
    ``people (P, 4)`` (:mod:`partlab.tracking.limbs.people`), else None; ``cut (H, W) bool``:
    pixels next to skin that is not observed (outside the foreground and every support box;
    ``blobs.cut_ends``), None without a foreground mask."""

    blobs: Blobs
    cands: Candidates
    skin_bins: np.ndarray
    people: np.ndarray | None = None
    cut: np.ndarray | None = None


class _CandidateSets:
    """The candidates each target sees this frame: blob centres for heads and small hands, the
    blobs' ends for hands (one set per hand size, built once), with the targets sitting on each."""

    def __init__(self, tracker: LimbTracker, view: _View, active: list[int]):
        self.tracker, self.cands, self.blobs, self.active = tracker, view.cands, view.blobs, active
        self.cut = view.cut
        self._cuts: list | None = None
        self._pixels: list | None = None  # each blob's pixels, read once when a hand needs its ends
        self._sets: dict = {}
        owner, within = tracker._owners(view.cands, active)
        # a head's blob (face and neck) is no hand's: its lower end would look like one
        self.heads = within & np.array([tracker.targets[o].part == "head" if o >= 0 else False for o in owner], bool)

    def points(self) -> list[np.ndarray]:
        if self._pixels is None:
            self._pixels = blob_points(self.blobs)
        return self._pixels

    def cuts(self) -> list[np.ndarray] | None:
        """Per blob, its pixels at a cut (:attr:`_View.cut`); None where no blob is cut."""
        if self.cut is None:
            return None
        if self._cuts is None:
            self._cuts = [self.cut[p[:, 1].astype(int), p[:, 0].astype(int)] for p in self.points()]
        return self._cuts if any(c.any() for c in self._cuts) else None

    def not_heads(self, c: Candidates) -> Candidates:
        return self.tracker._subset(c, ~self.heads[c.parents]) if c.parents is not None else c

    def by(self, t: int) -> tuple[Candidates, tuple[np.ndarray, np.ndarray]]:
        side = key = self.tracker._hand_side(t)
        tgt = self.tracker.targets[t]
        if side is None and self.tracker.params.blobs.cut_centres and tgt.part in ("left_hand", "right_hand") \
                and self.cut is not None and self.tracker.machine.state(t) in (LimbState.NORMAL, LimbState.UNLABELLED):
            # a hand that sees blob centres sees a cut blob's end away from the cut (while it
            # tracks one hand: a combined pair's blob is two arms, a lost hand's search box cuts
            # other arms)
            key = ("cut", float(round(sum(tgt.size) / 2)))
        if key not in self._sets:
            if side is not None:  # small hands (kept, seeing arm ends) only: blobs.cut_ends
                small = side < self.tracker.params.blobs.tip_min_side
                c = self.not_heads(tip_candidates(self.cands, self.points(), side, self.tracker.params,
                                                  self.cuts() if small else None))
            elif key is not None and self.cuts() is not None:
                c = tip_candidates(self.cands, self.points(), key[1], self.tracker.params, self.cuts(),
                                   span=np.inf)
            else:
                c = self.cands
            self._sets[key] = (c, self.tracker._owners(c, self.active))
        return self._sets[key]


class LimbTracker:
    """Head and hands of several people; implements ``partlab.tracking.protocol.FrameTracker``.

    ``init``: a tracks table (INIT.csv) whose head/left_hand/right_hand rows start
    tracks at their first listed frame with their ``track_id``; without it (or without
    limb rows in it), trackers
    start from persistent skin blobs and are labelled by the face detector and by
    position relative to a head.
    """

    def __init__(self, params: LimbParams | None = None, rng: np.random.Generator | None = None,
                 init: pd.DataFrame | None = None, skin: SkinModel | None = None,
                 face_detector: bool = True):
        self.params = params or LimbParams()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        # ``skin``: a trained model (e.g. from a model bundle); default: the YCrCb rule
        self.skin = skin or SkinModel.default()
        self.machine = LimbStateMachine(self.params)
        self.targets: dict[int, _Target] = {}
        self.face = load_face_detector() if face_detector else None
        self._next_tracker = 0
        self._next_person = 0
        self._last_frame = -1
        self._init: dict[int, list[tuple[int, str, np.ndarray]]] = {}
        self._given_people: np.ndarray | None = None  # person boxes of the next frame (set_people)
        #: found automatically, where person regions come from: "foreground" (its components) or
        #: "given" (set_people before each frame; a frame without boxes is not gated)
        self.people_from = "foreground"
        self._ended: dict[int, _Target] = {}  # trackers ended off people (their events still name them)
        rows = None if init is None else normalise_tracks(init)
        self._hidden_init: set[tuple[int, str]] = set()  # init boxes the table marks occluded
        self._arm_ends: set[tuple[int, str]] = set()  # small hands that see arm ends (blobs.tip_kept)
        if rows is not None:
            self._next_person = int(rows["track_id"].max()) + 1 if len(rows) else 0
            rows = rows[rows["part"].isin(LIMB_PARTS)]
        # an init table with only body rows (``--tracker all --init`` from the body tracker's
        # boxes) starts the limbs automatically, with person ids after the table's
        self.auto_start = rows is None or rows.empty
        if not self.auto_start:
            first = rows.sort_values("frame", kind="stable").groupby(["track_id", "part"], sort=False).head(1)
            for r in first.itertuples(index=False):
                self._init.setdefault(int(r.frame), []).append(
                    (int(r.track_id), str(r.part), np.array([r.x, r.y, r.w, r.h], float)))
                hidden = float(getattr(r, "occluded", 0.0) or 0.0)
                if hidden == hidden and hidden >= 0.5:  # NaN: not said
                    self._hidden_init.add((int(r.track_id), str(r.part)))

    # -- public ----------------------------------------------------------------------------
    def set_people(self, boxes) -> None:
        """Person boxes ``(P, 4) x, y, w, h`` of the next frame from another tracker (``--tracker
        all``: the body tracker's), used instead of the foreground's person regions; None: that
        tracker has no one in the frame, which is then not gated (a person seated at a desk,
        whom the body tracker does not start, keeps their limbs)."""
        self.people_from = "given"
        self._given_people = None if boxes is None else np.asarray(boxes, float).reshape(-1, 4)

    @property
    def events(self) -> pd.DataFrame:
        """Join/separation events so far (:data:`EVENT_COLUMNS`); a join still open ends at the last frame."""
        rows = []
        evs = list(self.machine.events)
        for t in self.machine.trackers():
            p = self.machine.partner(t)
            if self.machine.state(t) == LimbState.COMBINED and p is not None and t < p:
                evs.append(JoinEvent(self.machine.joined_at(t), self._last_frame, t, p, "open"))
        for e in evs:
            a = self.targets.get(e.tracker_a) or self._ended[e.tracker_a]
            b = self.targets.get(e.tracker_b) or self._ended[e.tracker_b]
            rows.append({"start_frame": e.start_frame, "end_frame": e.end_frame,
                         "kind": event_kind(a.part, a.track_id, b.part, b.track_id),
                         "track_id_a": a.track_id, "part_a": a.part, "track_id_b": b.track_id,
                         "part_b": b.part, "ended_by": e.ended_by})
        return pd.DataFrame(rows, columns=list(EVENT_COLUMNS))

    def step(self, index: int, frame: np.ndarray, foreground: np.ndarray | None = None) -> list[TrackRecord]:
        """One frame: observations, the low layer (every filter), the high layer (the state machine)."""
        frame = _check_frame(frame, foreground)
        self._last_frame = index
        # 1. observations
        starting = self._init.get(index, [])
        view = self._observe(index, frame, foreground, starting)
        for track_id, part, box in starting:
            self._start(box, view.skin_bins, track_id, part)
        self._fill_references(view.skin_bins)
        for t, tgt in self.targets.items():  # started before their head was: anchor them now
            if tgt.anchor is None and tgt.last is not None and tgt.part != "head":
                tgt.anchor = self._head_of(t)
        # 2. low layer
        active = [t for t in self.machine.trackers()
                  if self.machine.state(t) != LimbState.UNINITIALIZED and self.machine.is_leader(t)]
        seen = _CandidateSets(self, view, active)
        observations = {t: self._filter_step(t, seen, view) for t in active}
        self._follow_leaders(observations)
        if self.auto_start:
            self._propose(view.cands, observations, view.people)
        self._label(index, frame, observations, view.people)
        self._reacquire_heads(frame, view.skin_bins, observations)
        # 3. high layer
        for tr in self.machine.update(index, observations):
            self._apply(tr, index, view.skin_bins)
        self._fill_references(view.skin_bins)
        if view.people is not None:
            self._end_off_people(view.people)
        return self._records(index, view.people)

    # -- 1. observations -------------------------------------------------------------------
    def _observe(self, index: int, frame: np.ndarray, foreground: np.ndarray | None, starting) -> _View:
        """Skin pixels within the support, their blobs, candidates and the skin hue.

        Found automatically, skin and hue are computed only on the person regions and around the
        tracked targets (nothing is started or kept elsewhere), so the cost follows the people,
        not the frame."""
        p = self.params
        if starting and p.skin.adapt:
            # the given boxes show these people's skin against this scene: a Bayes skin model
            # (skin.train_skin_model) rejects skin-coloured wood, floors and walls that the rule
            # accepts, because their colours fill far more of the frame than the boxes.
            # a box the init table marks hidden (occluded >= 0.5: a hand behind its body) shows
            # clothes: its colours are never kept (skin.keep_hidden)
            keepable = [p.skin.keep_hidden or s[:2] not in self._hidden_init for s in starting]
            kept: list[bool] = []
            self.skin = train_skin_model([frame], [np.array([b for _, _, b in starting])],
                                         bins=self.skin.bins, ybins=p.skin.ybins, prior=self.skin,
                                         keep_mass=p.skin.keep_mass, keep_recall=p.skin.keep_recall,
                                         threshold=p.skin.threshold, keep_min_side=p.skin.keep_min_side,
                                         keep_spread=p.skin.keep_spread, kept=kept, keepable=keepable)
            # a small hand whose colours had to be kept shares them with its bare forearm: its
            # blob is hand and forearm, and the hand is its end (blobs.tip_kept)
            self._arm_ends |= {(t, part) for (t, part, b), k in zip(starting, kept)
                               if k and part != "head" and min(b[2], b[3]) < p.blobs.tip_min_side}
        people = self._people(foreground, frame.shape[:2])
        fg = None if foreground is None else self._support(np.asarray(foreground) > 0, index)
        rois = None if people is None else merge_boxes(np.vstack([people, self._support_boxes(index)]),
                                                       frame.shape[:2])
        skin_prob = on_regions(self.skin.probability, frame, rois, 0.0, np.float32, pad=self.skin.blur)
        skin_mask = skin_prob >= p.skin.threshold
        if fg is not None:
            skin_mask &= fg
        if p.skin.open > 1:  # remove speckle left by noise
            kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (p.skin.open, p.skin.open))
            skin_mask = cv2.morphologyEx(skin_mask.astype(np.uint8), cv2.MORPH_OPEN, kernel) > 0
        n_people = max(len({t.track_id for t in self.targets.values() if t.track_id is not None}), 1)
        blobs = find_blobs(skin_mask.astype(np.uint8), n_people, p.blobs.alpha, self._min_area(starting), rois)
        cands = candidate_terms(blobs, fg, skin_prob, p)
        cut = None
        if fg is not None and p.blobs.cut_ends:  # skin beyond the observed region: a blob cut there
            hidden = ((skin_prob >= p.skin.threshold) & ~fg).astype(np.uint8)
            cut = cv2.dilate(hidden, np.ones((3, 3), np.uint8)) > 0 if hidden.any() else None
        a = p.appearance

        def hue_bins(img: np.ndarray) -> np.ndarray:
            return hue_bin_image(cv2.cvtColor(img, cv2.COLOR_BGR2HSV), a.hue_bins, a.hue_min_saturation,
                                 a.hue_min_value)

        bins = on_regions(hue_bins, frame, rois, -1, np.int16)
        skin_bins = np.where(skin_mask, bins, -1).astype(np.int16)  # skin_mask is within the support
        # Hue is measured over skin pixels only: red objects (a cup) and wood share skin's hue
        # bins, so seed 003's whole-box hue histogram and back-projection would lock onto them.
        # The colour likelihood and the mean shift therefore run on the "skin-colour
        # probability map" (seed 003 sec. 3) of the skin model, not on raw hue.
        return _View(blobs, cands, skin_bins, people, cut)

    def _people(self, foreground: np.ndarray | None, shape: tuple[int, int]) -> np.ndarray | None:
        """Found automatically, this frame's person regions: the boxes given by :meth:`set_people`,
        else the foreground's (all of the frame without a foreground mask); with ``--init``, None."""
        given, self._given_people = self._given_people, None
        if not self.auto_start:
            return None
        if self.people_from == "given":
            return given
        if foreground is None:
            return np.array([[0.0, 0.0, float(shape[1]), float(shape[0])]])
        return foreground_people(foreground, self.params)

    # -- 2. low layer: one filter ----------------------------------------------------------
    def _filter_step(self, t: int, seen: _CandidateSets, view: _View) -> Observation:
        """Predict, weigh against the candidates this target may see, refine, resample."""
        tgt = self.targets[t]
        state = self.machine.state(t)
        own_c, owners = seen.by(t)
        before, prev, tgt.prev = tgt.filter.estimate.copy(), tgt.prev, None
        obs_c = self._predict(t, state, seen, own_c, owners)
        on_end = False  # the hand is seen as the end of an arm-long blob
        if obs_c.parents is not None and state != LimbState.COMBINED and len(obs_c):
            obs_c, on_end = self._nearest_ends(tgt, state, obs_c, own_c, before, prev, len(view.blobs),
                                               self._hand_side(t) is not None)
        tgt.filter.weigh(obs_c, view.skin_bins)
        modes = self._pair_modes(t, obs_c) if state == LimbState.COMBINED else ()
        if state != LimbState.LOST:
            self._refine(tgt, obs_c, on_end, view.skin_bins)
        tgt.filter.resample(self.rng)
        self._remember(t, state, before, view.skin_bins)
        partner = self.machine.partner(t) if state == LimbState.COMBINED else None
        two_people = partner is not None and tgt.track_id is not None and \
            self.targets[partner].track_id not in (None, tgt.track_id)
        observation = Observation(position=tuple(tgt.filter.estimate), likelihood=tgt.filter.confidence,
                                  labelled=tgt.labelled, modes=modes, size=self._side(t), two_people=two_people)
        self._place_pair(t, modes)
        return observation

    def _predict(self, t: int, state: LimbState, seen: _CandidateSets, own_c: Candidates, owners) -> Candidates:
        """Move the filter by its state's dynamics; the candidates it is weighed against."""
        p, tgt = self.params, self.targets[t]
        if state == LimbState.LOST:
            tgt.filter.reset(self._search_centre(t), self.rng, spread=p.dynamics.lost_search)
            return self._unclaimed(own_c, exclude=t, pairs=p.states.pair_span)
        if state == LimbState.COMBINED:
            # the pair's filter sees only candidates no other tracker explains (its own blobs)
            tgt.filter.predict(self.rng, p.dynamics.combined_noise_scale)
            side = self._hand_side(t)
            if side is not None:  # two hands: each blob's part nearest the pair
                own_c = seen.not_heads(nearest_part_candidates(seen.cands, seen.points(), tgt.filter.estimate,
                                                               side, p))
            # ... nor the place a lost target is looked for: a pair of hands that meet beside a lost
            # hand's blob (another person's hand the skin model barely sees) would split onto it
            return self._unclaimed(own_c, exclude=(t, self.machine.partner(t)), lost=p.states.pair_lost_claims)
        tgt.filter.predict(self.rng)
        return self._owned(own_c, t, owners)

    def _nearest_ends(self, tgt: _Target, state: LimbState, obs_c: Candidates, own_c: Candidates,
                      before: np.ndarray, prev: np.ndarray | None, n_blobs: int,
                      tips: bool = True) -> tuple[Candidates, bool]:
        """One end per blob, the one nearest the predicted hand: the other end of its arm is its
        elbow, and a posterior split between both ends would put it mid-arm. Also whether the
        nearest kept candidate is an arm's end. ``tips``: the hand sees arm ends (else blob
        centres, and a cut blob's end away from the cut, which ``tip_gate`` does not drop: a
        centre never was)."""
        p = self.params
        at = tgt.filter.estimate if state == LimbState.LOST else \
            before if prev is None else before + p.dynamics.velocity_decay * (before - prev)
        ends = np.bincount(own_c.parents, minlength=n_blobs)[obs_c.parents] >= 2
        if obs_c.ends is not None:  # the one end of a blob cut by the observed region's edge
            cut_ends = obs_c.ends
            gated = ends | cut_ends if tips else ends
            ends = ends | cut_ends
        else:
            gated = ends
        keep = nearest_per_parent(obs_c, at)
        if state != LimbState.LOST:
            # an arm's end farther than tip_gate sides is another part of it (an elbow
            # when the hand end merged into another blob): not this hand
            far = np.hypot(*(obs_c.centres - at[None, :]).T) > p.blobs.tip_gate * max(tgt.size)
            keep &= ~(gated & far)
        obs_c, ends = self._subset(obs_c, keep), ends[keep]
        on_end = bool(ends[int(np.argmin(np.hypot(*(obs_c.centres - at[None, :]).T)))]) if len(obs_c) else False
        return obs_c, on_end

    def _pair_modes(self, t: int, obs_c: Candidates) -> tuple:
        """The two strongest posterior modes of a combined pair's filter, among its own blobs."""
        s = self.params.states
        partner = self.machine.partner(t)
        ids = (self.targets[t].track_id, None if partner is None else self.targets[partner].track_id)
        search = s.people_mode_search if s.people_mode_search > 0 and None not in ids and ids[0] != ids[1] \
            else s.mode_search
        radius = search * distance_threshold(s.split_distance, s.split_size, self._side(t))
        # a kernel as wide as the search: the particles sit on one mode, the other may be far
        f = self.targets[t].filter
        m = candidate_modes(f.particles[:, :2], f.weights, obs_c, radius, radius)
        return tuple(map(tuple, m[:2]))

    def _refine(self, tgt: _Target, obs_c: Candidates, on_end: bool, skin_bins: np.ndarray) -> None:
        """Mean shift on the skin hue back-projection (Xu, Deng & Jia sec. 3); the refinement of
        an arm's end is the end itself (mean shift on the skin would slide the window up the arm)."""
        if on_end:
            d = np.hypot(*(obs_c.centres - tgt.filter.estimate[None, :]).T)
            if d.min() <= max(tgt.size):
                tgt.filter.shift_to(obs_c.centres[int(np.argmin(d))])
        else:
            tgt.filter.refine(skin_bins)

    def _remember(self, t: int, state: LimbState, before: np.ndarray, skin_bins: np.ndarray) -> None:
        """Velocity, last confident place (the lost-state search centre) and the model update."""
        p, tgt = self.params, self.targets[t]
        if state == LimbState.NORMAL:
            tgt.prev = before
        if tgt.filter.confidence >= p.states.recover_likelihood and state != LimbState.LOST:
            tgt.last = tgt.filter.estimate.copy()
            tgt.anchor = self._head_of(t)
            if state == LimbState.NORMAL:
                tgt.filter.update_reference(reference_histogram(skin_bins, tgt.filter.box(), p.appearance.hue_bins))

    def _follow_leaders(self, observations: dict[int, Observation]) -> None:
        """Followers of a combined pair report the leader's estimate."""
        for t in self.machine.trackers():
            if self.machine.state(t) == LimbState.COMBINED and not self.machine.is_leader(t):
                lead = observations.get(self.machine.partner(t))
                if lead is not None:
                    observations[t] = Observation(position=lead.position, likelihood=lead.likelihood,
                                                  labelled=self.targets[t].labelled, size=self._side(t))

    def _side(self, t: int) -> float:
        """Box side of a target (mean of width and height), the unit of the state machine's
        distances; a combined leader uses the mean of both members."""
        tgt = self.targets[t]
        side = (tgt.size[0] + tgt.size[1]) / 2
        partner = self.machine.partner(t)
        if self.machine.state(t) == LimbState.COMBINED and partner is not None:
            other = self.targets[partner]
            side = (side + (other.size[0] + other.size[1]) / 2) / 2
        return side

    def _hand_side(self, t: int) -> float | None:
        """Box side of a hand target (of both, for a combined pair of hands), rounded to a
        pixel so hands of one size share their candidates; None for heads and unlabelled targets."""
        hands = ("left_hand", "right_hand")
        members = [t]
        partner = self.machine.partner(t)
        if self.machine.state(t) == LimbState.COMBINED and partner is not None:
            members.append(partner)
        if any(self.targets[m].part not in hands for m in members):
            return None
        side = float(round(np.mean([sum(self.targets[m].size) / 2 for m in members])))
        b = self.params.blobs
        arm_ends = b.tip_kept and all(self._sees_arm_ends(m) for m in members)
        return side if b.tip_span > 0 and (side >= b.tip_min_side or arm_ends) else None

    def _sees_arm_ends(self, t: int) -> bool:
        """A small hand sees arm ends where its own init box's colours were kept, or (with
        ``blobs.tip_person``), while it is not lost, where one of its person's hands' was: the
        kept colour is the person's skin, so their other bare forearm shows with its hand too."""
        tgt = self.targets[t]
        if (tgt.track_id, tgt.part) in self._arm_ends:
            return True
        return self.params.blobs.tip_person and self.machine.state(t) != LimbState.LOST and \
            any(i == tgt.track_id for i, _ in self._arm_ends)

    def _head_of(self, t: int) -> np.ndarray | None:
        """Current estimate of the head of tracker ``t``'s person (None if no tracked head)."""
        tid = self.targets[t].track_id
        for h, tgt in self.targets.items():
            if (h != t and tgt.track_id == tid and tgt.part == "head" and tgt.filter is not None
                    and self.machine.state(h) in (LimbState.NORMAL, LimbState.UNLABELLED)):
                return tgt.filter.estimate.copy()
        return None

    def _search_centre(self, t: int) -> np.ndarray:
        """Where a lost target is looked for: its last confident position (sec. 5.2), moved
        with its person's head since then: a walker's hidden hand travels with the body."""
        tgt = self.targets[t]
        head = self._head_of(t)
        if tgt.anchor is None or head is None:
            return tgt.last
        return tgt.last + (head - tgt.anchor)

    def _place_pair(self, leader: int, modes: tuple) -> None:
        """Output positions of a combined pair: while two modes show (not yet far enough apart
        to split), each member takes the one on its side (direction cue of sec. 7.1); with one
        mode both sit on the filter's estimate."""
        tgt = self.targets[leader]
        tgt.shown = None
        if self.machine.state(leader) != LimbState.COMBINED:
            return
        other = self.targets[self.machine.partner(leader)]
        if len(modes) >= 2:
            pos_a, pos_b = assign_by_direction(self.machine.direction_before(leader), np.asarray(modes[:2]))
            tgt.shown, other.shown = pos_a, pos_b
        else:
            tgt.shown = other.shown = tgt.filter.estimate.copy()

    def _min_area(self, starting) -> float:
        """Smallest blob kept: ``min_blob_area``, or less when the targets are small (a distant
        walker's hand): a quarter of the smallest target's box area."""
        sizes = [t.size[0] * t.size[1] for t in self.targets.values() if t.filter is not None]
        sizes += [float(b[2] * b[3]) for _, _, b in starting]
        if not sizes:
            return self.params.blobs.min_area
        return min(self.params.blobs.min_area, 0.25 * min(sizes))

    def _support(self, fg: np.ndarray, index: int) -> np.ndarray:
        """The foreground plus a neighbourhood of every tracked target.

        An adaptive background model absorbs a person who sits still (the desk scene's head
        after a few seconds, or from the first frame when they are there from the start);
        a target already under track keeps its region observable, while new trackers still
        need real foreground to start. The neighbourhood is the target's box scaled by
        ``support_scale`` around its last estimate.
        """
        boxes = self._support_boxes(index)
        if not len(boxes):
            return fg
        out = fg.copy()
        hgt, wid = fg.shape
        for x, y, w, h in boxes:
            x1, y1 = max(int(x), 0), max(int(y), 0)
            x2, y2 = min(int(np.ceil(x + w)), wid), min(int(np.ceil(y + h)), hgt)
            if x2 > x1 and y2 > y1:
                out[y1:y2, x1:x2] = True
        return out

    def _support_boxes(self, index: int) -> np.ndarray:
        """``(B, 4)`` boxes kept observable: this frame's init boxes and every tracked target's box
        scaled by ``support_scale`` around its estimate (a lost one's around where it is looked for)."""
        boxes = [np.asarray(b, float) for _, _, b in self._init.get(index, [])]
        for t, tgt in self.targets.items():
            if tgt.filter is None or self.machine.state(t) == LimbState.UNINITIALIZED:
                continue
            c = tgt.filter.estimate if self.machine.state(t) != LimbState.LOST else self._search_centre(t)
            w, h = tgt.size[0] * self.params.blobs.support_scale, tgt.size[1] * self.params.blobs.support_scale
            boxes.append(np.array([c[0] - w / 2, c[1] - h / 2, w, h]))
        return np.array(boxes, float).reshape(-1, 4)

    # -- starting trackers -----------------------------------------------------------------
    def _new_tracker(self, target: _Target, state: LimbState) -> int:
        t = self._next_tracker
        self._next_tracker += 1
        self.targets[t] = target
        self.machine.add(t, state)
        return t

    def _make_filter(self, tgt: _Target, centre) -> LimbFilter:
        return LimbFilter(centre, tgt.size, tgt.ref_hist, self.params, self.rng)

    def _reference(self, box, skin_bins: np.ndarray) -> np.ndarray | None:
        """Hue reference of a box from its skin pixels; None when under a tenth of the box is
        skin (a hand hidden behind the body at its first frame)."""
        x, y, w, h = (int(round(v)) for v in box)
        hgt, wid = skin_bins.shape
        patch = skin_bins[max(y, 0):min(y + h, hgt), max(x, 0):min(x + w, wid)]
        if patch.size == 0 or (patch >= 0).sum() < 0.1 * max(w * h, 1):
            return None
        return reference_histogram(skin_bins, box, self.params.appearance.hue_bins)

    def _fill_references(self, skin_bins: np.ndarray) -> None:
        """Targets started without a usable reference take their person's face colour (seed 003
        sec. 3: the hands' reference comes from the face), else the hue of all skin in view."""
        for tgt in self.targets.values():
            if tgt.filter is None or tgt.ref_hist is not None:
                continue
            head = next((h for h in self.targets.values() if h.track_id == tgt.track_id and h.part == "head"
                         and h.ref_hist is not None), None)
            if head is not None:
                ref = head.ref_hist.copy()
            else:
                vals = skin_bins[skin_bins >= 0]
                ref = (np.bincount(vals, minlength=self.params.appearance.hue_bins).astype(float) if vals.size
                       else np.ones(self.params.appearance.hue_bins))
                ref = ref / ref.sum()
            tgt.ref_hist = ref
            tgt.filter.ref_hist = ref.copy()

    def _start(self, box, skin_bins: np.ndarray, track_id: int, part: str) -> None:
        """Start a labelled tracker from an INIT.csv box (state normal)."""
        box = np.asarray(box, float)
        tgt = _Target(track_id=track_id, part=part, size=(max(box[2], 2.0), max(box[3], 2.0)),
                      ref_hist=self._reference(box, skin_bins))
        centre = box[:2] + box[2:] / 2
        tgt.filter = self._make_filter(tgt, centre)
        tgt.last = centre.copy()
        self._new_tracker(tgt, LimbState.NORMAL)

    def _owners(self, cands: Candidates, active: list[int]) -> tuple[np.ndarray, np.ndarray]:
        """For each candidate, the nearest tracked target (by last frame's estimate) and whether
        it lies within that target's reach (half its size plus sigma_xy): ``(K,) int, (K,) bool``."""
        live = [t for t in active if self.machine.state(t) != LimbState.LOST]
        if len(cands) == 0 or not live:
            return np.full(len(cands), -1), np.zeros(len(cands), bool)
        est = np.array([self.targets[t].filter.estimate for t in live])
        reach = np.array([self._claim_radius(t) for t in live])
        d = np.hypot(cands.centres[:, None, 0] - est[None, :, 0], cands.centres[:, None, 1] - est[None, :, 1])
        j = d.argmin(axis=1)
        return np.asarray(live)[j], d[np.arange(len(cands)), j] <= reach[j]

    def _claim_radius(self, t: int) -> float:
        """How far from a target's estimate a candidate is its own: half its box plus sigma_xy; a
        combined pair's (with ``states.pair_span``) reaches a split distance: its two hands, apart
        but not yet split, are both its."""
        tgt = self.targets[t]
        reach = max(tgt.size) / 2 + self.params.priors.sigma_xy
        if self.params.states.pair_span and self.machine.state(t) == LimbState.COMBINED:
            st = self.params.states
            reach = max(reach, distance_threshold(st.split_distance, st.split_size, self._side(t)))
        return reach

    def _owned(self, cands: Candidates, t: int, owners: tuple[np.ndarray, np.ndarray]) -> Candidates:
        """The candidates a normal filter is weighted against: all but those another target sits on
        (exclusion). Without it, a filter whose blob vanishes jumps to a neighbour's blob within a
        frame and looks confident there, so it would never be declared lost (seed 000 sec. 5.2)."""
        nearest, within = owners
        keep = ~within | (nearest == t)
        return self._subset(cands, keep)

    @staticmethod
    def _subset(cands: Candidates, keep: np.ndarray) -> Candidates:
        return Candidates(cands.centres[keep], cands.boxes[keep], cands.areas[keep],
                          {k: v[keep] for k, v in cands.terms.items()}, cands.priors[keep],
                          None if cands.parents is None else cands.parents[keep],
                          None if cands.ends is None else cands.ends[keep])

    def _unclaimed(self, cands: Candidates, exclude: int | tuple, lost: bool = False,
                   pairs: bool = False) -> Candidates:
        """Candidates not explained by another active tracker (a lost target must not
        recover onto a limb someone else tracks); ``lost``: nor lying where a lost target is looked
        for (:meth:`_search_centre`); ``pairs``: nor within a split distance of a combined pair
        (its two hands, apart but not yet split) or on any part of a blob it sits on (the blob
        holds two hands already: its other end, an arm's, is no third hand)."""
        if len(cands) == 0:
            return cands
        keep = np.ones(len(cands), bool)
        exclude = set(exclude) if isinstance(exclude, tuple) else {exclude}
        for t, tgt in self.targets.items():
            if t in exclude or tgt.filter is None:
                continue
            state = self.machine.state(t)
            if state in (LimbState.NORMAL, LimbState.COMBINED, LimbState.UNLABELLED):
                at = tgt.filter.estimate
            elif lost and state == LimbState.LOST and tgt.last is not None:
                at = self._search_centre(t)
            else:
                continue
            reach = self._claim_radius(t) if pairs else max(tgt.size) / 2 + self.params.priors.sigma_xy
            near = np.hypot(*(cands.centres - at[None, :]).T) <= reach
            if pairs and state == LimbState.COMBINED and cands.parents is not None and near.any():
                near |= np.isin(cands.parents, cands.parents[near])
            keep &= ~near
        return self._subset(cands, keep)

    def _propose(self, cands: Candidates, observations: dict[int, Observation], people: np.ndarray | None) -> None:
        """Uninitialized trackers follow candidates no existing tracker explains (sec. 5.2), on a
        person region."""
        free = self._unclaimed(cands, exclude=-1)
        if people is not None and len(free):
            free = self._subset(free, in_regions(free.centres, people))
        pending = [t for t in self.machine.trackers() if self.machine.state(t) == LimbState.UNINITIALIZED]
        used: set[int] = set()
        for t in pending:
            tgt = self.targets[t]
            if len(free):
                d = np.hypot(*(free.centres - tgt.candidate[None, :]).T)
                d[list(used)] = np.inf
                j = int(np.argmin(d))
                if d[j] <= 2 * self.params.priors.sigma_xy + self.params.dynamics.noise_xy:
                    used.add(j)
                    tgt.candidate, tgt.candidate_box, tgt.missed = free.centres[j].copy(), free.boxes[j].copy(), 0
                    observations[t] = Observation(position=tuple(tgt.candidate), prior=float(free.priors[j]))
                    continue
            tgt.missed += 1
            observations[t] = Observation()
        for j in range(len(free)):
            if j not in used:
                tgt = _Target(candidate=free.centres[j].copy(), candidate_box=free.boxes[j].copy())
                t = self._new_tracker(tgt, LimbState.UNINITIALIZED)
                observations[t] = Observation(position=tuple(tgt.candidate), prior=float(free.priors[j]))
        for t in pending:  # forget candidates that vanished
            if self.targets[t].missed > self.params.states.start_frames:
                self.machine.remove(t)
                self.targets.pop(t)

    # -- labelling (unlabelled -> normal) -----------------------------------------------------
    def _faces(self, frame: np.ndarray, near: list[tuple[np.ndarray, float]]) -> np.ndarray:
        """Face boxes ``(F, 4) x, y, w, h`` found within ``near``: ``(centre, half side)`` squares.

        Only faces near a tracker are ever used (a face on a tracker labels it a head, one near a
        lost head re-acquires it), so the cascade scans those squares, not the frame: on PETS09
        (768 x 576, a dozen trackers) the whole-frame scan took 60% of the tracker's time."""
        if self.face is None or not near:
            return np.zeros((0, 4))
        grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
        hgt, wid = grey.shape
        found = []
        for (cx, cy), half in near:
            x1, y1 = max(int(cx - half), 0), max(int(cy - half), 0)
            x2, y2 = min(int(np.ceil(cx + half)), wid), min(int(np.ceil(cy + half)), hgt)
            if min(x2 - x1, y2 - y1) < FACE_WINDOW:  # the cascade's smallest window
                continue
            f = self.face.detectMultiScale(grey[y1:y2, x1:x2], scaleFactor=1.1, minNeighbors=4, minSize=(12, 12))
            if len(f):
                found.append(np.asarray(f, float).reshape(-1, 4) + np.array([x1, y1, 0, 0]))
        return np.concatenate(found) if found else np.zeros((0, 4))

    def _label(self, index: int, frame: np.ndarray, observations: dict[int, Observation],
               people: np.ndarray | None = None) -> None:
        """Cues for unlabelled trackers that never had a type: a face -> new person's head;
        beside a head -> that person's hand on that side; alone and topmost for a while -> head.
        Found automatically, a head only in the top of a person region, a hand only inside one."""
        p = self.params
        todo = [t for t in self.machine.trackers() if self.machine.state(t) == LimbState.UNLABELLED
                and not self.targets[t].labelled and self.targets[t].filter is not None]
        if not todo:
            return
        # a face holding a tracker's centre lies within a few of its sides
        faces = self._faces(frame, [(self.targets[t].filter.estimate, max(3.0 * max(self.targets[t].size), 32.0))
                                    for t in todo if max(self.targets[t].size) >= FACE_MIN_SIDE])
        for t in sorted(todo, key=lambda t: self.targets[t].filter.estimate[1]):  # topmost first
            tgt = self.targets[t]
            tgt.unlabelled_frames += 1
            cx, cy = tgt.filter.estimate
            may_head, may_hand = self._may_be(tgt.filter.estimate, people)
            on_face = may_head and any(fx <= cx <= fx + fw and fy <= cy <= fy + fh for fx, fy, fw, fh in faces)
            head = self._nearest_head(tgt.filter.estimate) if may_hand else None
            # a face that is not the nearby head's own is another person's head
            if on_face and (head is None or np.hypot(*(head[1].filter.estimate - tgt.filter.estimate))
                            > max(head[1].size)):
                self._assign(t, self._next_person, "head")
                self._next_person += 1
            elif head is not None:
                hid, htgt = head
                right_side = cx < htgt.filter.estimate[0]  # image left of the head
                side = ("right_hand" if right_side else "left_hand") if p.labels.facing_camera else \
                    ("left_hand" if right_side else "right_hand")
                taken = self._parts_of(htgt.track_id)
                other = "left_hand" if side == "right_hand" else "right_hand"
                if side not in taken:
                    self._assign(t, htgt.track_id, side)
                elif other not in taken:
                    self._assign(t, htgt.track_id, other)
            elif tgt.unlabelled_frames >= p.labels.head_guess_frames and may_head:
                self._assign(t, self._next_person, "head")
                self._next_person += 1
            if tgt.labelled and t in observations:
                o = observations[t]
                observations[t] = Observation(o.position, o.likelihood, o.prior, True, o.modes, o.size)

    def _may_be(self, point, people: np.ndarray | None) -> tuple[bool, bool]:
        """Whether a tracker at ``point`` may be labelled a head (in the top of a person region) and
        a hand (inside one); both when people are not looked for (``--init``)."""
        if people is None:
            return True, True
        pt = np.asarray(point, float)[None, :]
        return bool(in_regions(pt, people, self.params.people.head_top)[0]), bool(in_regions(pt, people)[0])

    def _on_people(self, t: int, people: np.ndarray | None) -> bool:
        """Whether tracker ``t``'s estimate is on a person region (a head in its top part)."""
        tgt = self.targets[t]
        if people is None or tgt.filter is None:
            return True
        head, hand = self._may_be(tgt.filter.estimate, people)
        return head if tgt.part == "head" else hand

    def _end_off_people(self, people: np.ndarray) -> None:
        """End trackers found automatically that stayed ``people.end_frames`` frames off every person
        region (a limb on a wall or a parked car, or a person who has left); a combined pair waits
        until it splits or is lost."""
        for t in list(self.targets):
            tgt, state = self.targets[t], self.machine.state(t)
            if tgt.filter is None or state in (LimbState.UNINITIALIZED, LimbState.COMBINED):
                continue
            tgt.off = 0 if state != LimbState.LOST and self._on_people(t, people) else tgt.off + 1
            if tgt.off >= self.params.people.end_frames:
                self.machine.end(t)
                self._ended[t] = self.targets.pop(t)

    def _assign(self, t: int, track_id: int, part: str) -> None:
        tgt = self.targets[t]
        tgt.track_id, tgt.part = track_id, part

    def _parts_of(self, track_id: int) -> set[str]:
        return {tgt.part for tgt in self.targets.values() if tgt.track_id == track_id and tgt.part}

    def _nearest_head(self, point) -> tuple[int, _Target] | None:
        best, best_d = None, math.inf
        for t, tgt in self.targets.items():
            if tgt.part != "head" or tgt.filter is None or self.machine.state(t) == LimbState.UNINITIALIZED:
                continue
            d = float(np.hypot(*(np.asarray(point) - tgt.filter.estimate)))
            if d <= self.params.labels.person_radius * tgt.size[1] and d < best_d:
                best, best_d = (t, tgt), d
        return best

    # -- head re-acquisition (seed 003 sec. 3) -------------------------------------------------
    def _reacquire_heads(self, frame: np.ndarray, skin_bins: np.ndarray, observations) -> None:
        p = self.params
        if self.face is None:
            return
        for t, tgt in self.targets.items():
            if tgt.part != "head" or tgt.filter is None or t not in observations:
                continue
            if self.machine.state(t) == LimbState.COMBINED:
                continue
            tgt.low_frames = tgt.low_frames + 1 if tgt.filter.confidence < p.adjustment.reacquire_confidence else 0
            # looked for every reacquire_frames frames while low, on heads whose face the cascade can see
            if (tgt.low_frames < p.adjustment.reacquire_frames or tgt.low_frames % p.adjustment.reacquire_frames
                    or max(tgt.size) < FACE_MIN_SIDE):
                continue
            last = tgt.last if tgt.last is not None else tgt.filter.estimate
            faces = self._faces(frame, [(last, (p.labels.person_radius + 1) * tgt.size[1])])
            if len(faces) == 0:
                continue
            centres = faces[:, :2] + faces[:, 2:] / 2
            d = np.hypot(*(centres - last[None, :]).T)
            j = int(np.argmin(d))
            if d[j] > p.labels.person_radius * tgt.size[1]:
                continue
            tgt.filter.reset(centres[j], self.rng)
            ref = reference_histogram(skin_bins, faces[j], p.appearance.hue_bins)
            if ref is not None:  # replace the colour reference with the face's (sec. 3)
                tgt.filter.ref_hist = ref
            tgt.last, tgt.low_frames = centres[j].copy(), 0
            o = observations[t]
            observations[t] = Observation(tuple(centres[j]), max(o.likelihood, p.states.recover_likelihood),
                                          o.prior, o.labelled, o.modes, o.size)

    # -- acting on transitions -----------------------------------------------------------------
    def _apply(self, tr, index: int, skin_bins: np.ndarray) -> None:
        tgt = self.targets[tr.tracker]
        if tr.old == LimbState.UNINITIALIZED and tr.new == LimbState.UNLABELLED:
            box = tgt.candidate_box
            side = float(max(box[2], box[3], 4.0))
            tgt.size = (side, side)
            tgt.ref_hist = self._reference(box, skin_bins)
            tgt.filter = self._make_filter(tgt, tgt.candidate)
            tgt.last = tgt.candidate.copy()
        elif tr.new == LimbState.COMBINED and not self.machine.is_leader(tr.tracker):
            tgt.filter = None  # the leader's filter tracks both
        elif tr.reason == "split":
            if tgt.filter is None:
                tgt.filter = self._make_filter(tgt, tr.position)
            tgt.filter.reset(tr.position, self.rng)
            tgt.last = np.asarray(tr.position, float)
        elif tr.reason == "split unseen":  # parted from its pair, not seen: looked for at the guess
            tgt.last, tgt.anchor = np.asarray(tr.position, float), self._head_of(tr.tracker)
            if tgt.filter is None:
                tgt.filter = self._make_filter(tgt, tgt.last)
        elif tr.new == LimbState.LOST:
            if tgt.filter is None:  # a follower of a lost pair
                tgt.filter = self._make_filter(tgt, tgt.last)
            if tgt.last is None:
                tgt.last = tgt.filter.estimate.copy()

    def _records(self, index: int, people: np.ndarray | None = None) -> list[TrackRecord]:
        """This frame's rows; found automatically, only of trackers on a person region, not lost."""
        out = []
        for t, tgt in self.targets.items():
            state = self.machine.state(t)
            if state == LimbState.UNINITIALIZED or not tgt.labelled:
                continue
            if people is not None and (state == LimbState.LOST or (
                    state != LimbState.COMBINED and not self._on_people(t, people))):
                continue
            if state == LimbState.COMBINED:
                lead = tgt.filter or self.targets[self.machine.partner(t)].filter
                centre = tgt.shown if tgt.shown is not None else lead.estimate
                conf = lead.confidence
            elif state == LimbState.LOST:
                centre = self._search_centre(t) if tgt.last is not None else tgt.filter.estimate
                conf = tgt.filter.confidence
            else:
                centre, conf = tgt.filter.estimate, tgt.filter.confidence
            w, h = tgt.size
            box = Box(float(centre[0] - w / 2), float(centre[1] - h / 2), float(w), float(h))
            out.append(TrackRecord(index, int(tgt.track_id), str(tgt.part), box, score=float(conf),
                                   failure=state == LimbState.LOST, state=state.value, source="limbs"))
        return out
