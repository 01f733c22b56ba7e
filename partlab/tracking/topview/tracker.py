"""The multi-person top-view tracker (Migniot & Ababsa sec. 2.1 and 4).

Per frame: the ROI is the depth pixels between two heights above the floor (sec. 2.1), back
projected to world points through the stream's calibration; each point goes to the person whose
predicted model is nearest (the exclusion principle, eq. 5, the prediction extrapolating the
last two estimates; with two people or more and colour, the distance is corrected by how common
the point's colour was on that person's nearest primitive, partlab's colour term); each
person's :class:`PersonFilter` then runs on its own points. Blobs of points nobody owns start
new people (their highest point is the top of a head); people who keep too few points are
dropped.

Output per person and frame: rows ``head, right/left_shoulder, right/left_elbow,
right/left_hand`` with ``X, Y, Z`` (world mm; the head row is the head's centre, the hand rows
the hands' centres) and a box around the joint's image.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import cv2
import numpy as np
import pandas as pd

from partlab.errors import UserError
from partlab.tracking.camera import Camera
from partlab.tracking.core.box import Box
from partlab.tracking.frame import Frame, FrameSet
from partlab.tracking.topview.filter import PersonFilter
from partlab.tracking.topview.likelihood import colour_bins, nearest, nearest_primitive
from partlab.tracking.topview.model import JOINTS, N_PRIMITIVES, Body, joints, neutral_state, primitives
from partlab.tracking.topview.params import TopViewParams
from partlab.tracking.topview.start import fit_person
from partlab.tracking.tracks import TrackRecord, empty_tracks, records_to_frame


@dataclass
class Target:
    track_id: int
    filter: PersonFilter
    missing: int = 0
    #: ``(N_PRIMITIVES, bins)`` the share of each colour bin on each primitive of the last
    #: frame's estimate, among the points the frame gave this person (eq. 5's colour term)
    colour: np.ndarray | None = None


@dataclass
class RoiPoints:
    """The ROI of one frame: ``mask (H, W) bool``, its pixels' flat indexes ``(M,)``, world
    points ``(M, 3)`` mm, colour bins ``(M,)`` (None without colour)."""

    mask: np.ndarray
    index: np.ndarray
    points: np.ndarray
    bins: np.ndarray | None


class Geometry:
    """Per-pixel lines of sight of a camera, so that a depth image becomes world points with one
    multiply: ``X = centre + depth * ray`` (rays scaled to unit optical-axis depth)."""

    def __init__(self, camera: Camera):
        w, h = camera.size
        u, v = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
        pix = np.stack([u.ravel(), v.ravel()], 1)
        self.camera = camera
        self.centre = camera.centre
        self.rays = camera.back_project(pix, np.ones(len(pix))) - self.centre

    def points(self, depth: np.ndarray, index: np.ndarray) -> np.ndarray:
        return self.centre + depth.ravel()[index, None].astype(np.float64) * self.rays[index]


class TopViewTracker:
    """Several people's upper bodies from a depth stream seen from above."""

    def __init__(self, params: TopViewParams, rng: np.random.Generator, init: pd.DataFrame | None = None,
                 cameras: Mapping[str, Camera | None] | None = None):
        self.params = params
        self.rng = rng
        self.cameras = dict(cameras or {})
        self.targets: list[Target] = []
        self._next_id = 1
        self._geometry: dict[str, Geometry] = {}
        self._pending = self._read_init(init) if init is not None and len(init) else None
        #: the last frame's eq. 5 assignment, ``(H, W) int32``: track id per ROI pixel, 0 = nobody/not ROI
        self.assignment: np.ndarray | None = None
        self.automatic = self._pending is None

    # -- starting ----------------------------------------------------------------------------
    def _read_init(self, init: pd.DataFrame) -> dict[int, tuple[int, dict[str, np.ndarray]]]:
        have = init.dropna(subset=["X", "Y", "Z"])
        have = have[have["part"].isin(JOINTS)]
        if have.empty:
            raise UserError("tracker 'topview' starts from 3D joints: the init table needs X,Y,Z rows for "
                            f"{', '.join(JOINTS)} (partlab synth --scenario topview_* writes one)")
        out = {}
        for tid, rows in have.groupby("track_id"):
            first = int(rows["frame"].min())
            rows = rows[rows["frame"] == first]
            out[int(tid)] = (first, {r.part: np.array([r.X, r.Y, r.Z], np.float64) for r in rows.itertuples()})
        return out

    def _start(self, track_id: int, body: Body, state: np.ndarray, spread: float = 1.0) -> None:
        child = np.random.default_rng(self.rng.integers(2**63))
        self.targets.append(Target(track_id, PersonFilter(self.params, child, body, state, spread)))
        self._next_id = max(self._next_id, track_id + 1)

    def _start_pending(self, index: int, roi: RoiPoints) -> None:
        """Start the init's people of this frame: each fitted to its joints, then to the ROI points
        nearest its joints' model (eq. 5 among everyone, :func:`.start.fit_person`)."""
        starting = [(tid, js) for tid, (first, js) in sorted(self._pending.items()) if first == index]
        if not starting:
            return
        first = [fit_person(js, None, self.params.start) for _, js in starting]
        models = [primitives(state[None], body)[0] for body, state in first]
        models += [primitives(t.filter.estimate[None], t.filter.body)[0] for t in self.targets]
        owner = np.full(len(roi.points), -1)
        if len(roi.points):
            dist = np.stack([nearest(roi.points, m)[0] for m in models])
            owner = np.where(dist.min(0) <= self.params.exclusion.max_assign_mm, np.argmin(dist, 0), -1)
        for k, (tid, js) in enumerate(starting):
            body, state = fit_person(js, roi.points[owner == k], self.params.start)
            self._start(tid, body, state, spread=0.5)

    def _start_from_roi(self, roi: RoiPoints, owner: np.ndarray, shape: tuple[int, int]) -> None:
        """Sec. 2.1's ROI, automatically: blobs of ROI pixels nobody owns start people."""
        sp = self.params.start
        free = np.zeros(shape[0] * shape[1], np.uint8)
        free[roi.index[owner < 0]] = 1
        n, labels, stats, _ = cv2.connectedComponentsWithStats(free.reshape(shape), connectivity=8)
        min_px = sp.min_person_fraction * shape[0] * shape[1]
        where = np.full(shape[0] * shape[1], -1, np.int64)
        where[roi.index] = np.arange(len(roi.index))
        for lab in range(1, n):
            if stats[lab, cv2.CC_STAT_AREA] < min_px:
                continue
            rest = roi.points[where[(labels.ravel() == lab)]]
            # a blob may hold several people whose arms touch: take the highest point as a head,
            # the points around it as that person, and look again in what is left
            while len(rest) >= min_px:
                top = int(np.argmax(rest[:, 2]))
                if rest[top, 2] < sp.min_head_height_mm:
                    break
                near = np.hypot(rest[:, 0] - rest[top, 0], rest[:, 1] - rest[top, 1]) < sp.person_radius_mm
                # a person spans from the head down past the shoulders; what is left of an arm
                # reaching out of someone already found is flatter (or smaller)
                span = rest[top, 2] - rest[near, 2].min()
                if near.sum() >= min_px and span >= sp.min_person_span_mm:
                    self._start_at(rest[near])
                rest = rest[~near]

    def _start_at(self, pts: np.ndarray) -> None:
        """Start a person from their points: the top of the head, its centre, the shoulders' axis."""
        sp = self.params.start
        top = pts[:, 2].max()
        body = Body().scaled(top)
        head = pts[pts[:, 2] > top - sp.head_band_mm]
        hx, hy = head[:, 0].mean(), head[:, 1].mean()
        sh_z = top - 2 * body.head_radius - body.neck_length
        band = pts[(pts[:, 2] > sh_z - 120) & (pts[:, 2] < sh_z + 40)]
        yaw = 0.0
        if len(band) > 10:  # the shoulders' long axis is the body's x axis (up to a half turn)
            xy = band[:, :2] - band[:, :2].mean(0)
            _, evecs = np.linalg.eigh(xy.T @ xy)
            yaw = float(np.arctan2(evecs[1, 1], evecs[0, 1]))
        # the top view cannot tell front from back at rest: half of the particles face each way
        starts = np.stack([neutral_state(hx, hy, body, yaw), neutral_state(hx, hy, body, yaw + np.pi)])
        self._start(self._next_id, body, starts, spread=1.5)

    # -- the ROI (sec. 2.1) ------------------------------------------------------------------
    def _view(self, frames: FrameSet) -> Frame:
        for view in frames.views.values():
            if view.depth is not None:
                return view
        raise UserError(f"tracker 'topview': frame {frames.index} has no depth image")

    def _geometry_of(self, view: Frame) -> Geometry:
        cam = view.camera or self.cameras.get(view.stream)
        if cam is None:
            raise UserError(f"tracker 'topview' needs the calibration of stream {view.stream!r}")
        g = self._geometry.get(view.stream)
        if g is None:
            if tuple(cam.size) != (view.depth.shape[1], view.depth.shape[0]):
                raise UserError(f"stream {view.stream!r}: calibration is for {cam.size[0]}x{cam.size[1]} but the "
                                f"depth is {view.depth.shape[1]}x{view.depth.shape[0]}")
            g = self._geometry[view.stream] = Geometry(cam)
        return g

    def roi(self, view: Frame) -> RoiPoints:
        rp = self.params.roi
        g = self._geometry_of(view)
        d = view.depth
        valid = np.isfinite(d) & (d >= rp.min_depth_mm) & (d <= rp.max_depth_mm)
        index = np.flatnonzero(valid)
        pts = g.points(d, index)
        keep = (pts[:, 2] >= rp.min_height_mm) & (pts[:, 2] <= rp.max_height_mm)
        index, pts = index[keep], pts[keep]
        mask = np.zeros(d.size, bool)
        mask[index] = True
        bins = None
        lk = self.params.likelihood
        if lk.use_colour and view.color is not None and view.color.shape[:2] == d.shape:
            bins = colour_bins(view.color.reshape(-1, 3)[index], lk.colour_levels)
        return RoiPoints(mask.reshape(d.shape), index, pts, bins)

    # -- the exclusion principle (eq. 5) -----------------------------------------------------
    def assign(self, roi: RoiPoints, fitted: bool = False) -> np.ndarray:
        """``(M,)`` index into :attr:`targets` of each ROI point's nearest predicted model (-1: none
        within ``max_assign_mm``); ``fitted``: nearest this frame's estimated model instead. With
        two people or more and colour, the distance is corrected by the colour term
        (:meth:`colour_cost`)."""
        if not self.targets or not len(roi.points):
            return np.full(len(roi.points), -1, np.int64)
        v = self.params.exclusion.velocity
        states = [t.filter.estimate if fitted else t.filter.predicted(v) for t in self.targets]
        near = [nearest_primitive(roi.points, primitives(s[None], t.filter.body)[0])
                for s, t in zip(states, self.targets)]
        dist = np.stack([d for d, _ in near])
        cost = dist
        if self._colour_on(roi) and all(t.colour is not None for t in self.targets):
            cost = dist + np.stack([self.colour_cost(t, prim, roi.bins) for t, (_, prim) in zip(self.targets, near)])
        owner = np.argmin(cost, 0)
        owner[dist[owner, np.arange(len(owner))] > self.params.exclusion.max_assign_mm] = -1
        return owner

    def colour_cost(self, t: Target, prim: np.ndarray, bins: np.ndarray) -> np.ndarray:
        """``(M,)`` mm added to each point's distance to ``t``'s model (its nearest primitives
        ``prim``): ``-colour_mm * ln(q + colour_floor)``, ``q`` how common the point's colour bin
        was the frame before on that primitive and on the whole person."""
        ex = self.params.exclusion
        whole = t.colour.mean(0)
        q = (1 - ex.colour_person_share) * t.colour[prim, bins] + ex.colour_person_share * whole[bins]
        return -ex.colour_mm * np.log(q + ex.colour_floor)

    def _colour_on(self, roi: RoiPoints) -> bool:
        return len(self.targets) > 1 and self.params.exclusion.colour_mm > 0 and roi.bins is not None

    def _update_colour(self, roi: RoiPoints, owner: np.ndarray) -> None:
        """Each person's colour shares per primitive of this frame's estimate, from the points
        the frame's assignment gave them (for eq. 5's colour term at the next frame)."""
        n_bins = self.params.likelihood.colour_levels ** 3
        for k, t in enumerate(self.targets):
            mine = np.flatnonzero(owner == k)
            if not len(mine):
                continue
            _, prim = nearest_primitive(roi.points[mine], primitives(t.filter.estimate[None], t.filter.body)[0])
            h = np.zeros((N_PRIMITIVES, n_bins))
            np.add.at(h, (prim, roi.bins[mine]), 1.0)
            t.colour = h / np.maximum(h.sum(1, keepdims=True), 1.0)

    # -- one frame -----------------------------------------------------------------------------
    def step(self, frames: FrameSet, foreground=None) -> list[TrackRecord]:
        view = self._view(frames)
        roi = self.roi(view)
        if self._pending is not None:
            self._start_pending(frames.index, roi)
        owner = self.assign(roi)
        if self.automatic:
            before = len(self.targets)
            self._start_from_roi(roi, owner, view.depth.shape)
            if len(self.targets) > before:
                owner = self.assign(roi)
        cam = view.camera or self.cameras.get(view.stream)
        keep, used = [], {}
        for k, t in enumerate(self.targets):
            mine = np.flatnonzero(owner == k)
            if len(mine) < self.params.start.min_points:
                t.missing += 1
                if t.missing < self.params.start.lost_after:
                    keep.append(t)
                continue
            t.missing = 0
            keep.append(t)
            used[t.track_id] = self._measure(t, roi, mine, view.depth, cam, first=True)
        dropped = len(keep) < len(self.targets)  # then ``owner`` indexes the targets before
        self.targets = keep
        if len(used) > 1 and self.params.exclusion.second_pass:
            owner = self._second_pass(roi, owner, used, view.depth, cam)
        if self._colour_on(roi) and not dropped:
            self._update_colour(roi, owner)
        assignment = np.zeros(view.depth.size, np.int32)
        ids = np.array([t.track_id for t in self.targets] + [0])
        assignment[roi.index] = ids[owner]
        self.assignment = assignment.reshape(view.depth.shape)
        return [row for t in self.targets if t.track_id in used
                for row in self._rows(frames.index, view, t, roi.points[used[t.track_id]])]

    def _measure(self, t: Target, roi: RoiPoints, mine: np.ndarray, depth: np.ndarray, cam, first: bool) -> np.ndarray:
        """Run ``t``'s filter on its ROI points ``mine`` (at most ``roi.max_points`` of them, drawn
        at random); ``first`` = False weighs this frame's particles again (the second pass).
        Returns the points used."""
        if len(mine) > self.params.roi.max_points:
            mine = self.rng.choice(mine, self.params.roi.max_points, replace=False)
        n_bins = self.params.likelihood.colour_levels ** 3
        bins = roi.bins[mine] if roi.bins is not None else None
        if bins is not None and t.filter.reference is None:
            t.filter.update_reference(roi.points[mine], bins, n_bins)
        if first:
            t.filter.step(roi.points[mine], bins, n_bins, depth, cam)
        else:
            t.filter.measure(roi.points[mine], bins, n_bins, depth, cam, again=True)
        return mine

    def _second_pass(self, roi: RoiPoints, owner: np.ndarray, used: dict[int, np.ndarray], depth: np.ndarray,
                     cam) -> np.ndarray:
        """Eq. 5 again with this frame's fitted models instead of the predicted ones (partlab's):
        where two people touch, a forearm that moved against its prediction took the other
        person's points; the people whose points changed are weighed again with their new ones
        (the same particles: no second resampling or propagation). Returns the new owners."""
        fitted = self.assign(roi, fitted=True)
        for k, t in enumerate(self.targets):
            if t.track_id not in used:
                fitted[fitted == k] = -1
                continue
            mine = np.flatnonzero(fitted == k)
            changed = np.count_nonzero((owner == k) != (fitted == k))
            if changed >= self.params.exclusion.second_pass_points and len(mine) >= self.params.start.min_points:
                used[t.track_id] = self._measure(t, roi, mine, depth, cam, first=False)
        return fitted

    def _rows(self, index: int, view: Frame, t: Target, points: np.ndarray) -> list[TrackRecord]:
        f = t.filter
        cam = view.camera or self.cameras.get(view.stream)
        dist, _ = nearest(points, primitives(f.estimate[None], f.body)[0])
        score = float(np.exp(-dist.mean() / self.params.likelihood.distance_scale_mm))
        rows = []
        sizes = self.params.output.joint_box_mm
        for name, X in zip(JOINTS, joints(f.estimate[None], f.body)[0]):
            uv = cam.project(X[None])[0]
            z = max(float(cam.to_camera(X[None])[0, 2]), 1.0)
            side = max(cam.K[0, 0] * sizes.get(name, 120.0) / z, 2.0)
            rows.append(TrackRecord(index, t.track_id, name, Box(float(uv[0] - side / 2), float(uv[1] - side / 2),
                                                                   float(side), float(side)),
                                    score=score, state="tracked", camera=view.stream,
                                    X=float(X[0]), Y=float(X[1]), Z=float(X[2])))
        return rows

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        return records_to_frame(records) if records else empty_tracks()
