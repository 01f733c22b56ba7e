"""The per-frame loop of ``--tracker limbs-depth`` (Xu, Deng & Jia), top to bottom as the paper:

1. sec. 3: the face's hue particle filter (state ``(x, y, alpha)``), its mean refined by mean
   shift on the back-projection weighted by the depth foreground, the samples redistributed; the
   face re-acquired by a face detector when its best confidence stays low;
2. sec. 2 and Table 1 step 1: the face's depth gives the depth foreground and the threshold of
   the hand candidate regions (Table 1 steps 2-4, :mod:`.regions`);
3. sec. 4: each hand's filter mixes standard samples (``1 - q``) with samples drawn from eq. 3's
   importance function around its candidate region (``q``), weighted ``f / g``
   (:mod:`.sampling`); the hands' reference is the face's colour; a hand starts (or restarts
   after it is lost) from importance samples alone, and counts as initialised when their mean
   confidence passes the success test;
4. sec. 5: the 3D posture (:mod:`.posture`), written as ``X, Y, Z`` on the head and hand rows and
   as ``torso``, ``left/right_shoulder`` and ``left/right_elbow`` rows.

One person, facing the camera, in the first stream of the take (colour + depth; without a
calibration the camera is taken as a pinhole with focal length = the image width, centred).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import cv2
import numpy as np
import pandas as pd

from partlab.tracking.camera import Camera
from partlab.tracking.core.box import Box
from partlab.tracking.core.hue_histogram import (
    back_projection,
    box_histograms,
    hue_bin_image,
    hue_confidence,
    integral_histogram,
    reference_histogram,
)
from partlab.tracking.depth.filter import HueFilter
from partlab.tracking.depth.params import DepthParams
from partlab.tracking.depth.posture import ArmFit, head_width, recover
from partlab.tracking.depth.regions import HandRegion, depth_foreground, face_depth, hand_regions, support_surfaces
from partlab.tracking.depth.sampling import draw_importance, icondensation_correction
from partlab.tracking.frame import FrameSet
from partlab.tracking.tracks import TrackRecord, empty_tracks, records_to_frame

HANDS = ("left_hand", "right_hand")
FaceDetector = Callable[[np.ndarray], Sequence[tuple[int, int, int, int]]]


def haar_faces(params) -> FaceDetector:
    """OpenCV's frontal-face Haar cascade (shipped with opencv-python in ``cv2.data``)."""
    cascade = cv2.CascadeClassifier(cv2.data.haarcascades + "haarcascade_frontalface_default.xml")

    def detect(bgr: np.ndarray):
        grey = cv2.equalizeHist(cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY))
        found = cascade.detectMultiScale(grey, scaleFactor=params.scale_factor, minNeighbors=params.min_neighbors,
                                         minSize=(params.min_face, params.min_face))
        return [tuple(int(v) for v in f) for f in found]

    return detect


def _in_frame(box, size) -> tuple[float, float, float, float] | None:
    """A window ``x, y, w, h`` clipped to the image (the filter's state may reach past its edge
    when a hand leaves the field of view); None when nothing of it is inside."""
    x, y, w, h = box
    x1, y1 = max(x, 0.0), max(y, 0.0)
    x2, y2 = min(x + w, float(size[0])), min(y + h, float(size[1]))
    return (x1, y1, x2 - x1, y2 - y1) if x2 > x1 and y2 > y1 else None


def hand_reference(bins: np.ndarray, skin_box, hue_bins: int, fill: float) -> np.ndarray | None:
    """``(hue_bins + 1,)`` the hands' reference (sec. 4: the face's colour): the hue histogram of
    ``skin_box`` (grey pixels in the last, *other* bin) times ``fill``, plus ``1 - fill`` in the
    other bin, the share of a hand's window that is not hand (``Appearance.hand_fill``)."""
    face = reference_histogram(np.where(bins >= 0, bins, hue_bins), skin_box, hue_bins + 1)
    if face is None:
        return None
    other = np.zeros(hue_bins + 1)
    other[hue_bins] = 1.0
    return fill * face + (1.0 - fill) * other


def default_camera(width: int, height: int) -> Camera:
    return Camera("cam0", [[width, 0, width / 2], [0, width, height / 2], [0, 0, 1]], (width, height))


@dataclass
class _Hand:
    name: str
    size: np.ndarray  # reference (w, h)
    filter: HueFilter | None = None
    initialised: bool = False
    low: int = 0  # consecutive frames under the lost threshold
    start: tuple[float, float] | None = None  # the init box's centre, when given
    region: HandRegion | None = None


@dataclass
class _Stats:
    """What the benchmark reads: how often each hand had a region and how its samples split."""

    frames: int = 0
    regions: dict = field(default_factory=lambda: {h: 0 for h in HANDS})
    reacquired: int = 0


class DepthTracker:
    """Face and both hands of one person with depth (see the module docstring)."""

    def __init__(self, params: DepthParams, rng: np.random.Generator, init: pd.DataFrame | None = None,
                 face_detector: FaceDetector | None = None):
        self.params = params
        self.rng = rng
        self.detector = face_detector
        self.track_id = 1
        self.start_frame = 0
        self.face: HueFilter | None = None
        self.face_size: np.ndarray | None = None
        self.face_low = 0
        self._init_boxes: dict[str, tuple] = {}
        if init is not None and len(init):
            heads = init[init["part"] == "head"]
            if len(heads):
                first = heads.sort_values("frame").iloc[0]
                self.track_id, self.start_frame = int(first["track_id"]), int(first["frame"])
                rows = init[(init["track_id"] == self.track_id) & (init["frame"] == self.start_frame)]
                self._init_boxes = {r.part: (float(r.x), float(r.y), float(r.w), float(r.h)) for r in rows.itertuples()}
        self.hands = {h: _Hand(h, np.zeros(2)) for h in HANDS}
        self.arms = ArmFit(params.posture)  # the person's arm lengths, fitted over the clip (sec. 5)
        self.stats = _Stats()
        self.events = None

    # -- sec. 3: the face ------------------------------------------------------------------------
    def _start_face(self, box, bins) -> bool:
        ref = reference_histogram(bins, box, self.params.appearance.hue_bins)
        if ref is None:
            return False
        x, y, w, h = box
        self.face_size = np.array([w, h], float)
        rng = self.rng
        if self.face is None:
            self.face = HueFilter((x + w / 2, y + h / 2), (w, h), ref, self.params.dynamics.particles, rng,
                                  self.params.dynamics.alpha_range)
        else:
            self.face.reset((x + w / 2, y + h / 2), (w, h), ref)
        self.face_low = 0
        self.head_mm = None  # measured on the next frame with depth under the new box
        return True

    def _detect_face(self, color: np.ndarray):
        if self.detector is None:
            self.detector = haar_faces(self.params.reacquisition)
        found = list(self.detector(color))
        if not found:
            return None
        if self.face is not None:  # the detection nearest to where the face was
            c = self.face.estimate[:2]
            found.sort(key=lambda b: (b[0] + b[2] / 2 - c[0]) ** 2 + (b[1] + b[3] / 2 - c[1]) ** 2)
        else:
            found.sort(key=lambda b: -b[2] * b[3])
        return found[0]

    def _track_face(self, bins, integral, weight_prev) -> None:
        p, d = self.params, self.params.dynamics
        f = self.face
        f.propagate(d.velocity_decay, d.face_noise * f.size[0], d.alpha_noise)
        f.weigh(integral, p.appearance.lam)
        f.estimate_mean()
        if p.refinement.mean_shift:
            f.refine(back_projection(bins, f.ref, weight_prev), p.refinement.iterations, p.refinement.eps)
        f.resample()

    # -- sec. 4: the hands -----------------------------------------------------------------------
    def _hand_reference(self, bins) -> np.ndarray | None:
        """The hands' reference: the hue of the face box's inner part (sec. 4), over the hue bins
        plus the *other* bin (:meth:`_hand_bins`; grey pixels of the face count there)."""
        x, y, w, h = self.face.box()
        iw, ih = self.params.appearance.face_inner
        inner = (x + w * (1 - iw) / 2, y + h * (1 - ih), w * iw, h * ih)  # lower middle: skin, no hair
        return hand_reference(bins, inner, self.params.appearance.hue_bins, self.params.appearance.hand_fill)

    def _hand_bins(self, bins, depth, fd, surfaces, face_box=None) -> np.ndarray:
        """The hands' bin image: hue bins, and one *other* bin (index ``hue_bins``) for pixels with
        no hue and, with depth, for pixels measured not in front of the face's plane (sec. 4
        constraint 1) or on a support surface (:func:`~.regions.support_surfaces`).

        Leaving such pixels out of the histogram (as eq. 1-2 do for grey pixels) makes every window
        that holds the hand score alike, however large: the scale alpha then drifts freely and the
        box outgrows the hand (Zhao & Lee's box rule fails with the centre on the hand). Counted in a
        bin the reference (the face's skin) hardly has, they lower the confidence of a window by the
        share of it that is not hand, as background of another hue does in colour alone.

        Unmeasured depth (NaN) is no evidence either way: the pixel's colour decides, as without
        depth (counted as *not in front*, a hand in the band along a stereo pair's left edge that
        the right camera does not see vanished there), except inside the face's box, where
        unmeasured skin is the face's (a hand there slid onto the face's unmatched pixels)."""
        nb = self.params.appearance.hue_bins
        keep = bins >= 0
        if fd is not None and self.params.depth.depth_foreground:
            with np.errstate(invalid="ignore"):
                keep &= ~(depth >= fd.mean - self.params.depth.hand_gap * fd.width_mm)  # NaN stays
            if surfaces is not None:
                keep &= ~surfaces
            if face_box is not None:
                x, y, w, h = (int(round(v)) for v in face_box)
                ys, xs = slice(max(y, 0), max(y + h, 0)), slice(max(x, 0), max(x + w, 0))
                keep[ys, xs] &= np.isfinite(depth[ys, xs])
        return np.where(keep, bins, nb).astype(bins.dtype)

    def _assign(self, regions: list[HandRegion]) -> None:
        """Give each hand the candidate region nearest its prediction (both hands jointly; the
        paper's two regions, one per hand); an uninitialised hand takes the region on its side."""
        for h in self.hands.values():
            h.region = None
        if not regions:
            return
        fc = self.face.estimate[:2]
        gate = self.params.depth.gate
        decay = self.params.dynamics.velocity_decay

        def where(h: _Hand):
            if h.initialised:
                return h.filter.predicted(decay)[:, :2].mean(axis=0)
            return None

        L, R = self.hands["left_hand"], self.hands["right_hand"]
        best, best_cost = None, np.inf
        options = [(a, b) for a in [None, *range(len(regions))] for b in [None, *range(len(regions))]
                   if a is None or b is None or a != b]
        for a, b in options:
            cost, ok = 0.0, True
            for h, k in ((L, a), (R, b)):
                if k is None:
                    cost += gate  # leaving a hand without a region costs the gate
                    continue
                reg = regions[k]
                pred = where(h)
                if pred is None:  # by side: the person's left hand is on the image's right
                    side_ok = (reg.xc >= fc[0]) == (h.name == "left_hand")
                    cost += 0.0 if side_ok else gate * 2
                    continue
                dist = np.hypot(reg.xc - pred[0], reg.yc - pred[1]) / max(h.size[0], 1.0)
                if dist > gate:
                    ok = False
                cost += dist
            if ok and cost < best_cost:
                best, best_cost = (a, b), cost
        if best is None:
            return
        for h, k in ((L, best[0]), (R, best[1])):
            if k is not None:
                h.region = regions[k]
                self.stats.regions[h.name] += 1

    def _sigma(self, h: _Hand) -> np.ndarray:
        r = h.region
        floor = self.params.depth.min_sigma * h.size
        return np.maximum(np.array([r.w / 2, r.h / 2]), floor)

    def _start_hand(self, h: _Hand, bins, integral, ref) -> None:
        """Sec. 4's initialisation: every sample from the importance function (or the init box),
        reference = the face colour; success when the samples' mean confidence passes the test."""
        p = self.params
        n = p.dynamics.particles
        if h.start is not None:
            centre = h.start
        elif h.region is not None:
            centre = (h.region.xc, h.region.yc)
        else:
            return
        if h.filter is None:
            h.filter = HueFilter(centre, h.size, ref, n, self.rng, p.dynamics.alpha_range)
        else:
            h.filter.reset(centre, h.size, ref)
        f = h.filter
        if h.start is None:
            xy = draw_importance(self.rng, n, np.array(centre), self._sigma(h))
            f.replace(np.arange(n), xy, p.dynamics.alpha_noise)
        f.weigh(integral, p.appearance.lam)
        if h.start is not None or f.conf.mean() >= p.reacquisition.hand_confidence:
            f.estimate_mean()
            f.resample()
            f.vel[:] = 0.0
            h.initialised, h.low, h.start = True, 0, None

    def _track_hand(self, h: _Hand, integral, backproj) -> None:
        p, d = self.params, self.params.dynamics
        f = h.filter
        noise = d.hand_noise * h.size[0]
        held = (f.pos.copy(), f.estimate.copy())
        predicted = f.predicted(d.velocity_decay)[:, :2].copy()
        f.propagate(d.velocity_decay, noise, d.alpha_noise)
        correction = None
        if p.depth.importance_sampling and h.region is not None and p.depth.q > 0:
            m = int(round(p.depth.q * f.n))
            idx = self.rng.choice(f.n, size=m, replace=False)
            u = np.array([h.region.xc, h.region.yc])
            sigma = self._sigma(h)
            xy = draw_importance(self.rng, m, u, sigma)
            f.replace(idx, xy, d.alpha_noise)
            correction = np.ones(f.n)  # standard and initialisation samples weigh 1
            k = int(round((1.0 - p.depth.reinit_share) * m))  # the first k are importance samples: f/g
            hgt, wid = integral.shape[1] - 1, integral.shape[2] - 1
            correction[idx[:k]] = icondensation_correction(xy[:k], u, sigma, predicted, noise,
                                                           p.depth.prior_floor, float(hgt * wid))
        f.weigh(integral, p.appearance.lam, correction)
        f.estimate_mean()
        if p.refinement.mean_shift:
            f.refine(backproj, p.refinement.iterations, p.refinement.eps)
        f.resample()
        if f.conf.max() < p.reacquisition.hand_lost:
            # nothing like a hand anywhere the samples went (hidden, or out of the frame): hold the
            # last state, without velocity, where the hand was last seen instead of coasting on
            # across the image (a coasting filter reached the other hand and stayed on it)
            f.pos, f.estimate = held
            f.vel[:] = 0.0
            h.low += 1
            if h.low >= p.reacquisition.hand_frames:
                h.initialised = False
        else:
            h.low = 0

    def _hands(self, bins, depth, fd, fbox, surfaces) -> None:
        """Sec. 4 for both hands: start (or restart) the uninitialised ones, track the others."""
        p = self.params
        ref = self._hand_reference(bins)
        if ref is None:
            return
        nb = p.appearance.hue_bins
        hand_bins = self._hand_bins(bins, depth, fd, surfaces, fbox)
        hand_integral = integral_histogram(hand_bins, nb + 1)
        backproj = None
        if p.refinement.mean_shift:
            weight = (hand_bins < nb).astype(np.float32)
            x, y, w, h = (int(round(v)) for v in fbox)  # the face is not a hand
            weight[max(y, 0):max(y + h, 0), max(x, 0):max(x + w, 0)] = 0.0
            backproj = back_projection(bins, ref[:nb], weight)
        done = None
        for hand in self._hand_order():
            integ = hand_integral if done is None else self._exclude(hand_bins, done, nb)
            if not hand.initialised:
                self._start_hand(hand, bins, integ, ref)
            elif hand.filter is not None:
                hand.filter.ref = ref
                self._track_hand(hand, integ, backproj)
            if hand.initialised and hand.low == 0:
                done = hand.filter.box()

    def _hand_order(self) -> list[_Hand]:
        """The hands, the one tracked with the best confidence first (sec. 4's one region per hand,
        as an exclusion: what one hand's window holds is not the other hand's)."""
        def key(h: _Hand) -> float:
            return -float(h.filter.conf.max()) if (h.initialised and h.filter is not None) else 1.0
        return sorted(self.hands.values(), key=key)

    @staticmethod
    def _exclude(hand_bins: np.ndarray, box, nb: int) -> np.ndarray:
        """The hands' integral histogram with ``box`` (the other hand's window) counted as *other*."""
        x, y, w, h = (int(round(v)) for v in box)
        masked = hand_bins.copy()
        masked[max(y, 0):max(y + h, 0), max(x, 0):max(x + w, 0)] = nb
        return integral_histogram(masked, nb + 1)

    # -- the loop ----------------------------------------------------------------------------------
    def _first_face(self, color, depth, bins, integral, camera) -> bool:
        """Start the face from the init box or a detection, and the hands' sizes from it."""
        p, ap = self.params, self.params.appearance
        box = self._init_boxes.get("head") or self._detect_face(color)
        if box is None or not self._start_face(box, bins):
            return False
        self.face.conf = self.face.conf + hue_confidence(
            box_histograms(integral, self.face.boxes(self.face.estimate)), self.face.ref, ap.lam)[0]
        for name in HANDS:
            hb = self._init_boxes.get(name)
            h = self.hands[name]
            if hb is not None:
                h.size = np.array(hb[2:], float)
                h.start = (hb[0] + hb[2] / 2, hb[1] + hb[3] / 2)
            else:
                s = p.reacquisition.hand_size * self.face_size[0]
                h.size = np.array([s, s])
        fd = face_depth(depth, self.face.box(), float(camera.K[0, 0]))
        self._fg = depth_foreground(depth, fd, p.depth) if (fd and p.depth.depth_foreground) else None
        return True

    def _follow_face(self, color, bins, integral) -> None:
        """Track the face; re-acquire it with the detector after ``face_frames`` unsure frames."""
        p = self.params
        self._track_face(bins, integral, self._fg)
        if self.face.conf.max() < p.reacquisition.face_confidence:
            self.face_low += 1
        else:
            self.face_low = 0
        if self.face_low >= p.reacquisition.face_frames:
            found = self._detect_face(color)
            if found is not None and self._start_face(found, bins):
                self.stats.reacquired += 1

    def step(self, frames: FrameSet, foreground: Mapping[str, np.ndarray | None]) -> list[TrackRecord]:
        view = frames.first
        index = frames.index
        color, depth = view.color, view.depth
        if color is None or depth is None:
            raise ValueError(f"frame {index}: the depth tracker needs colour and depth in stream {view.stream!r}")
        if index < self.start_frame:
            return []
        p = self.params
        hgt, wid = depth.shape
        camera = view.camera or default_camera(wid, hgt)
        ap = p.appearance
        bins = hue_bin_image(cv2.cvtColor(color, cv2.COLOR_BGR2HSV), ap.hue_bins, ap.min_saturation, ap.min_value)
        integral = integral_histogram(bins, ap.hue_bins)
        self.stats.frames += 1
        # 1. the face: started from the init box or a detection, then tracked
        if self.face is None:
            if not self._first_face(color, depth, bins, integral, camera):
                return []
        else:
            self._follow_face(color, bins, integral)
        fbox = self.face.box()
        fd = face_depth(depth, fbox, float(camera.K[0, 0]))
        # 2. depth foreground and hand candidate regions (Table 1)
        fg = depth_foreground(depth, fd, p.depth) if (fd is not None and p.depth.depth_foreground) else None
        self._fg = fg
        surfaces = self._surfaces(depth, fd, fbox, camera)
        regions = (hand_regions(depth, fd, fbox, float(camera.K[0, 0]), p.depth, surfaces=surfaces)
                   if fd is not None and p.depth.importance_sampling else [])
        self._assign(regions)
        # 3. the hands, observed in front of the face's plane (sec. 4 constraint 1) when depth is used
        self._hands(bins, depth, fd, fbox, surfaces)
        # 4. posture and rows
        hand_boxes = [self.hands[n].filter.box() if self.hands[n].initialised else None for n in HANDS]
        if self.head_mm is None:
            self.head_mm = head_width(camera, depth, fbox, p.posture)
        pose = recover(camera, depth, fbox, [self._seen(n, b, camera) for n, b in zip(HANDS, hand_boxes)],
                       p.posture, self.head_mm, self.arms)
        return self._rows(index, view.stream, camera, fbox, hand_boxes, pose)

    def _surfaces(self, depth, fd, fbox, camera) -> np.ndarray | None:
        """Large planes in front of the face (a desk top): not hands (:func:`~.regions.support_surfaces`)."""
        p = self.params.depth
        if fd is None or not p.surfaces or not (p.depth_foreground or p.importance_sampling):
            return None
        with np.errstate(invalid="ignore"):
            near = depth < fd.mean - p.hand_gap * fd.width_mm
        return support_surfaces(depth, near, np.asarray(camera.K, float), fd, float(fbox[2]) * float(fbox[3]),
                                p, self.rng)

    def _seen(self, name: str, box, camera) -> tuple | None:
        """The hand's box for the posture when the hand is seen now: tracked with confidence (not
        held, :meth:`_track_hand`) and at least half of its window inside the frame; else None
        (no 3D point, no elbow: a stale or cut-off hand would place the arm wrongly)."""
        h = self.hands[name]
        if box is None or h.low > 0:
            return None
        shown = _in_frame(box, tuple(camera.size))
        return box if shown is not None and shown[2] * shown[3] >= 0.5 * box[2] * box[3] else None

    def _rows(self, index, stream, camera, fbox, hand_boxes, pose) -> list[TrackRecord]:
        tid = self.track_id

        def rec(part, box, point, score=float("nan"), state="tracked"):
            X, Y, Z = (float(v) for v in point) if point is not None else (float("nan"),) * 3
            return TrackRecord(index, tid, part, Box(*box), score=score, state=state, camera=stream, X=X, Y=Y, Z=Z)

        size = tuple(camera.size)
        rows = [rec("head", _in_frame(fbox, size) or fbox, pose.head if pose else None, float(self.face.conf.max()))]
        for name, box in zip(HANDS, hand_boxes):
            shown = _in_frame(box, size) if box is not None else None
            if shown is None:  # a hand held outside the frame is not a box anyone can check
                continue
            rows.append(rec(name, shown, getattr(pose, name) if pose else None,
                            float(self.hands[name].filter.conf.max())))
        if pose is None:
            return rows
        side = self.params.posture.joint_box * pose.head_width
        fx = float(camera.K[0, 0])
        for part in ("torso", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow"):
            point = getattr(pose, part)
            if point is None:
                continue
            (u, v), = camera.project(point[None])
            z = float(camera.to_camera(point[None])[0, 2])
            if part == "torso":
                w, h = pose.torso_size[0] * fx / z, pose.torso_size[1] * fx / z
            else:
                w = h = side * fx / z
            state = "tracked"
            if part.endswith("elbow") and not pose.elbows_matched[part.startswith("right")]:
                state = "occluded"
            rows.append(rec(part, (u - w / 2, v - h / 2, w, h), point, state=state))
        return rows

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        return records_to_frame(records) if records else empty_tracks()
