"""Depth and stereo scenes with exact truth: a person facing a camera, hands moving fast.

The setting of Xu, Deng & Jia (sec. 2, Fig. 1): one person facing a calibrated stereo rig, upper
body upright, face and hands tracked while the hands move quickly and turn suddenly. Unlike the
walkers of :mod:`.scene` (drawn in 2D), these figures are 3D solids ray-cast through a pinhole
camera into a z-buffer, so colour, depth and the 3D truth agree exactly:

- the body: an ellipsoid head (face in skin, a hair cap), a neck, an ellipsoid torso, upper arms
  and forearms (sphere-swept capsules in the sleeve colour), round hands in skin, and for the
  ``standing`` scenario a pelvis and legs; every size a fraction of the person's randomised height;
- the room: a textured back wall and floor, and for ``desk`` a desk top in front of the person;
- shading: Lambertian under a random light, plus a texture that is a function of the 3D surface
  point (so the left and right images of a stereo pair show the same texture, as real cloth and
  skin do, and block matching has something to match);
- the hands move along random keyframes at up to ~3 m/s with sudden turns, in front of the torso
  (Xu, Deng & Jia's constraint 1); the elbows follow by two-link inverse kinematics.

World frame = the left camera (x right, y down, z forward, millimetres). The right camera sits
``baseline`` mm to the right, slightly rotated, so :func:`cv2.stereoRectify` has real work to do.

Truth (a tracks table): ``head``, ``left_hand``, ``right_hand`` boxes (tight extent of the pixels
the left camera sees of them) with ``X,Y,Z`` the part's centre; ``left/right_shoulder`` and
``left/right_elbow`` joints (a small box around the projected joint) with their 3D centres;
``torso`` box. ``occluded`` is the fraction of a part's silhouette not seen (hidden by the
person's other parts, or outside the frame); a part wholly outside the frame has no row (as in
:mod:`.scene`): fast hands of a person near the camera leave the field of view now and then.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from partlab.labelling.synth.appearance import sample_appearances
from partlab.tracking.camera import Camera
from partlab.tracking.tracks import normalise_tracks

DEPTH_SCENARIOS: tuple[str, ...] = ("desk_depth", "standing_depth")
FPS = 25.0

# label ids of the z-buffer's owner image
ROOM, HEAD, HAND_L, HAND_R, TORSO, ARM_L, ARM_R, NECK, LEGS, DESK = range(10)
_TRUTH_LABELS = {"head": (HEAD,), "left_hand": (HAND_L,), "right_hand": (HAND_R,), "torso": (TORSO,)}


@dataclass(frozen=True, eq=False)
class DepthScene:
    """``frames``/``right``: ``(T, H, W, 3) uint8`` BGR left and right views; ``depth``: ``(T, H, W)
    float32`` mm along the left camera's axis (exact z-buffer); ``labels``: ``(T, H, W) uint8``
    owner ids; ``truth``/``init``: tracks tables (see the module docstring); ``cameras``: the left
    (``cam0``) and right (``cam0_right``) calibrations; ``fps``."""

    frames: np.ndarray
    right: np.ndarray
    depth: np.ndarray
    labels: np.ndarray
    truth: pd.DataFrame
    init: pd.DataFrame
    cameras: dict[str, Camera]
    fps: float
    meta: dict


# -- geometry of one frame ---------------------------------------------------------------------

@dataclass(frozen=True)
class _Body:
    """Sizes (mm) of one person, fractions of the height ``H`` (adult proportions), with the
    shoulders' width and the arms' lengths varied per person (``shoulders``, ``arms``: factors)."""

    H: float
    shoulders: float = 1.0
    arms: float = 1.0

    @property
    def head_r(self):  # ellipsoid radii x, y, z
        return np.array([0.050, 0.066, 0.058]) * self.H

    @property
    def torso_r(self):
        return np.array([0.105, 0.16, 0.065]) * self.H

    @property
    def shoulder_half(self):
        return 0.118 * self.H * self.shoulders

    @property
    def upper_arm(self):
        return 0.17 * self.H * self.arms

    @property
    def forearm(self):
        return 0.15 * self.H * self.arms

    @property
    def arm_r(self):
        return 0.026 * self.H

    @property
    def hand_r(self):
        return 0.030 * self.H


def _elbow(shoulder: np.ndarray, hand: np.ndarray, l1: float, l2: float, side: float) -> np.ndarray:
    """Two-link inverse kinematics: the elbow below and outside the shoulder-hand line."""
    d = hand - shoulder
    dist = np.linalg.norm(d, axis=-1, keepdims=True)
    reach = np.clip(dist, 1e-6, (l1 + l2) * 0.999)
    u = d / np.maximum(dist, 1e-6)
    a = (l1 ** 2 - l2 ** 2 + reach ** 2) / (2 * reach)
    h = np.sqrt(np.clip(l1 ** 2 - a ** 2, 0, None))
    pole = np.array([0.6 * side, 1.0, 0.25])  # down (+y), outward, a little back
    pole = pole - (pole * u).sum(-1, keepdims=True) * u
    pole /= np.maximum(np.linalg.norm(pole, axis=-1, keepdims=True), 1e-9)
    return shoulder + a * u + h * pole


def _hand_paths(rng: np.random.Generator, n: int, centre: np.ndarray, body: _Body, fast: float) -> np.ndarray:
    """``(n, 2, 3)`` hand centres [left, right]: random keyframes every 0.2-0.6 s joined by
    smoothstep, in front of the torso, each hand on its own side (the paper's hands never overlap)."""
    out = np.empty((n, 2, 3))
    H = body.H
    for k, side in enumerate((1.0, -1.0)):  # the person's left hand is on image right (facing us)
        keys_t, keys_p = [0.0], []
        t = 0.0
        while t < n / FPS + 1:
            t += rng.uniform(0.2, 0.6) / fast
            keys_t.append(t)
        for _ in keys_t:
            x = side * rng.uniform(0.06, 0.30) * H
            y = rng.uniform(-0.14, 0.16) * H  # from face height to the waist
            z = -rng.uniform(0.10, 0.22) * H  # in front of the torso
            keys_p.append(centre + np.array([x, y, z]))
        keys_t, keys_p = np.array(keys_t), np.array(keys_p)
        ts = np.arange(n) / FPS
        j = np.clip(np.searchsorted(keys_t, ts, side="right") - 1, 0, len(keys_t) - 2)
        u = (ts - keys_t[j]) / (keys_t[j + 1] - keys_t[j])
        s = u * u * (3 - 2 * u)
        out[:, k] = keys_p[j] * (1 - s)[:, None] + keys_p[j + 1] * s[:, None]
    return out


# -- ray casting -------------------------------------------------------------------------------

class _Buffer:
    """z-buffer of one view: depth, owner label, normal (camera axes) and base colour."""

    def __init__(self, camera: Camera):
        w, h = camera.size
        self.cam = camera
        u, v = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
        K = camera.K
        self.dx = (u - K[0, 2]) / K[0, 0]  # ray (dx, dy, 1) in camera coordinates
        self.dy = (v - K[1, 2]) / K[1, 1]
        self.z = np.full((h, w), np.inf)
        self.label = np.zeros((h, w), np.uint8)
        self.colour = np.zeros((h, w, 3))
        self.normal = np.zeros((h, w, 3))

    def points(self) -> np.ndarray:
        """``(H, W, 3)`` world points of the visible surface (from the z-buffer)."""
        z = np.where(np.isfinite(self.z), self.z, 0.0)
        cam = np.stack([self.dx * z, self.dy * z, z], -1)
        return (cam - self.cam.t) @ self.cam.R

    def world_normals(self) -> np.ndarray:
        return self.normal @ self.cam.R

    def _box(self, c: np.ndarray, r: float):
        """Pixel window that can see a sphere of radius ``r`` at camera point ``c``."""
        K = self.cam.K
        w, h = self.cam.size
        if c[2] - r <= 1.0:
            return None
        zmin = max(c[2] - r, 1.0)
        rad = r * K[0, 0] / zmin * 1.2 + 2
        u = K[0, 0] * c[0] / c[2] + K[0, 2]
        v = K[1, 1] * c[1] / c[2] + K[1, 2]
        x1, x2 = int(max(u - rad, 0)), int(min(u + rad + 1, w))
        y1, y2 = int(max(v - rad, 0)), int(min(v + rad + 1, h))
        return (slice(y1, y2), slice(x1, x2)) if x1 < x2 and y1 < y2 else None

    def _write(self, win, t, hit, label, colour, normal_cam):
        zc = self.z[win]
        take = hit & (t < zc)
        if not take.any():
            return
        zc[take] = t[take]
        self.label[win][take] = label
        self.colour[win][take] = np.broadcast_to(colour, take.shape + (3,))[take]
        self.normal[win][take] = normal_cam[take]

    def ellipsoid(self, centre_w: np.ndarray, radii: np.ndarray, label: int, colour) -> None:
        """An axis-aligned (in the world) ellipsoid; ``colour``: BGR or a function of the local
        unit-sphere hit point returning ``(N, 3)``."""
        c = self.cam.R @ centre_w + self.cam.t
        win = self._box(c, float(radii.max()))
        if win is None:
            return
        Rt = self.cam.R  # world axes in camera coordinates: columns of R
        dx, dy = self.dx[win], self.dy[win]
        d = np.stack([dx, dy, np.ones_like(dx)], -1) @ Rt  # ray direction in world axes (R^T d)
        o = (-c) @ Rt  # camera origin relative to the centre, world axes
        ds, os_ = d / radii, o / radii
        a = (ds * ds).sum(-1)
        b = 2 * (ds * os_).sum(-1)
        cc = (os_ * os_).sum() - 1
        disc = b * b - 4 * a * cc
        hit = disc >= 0
        t = (-b - np.sqrt(np.where(hit, disc, 0))) / (2 * a)
        hit &= t > 0
        local = os_ + t[..., None] * ds  # unit sphere point
        n_w = local / radii
        n_w /= np.maximum(np.linalg.norm(n_w, axis=-1, keepdims=True), 1e-9)
        n_cam = n_w @ self.cam.R.T
        col = colour(local) if callable(colour) else np.broadcast_to(np.asarray(colour, float), local.shape)
        self._write(win, t, hit, label, col, n_cam)

    def capsule(self, a_w: np.ndarray, b_w: np.ndarray, r: float, label: int, colour) -> None:
        """A sphere-swept segment (spheres every r/2 along it: bumps of 3% of the radius)."""
        n = max(2, int(np.ceil(np.linalg.norm(b_w - a_w) / (r / 2))) + 1)
        for s in np.linspace(0, 1, n):
            self.ellipsoid(a_w + s * (b_w - a_w), np.array([r, r, r]), label, colour)

    def plane(self, normal_w: np.ndarray, offset: float, label: int, colour_fn, bounds=None) -> None:
        """The plane ``n . X = offset`` (world), coloured by ``colour_fn(points (N, 3)) -> (N, 3)``;
        ``bounds(points) -> bool mask`` limits it (the desk top)."""
        R, tt = self.cam.R, self.cam.t
        n_c = R @ normal_w
        off_c = offset + n_c @ tt  # n_c . X_cam = off_c
        denom = n_c[0] * self.dx + n_c[1] * self.dy + n_c[2]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(np.abs(denom) > 1e-9, off_c / denom, -1.0)
        hit = t > 0
        pts_cam = np.stack([self.dx * t, self.dy * t, t], -1)
        pts_w = (pts_cam - tt) @ R
        if bounds is not None:
            hit &= bounds(pts_w)
        win = (slice(None), slice(None))
        col = np.zeros(pts_w.shape)
        col[hit] = colour_fn(pts_w[hit])
        self._write(win, t, hit, label, col, np.broadcast_to(n_c, pts_cam.shape))


def _texture(rng: np.random.Generator, period_mm: float, n: int = 4):
    """A smooth 3D texture ``f(points (N, 3)) -> (N,)`` in [-1, 1]: sums of plane waves."""
    k = rng.normal(size=(n, 3))
    k /= np.linalg.norm(k, axis=1, keepdims=True)
    k *= 2 * np.pi / (period_mm * rng.uniform(0.6, 1.4, n))[:, None]
    ph = rng.uniform(0, 2 * np.pi, n)

    def f(p):
        return np.sin(np.asarray(p) @ k.T + ph).mean(-1)

    return f


# -- the scene ---------------------------------------------------------------------------------

def _cameras(rng: np.random.Generator, width: int, height: int) -> dict[str, Camera]:
    f = width * rng.uniform(0.9, 1.05)  # about 57-63 degrees across, a webcam
    K = np.array([[f, 0, width / 2 + rng.uniform(-3, 3)], [0, f, height / 2 + rng.uniform(-3, 3)], [0, 0, 1]])
    baseline = rng.uniform(90, 130)
    rvec = np.deg2rad(rng.uniform(-1.0, 1.0, 3))  # the right camera is not perfectly parallel
    R = cv2.Rodrigues(rvec)[0]
    t = -R @ np.array([baseline, 0.0, 0.0])
    left = Camera("cam0", K, (width, height))
    right = Camera("cam0_right", K.copy(), (width, height), R=R, t=t)
    return {"cam0": left, "cam0_right": right}


@dataclass(frozen=True, eq=False)
class _Layout:
    """Where everything is (world mm, the left camera's frame) for one scene: the person's body,
    the cameras, the room's planes and the fixed joints (head, neck, shoulders)."""

    name: str
    body: _Body
    cams: dict[str, Camera]
    distance: float
    wall_z: float
    torso_c: np.ndarray
    neck_top: np.ndarray
    head_c: np.ndarray
    shoulders: np.ndarray  # (2, 3) [left, right]; the person's left is image right
    floor_y: float
    desk_y: float


def _layout(rng: np.random.Generator, name: str, height_mm: float, width: int, height: int) -> _Layout:
    """Proportions (shoulders +-7 %, arms +-6 %), cameras, distance and the room, in that draw order."""
    body = _Body(height_mm, float(rng.uniform(0.93, 1.07)), float(rng.uniform(0.94, 1.06)))
    H = body.H
    cams = _cameras(rng, width, height)
    distance = rng.uniform(1100, 1600) if name == "desk_depth" else rng.uniform(1500, 2100)
    wall_z = distance + rng.uniform(900, 1800)
    # the torso centre: the upper body fills the middle of the frame, a little left or right
    torso_c = np.array([rng.uniform(-0.08, 0.08) * distance * width / cams["cam0"].K[0, 0],
                        rng.uniform(-0.02, 0.05) * H, distance])
    neck_top = torso_c + np.array([0, -body.torso_r[1] - 0.02 * H, 0])
    head_c = neck_top + np.array([0, -body.head_r[1] * 0.95, -0.01 * H])
    shoulders = np.array([torso_c + np.array([s * body.shoulder_half, -body.torso_r[1] * 0.78, 0])
                          for s in (1.0, -1.0)])
    floor_y = torso_c[1] + 0.42 * H if name == "standing_depth" else torso_c[1] + 0.55 * H
    desk_y = torso_c[1] + 0.13 * H  # desk top below the elbows
    return _Layout(name, body, cams, float(distance), float(wall_z), torso_c, neck_top, head_c, shoulders,
                   float(floor_y), float(desk_y))


def _arms(seed: int, lay: _Layout, n_frames: int, fast: float) -> tuple[np.ndarray, np.ndarray]:
    """``(hands, elbows)``, each ``(n_frames, 2, 3)``: the hands' paths (their own random stream,
    over at least 60 s, so a shorter clip of the same seed is a prefix), kept above the desk top and
    within reach, and the elbows by two-link inverse kinematics."""
    body, H = lay.body, lay.body.H
    index = DEPTH_SCENARIOS.index(lay.name)
    paths = _hand_paths(np.random.default_rng([seed, 200 + index]), max(n_frames, 1500),
                        lay.torso_c + np.array([0, 0.02 * H, 0]), body, fast)
    hands = paths[:n_frames].copy()
    if lay.name == "desk_depth":
        hands[..., 1] = np.minimum(hands[..., 1], lay.desk_y - 1.5 * body.hand_r)  # above the desk top
    elbows = np.stack([_elbow(lay.shoulders[k], hands[:, k], body.upper_arm, body.forearm, (1.0, -1.0)[k])
                       for k in range(2)], 1)
    # reach: keep each hand within the arm's length of its shoulder
    for k in range(2):
        d = hands[:, k] - lay.shoulders[k]
        L = np.linalg.norm(d, axis=1, keepdims=True)
        hands[:, k] = lay.shoulders[k] + d * np.minimum(1.0, (body.upper_arm + body.forearm) * 0.98 / L)
    return hands, elbows


# desk tops: grey, white, dark, blue-grey (a skin-hued wood top is a colour distractor of its own,
# the limb tracker's desk scene; here the hands' depth is under test)
_DESK_TOPS = ((128, 128, 128), (225, 225, 220), (45, 45, 50), (150, 120, 100))


@dataclass(frozen=True, eq=False)
class _Looks:
    """Light, colours (BGR) and textures of one scene."""

    light: np.ndarray  # unit vector, from above the camera, travelling +z
    ambient: float
    diffuse: float
    tint: np.ndarray
    skin: np.ndarray
    shirt: np.ndarray
    hair: np.ndarray
    trousers: np.ndarray
    wall: np.ndarray
    floor: np.ndarray
    desk: np.ndarray
    tex_skin: object
    tex_cloth: object
    tex_wall: object
    tex_wall2: object


def _looks(rng: np.random.Generator, app) -> _Looks:
    light = np.array([rng.uniform(-0.6, 0.6), rng.uniform(0.3, 0.9), 1.0])
    light /= np.linalg.norm(light)
    ambient, diffuse = rng.uniform(0.35, 0.55), rng.uniform(0.45, 0.7)
    tint = rng.uniform(0.9, 1.1, 3)
    skin, shirt, hair, trousers = (np.asarray(c, float) for c in (app.skin, app.shirt, app.hair, app.trousers))
    wall_col = rng.uniform(90, 220, 3)
    floor_col = rng.uniform(60, 160, 3)
    desk_col = np.asarray(_DESK_TOPS[int(rng.integers(4))], float)
    tex_skin, tex_cloth = _texture(rng, 25.0), _texture(rng, 14.0)
    tex_wall, tex_wall2 = _texture(rng, 180.0), _texture(rng, 35.0)
    return _Looks(light, ambient, diffuse, tint, skin, shirt, hair, trousers, wall_col, floor_col, desk_col,
                  tex_skin, tex_cloth, tex_wall, tex_wall2)


class _Renderer:
    """Ray-casts one scene's frames: the static room once per camera, the person per frame."""

    def __init__(self, lay: _Layout, looks: _Looks, hands: np.ndarray, elbows: np.ndarray):
        self.lay, self.looks, self.hands, self.elbows = lay, looks, hands, elbows
        self.rooms = {k: self._room(c) for k, c in lay.cams.items()}

    def _head_colour(self, local):
        hair_cap = (local[..., 1] < -0.35) | (local[..., 2] > 0.3)
        return np.where(hair_cap[..., None], self.looks.hair, self.looks.skin)

    def _room_colour(self, base, scale=1.0):
        lk = self.looks
        return lambda p: base * (1 + scale * (0.28 * lk.tex_wall(p) + 0.18 * lk.tex_wall2(p)))[:, None]

    def _room(self, cam: Camera) -> _Buffer:
        lay, lk = self.lay, self.looks
        H, torso_c = lay.body.H, lay.torso_c
        buf = _Buffer(cam)
        buf.plane(np.array([0, 0, 1.0]), lay.wall_z, ROOM, self._room_colour(lk.wall))
        buf.plane(np.array([0, 1.0, 0]), lay.floor_y, ROOM, self._room_colour(lk.floor, 0.7))
        if lay.name == "desk_depth":
            buf.plane(np.array([0, 1.0, 0]), lay.desk_y, DESK, self._room_colour(lk.desk, 0.6),
                      bounds=lambda p: (np.abs(p[..., 0] - torso_c[0]) < 0.45 * H)
                      & (p[..., 2] > torso_c[2] - 0.45 * H) & (p[..., 2] < torso_c[2] - 0.05 * H))
        return buf

    def render(self, cam: Camera, i: int) -> _Buffer:
        lay, lk, body = self.lay, self.looks, self.lay.body
        H = body.H
        buf = _Buffer(cam)
        r = self.rooms[cam.name]
        buf.z, buf.label, buf.colour, buf.normal = r.z.copy(), r.label.copy(), r.colour.copy(), r.normal.copy()
        buf.ellipsoid(lay.torso_c, body.torso_r, TORSO, lk.shirt)
        buf.capsule(lay.neck_top + np.array([0, 0.03 * H, 0]), lay.head_c, 0.028 * H, NECK, lk.skin)
        buf.ellipsoid(lay.head_c, body.head_r, HEAD, self._head_colour)
        if lay.name == "standing_depth":
            for s in (1.0, -1.0):
                hip = lay.torso_c + np.array([s * 0.05 * H, body.torso_r[1] * 0.9, 0])
                buf.capsule(hip, hip + np.array([s * 0.01 * H, 0.47 * H, 0]), 0.045 * H, LEGS, lk.trousers)
        for k, lab in ((0, ARM_L), (1, ARM_R)):
            buf.capsule(lay.shoulders[k], self.elbows[i, k], body.arm_r * 1.15, lab, lk.shirt)
            buf.capsule(self.elbows[i, k], self.hands[i, k], body.arm_r, lab, lk.shirt)
            buf.ellipsoid(self.hands[i, k], np.array([body.hand_r] * 3), (HAND_L, HAND_R)[k], lk.skin)
        return buf

    def shade(self, buf: _Buffer) -> np.ndarray:
        lk = self.looks
        lam = np.abs(buf.world_normals() @ lk.light)  # two-sided Lambert: the wall faces away from +z
        lab = buf.label
        body_px = (lab != ROOM) & (lab != DESK)  # the room's texture is in its colour already
        pts = buf.points()[body_px]
        tex = np.zeros(lab.shape)
        tex[body_px] = np.where(np.isin(lab[body_px], (HEAD, HAND_L, HAND_R, NECK)), 0.10 * lk.tex_skin(pts),
                                0.16 * lk.tex_cloth(pts))
        gain = (lk.ambient + lk.diffuse * lam) * (1 + tex)
        return np.clip(buf.colour * gain[..., None] * lk.tint, 0, 255)


def _truth_rows(i: int, labels: np.ndarray, lay: _Layout, hands: np.ndarray, elbows: np.ndarray) -> list[tuple]:
    """Frame ``i``'s truth: head, hand and torso boxes from the pixels the left camera sees of them
    (the projected extent when hidden), with the fraction occluded, and the four arm joints."""
    cam, body = lay.cams["cam0"], lay.body
    centres = {"head": lay.head_c, "left_hand": hands[i, 0], "right_hand": hands[i, 1], "torso": lay.torso_c}
    radii = {"head": body.head_r.max(), "left_hand": body.hand_r, "right_hand": body.hand_r,
             "torso": body.torso_r.max()}
    rows = []
    for part, labs in _TRUTH_LABELS.items():
        mask = np.isin(labels, labs)
        c = centres[part]
        if mask.any():
            cols = np.flatnonzero(mask.any(axis=0))
            rws = np.flatnonzero(mask.any(axis=1))
            box = (cols[0], rws[0], cols[-1] - cols[0] + 1, rws[-1] - rws[0] + 1)
        else:  # hidden: the projected extent; wholly outside the frame: no row (as in .scene)
            (u, v), = cam.project(c[None])
            r = radii[part] * cam.K[0, 0] / c[2]
            if u + r <= 0 or v + r <= 0 or u - r >= cam.size[0] or v - r >= cam.size[1]:
                continue
            box = (u - r, v - r, 2 * r, 2 * r)
        # occluded: the fraction of the part's own silhouette that something else covers
        occ = _occluded_fraction(cam, c, radii[part], mask) if part != "torso" else 0.0
        rows.append((i, 1, part, *box, occ, *c))
    for part, p in (("left_shoulder", lay.shoulders[0]), ("right_shoulder", lay.shoulders[1]),
                    ("left_elbow", elbows[i, 0]), ("right_elbow", elbows[i, 1])):
        (u, v), = cam.project(p[None])
        r = body.arm_r * cam.K[0, 0] / p[2]
        rows.append((i, 1, part, u - r, v - r, 2 * r, 2 * r, 0.0, *p))
    return rows


def make_depth_scene(name: str = "desk_depth", seed: int = 0, n_frames: int = 150, width: int = 320,
                     height: int = 240, *, fast: float = 1.0) -> DepthScene:
    """Render ``name`` (``desk_depth`` or ``standing_depth``) from ``seed``; ``fast`` scales the
    hands' speed (1: keyframes 0.2-0.6 s apart, up to about 3 m/s)."""
    if name not in DEPTH_SCENARIOS:
        raise ValueError(f"unknown depth scenario {name!r}; expected one of {', '.join(DEPTH_SCENARIOS)}")
    if n_frames < 1 or width < 64 or height < 48:
        raise ValueError(f"bad scene size {width}x{height} x {n_frames} frames")
    rng = np.random.default_rng([seed, 100 + DEPTH_SCENARIOS.index(name)])
    (app,) = sample_appearances(rng, 1)
    lay = _layout(rng, name, app.height_m * 1000.0, width, height)
    hands, elbows = _arms(seed, lay, n_frames, fast)
    renderer = _Renderer(lay, _looks(rng, app), hands, elbows)
    frames = np.empty((n_frames, height, width, 3), np.uint8)
    right = np.empty_like(frames)
    depth = np.empty((n_frames, height, width), np.float32)
    labels = np.empty((n_frames, height, width), np.uint8)
    noise_rng = np.random.default_rng([seed, 7])
    noise = rng.uniform(1.0, 3.0)
    rows = []
    for i in range(n_frames):
        lb = renderer.render(lay.cams["cam0"], i)
        rb = renderer.render(lay.cams["cam0_right"], i)
        for img, out in ((renderer.shade(lb), frames), (renderer.shade(rb), right)):
            out[i] = np.clip(img + noise_rng.normal(0, noise, img.shape), 0, 255).astype(np.uint8)
        depth[i] = lb.z.astype(np.float32)
        labels[i] = lb.label
        rows.extend(_truth_rows(i, lb.label, lay, hands, elbows))
    truth = pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h", "occluded", "X", "Y", "Z"])
    truth["source"] = "truth"
    truth["camera"] = "cam0"
    truth = normalise_tracks(truth)
    init = truth[(truth["frame"] == 0) & truth["part"].isin(["head", "left_hand", "right_hand"])].reset_index(drop=True)
    cams = lay.cams
    meta = {"name": name, "seed": seed, "fps": FPS, "width": width, "height": height, "n_frames": n_frames,
            "distance_mm": round(lay.distance, 1), "height_mm": round(lay.body.H, 1),
            "baseline_mm": round(float(np.linalg.norm(cams["cam0_right"].centre)), 2),
            "skin": list(app.skin), "shirt": list(app.shirt), "fast": fast,
            "hand_speed_mm_s_max": round(float(np.linalg.norm(np.diff(hands, axis=0), axis=-1).max() * FPS), 1)}
    return DepthScene(frames, right, depth, labels, truth, init, cams, FPS, meta)


def _occluded_fraction(cam: Camera, c: np.ndarray, r: float, visible: np.ndarray) -> float:
    """The fraction of the part's projected disc not seen: hidden by something nearer, or outside
    the frame (a hand at the image's edge is partly out of view)."""
    (u, v), = cam.project(c[None])
    rad = r * cam.K[0, 0] / c[2]
    h, w = visible.shape
    yy, xx = np.ogrid[:h, :w]
    disc = (xx - u) ** 2 + (yy - v) ** 2 <= rad ** 2
    n = max(float(np.pi * rad ** 2), float(disc.sum()))
    return round(1.0 - min(1.0, int((disc & visible).sum()) / n), 4) if n else 1.0


def render_depth_scenario(name: str, outdir: str | PathLike, seed: int = 0, n_frames: int = 150,
                          width: int = 320, height: int = 240) -> Path:
    """Write a depth scene as a take folder::

        OUT/clip.mp4 right.mp4         left (colour) and right views
        OUT/clip_depth/000000.png ...  rendered depth, 16-bit mm (0 where nothing: never here)
        OUT/calibration.json           cam0 and cam0_right
        OUT/take.json                  the take with rendered depth
        OUT/stereo/take.json           the same take with depth from the stereo pair
        OUT/truth.csv init.csv scene.json
    """
    from partlab.labelling.calibration import write_calibration
    from partlab.labelling.video import write_video
    from partlab.tracking.tracks import write_tracks_csv

    scene = make_depth_scene(name, seed, n_frames, width, height)
    out = Path(outdir)
    (out / "clip_depth").mkdir(parents=True, exist_ok=True)
    write_video(out / "clip.mp4", scene.frames, scene.fps)
    write_video(out / "right.mp4", scene.right, scene.fps)
    for i, d in enumerate(scene.depth):
        cv2.imwrite(str(out / "clip_depth" / f"{i:06d}.png"), np.clip(np.round(d), 0, 65535).astype(np.uint16))
    write_calibration(scene.cameras, out / "calibration.json")
    (out / "take.json").write_text(json.dumps(
        {"fps": scene.fps, "streams": [{"name": "cam0", "color": "clip.mp4", "depth": "clip_depth"}]}, indent=1) + "\n")
    (out / "stereo").mkdir(exist_ok=True)
    write_calibration(scene.cameras, out / "stereo" / "calibration.json")
    (out / "stereo" / "take.json").write_text(json.dumps(
        {"fps": scene.fps, "streams": [{"name": "cam0", "color": "../clip.mp4",
                                        "stereo": {"left": "../clip.mp4", "right": "../right.mp4",
                                                   "right_camera": "cam0_right"}}]}, indent=1) + "\n")
    write_tracks_csv(scene.truth, out / "truth.csv")
    write_tracks_csv(scene.init, out / "init.csv")
    (out / "scene.json").write_text(json.dumps(scene.meta, indent=2) + "\n")
    return out
