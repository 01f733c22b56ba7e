"""The multi-camera head-and-hands tracker, frame by frame (sec. 5-6).

Per frame (:meth:`Limbs3DTracker.step`):

1. per view (sec. 6.1-6.2): the person silhouettes (empty-scene plate or the adaptive
   foreground), skin pixels within them or around a tracked target's projection, the largest
   skin blobs and their centres of mass, each blob's relative row in its silhouette;
2. candidates (sec. 6.3, eq. 16, 18, 22-24) from every pair of views, their priors p_o p_t p_b
   (eq. 19, 25-27), pruned and merged (sec. 6.4);
3. the low layer: every active target's particle filter predicts and is weighted by eq. 17 over
   the candidates no other target is nearer to (a combined pair's filter over both's);
4. the high layer (sec. 5.2): the five-state machine of :mod:`partlab.tracking.limbs.state_machine`
   on 3D positions combines targets that come within ``combine_distance`` mm, splits them when the
   combined posterior's two modes part by ``split_distance`` mm, giving each tracker the mode that
   keeps the direction between them from before the join (sec. 7.1), loses and recovers targets;
5. output: each target's 3D estimate (``X, Y, Z``) and, for every view, its back-projected box
   (``camera`` column), so that every view can be corrected.

Targets start from ``--init`` (3D points, or boxes in two or more views that are triangulated with
``cv2.triangulatePoints``); without one, a strong candidate that persists ``start_frames`` frames
starts a target (uninitialized -> unlabelled), and a person's highest target is labelled its head,
the others its hands by side.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import cv2
import numpy as np
import pandas as pd

from partlab.tracking.camera import Camera
from partlab.tracking.core.background import half_size, plate_silhouette
from partlab.tracking.core.box import Box
from partlab.tracking.core.skin import SkinModel, find_blobs, train_skin_model
from partlab.tracking.frame import FrameSet
from partlab.tracking.limbs.state_machine import LimbState, LimbStateMachine, Observation
from partlab.tracking.limbs3d.filter import TargetFilter
from partlab.tracking.limbs3d.geometry import pair_candidates
from partlab.tracking.limbs3d.params import Limbs3DParams
from partlab.tracking.limbs3d.priors import (
    blob_keys,
    candidate_prior,
    observe_view,
    prune_and_merge,
    silhouette_distance,
    split_key,
)
from partlab.tracking.multiview import triangulate
from partlab.tracking.tracks import TrackRecord, empty_tracks, records_to_frame

LIMB_PARTS = ("head", "left_hand", "right_hand")


@dataclass
class _Target:
    track_id: int
    part: str
    filter: TargetFilter | None = None
    start_frame: int = 0
    position: np.ndarray | None = None
    labelled: bool = True
    waiting: int = 0  # frames an automatically started target has waited for a label
    missed: int = 0  # frames in a row without confidence (dynamics.gate_growth)
    # a candidate on the lines of sight of its single-view blobs (dynamics.line_of_sight): where it
    # was last frame and for how many frames in a row one has been there
    sight: np.ndarray | None = None
    sight_frames: int = 0
    alone_frames: int = 0  # frames in a row with no candidate from pairs of views in its gate
    # while so: per view, where its own blob (nearer its projection than any other target's) was
    # last seen and the frame (the blob a hand seen by one view follows, dynamics.line_of_sight)
    own: dict = field(default_factory=dict)
    # its position minus its person's head's when it was last tracked from pairs of views with no
    # other target near (dynamics.line_of_sight: where a hand seen by one view goes back to)
    home: np.ndarray | None = None
    returning: bool = False  # it left a combined pair and has not been tracked alone from pairs since
    foreign_pair: int = 0  # (a pair's leader) frames in a row nearer one head (states.foreign_pair_frames)
    # (a lost hand) a candidate nobody tracked claims on its person's side, and for how many frames in a
    # row one has been there (states.lost_claim_frames)
    orphan: np.ndarray | None = None
    orphan_frames: int = 0
    first_home: np.ndarray | None = None  # its home at its init frame (which side of its person it is on)
    parting: list = field(default_factory=list)  # distances of a combined pair's single-view mode, frame by frame
    history: list = field(default_factory=list)


class Limbs3DTracker:
    """Heads and hands of everybody in a calibrated take of two or more views."""

    def __init__(self, params: Limbs3DParams, rng: np.random.Generator, cameras: Mapping[str, Camera],
                 init: pd.DataFrame | None = None, backgrounds: Mapping[str, np.ndarray] | None = None):
        self.params = params
        self.rng = rng
        self.streams = list(cameras)
        self.cameras = [cameras[s] for s in self.streams]
        self.plates = {s: self._half(b) for s, b in (backgrounds or {}).items() if b is not None}
        self.skin = SkinModel.default()
        self._skin_fitted = False
        self.machine = LimbStateMachine(params)
        self.targets: dict[int, _Target] = {}
        self.pending: dict[int, _Target] = {}
        self._next = 0
        self.last: dict = {}  # the latest frame's candidates, priors and raw errors (training, the app)
        if init is not None and len(init):
            self._from_init(init)

    # -- starting targets -----------------------------------------------------------------
    def _from_init(self, init: pd.DataFrame) -> None:
        rows = init[init["part"].isin(LIMB_PARTS)]
        for (tid, part), g in rows.groupby(["track_id", "part"], sort=True):
            first = int(g["frame"].min())
            g = g[g["frame"] == first]
            xyz = g[["X", "Y", "Z"]].to_numpy(float) if {"X", "Y", "Z"} <= set(g.columns) else np.zeros((0, 3))
            xyz = xyz[np.isfinite(xyz).all(axis=1)] if len(xyz) else xyz
            if len(xyz):
                point = xyz.mean(axis=0)
            else:
                views = [(self.cameras[self.streams.index(r.camera)], (r.x + r.w / 2, r.y + r.h / 2))
                         for r in g.itertuples() if getattr(r, "camera", "") in self.streams]
                if len(views) < 2:
                    raise ValueError(f"init track {tid} {part}: needs X,Y,Z or boxes in two or more views "
                                     f"(has {len(views)})")
                point = triangulate([v[0] for v in views], [v[1] for v in views])
            self._add(int(tid), str(part), first, point, LimbState.NORMAL)

    def _add(self, track_id: int, part: str, frame: int, point, state: LimbState) -> int:
        key = self._next
        self._next += 1
        self.targets[key] = _Target(track_id, part, None, frame, np.asarray(point, float),
                                    labelled=state == LimbState.NORMAL)
        self.machine.add(key, LimbState.UNINITIALIZED if state == LimbState.NORMAL else state)
        if state == LimbState.NORMAL:  # an init target: normal from its first frame
            self.machine._status[key].state = LimbState.NORMAL
        return key

    # -- 1. observations per view (sec. 6.1-6.2) -----------------------------------------------
    @staticmethod
    def _half(image: np.ndarray) -> np.ndarray:
        """Silhouettes are found at half resolution (a 2 x 2 area average also halves the noise)."""
        return half_size(image)

    def _silhouette(self, stream: str, color: np.ndarray, foreground) -> np.ndarray:
        """``(H/2, W/2) uint8`` 0/1 person mask of one view."""
        plate = self.plates.get(stream)
        h, w = color.shape[0] // 2, color.shape[1] // 2
        if plate is not None and plate.shape == (h, w, 3):
            return plate_silhouette(self._half(color), plate, self.params.observations.plate_threshold)
        if foreground is None:
            return np.zeros((h, w), np.uint8)
        return cv2.resize((np.asarray(foreground) > 0).astype(np.uint8), (w, h), interpolation=cv2.INTER_NEAREST)

    def _support(self, camera: Camera, shape) -> np.ndarray:
        """Discs around the projections of the tracked targets (skin counts there even outside the
        silhouette: a person who sits still fades into an adaptive background model)."""
        mask = np.zeros(shape, np.uint8)
        for key, t in self.targets.items():
            if self.machine.state(key) == LimbState.UNINITIALIZED or t.position is None:
                continue
            uv, r = self._project(camera, t)
            if np.all(np.isfinite(uv)):
                radius = int(max(self.params.observations.support_scale * r, 3))
                cv2.circle(mask, (int(uv[0]), int(uv[1])), radius, 1, -1)
        return mask

    def _project(self, camera: Camera, t: _Target) -> tuple[np.ndarray, float]:
        cam = camera.to_camera(t.position[None])[0]
        size = self.params.output.head_size_mm if t.part == "head" else self.params.output.hand_size_mm
        return camera.project(t.position[None])[0], 0.5 * camera.K[0, 0] * size / max(cam[2], 1.0)

    def _adapt_skin(self, frames: FrameSet) -> None:
        """Refit the skin model on the starting targets' boxes in every view (once)."""
        images, boxes = [], []
        for stream, cam in zip(self.streams, self.cameras):
            view = frames.views.get(stream)
            if view is None or view.color is None:
                continue
            b = []
            for t in self.targets.values():
                if t.position is not None and t.start_frame <= frames.index:
                    uv, r = self._project(cam, t)
                    if np.all(np.isfinite(uv)):
                        b.append((uv[0] - r, uv[1] - r, 2 * r, 2 * r))
            images.append(view.color)
            boxes.append(np.array(b, float).reshape(-1, 4))
        if sum(len(b) for b in boxes):
            self.skin = train_skin_model(images, boxes, bins=self.skin.bins, ybins=self.params.observations.skin_ybins,
                                         prior=self.skin)
        self._skin_fitted = True

    def observe(self, frames: FrameSet, foreground: Mapping[str, np.ndarray | None]):
        p = self.params
        if p.observations.skin_adapt and not self._skin_fitted and self.targets:
            self._adapt_skin(frames)
        people = max(1, len({t.track_id for t in self.targets.values()}))
        centres, views = [], []
        for stream, cam in zip(self.streams, self.cameras):
            view = frames.views.get(stream)
            if view is None or view.color is None:
                h, w = cam.size[1], cam.size[0]
                centres.append(np.zeros((0, 2)))
                views.append(observe_view(np.zeros((h, w), np.uint8), np.zeros((0, 2))))
                continue
            sil = self._silhouette(stream, view.color, foreground.get(stream))
            H, W = view.color.shape[:2]
            allowed = cv2.resize(cv2.dilate(sil, np.ones((3, 3), np.uint8)), (W, H), interpolation=cv2.INTER_NEAREST)
            if stream not in self.plates:  # an adaptive background may have absorbed a still person
                allowed = np.maximum(allowed, self._support(cam, (H, W)))
            skin = np.zeros((H, W), np.uint8)
            x, y, w, h = cv2.boundingRect(allowed)
            if w > 0 and h > 0:  # skin is looked for only where people are (the costly part)
                pad = self.skin.blur
                x0, y0, x1, y1 = max(x - pad, 0), max(y - pad, 0), min(x + w + pad, W), min(y + h + pad, H)
                crop = self.skin.mask(view.color[y0:y1, x0:x1], allowed[y0:y1, x0:x1], p.observations.skin_threshold)
                k = p.observations.skin_open
                if k > 1:
                    crop = cv2.morphologyEx(crop, cv2.MORPH_OPEN, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k)))
                skin[y0:y1, x0:x1] = crop
            blobs = find_blobs(skin, people, p.observations.blob_alpha, p.observations.blob_min_area)
            blind = stream in self.plates and sil.mean() > p.observations.blind_fill
            centres.append(np.zeros((0, 2)) if blind else blobs.centres)
            views.append(observe_view(sil, centres[-1] / 2.0, scale=2.0, fragment=p.priors.fragment,
                                      either=p.priors.fragment_either, stack=p.priors.fragment_stack))
        self._centres = centres
        return centres, views

    # -- 2. candidates and their priors (sec. 6.3-6.4) -----------------------------------------
    def candidates(self, centres, views, anchors: np.ndarray | None = None):
        """Merged candidates ``(K, 3)`` and their priors; ``anchors``: the tracked targets'
        predictions, which decide which of the pairs sharing blobs are ghosts."""
        cands = pair_candidates(self.cameras, centres)
        prior, raw = candidate_prior(cands, self.cameras, views, self.params)
        points, weights, members = prune_and_merge(cands.points, prior.value, self.params,
                                                   blob_keys(cands.views, cands.blobs), anchors, with_members=True)
        self.last = {"candidates": cands, "prior": prior, "raw": raw, "points": points, "weights": weights,
                     "members": members}
        return points, weights

    # -- 3-4. one frame -------------------------------------------------------------------------
    def step(self, frames: FrameSet, foreground: Mapping[str, np.ndarray | None]) -> list[TrackRecord]:
        p = self.params
        index = frames.index
        centres, views = self.observe(frames, foreground)
        self._sight_modes: list = []  # this frame's modes seen by a single view (_single_view_mode)
        m = self.machine
        self._come_alive(index)
        active = [k for k, t in self.targets.items() if t.filter is not None and m.is_leader(k)
                  and m.state(k) != LimbState.UNINITIALIZED]
        # predict
        for k in active:
            t = self.targets[k]
            state = m.state(k)
            if state == LimbState.LOST:
                t.filter.reset(t.position, p.dynamics.lost_search)
            else:
                t.filter.predict(p.dynamics.combined_noise_scale if state == LimbState.COMBINED else 1.0)
        # exclusive use of candidates: each goes to the nearest predicted target (a combined pair
        # counts as one), unless it is about as near to several
        preds = np.array([self.targets[k].filter.estimate for k in active]).reshape(-1, 3)
        lost = np.array([m.state(k) == LimbState.LOST for k in active], bool)
        points, weights = self.candidates(centres, views, preds[~lost])
        self._claims: list = []  # (person, candidate, target, distance): each tracked target's nearest candidate
        if len(points) and len(active):
            dist = np.linalg.norm(points[:, None] - preds[None], axis=-1)
            self._claims = [(self.targets[k].track_id, int(np.argmin(dist[:, a])), k, float(dist[:, a].min()))
                            for a, k in enumerate(active)
                            if not lost[a] and dist[:, a].min() < p.dynamics.candidate_gate]
        observations: dict[int, Observation] = {}
        heads = {t.track_id: t.position for t in self.targets.values() if t.part == "head" and t.position is not None}
        seeing = sum(len(c) > 0 for c in centres)  # views with a skin blob: a dark camera has none
        growth = p.dynamics.gate_growth + (p.dynamics.gate_growth_dark if seeing < len(self.cameras) else 0.0)
        unseen = p.dynamics.hold_unseen and seeing < 2  # nothing can be triangulated this frame
        claimed: set = set()  # candidates a lost hand took this frame (states.lost_claim_frames)
        for a, k in enumerate(active):
            t = self.targets[k]
            rivals = self._rivals(a, lost)
            few = not (len(points) and len(rivals))
            mine = self._usable(t, points, None if few else dist[:, a], None if few else dist[:, rivals],
                                heads.get(t.track_id))
            use, use_w = points[mine], weights[mine]
            gate = p.dynamics.candidate_gate * (1 + growth * min(t.missed, p.states.lost_frames))
            state = m.state(k)
            self._refind(t, state, a, preds, use, use_w, gate)
            j = self._orphan(t, state, a, preds, lost, points, weights, heads, claimed)
            if j >= 0:  # a lost hand takes the strong candidate on its side that nobody tracked claims
                claimed.add(j)
                t.filter.reset(points[j])
                preds[a] = points[j]
                use, use_w, alone = points[j:j + 1], weights[j:j + 1], False
                t.sight, t.sight_frames, t.alone_frames, t.own = None, 0, 0, {}
            else:
                use, use_w, alone = self._without_pairs(t, state, a, use, use_w, gate, preds, centres, views, points,
                                                        weights, heads.get(t.track_id))
            est = t.filter.update(use, use_w, gate)
            foreign = self._foreign(t, state, est, heads)
            if alone and not foreign and heads.get(t.track_id) is not None:
                t.home, t.returning = est - heads[t.track_id], False
            t.missed = t.missed + 1 if t.filter.confidence < p.states.lost_likelihood else 0
            est = self._back_home(t, est, heads.get(t.track_id))
            if m.state(k) != LimbState.LOST or t.filter.confidence >= p.states.recover_likelihood:
                t.position = est  # a lost target is held until something is found where it is held
            else:
                if (t.returning or p.states.lost_home) and t.home is not None and heads.get(t.track_id) is not None:
                    t.position = heads[t.track_id] + t.home  # ... or at its home (states.lost_home)
                est = t.position
            obs = {"position": tuple(est), "likelihood": t.filter.confidence, "labelled": t.labelled,
                   "unseen": unseen}
            if m.state(k) == LimbState.COMBINED:
                obs["modes"] = self._foreign_pair(t, k, est, heads, self._combined_modes(
                    t, est, np.flatnonzero(mine), points, weights, centres, np.delete(preds, a, axis=0),
                    self._pair_heads(k, heads)))
            else:  # frames in a row of one combined pair (a count left from an earlier pair split seed 16's)
                t.foreign_pair = 0
            observations[k] = Observation(**obs)
            partner = m.partner(k)
            if partner is not None and m.state(k) == LimbState.COMBINED:
                self.targets[partner].position = est
                observations[partner] = Observation(position=tuple(est), likelihood=t.filter.confidence,
                                                    labelled=True, unseen=unseen)
        transitions = m.update(index, observations)
        splits = self._split_sides({tr.tracker: tr.position for tr in transitions
                                    if tr.new == LimbState.UNLABELLED and tr.reason == "split"}, heads)
        for tr in transitions:
            t = self.targets[tr.tracker]
            if tr.tracker in splits:
                self._split(t, splits[tr.tracker], heads.get(t.track_id))
            elif (p.states.combined_lost_home and tr.old == LimbState.COMBINED and tr.new == LimbState.LOST
                  and t.part != "head"):
                t.returning = True  # held at its home while lost (sec. 7.1: after a handshake each hand goes back)
            # (a target that becomes combined and is not its pair's leader: the leader's filter tracks both)
        return self._records(index)

    def _back_home(self, t: _Target, est: np.ndarray, head) -> np.ndarray:
        """A hand that left a combined pair (``returning``) and found nothing for a second frame in a
        row (its likelihood below ``states.lost_likelihood``) is put back where it came from, relative
        to its head (``home``), its particles spread ``dynamics.lost_search`` about it, instead of
        drifting with its particles for ``states.lost_frames`` frames until it is lost: after a
        handshake the hands go back where they came from (the direction cue of sec. 7.1, as
        :meth:`_split_position`). 3-camera handshake seed 8: the right hand that got the other mode
        had nothing there, drifted 230 -> 390 mm off while its home point was 16-42 mm from it. From
        the first missed frame, one miss right after seed 4's good split sent a hand to a stale home."""
        if t.missed < 2 or not t.returning or t.home is None or head is None:
            return est
        est = np.asarray(head, float) + t.home
        t.filter.reset(est, self.params.dynamics.lost_search)
        return est

    def _foreign(self, t: _Target, state: LimbState, est: np.ndarray, heads: dict) -> bool:
        """Whether hand ``t`` (tracked, ``states.foreign_pair_frames`` > 0) is estimated nearer
        another person's head than its own by more than ``states.foreign_home_margin`` (``heads``: the
        head estimates by person): its home is not taken from such a frame (:meth:`_foreign_pair`
        sends it there). A hand reaching for an exchange is a little nearer the other head, and more
        so when that head's estimate is off (held-out handshake seed 16, 4 cameras)."""
        own = heads.get(t.track_id)
        if (not self.params.states.foreign_pair_frames or t.part == "head" or state != LimbState.NORMAL
                or own is None):
            return False
        others = [h for tid, h in heads.items() if tid != t.track_id]
        return bool(others) and min(self._to_head(est, h) for h in others) < (
            self._to_head(est, own) - self.params.states.foreign_home_margin)

    def _foreign_points(self, t: _Target, points: np.ndarray, head) -> np.ndarray:
        """``(K,)`` whether each of ``points`` is nearer another person's head than hand ``t``'s own
        (``head``) by more than ``states.foreign_use`` mm (:meth:`_to_head`)."""
        out = np.zeros(len(points), bool)
        own = self._to_head(points, head)
        for o in self.targets.values():
            if o.part == "head" and o.track_id != t.track_id and o.position is not None:
                out |= self._to_head(points, o.position) < own - self.params.states.foreign_use
        return out

    def _to_head(self, point, head):
        """The distance (or ``(K,)`` distances of ``(K, 3)`` points) from ``point`` to ``head`` the
        rules on two people's hands read: in 3D, or horizontally with ``states.foreign_horizontal`` (a
        hand at the hip is 700-800 mm below either head, which hides how far it is to either side)."""
        d = np.subtract(point, head)
        d = d[..., :2] if self.params.states.foreign_horizontal else d
        return np.linalg.norm(d, axis=-1) if d.ndim > 1 else float(np.linalg.norm(d))

    def _foreign_pair(self, t: _Target, k: int, est: np.ndarray, heads: dict, modes: tuple) -> tuple:
        """The modes of combined pair ``k`` (leader ``t``) of two people's hands, or, once its estimate
        has been nearer one person's head than the other's by more than ``states.foreign_margin`` mm
        for ``states.foreign_pair_frames`` frames in a row, the estimate and the farther person's hand's
        home (relative to its head): the pair splits, that hand going home (the direction cue,
        ``states.split_heads``, gives each hand its own side). Handshake 4 cameras seed 7: person 2's
        right hand took person 1's when the hands parted (person 1's tracker lagged 230-360 mm off),
        followed it to person 1 and was combined with it 930-1040 mm from person 2's head, 230 mm
        nearer person 1's, for 56 frames. A home is not taken from a frame in which the hand is
        nearer another person's head than its own (:meth:`_foreign`): it had been, from there. With
        ``states.foreign_horizontal`` the distances to the heads are horizontal (:meth:`_to_head`):
        held-out 3-camera seed 15's pair of both right hands sat at person 1's hip, 780 mm from its
        head and 910 from person 2's in 3D (within the margin) but ~330 and ~700 mm across."""
        st = self.params.states
        partner = self.machine.partner(k)
        o = self.targets[partner] if partner is not None else None
        if (not st.foreign_pair_frames or o is None or o.track_id == t.track_id or t.part == "head"
                or t.track_id not in heads or o.track_id not in heads):
            t.foreign_pair = 0
            return modes
        d_t = self._to_head(est, heads[t.track_id])
        d_o = self._to_head(est, heads[o.track_id])
        t.foreign_pair = t.foreign_pair + 1 if abs(d_t - d_o) > st.foreign_margin else 0
        far = t if d_t > d_o else o
        if t.foreign_pair < st.foreign_pair_frames or far.home is None:
            return modes
        t.foreign_pair = 0
        return (tuple(est), tuple(heads[far.track_id] + far.home))

    def _orphan(self, t: _Target, state: LimbState, a: int, preds: np.ndarray, lost: np.ndarray, points: np.ndarray,
                weights: np.ndarray, heads: dict, claimed: set) -> int:
        """The candidate (index, -1 for none) lost hand ``t`` (``a``: its index in ``preds``, ``lost``:
        which of them are lost) takes wherever it lies (``states.lost_claim_frames``; our addition, the
        lost state retrieving the track, sec. 5.2): of prior at least ``states.start_prior``, spanning
        ``states.lost_claim_views`` views or more, within ``dynamics.hand_reach`` of its person's head,
        nearer it than every other person's head by ``states.lost_claim_margin``, at least
        ``states.lost_claim_side`` mm on the hand's own side of that head (:meth:`_side`), farther
        than ``dynamics.candidate_gate`` from every tracked target's prediction and not taken by
        another lost hand this frame (``claimed``); of those the one nearest where the hand is held
        (its home relative to its head when it has one), once one has been within ``candidate_gate``
        of it ``lost_claim_frames`` frames in a row. A lost hand is held where it was lost (or at its
        home) and looks for itself ``dynamics.lost_search`` about that point; a strong candidate of
        three views on its side that no tracked target is near is a hand nobody tracks. Handshake seed
        4, 4 cameras: person 2's right hand, lost at frame 68 and held ~600 mm off while its true
        candidate (prior 0.9-1.0, 3-4 views from frame 113) lay 30-40 mm from its hand; its left hand,
        drifting on single-view candidates, took that candidate through its line of sight at frame
        134 and stayed on it. The side: 3-camera handshake seed 2's lost right hand, held at its home,
        took its left hand's true candidate (its tracker 150-280 mm behind it for three frames) ~245
        mm on the left of the head, where the right hand's own candidates lay ~250 mm on the right."""
        st = self.params.states
        d = self.params.dynamics
        members = self.last.get("members") or []
        own = heads.get(t.track_id)
        if (not st.lost_claim_frames or state != LimbState.LOST or t.part == "head" or own is None
                or not len(points) or len(members) != len(points)):
            t.orphan, t.orphan_frames = None, 0
            return -1
        n_views = np.array([len({split_key(key)[0] for key in ms}) for ms in members])
        ok = (weights >= st.start_prior) & (n_views >= st.lost_claim_views)
        d_own = np.linalg.norm(points - own, axis=1)
        if d.hand_reach > 0:
            ok &= d_own <= d.hand_reach
        for tid, h in heads.items():
            if tid != t.track_id and h is not None:
                ok &= np.linalg.norm(points - h, axis=1) > d_own + st.lost_claim_margin
        tracked = preds[~lost]
        if len(tracked):
            ok &= np.linalg.norm(points[:, None] - tracked[None], axis=-1).min(axis=1) > d.candidate_gate
        for j in claimed:
            ok[j] = False
        side = self._side(t)
        if side is not None:  # on its own side of its head (a person's left hand on the left)
            ok &= (points - own) @ side >= st.lost_claim_side
        if not ok.any():
            t.orphan, t.orphan_frames = None, 0
            return -1
        held = own + t.home if t.home is not None else preds[a]
        j = int(np.flatnonzero(ok)[np.argmin(np.linalg.norm(points[ok] - held, axis=1))])
        same = t.orphan is not None and np.linalg.norm(points[j] - t.orphan) < d.candidate_gate
        t.orphan, t.orphan_frames = points[j], (t.orphan_frames + 1 if same else 1)
        if t.orphan_frames < st.lost_claim_frames:
            return -1
        t.orphan, t.orphan_frames = None, 0
        return j

    def _side(self, t: _Target) -> np.ndarray | None:
        """The horizontal unit vector from hand ``t``'s person's other hand to it where the two were at
        their init frame (a person's left-right axis; None without both)."""
        other = [o for o in self.targets.values() if o.track_id == t.track_id and o.part not in ("head", t.part)
                 and o.first_home is not None]
        if t.first_home is None or not other:
            return None
        v = t.first_home - other[0].first_home
        v = np.array([v[0], v[1], 0.0])
        n = float(np.linalg.norm(v))
        return v / n if n > 0 else None

    def _refind(self, t: _Target, state: LimbState, a: int, preds: np.ndarray, use: np.ndarray, use_w: np.ndarray,
                gate: float) -> None:
        """A normal hand with no candidate it may use (``use``, ``use_w``: no other target's
        prediction nearer, within reach of its head) within ``gate`` of its prediction ``preds[a]``
        is put (its filter and ``preds[a]``) on the nearest of prior at least ``states.start_prior``
        within ``dynamics.refind_gate`` that is also nearer to it than to every other target's
        estimate (a lost one's, where it is held: a tracked hand does not yield to lost ones). A hand
        leaving a clap at ~140 mm a frame is 300-400 mm from its lagging estimate when next seen
        from two views (standing seed 3, 2 cameras). With three views or more (``_line_of_sight``)
        :meth:`_through_own_blob` re-finds hands instead."""
        d = self.params.dynamics
        if (d.refind_gate <= gate or self._line_of_sight or t.part == "head" or state != LimbState.NORMAL
                or not len(use)):
            return
        dist = np.linalg.norm(use - preds[a], axis=1)
        ok = (dist < d.refind_gate) & (use_w >= self.params.states.start_prior)
        others = [o.position for o in self.targets.values() if o is not t and o.position is not None]
        if others:  # nearer it than every other target, a lost one where it is held included
            ok &= dist < np.linalg.norm(use[:, None] - np.array(others)[None], axis=-1).min(axis=1)
        if (dist < gate).any() or not ok.any():
            return
        j = np.flatnonzero(ok)[np.argmin(dist[ok])]
        t.filter.reset(use[j])
        preds[a] = use[j]

    def _come_alive(self, index: int) -> None:
        """Targets whose init frame is ``index`` get their filter (and their ``home``: an init point
        is a fix, from two views or in 3D)."""
        for key, t in self.targets.items():
            if t.filter is None and t.start_frame <= index and self.machine.state(key) == LimbState.NORMAL:
                t.filter = TargetFilter(t.position, self.params.dynamics, self.rng)
                head = [h.position for h in self.targets.values() if h.track_id == t.track_id and h.part == "head"]
                if head and head[0] is not None:
                    t.home = t.position - head[0]
                    t.first_home = t.home.copy()

    def _split_sides(self, splits: dict, heads: dict) -> dict:
        """The modes the state machine gave two hands of different people that split (``splits``:
        target -> mode), swapped when the direction cue (sec. 7.1) puts each on the other person's
        side: the modes' difference points against their heads' by more than ``states.split_heads``
        (cosine). The direction before the join comes from estimates that may have drifted (a hand
        lost or on single-view candidates while the hands met); the heads are tracked to 10-50 mm,
        and after a handshake or an exchange each hand goes back to its own person."""
        c = self.params.states.split_heads
        if c >= 1 or len(splits) < 2:
            return splits
        out = dict(splits)
        for k, pos in splits.items():
            t = self.targets[k]
            for j, other in splits.items():
                o = self.targets[j]
                if j <= k or o.track_id == t.track_id or t.track_id not in heads or o.track_id not in heads:
                    continue
                d = np.subtract(pos, other)
                h = np.subtract(heads[t.track_id], heads[o.track_id])
                if float(d @ h) < -c * np.linalg.norm(d) * np.linalg.norm(h):
                    out[k], out[j] = other, pos
        return out

    def _split(self, t: _Target, mode, head) -> None:
        """``t`` leaves its combined pair with ``mode`` (:meth:`_split_position`)."""
        t.position = self._split_position(t, mode, head)
        if t.filter is None:
            t.filter = TargetFilter(t.position, self.params.dynamics, self.rng)
        else:
            t.filter.reset(t.position)
        t.labelled = True  # the direction cue (sec. 7.1) keeps its label
        t.returning = self._line_of_sight

    @property
    def _line_of_sight(self) -> bool:
        """``dynamics.line_of_sight``, with three views or more: with two, ``p_b`` says nothing (a
        pair's projections lie on both silhouettes by construction), a pair through a hand's blob is
        anybody's, and the 2-camera handshake got worse (docs/measurements/limbs3d.md)."""
        return self.params.dynamics.line_of_sight and len(self.cameras) >= 3

    def _without_pairs(self, t: _Target, state: LimbState, a: int, use: np.ndarray, use_w: np.ndarray, gate: float,
                       preds: np.ndarray, centres: list, views: list, points: np.ndarray, weights: np.ndarray,
                       head) -> tuple[np.ndarray, np.ndarray, bool]:
        """The candidates (and priors) target ``t`` (``a``: its index in ``preds``) is weighed with,
        from ``use``: with no candidate from pairs of views within ``gate`` of its prediction, its
        single-view candidates (``dynamics.single_view_prior``), or, with ``dynamics.line_of_sight``,
        the candidate on its line of sight another view gives it (:meth:`_through_own_blob`, the
        filter put there); also whether it is tracked alone from pairs of views (its ``home``)."""
        p = self.params
        d = p.dynamics
        states = (LimbState.NORMAL, LimbState.LOST, LimbState.COMBINED) if self._line_of_sight else (LimbState.NORMAL,)
        if not (state in states and d.single_view_prior > 0) or (
                len(use) and (np.linalg.norm(use - preds[a], axis=1) < gate).any()):
            t.sight, t.sight_frames, t.alone_frames, t.own = None, 0, 0, {}
            others = np.delete(preds, a, axis=0)
            alone = state == LimbState.NORMAL and t.part != "head" and len(use) > 0 and not (
                len(others) and np.linalg.norm(others - preds[a], axis=1).min() < p.states.split_distance)
            return use, use_w, alone
        toward = head + t.home if t.returning and t.home is not None and head is not None else None
        picks: dict = {}
        single = self._single_view(preds[a], centres, np.delete(preds, a, axis=0), views, toward, picks)
        t.alone_frames += 1
        t.own = {m: (uv, age + 1) for m, (uv, age) in t.own.items() if age < p.states.lost_frames}
        t.own.update({m: (uv, 0) for m, uv in picks.items()})
        j = -1  # a target that just lost its pairs is not yet one seen by a single view (two hands that
        # part: the other's blob is nearest its projection)
        if state != LimbState.COMBINED and t.part != "head" and t.alone_frames > p.states.lost_frames:
            j = self._through_own_blob(t, preds[a], centres, points, weights, head, state != LimbState.LOST)
        if j >= 0:  # another view tells the depth along its line of sight
            same = t.sight is not None and np.linalg.norm(points[j] - t.sight) < d.candidate_gate
            t.sight, t.sight_frames = points[j], (t.sight_frames + 1 if same else 1)
            if t.sight_frames >= p.states.start_frames:
                t.filter.reset(points[j])
                return points[j:j + 1], weights[j:j + 1], False
        else:
            t.sight, t.sight_frames = None, 0
        if state == LimbState.LOST:
            return use, use_w, False
        return (np.vstack([use.reshape(-1, 3), single]),
                np.concatenate([use_w, np.full(len(single), d.single_view_prior)]), False)

    def _rivals(self, a: int, lost: np.ndarray) -> np.ndarray:
        """The active targets (indices) whose predictions compete with target ``a``'s for candidates:
        every other one, except that a lost target held where it was lost takes nothing from a
        tracked one (``dynamics.lost_yield``)."""
        rivals = np.delete(np.arange(len(lost)), a)
        if self.params.dynamics.lost_yield and not lost[a]:
            rivals = rivals[~lost[rivals]]
        return rivals

    def _single_view(self, pred: np.ndarray, centres: list[np.ndarray], others: np.ndarray,
                     views: list | None = None, toward: np.ndarray | None = None,
                     picks: dict | None = None) -> np.ndarray:
        """Single-view candidates ``(K, 3)`` of a target predicted at ``pred`` (see
        ``dynamics.single_view_prior``): per view, the blob nearest the prediction's projection
        within ``single_view_gate`` mm (``single_view_gate_alone`` when only one view has blobs)
        that is nearer to it than to every other target's projection (``others (M, 3)``), at the
        point of the blob's line of sight nearest ``pred`` (with ``dynamics.single_view_support``
        and ``views``, the silhouette measures of every view, the nearest such point hidden by a
        silhouette in every other view, :meth:`_hidden_depth`); with ``toward``, the point of the
        line nearest that point instead of the prediction; ``picks`` gets each view's blob taken
        (view -> its centre)."""
        out = []
        for m, (cam, cen) in enumerate(zip(self.cameras, centres)):
            cen = np.asarray(cen, float).reshape(-1, 2)
            depth = cam.to_camera(pred[None])[0, 2]
            if not len(cen) or depth <= 0:
                continue
            gate = self.params.dynamics.single_view_gate
            if sum(len(c) > 0 for c in centres) < 2:  # one view sees skin: nothing is triangulated
                gate = max(gate, self.params.dynamics.single_view_gate_alone)
            j = self._single_view_blob(cam, pred, cen, others, cam.K[0, 0] * gate / depth)
            if j < 0:
                continue
            if picks is not None:
                picks[m] = cen[j].copy()
            v = cam.rays(cen[j:j + 1])[0]
            s = float(v @ ((pred if toward is None else toward) - cam.centre))
            if self.params.dynamics.single_view_support > 0 and views is not None:
                s = self._hidden_depth(m, v, s, views)
            out.append(cam.centre + v * s)
        return np.array(out).reshape(-1, 3)

    def _through_own_blob(self, t: _Target, pred: np.ndarray, centres: list[np.ndarray], points: np.ndarray,
                          weights: np.ndarray, head, share: bool = True) -> int:
        """The merged candidate (index, -1 for none) that a target predicted at ``pred`` with no
        candidate from pairs of views in its gate takes wherever it lies along its line of sight
        (``dynamics.line_of_sight``): in each view, the blob nearest where its own blob was last seen
        (``own``, up to ``states.lost_frames`` frames ago) within ``single_view_gate`` mm (at its
        depth) is its own (two hands that touch make one blob, nearer the other's projection), and
        of the candidates of prior at least
        ``states.start_prior`` made from one of those and a blob of another view, within
        ``hand_reach`` of its person's head for a hand, none of whose blobs is another target's
        image (:meth:`_explained`; for a lost one, ``share`` False, none shared with anybody), the
        strongest. With ``dynamics.sight_meeting``, none where two other tracked hands already are
        (both estimates within ``split_distance``): held-out 3-camera handshake seed 14, person 2's
        left hand (hidden, 75 mm off) was put on the exchange of person 1's left and person 2's right
        hand, 540 mm from its own, and took part in it from there."""
        d = self.params.dynamics
        members = self.last.get("members")
        if not self._line_of_sight or members is None or not len(points):
            return -1
        mine = set()
        for m, (uv, _) in t.own.items():
            cam, cen = self.cameras[m], np.asarray(centres[m], float).reshape(-1, 2)
            depth = cam.to_camera(pred[None])[0, 2]
            if len(cen) and depth > 0:
                dist = np.linalg.norm(cen - uv, axis=1)
                j = int(np.argmin(dist))
                if dist[j] <= cam.K[0, 0] * d.single_view_gate / depth:
                    mine.add(int(blob_keys(np.array([m]), np.array([j]))[0]))
        ok = np.array([bool(mine & ms) for ms in members]) & (weights >= self.params.states.start_prior)
        if d.hand_reach > 0 and t.part != "head" and head is not None:
            ok &= np.linalg.norm(points - head, axis=1) <= d.hand_reach
        if self.params.states.foreign_use > 0 and t.part != "head" and head is not None:
            ok &= ~self._foreign_points(t, points, head)
        side = self._side(t) if d.hand_side > 0 and t.part != "head" and head is not None else None
        if side is not None:
            ok &= (points - head) @ side >= -d.hand_side
        for i in np.flatnonzero(ok):
            ok[i] = not self._explained(t, points[i], members[i], share)
        if d.sight_meeting and ok.any():
            hands = [o.position for k, o in self.targets.items() if o is not t and o.part != "head"
                     and o.position is not None and o.filter is not None
                     and self.machine.state(k) in (LimbState.NORMAL, LimbState.COMBINED)]
            if len(hands) >= 2:
                near = np.linalg.norm(points[:, None] - np.array(hands)[None], axis=-1) < (
                    self.params.states.split_distance)
                ok &= near.sum(axis=1) < 2  # two other hands meet there
        if not ok.any():
            return -1
        return int(np.flatnonzero(ok)[np.argmax(weights[ok])])

    def _explained(self, t: _Target, point: np.ndarray, keys: set, share: bool = True) -> bool:
        """Whether one of the blobs ``keys`` (view-blob keys) is another target's image: the
        projection nearest it is another target's, of the same person or whose estimate is more
        than ``split_distance`` from ``point`` (another person's hand there shares the blob: two
        people's hands that touch; a person's two hands on one line of sight in one view do not
        tell that they touch: handshake seed 7, 3 cameras, the right hand went to the left's).
        ``share`` False (a lost target): no blob is shared."""
        others = [o for o in self.targets.values() if o is not t and o.position is not None and o.filter is not None]
        if not others:
            return False
        pos = np.array([o.position for o in others])
        far = np.linalg.norm(pos - point, axis=1) > self.params.states.split_distance
        far |= np.array([o.track_id == t.track_id or not share for o in others])
        for key in keys:
            m, j = split_key(key)
            cam = self.cameras[m]
            blob = self._centres[m][j]
            d_other = np.linalg.norm(cam.project(pos) - blob, axis=1)
            d_own = np.linalg.norm(cam.project(t.position[None])[0] - blob)
            i = int(np.argmin(d_other))
            if d_other[i] < d_own and far[i]:
                return True
        return False

    @staticmethod
    def _single_view_blob(cam: Camera, pred: np.ndarray, cen: np.ndarray, others: np.ndarray, gate: float) -> int:
        """The blob (index, -1 for none) of ``cen (K, 2)`` a target predicted at ``pred`` takes in one
        view: the nearest its projection within ``gate`` pixels that is nearer to it than to every
        other target's projection."""
        dist = np.linalg.norm(cen - cam.project(pred[None])[0], axis=1)
        mine = dist
        if len(others):
            d_other = np.linalg.norm(cen[:, None] - cam.project(others)[None], axis=-1).min(axis=1)
            mine = np.where(dist < d_other, dist, np.inf)
        j = int(np.argmin(mine))
        return j if mine[j] <= gate else -1

    def _hidden_depth(self, m: int, v: np.ndarray, s: float, views: list) -> float:
        """The distance along view ``m``'s line of sight ``v`` (from its centre), within
        ``single_view_depth`` of ``s``, nearest ``s`` whose point lies in the room and projects within
        ``single_view_support`` pixels of a silhouette in every other view that has one; ``s``
        itself when none does."""
        d = self.params.dynamics
        step = 10.0
        ts = s + np.arange(-d.single_view_depth, d.single_view_depth + step, step)
        ts = ts[ts > 0]
        if not len(ts):
            return s
        pts = self.cameras[m].centre + ts[:, None] * v
        ok = (pts[:, 2] > 0) & (pts[:, 2] < self.params.priors.max_height)
        for k, (cam, view) in enumerate(zip(self.cameras, views)):
            if k == m or not view.has_silhouette:
                continue
            ok &= silhouette_distance(cam, view, pts) <= d.single_view_support
        if not ok.any():
            return s
        return float(ts[ok][np.argmin(np.abs(ts[ok] - s))])

    def _usable(self, t: _Target, points: np.ndarray, mine, others, head) -> np.ndarray:
        """The candidates target ``t`` may use: those no other target's prediction is nearer to
        (``mine``/``others``: distances to its and the other active targets' predictions, None with
        one target) and, for a hand, within ``hand_reach`` of its person's head estimate ``head``."""
        d = self.params.dynamics
        use = (mine <= d.exclusive_ratio * others.min(axis=1)) if mine is not None else np.ones(len(points), bool)
        if d.hand_reach > 0 and t.part != "head" and head is not None and len(points):
            use &= np.linalg.norm(points - head, axis=1) <= d.hand_reach
        if self.params.states.foreign_use > 0 and t.part != "head" and head is not None and len(points):
            use &= ~self._foreign_points(t, points, head)
        if d.hand_side > 0 and t.part != "head" and head is not None and len(points):
            side = self._side(t)
            if side is not None:
                use &= (points - head) @ side >= -d.hand_side
        if d.head_own_blobs and t.part == "head" and len(points):
            use &= ~self._borrowed(t, len(points))
        if (d.hand_own_blobs > 0 and len(self.cameras) <= d.hand_own_blobs_cameras and t.part != "head"
                and len(points) and mine is not None):
            use &= ~self._ghost_of_claim(t, points, mine)
        return use

    def _ghost_of_claim(self, t: _Target, points: np.ndarray, mine: np.ndarray) -> np.ndarray:
        """``(K,)`` whether each candidate shares a blob with the candidate another tracked target of
        the same person claims (``_claims``) of as many views or more, lies more than ``dynamics.hand_own_blobs``
        mm from it, and is farther from this hand's prediction (``mine``) than the claimed one is
        from its claimant's: one blob seen at two places far apart is one target's image, and the
        pair it makes with this hand's blob of another view a ghost on that blob's line of sight
        (sec. 6.4)."""
        members = self.last.get("members") or []
        out = np.zeros(len(points), bool)
        if len(members) != len(points):
            return out
        views = [len({split_key(k)[0] for k in m}) for m in members]
        far = self.params.dynamics.hand_own_blobs
        for _, i, key, d_claim in getattr(self, "_claims", []):
            if self.targets[key] is t or self.targets[key].track_id != t.track_id:
                continue
            for j in range(len(points)):
                if (j != i and views[j] <= views[i] and members[j] & members[i] and mine[j] > d_claim
                        and np.linalg.norm(points[j] - points[i]) > far):
                    out[j] = True
        return out

    def _borrowed(self, t: _Target, n: int) -> np.ndarray:
        """``(n,)`` whether each of the ``n`` merged candidates shares a blob with the candidate
        another person's tracked target claims (``_claims``: the one nearest its prediction, within
        ``dynamics.candidate_gate``) when that one spans more views (``dynamics.head_own_blobs``):
        the blob is the other target's image, and the pair it makes here a ghost (sec. 6.4)."""
        members = self.last.get("members") or []
        out = np.zeros(n, bool)
        if len(members) != n:
            return out
        views = [len({split_key(k)[0] for k in m}) for m in members]
        for track_id, i, *_ in getattr(self, "_claims", []):
            if track_id == t.track_id:
                continue
            for j in range(n):
                if j != i and views[j] < views[i] and members[j] & members[i]:
                    out[j] = True
        return out

    def _single_view_mode(self, est, modes: tuple, points: np.ndarray, idx: np.ndarray, centres,
                          others: np.ndarray) -> tuple:
        """``modes`` (at most one, from pairs of views) and a second one seen by a single view: a
        combined pair whose hands part where one of them is hidden from all views but one shows
        one mode of pairs and, in that view, a second blob (``dynamics.line_of_sight``). Of the
        blobs within ``mode_search`` split distances of the estimate's projection (at its depth),
        not one of the first mode's and nearer to it than to every other target's projection
        (``others``), the one whose line of sight passes nearest the estimate, at the point of that
        line nearest the estimate, if that is ``combine_distance`` or more from the first mode."""
        p = self.params
        members = self.last.get("members") or []
        first = np.asarray(modes[0], float) if modes else np.asarray(est, float)
        taken: set = set()
        if modes and len(points):
            near = idx[int(np.argmin(np.linalg.norm(points - first, axis=1)))]
            taken = set(members[near]) if near < len(members) else set()
        best, best_d = None, np.inf
        for m, (cam, cen) in enumerate(zip(self.cameras, centres)):
            cen = np.asarray(cen, float).reshape(-1, 2)
            depth = cam.to_camera(np.asarray(est, float)[None])[0, 2]
            if not len(cen) or depth <= 0:
                continue
            keys = blob_keys(np.full(len(cen), m), np.arange(len(cen)))
            free = np.array([int(key) not in taken for key in keys])
            if not free.any():
                continue
            gate = cam.K[0, 0] * p.states.mode_search * p.states.split_distance / depth
            j = self._single_view_blob(cam, np.asarray(est, float), np.where(free[:, None], cen, np.inf), others,
                                       gate)
            if j < 0:
                continue
            v = cam.rays(cen[j:j + 1])[0]
            point = cam.centre + v * float(v @ (np.asarray(est, float) - cam.centre))
            d = float(np.linalg.norm(point - np.asarray(est, float)))
            if d < best_d and np.linalg.norm(point - first) >= p.states.combine_distance:
                best, best_d = (point, m, v), d
        if best is None:
            return modes
        self._sight_modes.append((np.asarray(best[0], float), best[1], best[2]))
        return (tuple(first), tuple(best[0]))

    def _pair_heads(self, k: int, heads: dict) -> list:
        """The heads of combined target ``k``'s and its partner's people when they are two people."""
        partner = self.machine.partner(k)
        if partner is None:
            return []
        ids = {self.targets[k].track_id, self.targets[partner].track_id}
        return [heads[i] for i in ids if i in heads] if len(ids) == 2 else []

    def _combined_modes(self, t: _Target, est, idx: np.ndarray, points: np.ndarray, weights: np.ndarray, centres,
                        others: np.ndarray, pair_heads: list | None = None) -> tuple:
        """The modes of combined target ``t`` (the pair's leader) from the candidates ``idx`` it may
        use (:meth:`_modes`) and, with ``dynamics.line_of_sight`` and one mode of pairs, a second
        seen by a single view once it parts (:meth:`_single_view_mode`, :meth:`_parting`)."""
        modes = self._modes(est, points[idx], weights[idx])
        if len(modes) == 1 and pair_heads:
            modes = self._mode_towards_head(modes, points[idx], weights[idx], pair_heads)
        if len(modes) >= 2 or not self._line_of_sight:
            t.parting = []
            return modes
        return self._parting(t, self._single_view_mode(est, modes, points[idx], idx, centres, others))

    def _parting(self, t: _Target, modes: tuple) -> tuple:
        """``modes`` with a second one seen by a single view only once it has moved away from the
        first for ``states.start_frames`` frames in a row (sec. 5.2: the modes "move apart when the
        targets move away from each other"; a blob of a sleeve or an object next to two hands that
        touch is one frame's mode and does not move away)."""
        if len(modes) < 2:
            t.parting = []
            return modes
        d = float(np.linalg.norm(np.subtract(modes[1], modes[0])))
        t.parting = t.parting + [d] if t.parting and d >= t.parting[-1] else [d]
        return modes if len(t.parting) >= self.params.states.start_frames else modes[:1]

    def _split_position(self, t: _Target, mode, head) -> np.ndarray:
        """Where a target that leaves a combined pair with ``mode`` starts: the mode, or for the mode
        seen by a single view (:meth:`_single_view_mode`), the point of its line of sight nearest
        where the target was, relative to its person's head, when last tracked alone from pairs of
        views (``home``): one view cannot tell how far back the hand goes, and after a handshake or a
        clap it goes back where it came from (the direction cue of sec. 7.1 on the depth)."""
        mode = np.asarray(mode, float)
        sight = [s for s in self._sight_modes if np.allclose(mode, s[0])]
        if not sight or t.home is None or head is None:
            return mode
        cam, v = self.cameras[sight[0][1]], sight[0][2]
        return cam.centre + v * float(v @ (np.asarray(head, float) + t.home - cam.centre))

    def _mode_towards_head(self, modes: tuple, points: np.ndarray, weights: np.ndarray, pair_heads: list) -> tuple:
        """``modes`` (one) and, for a pair of two people's hands, a second: the strongest candidate
        beyond the usual search but within ``states.mode_search_heads`` split distances of the first
        that is nearer one of the two heads than the first and within
        ``dynamics.hand_reach`` of it (a hand leaving a handshake while hidden comes back on its own
        person's side, out of the pair's reach)."""
        p = self.params
        if p.states.mode_search_heads <= p.states.mode_search or not len(points):
            return modes
        first = np.asarray(modes[0], float)
        d = np.linalg.norm(points - first, axis=1)
        ok = (d >= p.states.mode_search * p.states.split_distance) & (
            d < p.states.mode_search_heads * p.states.split_distance) & (weights >= p.states.mode_heads_prior)
        towards = np.zeros(len(points), bool)
        for h in pair_heads:
            dh = np.linalg.norm(points - h, axis=1)
            towards |= (dh < np.linalg.norm(first - h)) & (
                dh <= (p.dynamics.hand_reach or np.inf))
        ok &= towards
        if not ok.any():
            return modes
        return (modes[0], tuple(points[np.flatnonzero(ok)[np.argmax(weights[ok])]]))

    def _modes(self, est, points, weights) -> tuple:
        """The combined posterior's two strongest modes: the strongest candidate near the filter,
        then the strongest at least ``combine_distance`` from it."""
        p = self.params
        if len(points) == 0:
            return ()
        near = np.linalg.norm(points - est, axis=1) < p.states.mode_search * p.states.split_distance
        pts, w = points[near], weights[near]
        if len(pts) < 2:
            return tuple(map(tuple, pts))
        order = np.argsort(-w, kind="stable")
        first = pts[order[0]]
        rest = [i for i in order[1:] if np.linalg.norm(pts[i] - first) >= p.states.combine_distance]
        return (tuple(first),) if not rest else (tuple(first), tuple(pts[rest[0]]))

    # -- 5. output ------------------------------------------------------------------------------
    def _records(self, index: int) -> list[TrackRecord]:
        out = []
        for key, t in self.targets.items():
            state = self.machine.state(key)
            if state == LimbState.UNINITIALIZED or t.position is None or t.start_frame > index:
                continue
            conf = self.targets[key].filter.confidence if t.filter is not None else 0.0
            X, Y, Z = (float(v) for v in t.position)
            for stream, cam in zip(self.streams, self.cameras):
                uv, r = self._project(cam, t)
                out.append(TrackRecord(index, t.track_id, t.part, Box(float(uv[0] - r), float(uv[1] - r),
                                                                      float(2 * r), float(2 * r)),
                                       score=round(conf, 4), state=state.value, camera=stream, X=X, Y=Y, Z=Z))
        return out

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        return records_to_frame(records) if records else empty_tracks()
