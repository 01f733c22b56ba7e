"""Multi-camera synthetic takes: one 3D scene seen by N calibrated pinhole cameras.

The scene lives in one world frame in millimetres: ``X, Y`` on the floor, ``Z`` up (so that, as
the 3D hand/head tracking paper's sec. 6.4 assumes, a higher point has a smaller image row in
every camera). Each camera is a :class:`partlab.tracking.camera.Camera` (exact ``K, R, t``, no
distortion) placed on an arc around the scene at a random height, distance, yaw and focal length,
looking at the people. The figures of :mod:`partlab.labelling.synth.figure` are drawn through a
:class:`PinholeView`: every body point is a real perspective projection (only the radii of limbs
use the scale at the person's centre), and the solids are ordered by depth along each camera's own
floor direction. The room (tiled floor, walls) is ray-cast per pixel, the table of the seated
scenario is a 3D box. Truth per frame: the 3D centres of each head and hand (``truth3d.csv``) and
per view the tight 2D boxes with their occluded fraction (``truth.csv`` with the ``camera``
column), exactly as :mod:`partlab.labelling.synth.scene` computes them for one camera.

Scenarios (:data:`SCENARIOS_3D`): ``standing`` (one person gesturing, with a clap), ``seated`` (at
a table: fidgeting, a clap, reaching), ``handshake`` (two people shake right hands, then one
passes an object from their left hand to the other's right hand). :func:`render_chessboard`
renders a chessboard sequence per camera for :mod:`partlab.commands.calibrate`; its first frame
lies on the floor with its first inner corner at the world origin and its rows along ``+X``: that
board defines the world frame.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from partlab.labelling.synth.activities import object_colour
from partlab.labelling.synth.appearance import Appearance, sample_appearances
from partlab.labelling.synth.background import CameraEffects, smooth_noise
from partlab.labelling.synth.figure import HAND_R, FigurePose, colour_table, draw_figure
from partlab.labelling.synth.motion import bump
from partlab.labelling.synth.scene import SKIN_LABELS
from partlab.tracking.camera import Camera
from partlab.tracking.parts import PART_NAMES
from partlab.tracking.tracks import normalise_tracks

SCENARIOS_3D: tuple[str, ...] = ("standing", "seated", "handshake")
FPS = 25.0
OBJECT_ID = 254  # owner value of a carried object
TABLE_ID = 253  # owner value of the table's near faces
LIMB_PARTS = ("head", "left_hand", "right_hand")
EZ = np.array([0.0, 0.0, 1.0])


# -- cameras --------------------------------------------------------------------------------

def look_at(name: str, centre_mm, target_mm, f: float, size: tuple[int, int],
            principal=None) -> Camera:
    """A pinhole camera at ``centre_mm`` looking at ``target_mm`` with the image's up towards +Z."""
    c, tgt = np.asarray(centre_mm, float), np.asarray(target_mm, float)
    fwd = (tgt - c) / np.linalg.norm(tgt - c)
    right = np.cross(fwd, EZ)
    right /= np.linalg.norm(right)
    down = np.cross(fwd, right)
    R = np.stack([right, down, fwd])
    w, h = size
    cx, cy = principal if principal is not None else (w / 2.0, h / 2.0)
    K = np.array([[f, 0.0, cx], [0.0, f, cy], [0.0, 0.0, 1.0]])
    return Camera(name, K, (w, h), np.zeros(5), R, -R @ c)


def place_cameras(rng: np.random.Generator, n: int, size: tuple[int, int], facing: float,
                  target_mm=(0.0, 0.0, 1000.0)) -> list[Camera]:
    """``n`` cameras on an arc in front of direction ``facing`` (radians in the floor plane).

    The arc spans 70 degrees for two cameras and 55 more per further camera (to 180 for four):
    pairs of views then meet at 50-110 degrees, where triangulation is well conditioned (opposite
    cameras see nearly the same line of sight). Each camera is jittered by +-10 degrees of yaw,
    2.6-3.4 m from the scene, 1.9-2.6 m high, 52-64 degrees of horizontal field of view.
    """
    span = np.radians(70.0 + 55.0 * max(n - 2, 0))
    yaws = facing + (np.linspace(-span / 2, span / 2, n) if n > 1 else np.zeros(1))
    w, h = size
    tgt0 = np.asarray(target_mm, float)
    cams = []
    for i, yaw in enumerate(yaws):
        yaw = yaw + np.radians(rng.uniform(-10, 10))
        dist = rng.uniform(2600, 3400)
        height = rng.uniform(1900, 2600)
        centre = tgt0[:2] + dist * np.array([np.cos(yaw), np.sin(yaw)])
        tgt = tgt0 + np.array([rng.uniform(-120, 120), rng.uniform(-120, 120), rng.uniform(-100, 150)])
        f = (w / 2) / np.tan(np.radians(rng.uniform(52, 64)) / 2)
        pp = (w / 2 + rng.uniform(-6, 6), h / 2 + rng.uniform(-6, 6))
        cams.append(look_at(f"cam{i}", [*centre, height], tgt, f, size, pp))
    return cams


def project(camera: Camera, points_mm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(N, 3)`` world mm -> ``(N, 2)`` pixels and ``(N,)`` depths (no distortion: fast path)."""
    cam = np.asarray(points_mm, float).reshape(-1, 3) @ camera.R.T + camera.t
    z = cam[:, 2]
    uv = cam[:, :2] / np.maximum(z, 1e-6)[:, None]
    return uv * np.diag(camera.K)[:2] + camera.K[:2, 2], z


@dataclass(frozen=True)
class PinholeView:
    """A person's view through a calibrated camera, in the interface of
    :class:`~partlab.labelling.synth.camera.LocalView` (``project(dx, dz, u)``, ``s``, ``k``).

    ``(dx, dz)`` are floor offsets (metres) along the camera's horizontal right ``ax`` and
    horizontal forward ``az`` from the person's foot point ``origin`` (mm), ``u`` the height."""

    camera: Camera
    origin: np.ndarray
    ax: np.ndarray
    az: np.ndarray
    s: float
    k: float

    @classmethod
    def make(cls, camera: Camera, origin_mm, height_m: float) -> PinholeView:
        o = np.asarray(origin_mm, float)
        ax = camera.R[0].copy()
        ax[2] = 0.0
        ax /= np.linalg.norm(ax)
        az = np.cross(EZ, ax)  # right x forward = down, so forward = up x right
        mid = o + EZ * 500.0 * height_m
        _, z = project(camera, mid[None])
        s = camera.K[0, 0] / (float(z[0]) / 1000.0)
        horiz = float(np.hypot(*(mid - camera.centre)[:2]))
        k = max(camera.centre[2] - mid[2], 0.0) / max(horiz, 1.0)
        return cls(camera, o, ax, az, s, k)

    def world(self, dx, dz, u) -> np.ndarray:
        dx, dz, u = (np.asarray(v, float).reshape(-1) for v in (dx, dz, u))
        return self.origin + 1000.0 * (dx[:, None] * self.ax + dz[:, None] * self.az + u[:, None] * EZ)

    def project(self, dx, dz, u) -> np.ndarray:
        return project(self.camera, self.world(dx, dz, u))[0]

    def facing(self, direction_xy) -> float:
        """A world floor heading as the figure's ``facing`` in this view's floor frame."""
        d = np.array([direction_xy[0], direction_xy[1], 0.0])
        return float(np.arctan2(d @ self.az, d @ self.ax))


# -- scenarios ----------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Actor3D:
    """One person: looks, floor position ``(T, 2)`` mm, world heading ``(T,)`` radians, head yaw
    ``(T,)`` and hand targets ``(T, 2, 3)`` in the body frame (lateral, forward, up; metres)."""

    appearance: Appearance
    position: np.ndarray
    heading: np.ndarray
    head_yaw: np.ndarray
    hands: np.ndarray
    seated: bool = False


@dataclass(frozen=True, eq=False)
class Script3D:
    actors: list[Actor3D]
    facing: float  # direction (radians) the cameras' arc is centred on, seen from the scene
    table: np.ndarray | None = None  # (8, 3) corners in mm: 4 top (z = height) then 4 bottom
    objects: list = field(default_factory=list)  # (holder track per frame (T,), hand index, radius mm, BGR)
    #: activity truth in story frames (of 150): (kind, start, end, track a, part a, track b, part b)
    events: list = field(default_factory=list)


def _story_time(n: int) -> np.ndarray:
    """Each scenario's story takes 150 frames at 25 fps (a clap around frames 60-80, ...): frame
    ``i`` is at story time ``i / 149``, so a shorter take is the story's beginning and moves at the
    same speeds (a longer one goes on at rest)."""
    return np.arange(n) / 149.0


def _wander(rng, n, amp, lo=0.15, hi=0.45) -> np.ndarray:
    """A smooth random signal of amplitude about ``amp`` (two sines of random frequency and phase)."""
    t = np.arange(n) / FPS
    f, p = rng.uniform(lo, hi, 2), rng.uniform(0, 2 * np.pi, 2)
    return amp * 0.5 * (np.sin(2 * np.pi * f[0] * t + p[0]) + np.sin(2 * np.pi * f[1] * t + p[1]))


def _blend(a: np.ndarray, b: np.ndarray, w: np.ndarray) -> np.ndarray:
    return a * (1 - w)[:, None] + b * w[:, None]


def _to_body(world_m: np.ndarray, pos_m: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """World points ``(T, 3)`` metres -> body frame (lateral left, forward, up) of a person."""
    F = np.stack([np.cos(heading), np.sin(heading)], 1)
    L = np.stack([-F[:, 1], F[:, 0]], 1)
    d = world_m[:, :2] - pos_m
    return np.stack([(d * L).sum(1), (d * F).sum(1), world_m[:, 2]], 1)


def _people(rng, n: int) -> list[Appearance]:
    """``n`` people in long sleeves: the paper assumes the heads and hands are the only unclothed
    parts (sec. 6), so a skin blob is a hand and not a hand with its forearm."""
    from dataclasses import replace

    return [replace(a, short_sleeves=False) for a in sample_appearances(rng, n)]


def _span(story: np.random.Generator, lo: float, hi: float, length: tuple[float, float]) -> tuple[int, int]:
    """An activity's story frames: it starts between ``lo`` and ``hi`` and lasts ``length`` frames
    (drawn from ``story``, the scene's timing generator, so that the detector meets no fixed timing)."""
    a = int(round(story.uniform(lo, hi)))
    return a, a + int(round(story.uniform(*length)))


def _standing(rng, n, story) -> Script3D:
    (app,) = _people(rng, 1)
    H = app.height_m
    t = _story_time(n)
    heading = np.full(n, rng.uniform(-np.pi, np.pi)) + _wander(rng, n, 0.35, 0.05, 0.15)
    pos = np.stack([_wander(rng, n, 60.0, 0.05, 0.2), _wander(rng, n, 60.0, 0.05, 0.2)], 1)
    hands = np.empty((n, 2, 3))
    for i, side in enumerate((1.0, -1.0)):  # gesturing in front of the body
        hands[:, i, 0] = side * (0.22 + np.abs(_wander(rng, n, 0.16)))
        hands[:, i, 1] = 0.28 + _wander(rng, n, 0.12)
        hands[:, i, 2] = (0.62 + 0.1 * rng.uniform(-1, 1)) * H + _wander(rng, n, 0.22 * H, 0.2, 0.6)
    # a clap (about frames 45-95 of 150, 16-26 frames long): the hands meet in front of the chest three times
    c0, c1 = _span(story, 45, 70, (16, 26))
    c = bump(t, c0 / 149, c1 / 149, ramp=0.04)
    u = np.clip((t - c0 / 149) / ((c1 - c0) / 149), 0, 1)
    sep = HAND_R * H * 1.05 + 0.1 * (0.5 - 0.5 * np.cos(2 * np.pi * 3 * u))
    clap = np.stack([np.stack([sep, np.full(n, 0.32), np.full(n, 0.72 * H)], 1),
                     np.stack([-sep, np.full(n, 0.32), np.full(n, 0.72 * H)], 1)], 1)
    hands = hands * (1 - c)[:, None, None] + clap * c[:, None, None]
    yaw = _wander(rng, n, 0.3, 0.1, 0.3)
    return Script3D([Actor3D(app, pos, heading, yaw, hands)], facing=float(heading[0]),
                    events=[("clap", c0, c1, 1, "left_hand", 1, "right_hand")])


TABLE_H = 740.0
TABLE_COLOURS = ((150, 150, 148), (215, 215, 210), (120, 80, 50), (70, 110, 70))


def _seated(rng, n, story) -> Script3D:
    (app,) = _people(rng, 1)
    H = app.height_m
    t = _story_time(n)
    frames = np.arange(n)
    heading0 = rng.uniform(-np.pi, np.pi)
    heading = np.full(n, heading0)
    pos = np.zeros((n, 2))
    desk = TABLE_H / 1000.0
    hr = HAND_R * H
    rest = np.array([[0.19, 0.35, desk + hr], [-0.19, 0.35, desk + hr]])
    hands = np.repeat(rest[None], n, axis=0)
    for i in range(2):
        for d in (0, 1):
            hands[:, i, d] += _wander(rng, n, 0.06, 0.2, 0.5)
    c0, c1 = _span(story, 30, 50, (16, 24))  # a clap in front of the chest
    c = bump(t, c0 / 149, c1 / 149, ramp=0.04)
    u = np.clip((t - c0 / 149) / ((c1 - c0) / 149), 0, 1)
    sep = hr * 1.05 + 0.11 * (0.5 - 0.5 * np.cos(2 * np.pi * 3 * u))
    clap = np.stack([np.stack([sep, np.full(n, 0.3), np.full(n, desk + 0.25)], 1),
                     np.stack([-sep, np.full(n, 0.3), np.full(n, desk + 0.25)], 1)], 1)
    hands = hands * (1 - c)[:, None, None] + clap * c[:, None, None]
    r0, r1 = _span(story, c1 + 20, c1 + 40, (16, 24))  # the right hand reaches across the table and back
    r = bump(t, r0 / 149, r1 / 149, ramp=0.035)
    reach = np.array([-0.45, 0.55, desk + 0.06])
    hands[:, 1] = _blend(hands[:, 1], np.repeat(reach[None], n, 0), r)
    yaw = 0.3 * np.sin(2 * np.pi * frames / (FPS * 3.5) + rng.uniform(0, 6.3)) * (1 - r) - 0.5 * r
    # the table: 1.3 m wide, from 0.2 to 0.9 m in front of the person
    F = np.array([np.cos(heading0), np.sin(heading0)])
    L = np.array([-F[1], F[0]])
    corners = []
    for z in (TABLE_H, 0.0):
        for fl, ll in ((0.2, -0.65), (0.2, 0.65), (0.9, 0.65), (0.9, -0.65)):
            corners.append([*(1000 * (fl * F + ll * L)), z])
    return Script3D([Actor3D(app, pos, heading, yaw, hands, seated=True)], facing=float(heading0),
                    table=np.array(corners), events=[("clap", c0, c1, 1, "left_hand", 1, "right_hand")])


def _handshake(rng, n, story) -> Script3D:
    apps = _people(rng, 2)
    t = _story_time(n)
    axis = rng.uniform(-np.pi, np.pi)  # the line between the two people
    # mm between their feet: close enough for the hands to meet halfway (an arm reaches about 0.35 H
    # from the shoulder; at 1.05-1.25 m they stopped 0.3 m short of each other)
    gap = rng.uniform(700, 850)
    u = np.array([np.cos(axis), np.sin(axis)])
    side = np.array([-u[1], u[0]])
    posA = np.repeat((-u * gap / 2)[None], n, 0)
    posB = np.repeat((u * gap / 2)[None], n, 0)
    hA, hB = np.full(n, axis), np.full(n, axis + np.pi)
    actors_h = []
    for app, pos, hd in ((apps[0], posA, hA), (apps[1], posB, hB)):
        H = app.height_m
        hands = np.empty((n, 2, 3))
        for i, sgn in enumerate((1.0, -1.0)):
            hands[:, i, 0] = sgn * (0.24 + np.abs(_wander(rng, n, 0.06)))
            hands[:, i, 1] = 0.12 + _wander(rng, n, 0.05)
            hands[:, i, 2] = 0.5 * H + _wander(rng, n, 0.05 * H)
        actors_h.append((app, pos, hd, hands))
    hmean = 0.5 * (apps[0].height_m + apps[1].height_m)
    # handshake: both right hands meet at the midpoint, shaking up and down (about frames 25-70, 18-28 long)
    s0, s1 = _span(story, 25, 40, (18, 28))
    shake = bump(t, s0 / 149, s1 / 149, ramp=0.06)
    mid = np.zeros((n, 3))
    mid[:, 2] = 0.62 * hmean + 0.045 * np.sin(2 * np.pi * 3.0 * np.arange(n) / FPS) * (shake > 0.99)
    mid[:, :2] = -0.02 * side
    # passing: A's left hand gives an object to B's right hand (about frames 80-125), B keeps it
    g0, g1 = _span(story, s1 + 25, s1 + 45, (12, 18))
    give = bump(t, g0 / 149, g1 / 149, ramp=0.06)
    meet = np.zeros((n, 3))
    meet[:, :2] = 0.22 * side
    meet[:, 2] = 0.6 * hmean
    for k, (_app, pos, hd, hands) in enumerate(actors_h):
        pos_m = pos / 1000.0
        target = _to_body(mid, pos_m, hd)
        hands[:, 1] = _blend(hands[:, 1], target, shake)  # the right hand (index 1) shakes
        g = _to_body(meet, pos_m, hd)
        hi = 0 if k == 0 else 1  # A gives with the left hand, B takes with the right
        hands[:, hi] = _blend(hands[:, hi], g, give)
    holder = np.where(t < (g0 + g1) / 2 / 149, 1, 2)
    radius = float(rng.uniform(38, 48))
    rng.choice(4)  # drawn as before, so that the cameras and rooms of a seed are those of earlier versions
    # a saturated colour far from both people's clothes (hue cannot see a grey object, nor one of a
    # sleeve's colour: docs/trackers/activities.md)
    obj = (holder, np.where(holder == 1, 0, 1), radius, object_colour(story, apps))
    actors = [Actor3D(app, pos, hd, _wander(rng, n, 0.25, 0.1, 0.3), hands) for app, pos, hd, hands in actors_h]
    events = [("handshake", s0, s1, 1, "right_hand", 2, "right_hand"),
              ("exchange", g0, g1, 1, "left_hand", 2, "right_hand")]
    return Script3D(actors, facing=float(axis - np.pi / 2 if rng.random() < 0.5 else axis + np.pi / 2),
                    objects=[obj], events=events)


BUILDERS_3D = {"standing": _standing, "seated": _seated, "handshake": _handshake}


# -- the room -------------------------------------------------------------------------------

ROOM_HALF = 4500.0  # mm from the centre to each wall
ROOM_HEIGHT = 3000.0


def _rays(camera: Camera) -> np.ndarray:
    w, h = camera.size
    u, v = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    kinv = np.linalg.inv(camera.K)
    d = np.stack([u, v, np.ones_like(u)], -1) @ kinv.T @ camera.R  # R^T per row
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def room_image(rng: np.random.Generator, camera: Camera, colours: dict) -> np.ndarray:
    """``(H, W, 3) uint8`` ray-cast room: tiled floor, four walls, ceiling, lit from above."""
    d = _rays(camera)
    c = camera.centre
    big = np.inf
    with np.errstate(divide="ignore", invalid="ignore"):
        t_floor = np.where(d[..., 2] < 0, -c[2] / d[..., 2], big)
        t_ceil = np.where(d[..., 2] > 0, (ROOM_HEIGHT - c[2]) / d[..., 2], big)
        tx = np.where(d[..., 0] > 0, (ROOM_HALF - c[0]) / d[..., 0], (-ROOM_HALF - c[0]) / d[..., 0])
        ty = np.where(d[..., 1] > 0, (ROOM_HALF - c[1]) / d[..., 1], (-ROOM_HALF - c[1]) / d[..., 1])
    ts = np.stack([t_floor, t_ceil, np.where(np.isfinite(tx) & (tx > 0), tx, big),
                   np.where(np.isfinite(ty) & (ty > 0), ty, big)], -1)
    which = np.argmin(ts, -1)
    tmin = np.min(ts, -1)
    p = c + d * tmin[..., None]
    h, w = which.shape
    img = np.empty((h, w, 3), np.float32)
    floor = which == 0
    tile = 500.0
    chk = ((np.floor(p[..., 0] / tile) + np.floor(p[..., 1] / tile)) % 2).astype(np.float32)
    img[floor] = np.asarray(colours["floor"], np.float32) * (0.92 + 0.08 * chk[floor])[:, None]
    img[which == 1] = colours["ceiling"]
    wall = which >= 2
    side = np.where(which == 2, np.sign(d[..., 0]), 2 * np.sign(d[..., 1]))  # which of the four walls
    shade = 1.0 - 0.05 * (side + 2) % 3 - 0.12 * (1 - np.clip(p[..., 2] / ROOM_HEIGHT, 0, 1))
    img[wall] = np.asarray(colours["wall"], np.float32) * shade[wall][:, None]
    img += 4.0 * smooth_noise(rng, h, w, 5)[..., None]
    return np.clip(img, 0, 255).astype(np.uint8)


def _room_colours(rng) -> dict:
    # bluish greys: chroma well outside the skin rule (Cr under 128) under every camera's cast
    return {"floor": np.array([134, 128, 116]) + rng.uniform(-12, 12, 3),
            "wall": np.array([200, 192, 172]) + rng.uniform(-12, 12, 3),
            "ceiling": np.array([215, 215, 212]) + rng.uniform(-10, 10, 3)}


_TABLE_FACES = ((0, 1, 2, 3), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))


def _table_faces(camera: Camera, corners: np.ndarray, person_xy: np.ndarray):
    """The table's visible faces as image polygons, split into those behind the person and those in
    front (drawn over them). Side faces hide what is below the top; the top is always behind."""
    uv, _ = project(camera, corners)
    c = camera.centre
    centre = corners.mean(0)
    back, front = [], []
    d_person = np.hypot(*(person_xy - c[:2]))
    for k, face in enumerate(_TABLE_FACES):
        pts = corners[list(face)]
        fc = pts.mean(0)
        normal = EZ if k == 0 else np.append((fc - centre)[:2], 0.0)
        if normal @ (c - fc) <= 0:
            continue
        poly = uv[list(face)]
        if k == 0 or np.hypot(*(fc[:2] - c[:2])) > d_person:
            back.append((k, poly))
        else:
            front.append((k, poly))
    return back, front


def _fill(img, poly, value) -> None:
    cv2.fillConvexPoly(img, np.round(poly * 16).astype(np.int32), value, cv2.LINE_8, 4)


# -- rendering ------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class MultiScene:
    """A rendered multi-camera scene: ``frames[camera]: (T, H, W, 3) uint8``; ``cameras``;
    ``truth`` per-view 2D rows (``camera`` column, ``X, Y, Z`` on head and hand rows);
    ``truth3d``: ``frame, track_id, part, X, Y, Z`` (mm); ``init``: every track's first frame."""

    frames: dict
    cameras: list
    truth: pd.DataFrame
    truth3d: pd.DataFrame
    init: pd.DataFrame
    fps: float
    appearances: tuple = ()
    backgrounds: dict = field(default_factory=dict)  # camera -> the empty scene it sees (the table included)
    #: activity truth (:data:`partlab.labelling.synth.scene.EVENT_TRUTH_COLUMNS`): the clap, the handshake and
    #: the exchange, frames where the hands are together
    events: pd.DataFrame | None = None


def _check(name: str, n_cameras: int, seed: int, n_frames: int, width: int, height: int) -> None:
    if name not in SCENARIOS_3D:
        raise ValueError(f"unknown multi-camera scenario {name!r}; expected one of {', '.join(SCENARIOS_3D)}")
    if not 1 <= n_cameras <= 8:
        raise ValueError(f"cameras must be between 1 and 8, got {n_cameras}")
    if seed < 0 or n_frames < 1 or width < 64 or height < 48:
        raise ValueError("seed must be >= 0, frames >= 1 and the size at least 64x48")


def _part_rows(drawn, owner: np.ndarray, i: int, camera: str) -> list[tuple]:
    """Truth rows of one view at frame ``i`` (:func:`partlab.labelling.synth.scene._truth_rows`
    with the view's name)."""
    from partlab.labelling.synth.scene import _truth_rows

    return [row + (camera,) for row in _truth_rows(i, drawn, owner)]


def _draw_carried(frame, owner, cam: Camera, view: PinholeView, anchors: dict, objects, track: int, i: int) -> None:
    """Carried objects in front of the hand holding them (owner :data:`OBJECT_ID`)."""
    height, width = owner.shape
    for holder, hand, radius, colour in objects:
        if holder[i] != track:
            continue
        part = LIMB_PARTS[1 + int(hand[i])]
        X = view.world(*anchors[part])[0] + np.array([0.0, 0.0, 30.0])
        uv, z = project(cam, X[None])
        r = cam.K[0, 0] * radius / float(z[0])
        mask = np.zeros((height, width), np.uint8)
        cv2.circle(mask, tuple(int(round(v * 16)) for v in uv[0]), int(round(r * 16)), 1, -1, cv2.LINE_8, 4)
        frame[mask > 0] = colour
        owner[mask > 0] = OBJECT_ID


def make_multiview_scene(name: str, n_cameras: int = 3, seed: int = 0, n_frames: int = 150, width: int = 640,
                         height: int = 480, *, clean: bool = False) -> MultiScene:
    """Render scenario ``name`` (:data:`SCENARIOS_3D`) from ``n_cameras`` cameras, deterministically."""
    _check(name, n_cameras, seed, n_frames, width, height)
    rng = np.random.default_rng([seed, 100 + SCENARIOS_3D.index(name)])
    # the activities' timings come from a generator of their own: the people, cameras and rooms of a
    # seed stay what they were when the timings were fixed
    script = BUILDERS_3D[name](rng, n_frames, np.random.default_rng([seed, 200 + SCENARIOS_3D.index(name)]))
    cams = place_cameras(rng, n_cameras, (width, height), script.facing)
    luts = [colour_table(a.appearance) for a in script.actors]
    colours = _room_colours(rng)
    # lighting: a colour cast and exposure per camera (white balance differs between cameras)
    casts = [rng.uniform(0.9, 1.1, 3).astype(np.float32) * rng.uniform(0.85, 1.1) for _ in cams]
    rows: list[tuple] = []
    rows3d: list[tuple] = []
    frames: dict[str, np.ndarray] = {}
    plates: dict[str, np.ndarray] = {}
    table_pick = rng.integers(len(TABLE_COLOURS))
    for ci, cam in enumerate(cams):
        background = room_image(rng, cam, colours)
        effects = None if clean else CameraEffects.make(rng, n_frames, width, height, FPS)
        centre_xy = np.mean([a.position[0] for a in script.actors], axis=0)
        back_faces, front_faces = ([], []) if script.table is None else _table_faces(cam, script.table, centre_xy)
        # a painted or laminated table (grey, white, blue, green): a skin-coloured wooden top right
        # under skin-coloured hands is the one-camera desk scene's distractor, not this one's
        wood = np.array(TABLE_COLOURS[int(table_pick)]) + rng.uniform(-10, 10, 3)
        for k, poly in back_faces:
            _fill(background, poly, tuple(float(v) * (1.0 if k == 0 else 0.7) for v in wood))
        plate = background.copy()
        for _, poly in front_faces:
            _fill(plate, poly, tuple(float(v) for v in (wood * 0.7).astype(np.uint8)))
        plates[cam.name] = np.clip(plate.astype(np.float32) * casts[ci], 0, 255).astype(np.uint8)
        out = np.empty((n_frames, height, width, 3), np.uint8)
        owner = np.zeros((height, width), np.uint8)
        for i in range(n_frames):
            frame = background.copy()
            owner[:] = 0
            views = [PinholeView.make(cam, [*a.position[i], 0.0], a.appearance.height_m) for a in script.actors]
            order = sorted(range(len(script.actors)),
                           key=lambda a: -float(np.hypot(*(script.actors[a].position[i] - cam.centre[:2]))))
            drawn = []
            for a in order:
                actor, view = script.actors[a], views[a]
                F = (np.cos(actor.heading[i]), np.sin(actor.heading[i]))
                pose = FigurePose(facing=view.facing(F), head_yaw=float(actor.head_yaw[i]), hands=actor.hands[i],
                                  seated=actor.seated)
                anchors: dict = {}
                fig = draw_figure(pose, actor.appearance, view, anchors)
                if ci == 0:
                    for part in LIMB_PARTS:
                        X = view.world(*anchors[part])[0]
                        rows3d.append((i, a + 1, part, *np.round(X, 2)))
                x0, y0 = fig.origin
                fh, fw = fig.labels.shape
                cx1, cy1, cx2, cy2 = max(x0, 0), max(y0, 0), min(x0 + fw, width), min(y0 + fh, height)
                if cx1 >= cx2 or cy1 >= cy2:
                    continue
                crop = (slice(cy1 - y0, cy2 - y0), slice(cx1 - x0, cx2 - x0))
                lab = fig.labels[crop]
                on = lab > 0
                cols = luts[a][lab[on]].astype(np.float32)
                if not clean:  # lit from above: brighter shoulders, darker below; skin stays smooth
                    ry = (np.arange(cy1 - y0, cy2 - y0, dtype=np.float32) / max(fh, 1))[:, None]
                    gain = np.broadcast_to(1.06 - 0.14 * ry, lab.shape)
                    gain = np.where(np.isin(lab, SKIN_LABELS), 1.0, gain)
                    cols *= gain[on][:, None]
                frame[cy1:cy2, cx1:cx2][on] = np.clip(cols, 0, 255).astype(np.uint8)
                owner[cy1:cy2, cx1:cx2][on] = a + 1
                drawn.append((a, fig, crop, (cx1, cy1, cx2, cy2)))
                _draw_carried(frame, owner, cam, view, anchors, script.objects, a + 1, i)
            for _, poly in front_faces:
                m = np.zeros((height, width), np.uint8)
                _fill(m, poly, 1)
                frame[m > 0] = (wood * 0.7).astype(np.uint8)
                owner[m > 0] = TABLE_ID
            rows += _part_rows(drawn, owner, i, cam.name)
            frame = np.clip(frame.astype(np.float32) * casts[ci], 0, 255).astype(np.uint8)
            out[i] = frame if effects is None else effects.apply(frame, i)
        frames[cam.name] = out
    truth3d = pd.DataFrame(rows3d, columns=["frame", "track_id", "part", "X", "Y", "Z"])
    truth = pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h", "occluded", "camera"])
    truth["source"] = "truth"
    truth = truth.merge(truth3d, on=["frame", "track_id", "part"], how="left")
    order = {p: k for k, p in enumerate(PART_NAMES)}
    cam_order = {c.name: k for k, c in enumerate(cams)}
    truth = truth.assign(_p=truth["part"].map(order), _c=truth["camera"].map(cam_order)).sort_values(
        ["frame", "_c", "track_id", "_p"], kind="stable").drop(columns=["_p", "_c"])
    truth = normalise_tracks(truth)
    first = truth.groupby("track_id")["frame"].transform("min")
    init = truth[truth["frame"] == first].reset_index(drop=True)
    return MultiScene(frames, cams, truth, truth3d, init, FPS, tuple(a.appearance for a in script.actors), plates,
                      _events(script, n_frames))


def _events(script: Script3D, n: int) -> pd.DataFrame:
    """The script's activities within the take's ``n`` frames (the story is 150 frames long)."""
    from partlab.labelling.synth.scene import EVENT_TRUTH_COLUMNS

    rows = []
    for kind, a, b, ta, pa, tb, pb in script.events:
        if b < n:
            colour = script.objects[0][3] if kind == "exchange" and script.objects else None
            rows.append(dict(kind=kind, start_frame=a, end_frame=b, track_id_a=ta, part_a=pa, track_id_b=tb,
                             part_b=pb, colour="" if colour is None else "#{:02x}{:02x}{:02x}".format(*colour[::-1])))
    return pd.DataFrame(rows, columns=list(EVENT_TRUTH_COLUMNS))


def hide_camera(scene_dir: str | PathLike, camera: str, start: int, stop: int) -> None:
    """Black out frames ``start..stop-1`` of one camera's clip in a rendered take (a covered lens)."""
    from partlab.labelling.video import VideoClip, write_video

    p = Path(scene_dir) / f"{camera}.mp4"
    clip = VideoClip(p)
    frames = np.stack([f for _, f in clip.frames(0, clip.frame_count)])
    clip.close()
    frames[start:stop] = 0
    write_video(p, frames, FPS)


# -- the chessboard -------------------------------------------------------------------------

BOARD = (9, 6)  # inner corners (columns, rows): 10 x 7 squares, not symmetric under a half turn
SQUARE_MM = 100.0


def board_poses(rng: np.random.Generator, n_frames: int,
                facing: float | list[float]) -> list[tuple[np.ndarray, np.ndarray]]:
    """Board poses ``(R, origin)`` (board -> world: ``X = R @ [x, y, 0] + origin``, mm).

    Frame 0 lies on the floor, first inner corner at the origin, rows along +X, columns along +Y:
    it defines the world frame. The others are held up near the scene centre, turned towards the
    cameras and tilted by up to 30 degrees. ``facing``: the cameras' direction seen from the
    scene, or one per camera: each board then turns towards one camera picked at random (+-20
    degrees) or, 60% of the time, between two neighbouring cameras, so that every camera sees a
    good share of them and neighbours share enough for ``stereoCalibrate``."""
    poses = [(np.eye(3), np.zeros(3))]
    facings = np.atleast_1d(np.asarray(facing, float))
    mean = float(np.arctan2(np.sin(facings).mean(), np.cos(facings).mean()))
    fw = np.array([np.cos(mean), np.sin(mean), 0.0])
    for _ in range(n_frames - 1):
        if len(facings) > 1 and rng.random() < 0.6:  # between two neighbouring cameras: both see it
            order = np.sort(np.unwrap(facings))
            k = int(rng.integers(len(order) - 1))
            yaw = 0.5 * (order[k] + order[k + 1]) + np.radians(rng.uniform(-10, 10))
        else:
            yaw = float(rng.choice(facings)) + np.radians(rng.uniform(-20, 20))
        normal = np.array([np.cos(yaw), np.sin(yaw), 0.0])
        tilt = np.radians(rng.uniform(-30, 10))
        normal = np.cos(tilt) * normal + np.sin(tilt) * EZ
        xa = np.cross(EZ, normal)
        xa /= np.linalg.norm(xa)
        roll = np.radians(rng.uniform(-20, 20))
        xr = np.cos(roll) * xa + np.sin(roll) * np.cross(normal, xa)
        # the printed side (z = x cross y) faces the cameras, as the floor board's z = +Z does
        R = np.stack([xr, np.cross(normal, xr), normal], 1)
        centre = np.array([rng.uniform(-300, 300), rng.uniform(-300, 300), rng.uniform(900, 1400)])
        centre[:2] += 300 * fw[:2]
        w, h = (BOARD[0] + 1) * SQUARE_MM, (BOARD[1] + 1) * SQUARE_MM
        origin = centre - R @ np.array([w / 2 - SQUARE_MM, h / 2 - SQUARE_MM, 0.0])
        poses.append((R, origin))
    return poses


def render_board(camera: Camera, R: np.ndarray, origin: np.ndarray, background: np.ndarray,
                 supersample: int = 3) -> np.ndarray:
    """The board (black and white squares, a white margin of half a square) ray-cast over
    ``background``, with ``supersample``^2 rays per pixel for sub-pixel accurate edges."""
    w, h = camera.size
    s = supersample
    # sub-pixel sample positions (OpenCV's pixel centres are at integer coordinates)
    u, v = np.meshgrid((np.arange(w * s) + 0.5) / s - 0.5, (np.arange(h * s) + 0.5) / s - 0.5)
    d = np.stack([u, v, np.ones_like(u)], -1) @ np.linalg.inv(camera.K).T @ camera.R
    c = camera.centre
    n = R[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        tt = ((origin - c) @ n) / (d @ n)
    p = c + d * tt[..., None] - origin
    bx, by = p @ R[:, 0], p @ R[:, 1]  # board coordinates (mm), first inner corner at 0
    sq = SQUARE_MM
    i, j = np.floor(bx / sq) + 1, np.floor(by / sq) + 1  # square index (0 = first square)
    # printed on one side (z = x cross y): a camera behind the board sees its plain back
    front = (d @ n) < 0
    inside = (tt > 0) & (bx > -1.5 * sq) & (bx < (BOARD[0] + 0.5) * sq) & (by > -1.5 * sq) & (
        by < (BOARD[1] + 0.5) * sq)
    squares = (i >= 0) & (i <= BOARD[0]) & (j >= 0) & (j <= BOARD[1])
    black = squares & ((i + j) % 2 == 0)  # the first square (at the origin's outer diagonal) is black
    val = np.where(black, 20.0, 235.0)
    img = cv2.resize(background, (w * s, h * s), interpolation=cv2.INTER_NEAREST).astype(np.float32)
    img[inside] = np.where(front[inside], val[inside], 150.0)[:, None]
    return cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA).astype(np.uint8)


def render_chessboard(cameras: list[Camera], outdir: str | PathLike, seed: int = 0, n_frames: int = 30) -> Path:
    """Write ``chessboard/<camera>.mp4`` (lossless-enough MJPG .avi) of the same board poses per camera,
    and ``chessboard/board.json`` (the board's size)."""
    from partlab.labelling.video import write_video

    rng = np.random.default_rng([seed, 999])
    out = Path(outdir) / "chessboard"
    out.mkdir(parents=True, exist_ok=True)
    poses = board_poses(rng, n_frames, [float(np.arctan2(c.centre[1], c.centre[0])) for c in cameras])
    colours = _room_colours(rng)
    for cam in cameras:
        bg = room_image(rng, cam, colours)
        frames = [render_board(cam, R, o, bg) for R, o in poses]
        write_video(out / f"{cam.name}.avi", frames, FPS)
    (out / "board.json").write_text(json.dumps({"inner_corners": list(BOARD), "square_mm": SQUARE_MM,
                                                "world": "the board of frame 0"}) + "\n")
    return out


def render_take(name: str, outdir: str | PathLike, n_cameras: int = 3, seed: int = 0, n_frames: int = 150,
                width: int = 640, height: int = 480, *, chessboard: bool = True) -> Path:
    """Render a multi-camera take: ``<cam>.mp4`` per camera, ``calibration.json``, ``truth.csv`` (per
    view, ``camera`` column), ``truth3d.csv``, ``init.csv``, ``scene.json``, ``<cam>_background.png``
    (the empty scene, as the
    paper's background model is trained on, sec. 6.1), ``events.csv`` (the activity truth) and
    ``chessboard/``."""
    from partlab.labelling.calibration import write_calibration
    from partlab.labelling.video import write_video
    from partlab.tracking.tracks import write_tracks_csv

    scene = make_multiview_scene(name, n_cameras, seed, n_frames, width, height)
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    for cam in scene.cameras:
        write_video(out / f"{cam.name}.mp4", scene.frames[cam.name], scene.fps)
        cv2.imwrite(str(out / f"{cam.name}_background.png"), scene.backgrounds[cam.name])
    write_calibration(scene.cameras, out / "calibration.json")
    write_tracks_csv(scene.truth, out / "truth.csv")
    write_tracks_csv(scene.init, out / "init.csv")
    scene.truth3d.to_csv(out / "truth3d.csv", index=False, lineterminator="\n")
    scene.events.to_csv(out / "events.csv", index=False, lineterminator="\n")
    meta = {"name": name, "seed": seed, "fps": scene.fps, "cameras": [c.name for c in scene.cameras],
            "width": width, "height": height, "n_frames": n_frames, "units": "mm",
            "people": [{"track_id": k + 1, "skin": list(p.skin), "shirt": list(p.shirt),
                        "height_m": round(p.height_m, 3)}
                       for k, p in enumerate(scene.appearances)]}
    (out / "scene.json").write_text(json.dumps(meta, indent=2) + "\n")
    if chessboard:
        render_chessboard(scene.cameras, out, seed)
    return out
