"""The multi-person three-part body tracker (seed 002 sec. 4).

Every tracked person has three part filters (head, torso, hip-leg; or one ``person``
filter in whole-body mode, the paper's baseline of Fig. 4(d)). Each frame:

1. tracks listed in ``init`` start at their first frame (a person row is decomposed
   by sec. 4.1; part rows are used as given, shrunk to their inner rectangles); without
   ``init``, person-size foreground blobs seen for ``start_frames`` frames running start
   tracks;
2. every part is predicted; parts behind a given occluder region (pillars, doors,
   sec. 4.3.2) and persons hidden behind another person (sec. 4.3.1) follow their
   dynamics with the appearance model frozen; the others are measured, the torso first,
   then head and hip-leg carried by the torso's motion and kept near their place on the
   body (``shared_motion``, ``coherence``: additions to the paper's independent filters);
3. when parts of two measured persons touch, the one whose touching parts match their
   models worse is the occluded one: it goes back to its dynamics until the two separate,
   or until its torso shows clearly again clear of the other person;
4. the failure detector (if any) judges the unoccluded persons and
   ``partlab.tracking.body.adjustment`` repairs failed parts (sec. 4.3);
5. models are updated by eq. (1), particles resampled by eq. (2), tracks that leave
   the frame (or, when detecting automatically, lose their foreground) end.

The output of a frame is one row per part and a ``person`` row holding the minimum
bounding rectangle of the three parts (sec. 5.3). All numbers come from ``BodyParams``.
"""

from __future__ import annotations

import copy
from collections import deque
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import cv2
import numpy as np

from partlab.tracking.body.cue import DetectionCue, _layout, _placed, border_gaps
from partlab.tracking.body.decomposition import decompose, minimum_bounding_rectangle, shrink_part
from partlab.tracking.body.detection import edge_contrast, person_blobs
from partlab.tracking.body.part_filter import PartFilter, state_to_box, surround_counts
from partlab.tracking.core.box import Box, iou_xywh
from partlab.tracking.core.camera_motion import CameraMotion, MotionSettings
from partlab.tracking.core.lazy_ycc import LazyYcc, as_array
from partlab.tracking.params import BodyParams
from partlab.tracking.parts import BODY_PARTS
from partlab.tracking.protocol import FailureDetector, FailureVerdict
from partlab.tracking.tracks import TrackRecord, frame_to_records

if TYPE_CHECKING:
    import pandas as pd

#: a person moving less than this share of its box height a frame stands still (at a border: leaving)
STILL = 0.01
#: frames of camera travel kept (``BodyTracker.scene_velocity`` reads those of a person's last clean frames)
SHIFTS = 64


@dataclass
class TrackStart:
    """Boxes a track starts from (rows of an init CSV at the track's first frame)."""

    frame: int
    boxes: dict[str, Box]


def init_starts(init: pd.DataFrame | list[TrackRecord], whole: bool = False) -> dict[int, TrackStart]:
    """Per track id (ascending), its first listed frame and the boxes given there (in the
    order of their rows).

    ``init``: a tracks table or its rows as :class:`TrackRecord`. Rows of parts this tracker
    does not track (hands) are ignored; a track with neither a person row nor a body-part row
    at its first frame is refused with a clear message.
    """
    records = init if isinstance(init, list) else frame_to_records(init)
    wanted = ("person",) + BODY_PARTS
    by_track: dict[int, list[TrackRecord]] = {}
    for r in records:
        if r.part in wanted:
            by_track.setdefault(r.track_id, []).append(r)
    starts: dict[int, TrackStart] = {}
    for tid in sorted(by_track):
        rows = by_track[tid]
        first = min(r.frame for r in rows)
        boxes = {}
        for r in rows:
            if r.frame != first:
                continue
            b = r.box
            if b.w < 2 or b.h < 2:
                raise ValueError(f"init track {tid} frame {first}: the {r.part} box {b.w:g} x {b.h:g} is too small "
                                 f"to track (at least 2 x 2 pixels)")
            boxes[r.part] = Box(float(b.x), float(b.y), float(b.w), float(b.h))
        starts[tid] = TrackStart(first, boxes)
    return starts


@dataclass
class Dormant:
    """A track given by the user that ended (lost and withdrawn, or left the frame), kept for
    ``detector.reid_hits``: its person, the frame it ended and, when it walked out, the border it
    left through (``left``, ``right``, ``top``, ``bottom``; None when lost inside the frame)."""

    person: Person
    ended: int
    border: str | None


@dataclass
class Person:
    """One tracked person: its part filters and the bookkeeping of occlusion and failure."""

    track_id: int
    filters: dict[str, PartFilter]
    history: deque = field(default_factory=deque)
    occluded_by: int | None = None          # track id of the person in front (sec. 4.3.1)
    hidden_parts: tuple[str, ...] = ()      # parts behind an occluder region (sec. 4.3.2)
    failed: tuple[str, ...] = ()
    adjusted: bool = False
    unsupported: int = 0
    started: int = 0
    scores: dict[str, float] = field(default_factory=dict)
    prev: dict[str, np.ndarray] = field(default_factory=dict)
    observed: dict[str, np.ndarray] = field(default_factory=dict)
    centres: deque = field(default_factory=lambda: deque(maxlen=11))  # (frame, cx, cy), clean frames
    touching: bool = False                  # parts touch another person's this frame
    occluded_frames: int = 0
    offsets: dict[str, float] = field(default_factory=dict)  # part Y - torso Y, in torso heights
    lost_since: int | None = None           # frame it went lost (no foreground support), coasting since
    layout: dict[str, tuple] = field(default_factory=dict)  # parts in the person box at its first detection
    coast_start: int | None = None          # first frame of the coasting stretch it is in (lost or occluded)
    at_border: int | None = None            # last supported frame its box was at a border, not moving away
    given: dict[str, Box] = field(default_factory=dict)  # boxes it was started from (--init, keyframes), as drawn
    first: dict[str, PartFilter] = field(default_factory=dict)  # its filters as started (models of the given boxes)
    seen: tuple[int, float, float] | None = None  # (frame, cx, cy): last measured clear of everyone, not lost
    revived: int | None = None  # frame it was re-identified (``detector.reid_hits``), if it was
    steps: deque = field(default_factory=lambda: deque(maxlen=3))  # torso displacements of its first measured frames
    learns_from: int = 0  # frame its velocity started from zero (its start; a re-acquisition standing)
    yields_from: int | None = None  # frame it went lost on someone else's person (``detector.lost_yields``)
    released: bool = False  # its torso probe ended a yielding loss this frame (not measured)

    @property
    def yielding(self) -> bool:
        """Lost because its first models said the person it sat on is another track's (a duplicate
        or a claim, ``detector.duplicate_margin``), and still in that loss."""
        return self.lost_since is not None and self.lost_since == self.yields_from

    def velocity(self) -> np.ndarray | None:
        """Median per-frame motion of the person box's centre over its recent *clean* frames
        (not touching anyone, not occluded: another person passing in front drags the
        estimate before the occlusion is decided); None if too few."""
        return median_velocity(self.centres)

    def part_boxes(self) -> dict[str, Box]:
        return {name: f.box for name, f in self.filters.items()}

    def box(self) -> Box:
        return minimum_bounding_rectangle(f.box for f in self.filters.values())


def median_velocity(centres) -> np.ndarray | None:
    """Median per-frame motion of ``(frame, cx, cy)`` entries; None if fewer than three."""
    if len(centres) < 3:
        return None
    c = np.asarray(centres, dtype=np.float64)
    return np.median(np.diff(c[:, 1:], axis=0) / np.diff(c[:, 0])[:, None], axis=0)


def _moved(first: Box, now: Box, by: float) -> bool:
    """Both side edges (or both the top and bottom edge) moved at least ``by`` pixels the same
    way: a walker moves, while a walker separating from its ghost has one edge held by the ghost."""
    for a, b in (((first.x, first.x2), (now.x, now.x2)), ((first.y, first.y2), (now.y, now.y2))):
        d1, d2 = b[0] - a[0], b[1] - a[1]
        if d1 * d2 > 0 and min(abs(d1), abs(d2)) >= by:
            return True
    return False


def _piece_of(blob: Box, person: Box, p: BodyParams) -> bool:
    """A blob beside a tracked person box that is a part of that person the box does not cover
    (legs or head above or below it, within its width; an arm or a leg beside it, within its
    height and shorter than the person), not someone new."""
    near = p.detection.margin * person.h * 2
    across = max(0.0, min(blob.x2, person.x2) - max(blob.x, person.x))
    if across >= 0.5 * blob.w and max(person.y - blob.y2, blob.y - person.y2, 0.0) <= near:
        return True
    along = max(0.0, min(blob.y2, person.y2) - max(blob.y, person.y))
    return (along >= 0.5 * blob.h and blob.h < 0.7 * person.h
            and max(person.x - blob.x2, blob.x - person.x2, 0.0) <= near)


def _support(mask: np.ndarray, box: Box) -> float:
    """Share of foreground pixels in ``box`` (clipped to the mask)."""
    H, W = mask.shape[:2]
    c = box.clip(W, H)
    region = mask[int(c.y):int(c.y2), int(c.x):int(c.x2)]
    return float((region > 0).mean()) if region.size else 0.0


def _supports(mask: np.ndarray, states: np.ndarray) -> np.ndarray:
    """Share of foreground pixels in each of ``states``' boxes ``(N, >=4)`` (centre, size), by
    one integral image."""
    H, W = mask.shape[:2]
    ii = cv2.integral((mask > 0).astype(np.uint8))
    s = np.asarray(states, dtype=np.float64)
    x1 = np.clip(np.round(s[:, 0] - s[:, 2] / 2), 0, W).astype(int)
    x2 = np.clip(np.round(s[:, 0] + s[:, 2] / 2), 0, W).astype(int)
    y1 = np.clip(np.round(s[:, 1] - s[:, 3] / 2), 0, H).astype(int)
    y2 = np.clip(np.round(s[:, 1] + s[:, 3] / 2), 0, H).astype(int)
    area = (x2 - x1) * (y2 - y1)
    inside = ii[y2, x2] - ii[y1, x2] - ii[y2, x1] + ii[y1, x1]
    return np.where(area > 0, inside / np.maximum(area, 1), 0.0)


def _frozen(f: PartFilter) -> PartFilter:
    """A copy of a part filter's appearance model as it is now (its model arrays are replaced,
    never changed in place, by later updates), for comparing regions with it later."""
    g = copy.copy(f)
    g.state = f.state.copy()
    return g


def _nearest_border(box: Box, W: int, H: int) -> str:
    """The border of a ``W`` x ``H`` frame nearest to ``box``."""
    gaps = border_gaps(box, W, H)
    return min(gaps, key=gaps.get)


def _motion(person) -> tuple[float, float]:
    """A person's per-frame motion: its person box's recent median (``Person.velocity``), else the
    mean of its parts' filter velocities."""
    v = person.velocity()
    if v is None:
        v = np.mean([f.state[4:6] for f in person.filters.values()], axis=0)
    return float(v[0]), float(v[1])


def _overlap_fraction(a: Box, b: Box) -> float:
    """Share of ``a``'s area covered by ``b``."""
    return a.intersection(b) / a.area if a.area > 0 else 0.0


class BodyTracker:
    """Three-part (or whole-body) colour particle-filter tracker of every person in a clip.

    ``init``: a tracks table (person and/or part rows) to start tracks from instead of
    detecting people; ``occluders``: fixed regions (``Box``) that hide people;
    ``failure_detector``: a :class:`partlab.tracking.protocol.FailureDetector` called each
    frame for every person not in occlusion; ``whole``: one box per person.
    """

    def __init__(self, params: BodyParams | None = None, rng: np.random.Generator | None = None,
                 init: pd.DataFrame | list[TrackRecord] | None = None, occluders=(),
                 failure_detector: FailureDetector | None = None,
                 whole: bool = False, fps: float = 25.0):
        self.params = params or BodyParams()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.whole = whole
        self.parts = ("person",) if whole else BODY_PARTS
        self.occluders = [b if isinstance(b, Box) else Box(*b) for b in occluders]
        self.failure_detector = failure_detector
        self.fps = float(fps)
        self.auto = init is None
        self.starts = {} if init is None else init_starts(init, whole)
        self.pending = dict(self.starts)
        self.people: dict[int, Person] = {}
        self.next_id = max(self.starts, default=0) + 1
        self.candidates: list[tuple[Box, int, Box]] = []  # (box, frames seen running, box when first seen)
        self.frames_seen = 0
        self.withdrawn: list[tuple[int, int]] = []  # (track_id, first frame): rows of a lost track that ended
        self.dormant: dict[int, Dormant] = {}  # given tracks that ended, by id (``detector.reid_hits``)
        self.revived: list[tuple[int, int]] = []  # (track_id, frame): a dormant track re-identified there
        self.bridges: list[tuple[int, int, int]] = []  # (track_id, first coasted frame, frame found again)
        self._ycc = LazyYcc()
        self.cue = DetectionCue(self) if self.params.detector.enabled else None
        bg = self.params.background
        self.camera = (CameraMotion(MotionSettings(threshold=bg.camera_motion, hold=bg.camera_hold,
                                                   residual=bg.camera_residual))
                       if bg.camera_motion > 0 else None)
        self.moving_mask: np.ndarray | None = None  # while the camera moves: what moves in the scene
        self._travelled = np.zeros(2)  # the camera's summed shifts while moving, up to the last frame
        self.travel: dict[int, np.ndarray] = {}  # frame -> _travelled at it, the last SHIFTS frames

    # -- starting tracks --------------------------------------------------------------
    def _part_boxes_for_start(self, boxes: dict[str, Box], ycc, mask) -> dict[str, Box]:
        if self.whole:
            if "person" in boxes:
                return {"person": boxes["person"]}
            return {"person": minimum_bounding_rectangle(boxes[p] for p in BODY_PARTS if p in boxes)}
        parts = {p: boxes[p] for p in BODY_PARTS if p in boxes}
        if self.params.decomposition.shrink_given_parts:
            parts = {p: shrink_part(ycc, mask, b, p) for p, b in parts.items()}
        if len(parts) < 3:
            person = boxes.get("person")
            if person is None:  # some parts only: their MBR stands in for the person
                person = minimum_bounding_rectangle(parts.values())
            decomposed = decompose(ycc, mask, person, self.params)
            for p in BODY_PARTS:
                parts.setdefault(p, decomposed[p])
        return parts

    def start_track(self, track_id: int, boxes: dict[str, Box], ycc: np.ndarray, mask: np.ndarray | None,
                    index: int, from_mask: bool = False) -> Person:
        """Start tracking a person from its boxes (person and/or part boxes); ``from_mask``: the
        boxes come from the foreground mask itself (automatic detection), so it is trusted even
        while the background model is young."""
        if not from_mask and self.frames_seen < self.params.background.warmup // 2:
            mask = None  # the background model has not learnt the scene yet: decompose by contrast
        ycc = as_array(ycc)
        parts = self._part_boxes_for_start(boxes, ycc, mask)
        H, W = ycc.shape[:2]
        filters = {}
        around = None
        if self.params.appearance.surround > 0:  # the ring around the person (background-weighted models)
            person_box = boxes.get("person") or minimum_bounding_rectangle(parts[n] for n in self.parts)
            around = surround_counts(ycc, person_box, self.params.appearance.surround)
        for name in self.parts:
            b = parts[name].clip(W, H)
            if b.w < 2 or b.h < 2:
                b = Box(b.x, b.y, max(b.w, 2.0), max(b.h, 2.0))
            filters[name] = PartFilter(b, ycc, self.params, self.params.dynamics.noise[name], self.rng,
                                       surround=around)
        person = Person(track_id, filters, deque(maxlen=self.params.adjustment.history_frames), started=index,
                        learns_from=index)
        if not self.auto:  # the models of the boxes it was started from, for re-identification (reid_hits)
            person.first = {n: _frozen(f) for n, f in filters.items()}
        if "torso" in filters:
            t = filters["torso"].state
            person.offsets = {n: float((f.state[1] - t[1]) / max(t[3], 1.0))
                              for n, f in filters.items() if n != "torso"}
        self.people[track_id] = person
        return person

    def _start_pending(self, index: int, ycc, mask) -> None:
        for tid in sorted(self.pending):
            start = self.pending[tid]
            if start.frame <= index:
                del self.pending[tid]
                self._undo_revivals(start, index)
                self.start_track(tid, start.boxes, ycc, mask, index).given = dict(start.boxes)

    def _undo_revivals(self, start: TrackStart, index: int) -> None:
        """A person given now (their first box) on whom a re-identified track stands
        (``detector.reid_undo_iou``) is someone new: the re-identification took them for the
        dormant person, so it is undone (its rows since then withdrawn, the track dormant again)."""
        iou_min = self.params.detector.reid_undo_iou
        if not self.revived or iou_min <= 0:
            return
        given = start.boxes.get("person") or minimum_bounding_rectangle(start.boxes.values())
        for tid, frame in list(self.revived):
            person = self.people.get(tid)
            if person is None or frame != max(f for t, f in self.revived if t == tid):
                continue
            if self._reported_person_box(person).iou(given) >= iou_min:
                self.withdrawn.append((tid, frame))
                del self.people[tid]
                self.dormant[tid] = Dormant(person, index, None)
                for q in self.people.values():
                    if q.occluded_by == tid:
                        q.occluded_by = None

    def _detect(self, index: int, frame: np.ndarray, ycc, mask) -> None:
        """Start tracks on person-size blobs of the foreground no tracked person covers, once
        they have been seen ``start_frames`` frames running, have moved and have an outline on
        image edges (ghosts do neither)."""
        p = self.params
        tracked = [self._reported_person_box(person) for person in self.people.values()]
        free = mask
        if tracked and p.detection.margin >= 0:
            free = mask.copy()
            H, W = mask.shape[:2]
            for t in tracked:
                m = p.detection.margin
                c = t.transformed(1 + 2 * m, 1 + 2 * m, 0.0, 0.0).clip(W, H)
                free[int(c.y):int(np.ceil(c.y2)), int(c.x):int(np.ceil(c.x2))] = 0
        fresh: list[tuple[Box, int, Box]] = []
        for blob in person_blobs(free, p):
            if any(blob.intersection(t) > p.detection.overlap * blob.area or _piece_of(blob, t, p) for t in tracked):
                continue
            count, first = 1, blob
            if self.candidates:
                prev = np.array([c[0].as_tuple() for c in self.candidates])
                ious = iou_xywh(np.array([blob.as_tuple()]), prev)[0]
                k = int(np.argmax(ious))
                if ious[k] > 0.3:
                    count, first = self.candidates[k][1] + 1, self.candidates[k][2]
            if (count >= p.detection.start_frames and _moved(first, blob, p.detection.start_min_motion * blob.h)
                    and edge_contrast(frame, mask, blob) >= p.detection.ghost_edge_contrast):
                self.start_track(self.next_id, {"person": blob}, ycc, mask, index, from_mask=True)
                tracked.append(blob)
                self.next_id += 1
            else:
                fresh.append((blob, count, first))
        self.candidates = fresh

    def _reported_person_box(self, person: Person) -> Box:
        """The person box the tracker reasons with (starts, the detection cue): the MBR of its
        parts' reported boxes (``output.person`` only changes what is written)."""
        return minimum_bounding_rectangle(self.report_box(n, f.box) for n, f in person.filters.items())

    def report_person(self, mbr: Box) -> Box:
        """The person box written for the MBR of the reported part boxes: scaled and shifted by
        ``BodyParams.output.person`` (fitted from corrected person boxes), clipped to the frame.
        Only the output changes: the tracker itself (the detection cue's matching and steering,
        automatic starts) goes on with the MBR, so a refit of it cannot change how people are
        tracked, only how their boxes are written."""
        sw, sh, dx, dy = self.params.output.person
        if self.whole or (sw, sh, dx, dy) == (1.0, 1.0, 0.0, 0.0):
            return mbr
        out = mbr.transformed(sw, sh, dx, dy)
        size = getattr(self, "frame_size", None)
        return out.clip(*size) if size else out

    # -- one frame ----------------------------------------------------------------------
    def step(self, index: int, frame: np.ndarray, foreground: np.ndarray | None) -> list[TrackRecord]:
        """Predict every part; decide who is hidden; measure the others; detect failures and
        adjust; update the models and resample; end tracks and look for new people."""
        ycc = self._ycc.load(frame)  # converted to YCrCb only where the filters look
        H, W = ycc.shape[:2]
        self.frame_size = (W, H)
        self.frames_seen += 1
        mask = self._follow_camera(frame, foreground)
        self._note_travel(index)
        support = mask if mask is not None else self.moving_mask  # foreground support of tracks
        moving = self.camera is not None and self.camera.moving
        new_ids = set()
        if self.pending:
            before = set(self.people)
            self._start_pending(index, ycc, mask)
            new_ids = set(self.people) - before
        active = [self.people[t] for t in sorted(self.people) if t not in new_ids]
        for person in self.people.values():  # colour models weighted against the background while the camera moves
            for pf in person.filters.values():
                pf.weigh_by_background(moving)

        # predict every part; decide who is hidden; measure the others
        for person in active:
            person.observed.clear()
            person.released = False
            person.prev = {n: f.state.copy() for n, f in person.filters.items()}
            person.failed = ()
            person.adjusted = False
            for f in person.filters.values():
                f.predict()
        for person in active:
            self._update_person_occlusion(person)
            self._measure(person, ycc, support)
        self._resolve_inter_person_occlusion(active)

        if not self.whole:
            self._detect_failures(active, ycc, mask)
        self._update_models(active)
        self._learn_start_velocity(active, index)

        for person in active:
            if not person.touching and person.occluded_by is None and not person.hidden_parts:
                person.centres.append((index, *person.box().centre))
                if person.lost_since is None:
                    person.seen = person.centres[-1]
        self._end_tracks(active, support, W, H, index)
        if self.cue is not None:
            self.cue.step(index, frame, ycc, mask, scan=self.moving_mask if self.auto else None)
        if self.auto and mask is not None and (self.cue is None or self.params.detector.blob_starts):
            self._detect(index, frame, ycc, mask)
        self._note_coasting(index, new_ids)
        return self._records(index, new_ids)

    def _learn_start_velocity(self, active: list[Person], index: int) -> None:
        """``dynamics.start_velocity_frames``: in a track's first frames, every part's velocity goes
        ``start_velocity_gain`` of the way to the median of the torso estimate's last displacements
        (Xu, Deng & Jia sec. 3: the velocity is the last displacement of the estimate). A track
        starts standing, and the colour filters learn a walker's speed only through their velocity
        noise; a lagging new track slides onto a slower neighbour. A track the detection cue re-acquired
        standing learns its velocity again the same way (``relearn_velocity``)."""
        d = self.params.dynamics
        if d.start_velocity_frames <= 0 or d.start_velocity_gain <= 0:
            return
        if self.camera is not None and self.camera.moving:
            return  # a panning camera follows its walker: the image displacement is not theirs
        for person in active:
            if index - person.learns_from > d.start_velocity_frames or "torso" not in person.prev:
                continue
            if person.occluded_by is not None or person.lost_since is not None or person.adjusted:
                continue  # coasting or re-initialised: no displacement measured this frame
            person.steps.append(person.filters["torso"].state[0:2] - person.prev["torso"][0:2])
            if len(person.steps) < 2:
                continue
            v = np.median(np.asarray(person.steps), axis=0)
            for f in person.filters.values():
                f.nudge_velocity(v, d.start_velocity_gain)

    def _note_coasting(self, index: int, new_ids: set[int]) -> None:
        """Keep, per person, where its current coasting stretch (lost, or behind someone) began; a
        stretch that ended with the person found again this frame is remembered for ``bridge``."""
        for tid, person in self.people.items():
            if tid in new_ids:
                continue
            if person.lost_since is not None or person.occluded_by is not None:
                first = person.lost_since if person.lost_since is not None else index
                person.coast_start = first if person.coast_start is None else min(person.coast_start, first)
            elif person.coast_start is not None:
                if self.params.occlusion.bridge and person.coast_start < index:
                    self.bridges.append((tid, person.coast_start, index))
                person.coast_start = None

    def _follow_camera(self, frame: np.ndarray, foreground: np.ndarray | None) -> np.ndarray | None:
        """The foreground mask to use this frame: None while the camera moves (``camera_motion``).
        The filters are not moved with the camera: a camera that pans follows someone, whose place
        in the image its constant velocity already predicts (moving every part with the scene's
        shift made the walker of OTB Human3 lag behind: rate 0.29 -> 0.21)."""
        if self.camera is None:
            return foreground
        self.camera.update(frame)
        self.moving_mask = self.camera.moving_mask() if self.camera.moving else None
        return None if self.camera.moving else foreground

    def _detect_failures(self, active: list[Person], ycc, mask: np.ndarray | None) -> None:
        """Failure detection and adjustment (sec. 4.2-4.3) for persons not in occlusion."""
        for person in active:
            # the detector sees the boxes as reported (and as corrected by people), not the
            # inner rectangles, so that what it was trained on and what it judges agree
            reported = [self.report_box(n, person.filters[n].box) for n in BODY_PARTS]
            person.history.append(np.array([[*b.centre, b.w, b.h] for b in reported]))
            if self.failure_detector is None or person.occluded_by is not None or person.hidden_parts:
                continue
            verdict = self.failure_detector.detect(np.stack(person.history), self.fps)
            if verdict.failed or verdict.multi:
                self._adjust(person, verdict, ycc, mask)

    def _update_models(self, active: list[Person]) -> None:
        """Model update (eq. (1)) where the estimate matches well, and resampling (eq. (2))."""
        least = self.params.appearance.update_min_similarity
        for person in active:
            for name, f in person.filters.items():
                if person.occluded_by is not None or name in person.hidden_parts:
                    continue
                q = person.observed.pop(name, None)
                if q is not None and person.scores[name] >= least and not person.adjusted:
                    f.update_model(q)
                f.resample()

    def _update_person_occlusion(self, person: Person) -> None:
        """Sec. 4.3.1: stay occluded while the person in front still overlaps; sec. 4.3.2:
        which parts are behind an occluder region."""
        person.touching = False
        if person.occluded_by is not None:
            person.occluded_frames += 1
            front = self.people.get(person.occluded_by)
            predicted = {n: f.predicted_box() for n, f in person.filters.items()}
            if (front is None or not self._touching(predicted, front.part_boxes())[0]
                    or person.occluded_frames > self.params.occlusion.max_frames):
                person.occluded_by = None
                person.occluded_frames = 0
        hidden = []
        for name, f in person.filters.items() if self.occluders else ():
            b = f.predicted_box()
            if any(_overlap_fraction(b, o) >= self.params.occlusion.occluder_overlap for o in self.occluders):
                hidden.append(name)
        person.hidden_parts = tuple(hidden)

    def _measure(self, person: Person, ycc: np.ndarray, mask=None) -> None:
        if person.lost_since is not None:
            for f in person.filters.values():
                f.coast()
            self._probe_lost(person, ycc, mask)
            return
        if person.occluded_by is not None:
            for f in person.filters.values():
                f.coast()
            self._probe_occluded(person, ycc)
            return
        visible = [n for n in person.filters if n not in person.hidden_parts]
        # the torso first: head and hip-leg are then kept near its centre line (coherence)
        visible.sort(key=lambda n: n != "torso")
        torso = None
        for name in visible:
            f = person.filters[name]
            if torso is None or name not in person.offsets:
                f.measure(ycc)
            else:
                s = self.params.dynamics.shared_motion
                if s > 0:  # one body moves as one: the torso's motion carries the other parts
                    step = torso[0:2] - person.prev["torso"][0:2]
                    delta = np.float32(s) * (step.astype(np.float32) - f.particles[:, 4:6])
                    f.particles[:, 0:2] += delta
                    f.particles[:, 4:6] += delta
                ax, ay = torso[0], torso[1] + person.offsets[name] * torso[3]
                dyn = self.params.dynamics
                f.measure(ycc, ax, dyn.coherence * torso[2], ay, dyn.coherence_y * torso[3])
            if name == "torso":
                torso = f.state.copy()
            person.observed[name] = q = f.appearance(ycc)
            person.scores[name] = f.score(q)
        if visible and self._keeps_scene_motion(person):
            return
        if person.hidden_parts:
            # hidden parts follow the visible parts' motion (they belong to one body); when all
            # are hidden, the person's own recent motion
            if visible:
                v = np.mean([person.filters[n].state[4:6] for n in visible], axis=0)
            else:
                v = person.velocity()
            for name in person.hidden_parts:
                f = person.filters[name]
                if v is not None:
                    f.set_velocity(v)
                f.coast()
            if not visible:
                self._probe_hidden(person, ycc)

    def _keeps_scene_motion(self, person: Person) -> bool:
        """``background.camera_keep_motion``: while the camera moves, a measurement that left the
        person where less moves in the scene (the share of its person box in the moving mask) than
        where its own motion in the scene (:meth:`scene_velocity` of its last clean frames) plus the
        camera's shift would have put it, by more than ``camera_keep_motion``, is undone: every part
        goes back to where it was and coasts this frame there, its models not updated. Where two
        walkers pass each other, the colour models slide off the tracked one towards the other
        across the still ground between them. Whether it was undone."""
        margin = self.params.background.camera_keep_motion
        mask = self.moving_mask
        if margin <= 0 or mask is None or self.camera is None or not self.camera.moving or not person.prev:
            return False
        v = self.scene_velocity(person.centres)
        if v is None:
            return False
        now = v + self.camera.shift
        before = minimum_bounding_rectangle(state_to_box(s) for s in person.prev.values())
        coasted = Box(before.x + float(now[0]), before.y + float(now[1]), before.w, before.h)
        if _support(mask, coasted) <= _support(mask, person.box()) + margin:
            return False
        for name, f in person.filters.items():
            f.state = person.prev[name].copy()
            f.set_velocity(now)
            f.coast()
        person.observed.clear()
        return True

    def _probe_anchor(self, person: Person, ycc: np.ndarray, mask: np.ndarray | None = None):
        """The person's torso (or only part) model searched for around its state: ``(filter,
        state, box)`` of a clear match (similarity at least ``release_similarity`` within
        ``release_search`` widths), or None."""
        p = self.params
        if p.occlusion.release_similarity <= 0:
            return None
        f = person.filters["torso" if "torso" in person.filters else next(iter(person.filters))]
        # with a mask, only where something moves: a still object of the same colours is not the person
        allowed = None if mask is None else (lambda cand: _supports(mask, cand) >= 2 * p.detection.support_min)
        state, rho = f.probe(ycc, p.occlusion.release_search * float(f.state[2]), allowed=allowed)
        if rho < p.occlusion.release_similarity:
            return None
        return f, state, Box(state[0] - state[2] / 2, state[1] - state[3] / 2, state[2], state[3])

    def _probe_hidden(self, person: Person, ycc: np.ndarray) -> None:
        """A person wholly behind occluder regions whose torso shows clearly again away from
        them (similarity at least ``release_similarity``) is moved there: a walker may speed
        up or slow down behind a pillar."""
        p = self.params
        probed = self._probe_anchor(person, ycc)
        if probed is None:
            return
        f, state, found = probed
        if any(_overlap_fraction(found, o) >= p.occlusion.occluder_overlap for o in self.occluders):
            return
        delta = state[0:2] - f.state[0:2]
        for g in person.filters.values():
            g.shift(delta)

    def _probe_lost(self, person: Person, ycc: np.ndarray, mask) -> None:
        """A lost person (no foreground support, e.g. behind an obstacle nobody listed) is looked
        for near the coasting prediction by the torso's model; a clear match (similarity at least
        ``release_similarity``) on foreground brings every part there and ends the loss."""
        p = self.params
        probed = self._probe_anchor(person, ycc, mask if self._rewinds(mask) else None)
        if probed is None:
            return
        f, state, found = probed
        if mask is not None and _support(mask, found) < 2 * p.detection.support_min:
            return
        delta = state[0:2] - f.state[0:2]
        if p.detector.lost_yields and person.yielding and self._on_another(person, delta):
            return  # that is someone else's person (the exclusion principle)
        for g in person.filters.values():
            g.shift(delta)
        person.released = person.yielding
        person.lost_since = None
        person.unsupported = 0

    def _on_another(self, person: Person, delta: np.ndarray) -> bool:
        """Whether the person's box moved by ``delta`` would overlap the box of another track that
        is not lost (nor behind someone) at ``detector.duplicate_iou`` or more."""
        b = person.box()
        moved = Box(b.x + float(delta[0]), b.y + float(delta[1]), b.w, b.h)
        return any(moved.iou(q.box()) >= self.params.detector.duplicate_iou for q in self.people.values()
                   if q is not person and q.lost_since is None and q.occluded_by is None)

    def _probe_occluded(self, person: Person, ycc: np.ndarray) -> None:
        """An occluded person whose torso shows clearly again (similarity at least
        ``release_similarity``, clear of the front person's box) near its prediction is released
        there, all parts moved with it: dynamics cannot foresee a stop or a turn behind
        someone, and the two may walk on together without ever separating."""
        if person.occluded_frames < 2:
            return
        probed = self._probe_anchor(person, ycc)
        if probed is None:
            return
        f, state, found = probed
        front = self.people.get(person.occluded_by)
        if front is not None and found.intersection(front.box()) > 0:
            return  # still behind (or beside and touching) the front person: keep waiting
        delta = state[0:2] - f.state[0:2]
        for g in person.filters.values():
            g.shift(delta)
            g.set_velocity(np.zeros(2))
        person.occluded_by = None
        person.occluded_frames = 0

    def _resolve_inter_person_occlusion(self, active: list[Person]) -> None:
        """Sec. 4.3.1: when parts of two measured persons touch, the one whose touching parts
        look less like their models is behind; it goes back to its dynamics-only prediction.
        While the two similarities differ by less than ``occlusion_margin`` nobody is hidden
        yet (both still fully visible); the decision waits for a frame that tells them apart."""
        p = self.params
        visible = [q for q in active if q.occluded_by is None]
        p_boxes = {q.track_id: q.box() for q in visible}
        pad = 1 + 2 * p.occlusion.pad
        for i, a in enumerate(visible):
            for b in visible[i + 1:]:
                if a.occluded_by is not None or b.occluded_by is not None:
                    continue
                ba, bb = p_boxes[a.track_id], p_boxes[b.track_id]
                if abs(ba.centre[0] - bb.centre[0]) * 2 > pad * (ba.w + bb.w) or ba.y > bb.y2 or bb.y > ba.y2:
                    continue  # person boxes far apart: no part can touch
                touching_a, touching_b = self._touching(a.part_boxes(), b.part_boxes())
                if not touching_a:
                    continue
                a.touching = b.touching = True
                sa = min(a.scores.get(n, 1.0) for n in touching_a)
                sb = min(b.scores.get(n, 1.0) for n in touching_b)
                stale = self._yields_to(a, b), self._yields_to(b, a)
                if stale[0] != stale[1]:  # a just released track's scores are stale: it is the one behind
                    behind, front = (a, b) if stale[0] else (b, a)
                elif abs(sa - sb) < p.occlusion.margin:
                    continue
                else:
                    behind, front = (a, b) if sa < sb else (b, a)
                behind.occluded_by = front.track_id
                behind.observed.clear()
                v = behind.velocity()
                for name, f in behind.filters.items():
                    f.state = behind.prev[name].copy()
                    if v is not None:
                        f.set_velocity(v)
                    f.coast()

    def _yields_to(self, a: Person, b: Person) -> bool:
        """``detector.released_behind``: ``a``'s probe has just ended its yielding loss (it was not
        measured) and ``b`` is measured this frame."""
        d = self.params.detector
        return d.released_behind and d.lost_yields and a.released and b.lost_since is None and bool(b.observed)

    def _touching(self, boxes_a: dict[str, Box], boxes_b: dict[str, Box]) -> tuple[set, set]:
        """Parts of two persons that overlap by more than ``occlusion_overlap`` of the smaller."""
        ta, tb = set(), set()
        pad = self.params.occlusion.pad
        if pad > 0:  # inner rectangles are narrower than the parts they stand for
            grow = lambda b: Box(b.x - pad * b.w, b.y, b.w * (1 + 2 * pad), b.h)  # noqa: E731
            boxes_a = {n: grow(b) for n, b in boxes_a.items()}
            boxes_b = {n: grow(b) for n, b in boxes_b.items()}
        for na, ba in boxes_a.items():
            for nb, bb in boxes_b.items():
                smaller = min(ba.area, bb.area)
                if smaller > 0 and ba.intersection(bb) > self.params.occlusion.overlap * smaller:
                    ta.add(na)
                    tb.add(nb)
        return ta, tb

    def _similarity(self, person: Person) -> float:
        return float(np.mean([person.scores.get(n, 1.0) for n in person.filters]))

    def _adjust(self, person: Person, verdict: FailureVerdict, ycc: np.ndarray, mask) -> None:
        from partlab.tracking.body.adjustment import adjust_person

        adjust_person(self, person, verdict, as_array(ycc), mask)
        person.failed = tuple(verdict.failed) if verdict.failed else (BODY_PARTS if verdict.multi else ())
        person.adjusted = True

    def _walked_out(self, person: Person, W: int, H: int, went: int) -> bool:
        """The person's reported box lies within ``exit_margin`` of its size from a border of the
        frame and the person does not move away from that border (``detection.exit_margin``), or
        did so on a supported frame at most ``exit_window`` frames before its support went (frame
        ``went``)."""
        if self._at_border(person, W, H):
            return True
        d = self.params.detection
        return d.exit_window > 0 and person.at_border is not None and person.at_border >= went - d.exit_window

    def _at_border(self, person: Person, W: int, H: int) -> bool:
        """The person's reported box lies within ``exit_margin`` of its size from a border of the
        frame and the person does not move away from that border."""
        m = self.params.detection.exit_margin
        if m <= 0:
            return False
        box = self._reported_person_box(person).clip(W, H)
        vx, vy = _motion(person)
        # walking along a border is not walking out of it (PETS09: walkers at the bottom edge, their
        # feet cut off, going sideways at 14 px a frame ended as "out" when their support lagged)
        along_x = abs(vx) > max(abs(vy), STILL * box.h)  # moves sideways: along the top or bottom border
        along_y = abs(vy) > max(abs(vx), STILL * box.h)
        side = not along_y and ((box.x <= m * box.w and vx <= 0) or (W - box.x2 <= m * box.w and vx >= 0))
        return side or (not along_x and ((box.y <= m * box.h and vy <= 0) or (H - box.y2 <= m * box.h and vy >= 0)))

    def _kept_at_edge(self, person: Person, box: Box, inside: float, W: int, H: int) -> bool:
        """A box cut by the frame (``inside`` of it in view, under ``leave_fraction``) whose person
        moves along the border that cuts it, or back into the frame, and with at least half of
        ``leave_fraction`` in view: not leaving (``detection.leave_along``)."""
        d = self.params.detection
        if not d.leave_along or inside < 0.5 * d.leave_fraction:
            return False
        vx, vy = _motion(person)
        if max(abs(vx), abs(vy)) <= STILL * box.h:
            return False  # standing: its box's share decides
        out_x = -vx if box.x < 0 else (vx if box.x2 > W else None)  # speed out through a cutting side
        out_y = -vy if box.y < 0 else (vy if box.y2 > H else None)
        outward = [o for o in (out_x, out_y) if o is not None]
        if not outward:
            return False
        along = [abs(vy) if out_x is not None else 0.0, abs(vx) if out_y is not None else 0.0]
        return all(o <= 0 or o < max(along) for o in outward)

    def _end_tracks(self, active: list[Person], mask, W: int, H: int, index: int = 0) -> None:
        p = self.params
        frame_box = Box(0, 0, W, H)
        for person in active:
            box = person.box()
            inside = _overlap_fraction(box, frame_box) if box.area > 0 else 0.0
            if inside < p.detection.leave_fraction and not self._kept_at_edge(person, box, inside, W, H):
                if person.lost_since is not None and p.detection.exit_margin > 0:
                    self.withdrawn.append((person.track_id, person.lost_since))  # coasted out: those rows too
                self._retire(person, index, W, H, walked=True)
                continue
            if mask is None or person.occluded_by is not None or person.hidden_parts:
                continue
            learning = self.frames_seen < p.background.warmup and mask is not self.moving_mask  # MOG2 warming up
            if not self.auto and (not p.detection.end_init_tracks or learning):
                continue
            if person.lost_since is not None:
                walked = self._walked_out(person, W, H, person.lost_since)
                if index - person.lost_since >= p.detection.lost_frames + p.detection.coast_frames or walked:
                    self.withdrawn.append((person.track_id, person.lost_since))
                    self._retire(person, index, W, H, walked)
                continue
            support = _support(mask, box)
            person.unsupported = person.unsupported + 1 if support < p.detection.support_min else 0
            if not person.unsupported and p.detection.exit_window > 0 and self._at_border(person, W, H):
                person.at_border = index
            if person.unsupported >= p.detection.lost_frames:
                if self._walked_out(person, W, H, index - p.detection.lost_frames + 1):
                    # left the frame: the rows written since its support went are on background
                    self.withdrawn.append((person.track_id, index - p.detection.lost_frames + 1))
                    self._retire(person, index, W, H, walked=True)
                    continue
                if person.revived is not None:
                    # re-identified: no motion of its own to coast on; it ends (dormant again) and waits
                    self.withdrawn.append((person.track_id, index - p.detection.lost_frames + 1))
                    self._retire(person, index, W, H, walked=False)
                    continue
                if p.detection.coast_frames <= 0 or self.auto:
                    # found automatically, a track without support ends at once (as before): the
                    # detection starts it again when the person shows; coasting there gave PETS
                    # more ghost and duplicate tracks (seed 1: 24 -> 29 tracks, MOTA 0.25 -> 0.06)
                    del self.people[person.track_id]
                    continue
                self._go_lost(person, index, mask)
        for q in list(self.people.values()):
            if q.occluded_by is not None and q.occluded_by not in self.people:
                q.occluded_by = None

    def _retire(self, person: Person, index: int, W: int, H: int, walked: bool) -> None:
        """The track ends; a given one (``--init``) stays dormant for re-identification
        (``detector.reid_hits``), with the border it walked out through."""
        del self.people[person.track_id]
        if self.auto or not person.first or self.params.detector.reid_hits <= 0:
            return
        border = _nearest_border(self._reported_person_box(person).clip(W, H), W, H) if walked else None
        self.dormant[person.track_id] = Dormant(person, index, border)

    def revive(self, track_id: int, det: Box, index: int) -> Person:
        """A dormant track re-identified on the detection ``det``: back with its id and the models
        of the boxes it was started from, every part placed in ``det`` as laid out when it started,
        standing still, nothing of its last coasting kept."""
        person = self.dormant.pop(track_id).person
        started = minimum_bounding_rectangle(self.report_box(n, f.box) for n, f in person.first.items())
        # the inner rectangles as they lay in the reported person box at the start
        layout = _layout({n: f.box for n, f in person.first.items()}, started)
        for name, f in person.filters.items():
            first = person.first[name]
            f.reference, f.surround, f.weighted = first.reference, first.surround, False
            f._refresh_map()
            f.steer(_placed(layout[name], det), 1.0)
            f.set_velocity(np.zeros(2))
        person.lost_since = person.coast_start = person.at_border = person.occluded_by = None
        person.unsupported = person.occluded_frames = 0
        person.hidden_parts, person.failed, person.touching = (), (), False
        person.centres.clear()
        person.history.clear()
        person.observed.clear()
        person.scores = {}
        person.revived = index
        self.people[track_id] = person
        self.revived.append((track_id, index))
        return person

    def _go_lost(self, person: Person, index: int, mask: np.ndarray) -> None:
        """From now on every part coasts on the person's recent velocity."""
        person.lost_since = index - self.params.detection.lost_frames + 1
        v = self._rewind(person, index) if self._rewinds(mask) else person.velocity()
        for f in person.filters.values():
            f.set_velocity(v if v is not None else np.zeros(2))

    def _rewinds(self, mask: np.ndarray | None) -> bool:
        """``background.camera_rewind`` applies: the support is the moving camera's scene motion."""
        return self.params.background.camera_rewind and mask is not None and mask is self.moving_mask

    def _note_travel(self, index: int) -> None:
        """Keeps the camera's travel up to frame ``index`` (:attr:`travel`, the last SHIFTS frames),
        for :meth:`scene_velocity`."""
        if self.camera is None:
            return
        if self.camera.moving:
            self._travelled = self._travelled + self.camera.shift
        self.travel[index] = self._travelled
        for k in [k for k in self.travel if k <= index - SHIFTS]:
            del self.travel[k]

    def scene_velocity(self, centres) -> np.ndarray | None:
        """Median per-frame motion in the scene of ``(frame, cx, cy)`` entries (:func:`median_velocity`
        of the centres less the camera's travel up to their frames, :attr:`travel`); None if fewer
        than three or a frame's travel is no longer known."""
        if len(centres) < 3 or any(int(f) not in self.travel for f, _, _ in centres):
            return None
        return median_velocity([(f, x - self.travel[int(f)][0], y - self.travel[int(f)][1]) for f, x, y in centres])

    def _rewind(self, person: Person, index: int) -> np.ndarray:
        """``background.camera_rewind``: a person that just went lost coasts on from where it was
        when its support went (frame ``lost_since``), at the velocity it had up to then (zero
        when too few frames tell), rather than from wherever the frames since took it (a still
        object of its colours). Moves every part there; returns the velocity."""
        before = [c for c in person.centres if c[0] < person.lost_since]
        v = median_velocity(before)
        v = np.zeros(2) if v is None else v
        if before:
            frame, cx, cy = before[-1]
            delta = np.array([cx, cy]) + v * (index - frame) - np.array(person.box().centre)
            for f in person.filters.values():
                f.shift(delta)
        return v

    def finish(self, records: list[TrackRecord]) -> list[TrackRecord]:
        """The records without those of tracks that went lost and never came back (written while
        they coasted, then withdrawn), including tracks still lost when the clip ends."""
        records = self._bridged(records)
        gone = list(self.withdrawn) + [(tid, q.lost_since) for tid, q in self.people.items()
                                       if q.lost_since is not None]
        if not gone:
            return records
        # a withdrawn stretch lasts until the track was re-identified (``detector.reid_hits``), if ever
        spans: dict[int, list[tuple[int, float]]] = {}
        for tid, first in gone:
            back = [f for t, f in self.revived if t == tid and f > first]
            spans.setdefault(tid, []).append((first, min(back, default=np.inf)))
        return [r for r in records
                if r.track_id not in spans or not any(a <= r.frame < b for a, b in spans[r.track_id])]

    def _bridged(self, records: list[TrackRecord]) -> list[TrackRecord]:
        """``occlusion.bridge``: the rows of each coasting stretch that ended with the person found
        again replaced by the straight line (centre and size, per part) from the boxes of the frame
        before the stretch to those of the frame it was found."""
        if not self.bridges:
            return records
        at = {(r.track_id, r.frame, r.part): i for i, r in enumerate(records)}
        out = list(records)
        for tid, first, found in self.bridges:
            before = first - 1
            for part in dict.fromkeys(("person", *self.parts)):
                i0, i1 = at.get((tid, before, part)), at.get((tid, found, part))
                if i0 is None or i1 is None:
                    continue
                a = np.array(out[i0].box.as_tuple())
                b = np.array(out[i1].box.as_tuple())
                for frame in range(first, found):
                    i = at.get((tid, frame, part))
                    if i is not None:
                        t = (frame - before) / (found - before)
                        out[i] = replace(out[i], box=Box(*((1 - t) * a + t * b).tolist()))
        return out

    def report_box(self, part: str, box: Box) -> Box:
        """The box written for a part: its tracked inner rectangle widened to the part's extent
        (``BodyParams.output.extent``), clipped to the frame."""
        sw, sh, dx, dy = self.params.output.extent.get(part, (1.0, 1.0, 0.0, 0.0))
        out = box.transformed(sw, sh, dx, dy)
        size = getattr(self, "frame_size", None)
        return out.clip(*size) if size else out

    def _records(self, index: int, new_ids: set[int]) -> list[TrackRecord]:
        out: list[TrackRecord] = []
        for tid in sorted(self.people):
            person = self.people[tid]
            if tid in new_ids:
                state = "init"
            elif person.lost_since is not None:
                state = "lost"
            elif person.occluded_by is not None:
                state = "occluded"
            elif person.adjusted:
                state = "adjusted"
            else:
                state = "tracked"
            scores = [person.scores.get(n, 1.0) for n in person.filters]
            boxes = {name: self.report_box(name, f.box) for name, f in person.filters.items()}
            drawn = person.given if tid in new_ids else {}  # on its first frame a given track is what was drawn
            boxes.update({name: b for name, b in drawn.items() if name in boxes})
            if not self.whole:
                mbr = minimum_bounding_rectangle(boxes.values())
                if not self.params.output.head_sets_sides and "head" in boxes:
                    body = minimum_bounding_rectangle(b for n, b in boxes.items() if n != "head")
                    mbr = Box(body.x, mbr.y, body.w, mbr.h)
                whole_box = drawn["person"] if "person" in drawn else self.report_person(mbr)
                out.append(TrackRecord(index, tid, "person", whole_box, float(np.mean(scores)),
                                       bool(person.failed), 1.0 if person.occluded_by is not None else 0.0,
                                       state))
            for name in person.filters:
                hidden = person.occluded_by is not None or name in person.hidden_parts or person.lost_since is not None
                part_state = "occluded" if hidden and state == "tracked" else state
                out.append(TrackRecord(index, tid, name, boxes[name], person.scores.get(name, 1.0),
                                       name in person.failed, 1.0 if hidden else 0.0, part_state))
        return out
