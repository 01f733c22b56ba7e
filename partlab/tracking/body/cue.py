"""Detection as a cue for the body tracker (not in Zhao & Lee; after Breitenstein et al. 2009).

Breitenstein et al. ("Robust tracking-by-detection using a detector confidence particle filter")
let a people detector decide where tracks start, end and re-appear, and keep a particle filter per
person in between. Here the colour part filters of Zhao & Lee stay as they are; every
``detector.every`` frames OpenCV's HOG people detector scans the foreground blobs and the tracks'
boxes (:mod:`partlab.tracking.core.people`, not the whole frame) and its detections

1. are assigned to tracks (Hungarian method on IoU): a matched detection re-sizes and moves the
   track's parts towards it (``steer``), because colour hardly constrains a box's size;
2. re-acquire lost tracks (no foreground support, behind an obstacle nobody listed) and tracks no
   detection has matched for a while, when near their prediction and alike in colour;
3. start tracks (automatic mode) once confirmed in several scans; blobs still start people the
   detector does not see;
4. re-identify tracks given by the user that ended (``--init``): a free detection where that
   person could be by now, matching its first models, in several scans running brings it back
   there with its id;
5. end duplicate tracks (one person tracked twice), and optionally tracks never detected.

All numbers come from ``BodyParams.detector``.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from partlab.tracking.body.decomposition import minimum_bounding_rectangle
from partlab.tracking.core.box import Box, iou_xywh
from partlab.tracking.core.lazy_ycc import as_array
from partlab.tracking.core.people import PeopleDetector, associate, associate_near


@dataclass
class Candidate:
    """An unexplained detection seen in recent scans: its latest box and the scans it was in."""

    box: Box
    hits: int
    last_scan: int
    track_id: int = 0  # re-identification: the dormant track it matches


def _blob_regions(mask: np.ndarray | None, min_height: float) -> list[Box]:
    if mask is None or not mask.any():
        return []
    n, _, stats, _ = cv2.connectedComponentsWithStats((mask > 0).astype(np.uint8), connectivity=8)
    return [Box(*(float(v) for v in stats[i, :4])) for i in range(1, n) if stats[i, 3] >= min_height]


def border_gaps(box: Box, W: int, H: int) -> dict[str, float]:
    """Pixels between ``box`` and each border of a ``W`` x ``H`` frame (left, right, top, bottom)."""
    return {"left": box.x, "right": W - box.x2, "top": box.y, "bottom": H - box.y2}


def _target(part: Box, person: Box, det: Box) -> Box:
    """Where ``part`` goes when ``person`` becomes ``det`` (scaled about the person's centre,
    moved with it)."""
    sx, sy = det.w / max(person.w, 1e-6), det.h / max(person.h, 1e-6)
    (pcx, pcy), (dcx, dcy), (cx, cy) = person.centre, det.centre, part.centre
    w, h = part.w * sx, part.h * sy
    return Box(dcx + (cx - pcx) * sx - w / 2, dcy + (cy - pcy) * sy - h / 2, w, h)


def _layout(parts: dict[str, Box], person: Box) -> dict[str, tuple]:
    """Each part box's centre offset from ``person``'s centre and its size, in the person box's
    width and height."""
    (pcx, pcy), pw, ph = person.centre, max(person.w, 1e-6), max(person.h, 1e-6)
    return {n: ((b.centre[0] - pcx) / pw, (b.centre[1] - pcy) / ph, b.w / pw, b.h / ph) for n, b in parts.items()}


def _placed(layout: tuple, det: Box) -> Box:
    """A part box at its place ``layout`` (centre offset and size relative to the person box) in ``det``."""
    rx, ry, rw, rh = layout
    w, h = rw * det.w, rh * det.h
    cx, cy = det.centre
    return Box(cx + rx * det.w - w / 2, cy + ry * det.h - h / 2, w, h)


def _within(box: Box, layout: Box, tolerance: float) -> Box:
    """``box`` with its width and height brought within ``tolerance`` times those of ``layout``
    (same centre)."""
    w = min(max(box.w, layout.w / tolerance), layout.w * tolerance)
    h = min(max(box.h, layout.h / tolerance), layout.h * tolerance)
    cx, cy = box.centre
    return Box(cx - w / 2, cy - h / 2, w, h)


def detection_velocity(prev, now, old, window: int) -> np.ndarray | None:
    """The per-frame motion a track's detections show: from ``prev`` to ``now`` (``(frame, cx,
    cy)``, at most ``window`` frames apart) averaged with the previous estimate ``old``; None when
    ``prev`` is missing or too far back (the estimate starts again)."""
    if prev is None or not 0 < now[0] - prev[0] <= window:
        return None
    v = np.array([now[1] - prev[1], now[2] - prev[2]]) / (now[0] - prev[0])
    return v if old is None else 0.5 * (v + old)


class DetectionCue:
    """The detector, the unconfirmed detections and, per track, the frame a detection last
    matched it."""

    def __init__(self, tracker):
        self.tracker = tracker
        self.p = tracker.params.detector
        self.detector = PeopleDetector(self.p.scan())
        self.candidates: list[Candidate] = []
        self.last_match: dict[int, int] = {}
        self.last_seen: dict[int, tuple[int, float, float]] = {}  # track id -> (frame, centre) of its last detection
        self.velocity: dict[int, np.ndarray] = {}  # track id -> per-frame motion between its detections
        self.scans = 0
        self.detections = np.zeros((0, 5))
        self.reid_candidates: list[Candidate] = []  # free detections matching a dormant track, scans running
        self.by_identity: set[int] = set()  # duplicates the first models sent lost at the last scan

    def step(self, index: int, frame: np.ndarray, ycc, mask: np.ndarray | None,
             scan: np.ndarray | None = None) -> None:
        """One frame: scan (every ``every`` frames), then assign, re-acquire, start and end.
        ``scan``: where things move when there is no foreground ``mask`` (a moving camera's
        :meth:`~partlab.tracking.core.camera_motion.CameraMotion.moving_mask`): its regions are
        scanned too, so people are found while the camera pans."""
        t = self.tracker
        for tid, person in t.people.items():
            self.last_match.setdefault(tid, person.started)
        if index % self.p.every:  # by the frame's index: a run started elsewhere (a chunk) scans the same frames
            return
        self.scans += 1
        people = [t.people[k] for k in sorted(t.people)]
        boxes = [t._reported_person_box(q) for q in people]
        regions = _blob_regions(mask if mask is not None else scan, self.p.min_region_height) + boxes
        dets = self.detector.detect(frame, regions)
        self.detections = dets
        track_boxes = np.array([b.as_tuple() for b in boxes]).reshape(-1, 4)
        pairs = self._associate(people, track_boxes, dets, self._affinity(people, boxes, dets, ycc))
        used = set()
        contested = self._contested(track_boxes, dets, pairs)
        for i, j in pairs:
            det = Box(*dets[j, :4])
            self._seen(people[i].track_id, index, det)
            if (i, j) in contested:
                pass  # another track overlaps the detection about as much: steering could swap them
            elif self.p.steer_coasting > 0 and (people[i].occluded_by is not None or people[i].lost_since is not None):
                self._steer_coasting(people[i], boxes[i], det)
            elif det.iou(boxes[i]) < self.p.steer_below:
                self._steer(people[i], boxes[i], det, self.p.steer)
                self._steer_motion(people[i])
            self.last_match[people[i].track_id] = index
            if people[i].lost_since is not None:
                people[i].lost_since = None
                people[i].unsupported = 0
            used.add(j)
        matched = {i for i, _ in pairs}
        free = [j for j in range(len(dets)) if j not in used]
        held = {j: people[i] for i, j in pairs}
        free = self._reacquire(index, [q for i, q in enumerate(people) if i not in matched], dets, free, ycc, held)
        if t.auto:
            self._confirm(index, dets, free, ycc, mask)
        else:
            free = self._reidentify(index, dets, free, ycc)
        self._end(index, ycc)

    def _associate(self, people: list, tracks: np.ndarray, dets: np.ndarray,
                   affinity: np.ndarray | None) -> list[tuple[int, int]]:
        """Tracks to detections (Hungarian on IoU, gated by ``affinity``); with ``lost_yields``,
        the others first, then the tracks yielding (lost on another's person) among the detections
        left that none of the others overlaps at ``match_iou``."""
        p = self.p
        lost = np.array([q.yielding for q in people], dtype=bool)
        if not p.lost_yields or not lost.any() or lost.all() or not len(dets):
            return associate(tracks, dets, p.match_iou, affinity, p.match_similarity, p.similarity_weight)

        def subset(rows: np.ndarray, cols: np.ndarray) -> list[tuple[int, int]]:
            a = None if affinity is None else affinity[np.ix_(rows, cols)]
            found = associate(tracks[rows], dets[cols], p.match_iou, a, p.match_similarity, p.similarity_weight)
            return [(int(rows[i]), int(cols[j])) for i, j in found]

        live = np.flatnonzero(~lost)
        pairs = subset(live, np.arange(len(dets)))
        claimed = (iou_xywh(tracks[live], dets[:, :4]) >= p.match_iou).any(axis=0)
        left = np.array([j for j in range(len(dets)) if not claimed[j]], dtype=int)
        if len(left):
            pairs += subset(np.flatnonzero(lost), left)
        return pairs

    def _contested(self, tracks: np.ndarray, dets: np.ndarray, pairs: list[tuple[int, int]]) -> set[tuple[int, int]]:
        """``swap_guard``: the pairs whose detection overlaps another track at least ``swap_guard``
        times as much as its own track (and at least ``match_iou``)."""
        g = self.p.swap_guard
        if g <= 0 or len(tracks) < 2 or not pairs:
            return set()
        iou = iou_xywh(tracks, dets[:, :4])
        out = set()
        for i, j in pairs:
            others = np.delete(iou[:, j], i)
            if others.max() >= max(g * iou[i, j], self.p.match_iou):
                out.add((i, j))
        return out

    def _affinity(self, people: list, boxes: list[Box], dets: np.ndarray, ycc) -> np.ndarray | None:
        """``(tracks, detections)`` Bhattacharyya coefficient of each track's torso model (or only
        part's) at the place the detection puts the torso; NaN where the boxes overlap below
        ``match_iou`` (never paired anyway). None when appearance does not gate association."""
        if self.p.match_similarity <= 0 and self.p.similarity_weight <= 0:
            return None
        out = np.full((len(people), len(dets)), np.nan)
        if not len(people) or not len(dets):
            return out
        iou = iou_xywh(np.array([b.as_tuple() for b in boxes]).reshape(-1, 4), dets[:, :4])
        arr = None
        for i, person in enumerate(people):
            near = np.flatnonzero(iou[i] >= self.p.match_iou)
            if not len(near):
                continue
            arr = as_array(ycc) if arr is None else arr
            f = person.filters["torso" if "torso" in person.filters else next(iter(person.filters))]
            states = np.array([[*t.centre, t.w, t.h, 0.0, 0.0] for t in
                               (_target(f.box, boxes[i], Box(*dets[j, :4])) for j in near)], dtype=np.float32)
            out[i, near] = f.similarities(arr, states)
        return out

    def _seen(self, track_id: int, index: int, det: Box) -> None:
        """Remember where a detection saw the track and how fast it moved since the one before
        (within ``velocity_frames``; averaged with the previous estimate)."""
        now = (index, *det.centre)
        v = detection_velocity(self.last_seen.get(track_id), now, self.velocity.get(track_id), self.p.velocity_frames)
        if v is None:
            self.velocity.pop(track_id, None)
        else:
            self.velocity[track_id] = v
        self.last_seen[track_id] = now

    def _steer_motion(self, person) -> None:
        """``steer_velocity`` (``steer_velocity_auto`` in automatic runs): every part's velocity goes
        that share of the way to the motion its detections show."""
        v = self.velocity.get(person.track_id)
        gain = self.p.steer_velocity_auto if self.tracker.auto else self.p.steer_velocity
        if gain <= 0 or v is None:
            return
        for f in person.filters.values():
            f.nudge_velocity(v, gain)

    def _steer_coasting(self, person, reported: Box, det: Box) -> None:
        """A track coasting on its dynamics (behind someone, or lost) that a detection sees (its
        colour gating passed) goes ``steer_coasting`` of the way there and coasts on with the
        motion its detections show: people in groups stop and turn, which the velocity it had
        before the occlusion cannot foresee."""
        self._steer(person, reported, det, self.p.steer_coasting)
        v = self.velocity.get(person.track_id)
        for f in person.filters.values():
            f.set_velocity(v if v is not None else np.zeros(2))

    def _steer(self, person, reported: Box, det: Box, gain: float) -> None:
        if gain <= 0:
            return
        # the reported boxes are the tracked inner rectangles widened (output.extent, scales and
        # shifts relative to the part): mapping the reported person box onto the detection maps
        # each part's inner rectangle with it
        torso = person.filters.get("torso")
        follows = not self.p.steer_head and torso is not None and "head" in person.filters
        before = torso.state[0:2].copy() if torso is not None else None
        steered = [n for n in person.filters if n != "head" or not follows]
        if len(steered) < len(person.filters):
            # across, the detection maps the parts it steers (a head wider than the body, the
            # decomposition's strip, would otherwise narrow the torso at every scan: the person
            # box never narrows while the head is not steered); down, the whole person
            across = minimum_bounding_rectangle(self.tracker.report_box(n, person.filters[n].box) for n in steered)
            reported = Box(across.x, reported.y, across.w, reported.h)
        tolerance = self.p.layout_tolerance
        if tolerance > 0 and not person.layout:  # the first detection of the track: its layout now
            person.layout = _layout({n: person.filters[n].box for n in steered}, reported)
        for name in steered:
            f = person.filters[name]
            target = _target(f.box, reported, det)
            if tolerance > 0 and name in person.layout:
                target = _within(target, _placed(person.layout[name], det), tolerance)
            f.steer(target, gain)
        if follows:  # the head moves with the torso's correction, keeping its size and place on it
            person.filters["head"].shift(torso.state[0:2] - before)

    def _reacquire(self, index: int, unmatched: list, dets: np.ndarray, free: list[int], ycc,
                   held: dict | None = None) -> list[int]:
        """Lost tracks, and tracks unmatched for ``reacquire_after`` frames, jump to a free detection
        near their prediction whose torso region matches the torso's model, standing (and learning
        its velocity again, ``dynamics.relearn_velocity``); with ``reacquire_claims``, also to one a
        track holds (``held``: detection index -> track) whose first models match it worse by
        ``duplicate_margin`` (that track goes lost). The free rest."""
        t, p = self.tracker, self.p
        held = dict(held or {}) if p.reacquire_claims and p.duplicate_margin > 0 else {}
        left = self._left_to_others(index, unmatched, dets) if p.reacquire_owner else {}
        for person in unmatched:
            if not free and not held:
                break
            if not self._due(index, person):
                continue
            tid = person.track_id
            reported = t._reported_person_box(person)
            cx, cy = reported.centre
            heading = self._heading(person, reported)
            best, best_rho = None, p.reacquire_similarity
            f = person.filters["torso" if "torso" in person.filters else next(iter(person.filters))]
            for j in [*free, *(held if person.first else ())]:
                det = Box(*dets[j, :4])
                dx, dy = det.centre[0] - cx, det.centre[1] - cy
                if np.hypot(dx, dy) > p.reacquire_distance * det.h:
                    continue
                if (heading is not None and self._on_its_path(heading, dx, dy, det)) or j in left.get(tid, ()):
                    # behind a walker its track was measured on (the one following it), or left to a
                    # track placed on its walker earlier (``reacquire_owner``)
                    continue
                holder = held.get(j)
                if any(det.iou(t._reported_person_box(q)) >= p.match_iou for q in t.people.values()
                       if q is not person and q is not holder):
                    continue  # someone else's
                if holder is not None and self._claims(person, holder, det, ycc) is not person:
                    continue  # the holder's as much as ours
                target = _target(f.box, reported, det)
                state = np.array([[*target.centre, target.w, target.h, 0.0, 0.0]], dtype=np.float32)
                rho = float(f.similarities(as_array(ycc), state)[0])
                if rho >= best_rho:
                    best, best_rho = j, rho
            if best is None:
                continue
            holder = held.pop(best, None)
            if holder is not None:  # it was on someone else's person: it coasts, lost, and yields
                if holder.lost_since is None:
                    holder.lost_since = holder.yields_from = index
            self._stand(person, index)
            self._steer(person, reported, Box(*dets[best, :4]), 1.0)
            person.lost_since = None
            person.unsupported = 0
            person.occluded_by = None
            self.last_match[person.track_id] = index
            free = [j for j in free if j != best]
        return free

    def _stand(self, person, index: int) -> None:
        """A re-acquired track stands where it jumps: it learns its walker's speed again as a new
        track (``dynamics.relearn_velocity``) and, with ``reacquire_forgets``, forgets the clean
        centres of the walker it left (its motion there is not its walker's)."""
        for g in person.filters.values():
            g.set_velocity(np.zeros(2))
        if self.tracker.params.dynamics.relearn_velocity:
            person.learns_from = index
            person.steps.clear()
        if self.p.reacquire_forgets:
            person.centres.clear()

    def _due(self, index: int, person) -> bool:
        """Lost, or unmatched for ``reacquire_after`` frames: re-acquired by a detection near it."""
        return (person.lost_since is not None
                or index - self.last_match.get(person.track_id, index) >= self.p.reacquire_after)

    @staticmethod
    def _placed(person) -> tuple[int, int]:
        """``reacquire_owner``: the last frame a track was placed on its walker: its start from given
        boxes, or its last measurement clear of every other track (``Person.seen``); a given box
        ranks before a measurement of the same frame (what was drawn is the person, a measurement
        may already sit on a neighbour)."""
        given = (person.started, 1) if person.given else (-1, 1)
        seen = (person.seen[0], 0) if person.seen is not None else (-1, 0)
        return max(given, seen)

    def _left_to_others(self, index: int, unmatched: list, dets: np.ndarray) -> dict[int, set[int]]:
        """``reacquire_owner``: track id -> the detections it leaves to a track it touches (two tracks
        on one walker, both unmatched and due) that was placed on that walker earlier
        (:meth:`_placed`), within that track's ``reacquire_distance``. The one placed later stays:
        the other came onto the shared walker from elsewhere, and a detection near the pair is
        more likely that other walker's."""
        t, p = self.tracker, self.p
        due = [q for q in unmatched if self._due(index, q) and q.lost_since is None and q.occluded_by is None]
        out: dict[int, set[int]] = {}
        for a in due:
            for b in due:
                if a is b or self._placed(b) >= self._placed(a):
                    continue
                if not t._touching(a.part_boxes(), b.part_boxes())[0]:
                    continue
                cx, cy = t._reported_person_box(b).centre
                near = {j for j in range(len(dets))
                        if np.hypot(dets[j, 0] + dets[j, 2] / 2 - cx, dets[j, 1] + dets[j, 3] / 2 - cy)
                        <= p.reacquire_distance * dets[j, 3]}
                out.setdefault(a.track_id, set()).update(near)
        return out

    def _heading(self, person, reported: Box) -> np.ndarray | None:
        """``reacquire_against``: the velocity of a track measured up to now on its walker alone (not
        lost, not behind someone, no coasting stretch open, touching nobody, its torso matching its
        model at least ``occlusion.release_similarity``, a clear match) that moves more than ``STILL``
        of its height a frame; None for the others (re-acquired anywhere near)."""
        from partlab.tracking.body.tracker import STILL, _motion

        if self.p.reacquire_against <= 0 or person.lost_since is not None or person.occluded_by is not None:
            return None
        if person.coast_start is not None or person.touching:
            return None  # coasting, or sharing its walker with another track: either may be the wrong one
        anchor = "torso" if "torso" in person.filters else next(iter(person.filters))
        if person.scores.get(anchor, 0.0) < self.tracker.params.occlusion.release_similarity:
            return None
        v = np.array(_motion(person))
        if float(np.hypot(*v)) <= STILL * reported.h:
            return None
        return v

    def _on_its_path(self, velocity: np.ndarray, dx: float, dy: float, det: Box) -> bool:
        """``reacquire_against``: a detection ``(dx, dy)`` from the track's centre lies behind it,
        against its ``velocity``, by more than ``reacquire_against`` of its width, and no further
        than the track walked in the last ``reacquire_after`` frames: on the path its walker took
        while the track went on measuring them, where the walker following them is now."""
        speed = float(np.hypot(*velocity))
        back = -(dx * velocity[0] + dy * velocity[1]) / speed
        return self.p.reacquire_against * det.w < back <= self.p.reacquire_after * speed

    def _reidentify(self, index: int, dets: np.ndarray, free: list[int], ycc) -> list[int]:
        """``reid_hits``: a free detection no tracked person covers, where a dormant track's person
        could be by now (:meth:`_plausible`), whose torso and hip-leg regions match that track's
        models (those of the boxes it was started from) at least ``reid_similarity`` and better by
        ``reid_margin`` than every other such dormant track's, seen so in ``reid_hits`` scans
        running, re-activates that track there with its id; a track that walked out is only looked
        for within ``reid_border`` detection heights of the border it left through. The free rest."""
        t, p = self.tracker, self.p
        if p.reid_hits <= 0 or not t.dormant or not free:
            self.reid_candidates = [] if not t.dormant else self.reid_candidates
            return free
        arr = as_array(ycc)
        W, H = t.frame_size
        matches = []
        for j in free:
            det = Box(*dets[j, :4])
            if not self._clear(det):
                continue
            sims = {tid: self._first_similarity(d.person, det, arr) for tid, d in t.dormant.items()
                    if self._plausible(d, det, index)}
            if not sims:
                continue
            best = max(sims, key=sims.get)
            if sims[best] < p.reid_similarity:
                continue
            rivals = [v for k, v in sims.items() if k != best]
            if rivals and sims[best] - max(rivals) < p.reid_margin:
                continue
            matches.append((j, det, best))
        kept = []
        for j, det, tid in matches:
            if tid not in t.dormant:
                continue  # revived at another detection of this scan
            before = [c for c in self.reid_candidates if c.track_id == tid and c.last_scan == self.scans - 1]
            near = associate_near(np.array([c.box.as_tuple() for c in before]).reshape(-1, 4),
                                  np.array([det.as_tuple()]), self.p.confirm_distance)
            if near:
                c = before[near[0][0]]
                c.box, c.hits, c.last_scan = det, c.hits + 1, self.scans
            else:
                border = t.dormant[tid].border
                if border is not None and border_gaps(det, W, H)[border] > p.reid_border * det.h:
                    continue  # it walked out elsewhere
                c = Candidate(det, 1, self.scans, tid)
            if c.hits >= p.reid_hits and tid in t.dormant:
                t.revive(tid, det.clip(W, H), index)
                self.last_match[tid] = index
                self.last_seen.pop(tid, None)
                self.velocity.pop(tid, None)
                free = [k for k in free if k != j]
                continue
            kept.append(c)
        self.reid_candidates = [c for c in kept if c.track_id in t.dormant]
        return free

    def _first_similarity(self, person, det: Box, arr: np.ndarray) -> float:
        """Mean similarity of the torso and hip-leg models a track was started with (its only part's
        in whole-body mode) to the regions ``det`` puts those parts in, laid out as at its start."""
        first = person.first
        started = minimum_bounding_rectangle(self.tracker.report_box(n, f.box) for n, f in first.items())
        layout = _layout({n: f.box for n, f in first.items()}, started)
        names = [n for n in ("torso", "hipleg") if n in first] or list(first)
        rho = []
        for n in names:
            b = _placed(layout[n], det)
            rho.append(float(first[n].similarities(arr, np.array([[*b.centre, b.w, b.h, 0.0, 0.0]],
                                                                  dtype=np.float32))[0]))
        return float(np.mean(rho))

    def _plausible(self, dormant, det: Box, index: int) -> bool:
        """The ended track's person could be at ``det`` now: its height within ``reid_size`` times
        that of the track's last box, its centre within ``reid_distance`` + ``reid_speed`` x (frames
        since) detection heights of where the track was last measured clear of everyone and not
        lost (where it ended, if never)."""
        p, person = self.p, dormant.person
        last = self.tracker._reported_person_box(person)
        if not 1 / p.reid_size <= det.h / max(last.h, 1e-6) <= p.reid_size:
            return False
        frame, cx, cy = person.seen if person.seen is not None else (dormant.ended, *last.centre)
        reach = (p.reid_distance + p.reid_speed * (index - frame)) * det.h
        return bool(np.hypot(det.centre[0] - cx, det.centre[1] - cy) <= reach)

    def _confirm(self, index: int, dets: np.ndarray, free: list[int], ycc, mask) -> None:
        """Free detections matched to candidates of earlier scans; confirmed ones start tracks."""
        t, p = self.tracker, self.p
        self.candidates = [c for c in self.candidates if self.scans - c.last_scan < p.confirm_window]
        boxes = dets[free, :4] if free else np.zeros((0, 4))
        prev = np.array([c.box.as_tuple() for c in self.candidates]).reshape(-1, 4)
        pairs = dict((d, c) for c, d in associate_near(prev, boxes, p.confirm_distance))
        fresh = []
        for k, j in enumerate(free):
            det = Box(*dets[j, :4])
            if k in pairs:
                c = self.candidates[pairs[k]]
                c.box, c.hits, c.last_scan = det, c.hits + 1, self.scans
            else:
                c = Candidate(det, 1, self.scans)
                fresh.append(c)
            if c.hits >= p.confirm_hits and self._clear(det):
                W, H = t.frame_size
                box = det.clip(W, H)
                if box.w >= 4 and box.h >= 8:
                    t.start_track(t.next_id, {"person": box}, ycc, mask, index, from_mask=True)
                    self.last_match[t.next_id] = index
                    t.next_id += 1
                c.hits = -10 ** 6  # started (or refused): never again from this candidate
        self.candidates = [c for c in self.candidates + fresh if c.hits > 0]

    def _clear(self, det: Box) -> bool:
        """No tracked person covers the detection (IoU below match_iou, nor a third of it)."""
        t = self.tracker
        for q in t.people.values():
            b = t._reported_person_box(q)
            if det.iou(b) >= self.p.match_iou or det.intersection(b) > det.area / 3:
                return False
        return True

    def _end(self, index: int, ycc=None) -> None:
        """Duplicates end (the one whose first models match their shared region worse, or else
        the one matched less recently, then the younger); automatic tracks no detection has
        matched for ``undetected_frames`` frames end."""
        t, p = self.tracker, self.p
        ids = sorted(t.people)
        if p.duplicate_iou < 1 and len(ids) > 1:
            boxes = np.array([minimum_bounding_rectangle(f.box for f in t.people[k].filters.values()).as_tuple()
                              for k in ids])
            for k in self._duplicates(ids, iou_xywh(boxes, boxes), ycc):
                if t.auto:
                    self._drop(k)
                elif t.people[k].lost_since is None:  # a given person is not dropped: it coasts, lost
                    t.people[k].lost_since = index
                    if k in self.by_identity:
                        t.people[k].yields_from = index
        if t.auto and p.undetected_frames > 0:
            for k in sorted(t.people):
                if index - self.last_match.get(k, index) >= p.undetected_frames:
                    self._drop(k)

    def _duplicates(self, ids: list[int], iou: np.ndarray, ycc=None) -> set[int]:
        """Of each pair of tracks overlapping at ``duplicate_iou`` or more (neither behind the
        other), the one whose first models match the region they share worse by ``duplicate_margin``
        (:meth:`_whose`), else the one a detection matched less recently, then the younger."""
        t, gone = self.tracker, set()
        self.by_identity = set()  # the ones the first models decided
        for a in range(len(ids)):
            for b in range(a + 1, len(ids)):
                ka, kb = ids[a], ids[b]
                if iou[a, b] < self.p.duplicate_iou or ka in gone or kb in gone:
                    continue
                if t.people[ka].occluded_by is not None or t.people[kb].occluded_by is not None:
                    continue
                owner = self._whose(t.people[ka], t.people[kb], ycc)
                if owner is not None:
                    loser = kb if owner is t.people[ka] else ka
                    gone.add(loser)
                    self.by_identity.add(loser)
                    continue
                rank_a, rank_b = (self.last_match.get(ka, -1), -ka), (self.last_match.get(kb, -1), -kb)
                gone.add(ka if rank_a < rank_b else kb)
        return gone

    def _claims(self, a, b, det: Box, ycc):
        """Of tracks ``a`` and ``b`` (both with first models), the one whose first models match the
        detection ``det`` better by ``duplicate_margin``, or None."""
        if not a.first or not b.first:
            return None
        arr = as_array(ycc)
        sa, sb = self._first_similarity(a, det, arr), self._first_similarity(b, det, arr)
        if abs(sa - sb) < self.p.duplicate_margin:
            return None
        return a if sa > sb else b

    def _whose(self, a, b, ycc):
        """``duplicate_margin``: of two tracks on one person, the one whose first models (the boxes
        it was given) match the region the two share (their mean person box) better by the margin;
        None when neither does, or a track has no first models (found automatically)."""
        if self.p.duplicate_margin <= 0 or ycc is None or not a.first or not b.first:
            return None
        t = self.tracker
        ra, rb = t._reported_person_box(a), t._reported_person_box(b)
        shared = Box((ra.x + rb.x) / 2, (ra.y + rb.y) / 2, (ra.w + rb.w) / 2, (ra.h + rb.h) / 2)
        return self._claims(a, b, shared, ycc)

    def _drop(self, track_id: int) -> None:
        t = self.tracker
        person = t.people.pop(track_id)
        if person.lost_since is not None:
            t.withdrawn.append((track_id, person.lost_since))
        for q in t.people.values():
            if q.occluded_by == track_id:
                q.occluded_by = None
