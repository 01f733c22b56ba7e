"""Synthetic top-view RGB-D takes with exact truth (the setting of Migniot & Ababsa sec. 3).

A depth-and-colour camera about 2.9 m above the floor looks straight down on people standing at
a shelf and moving their arms. Each person is the tracker's own articulated model
(:mod:`partlab.tracking.topview.model`: a sphere head, an elliptic-cylinder torso, cylinder arms
and forearms, plane hands) with randomised sizes, clothes and arm motions, ray cast exactly per
pixel; the floor and a low basket (below the tracker's height threshold) fill the rest. Depth is
quantised in disparity as a structured-light sensor does (steps grow with the square of the
distance), gets noise and loses pixels at depth edges and at random (0 = unmeasured).

Scenarios (:data:`TOPVIEW_SCENARIOS`):

* ``topview_s1``: one person in dark clothes moving both arms (the paper's S1);
* ``topview_s2``: one person in bright, flashy clothes (S2);
* ``topview_s3``: two people facing each other whose reaching arms cross and overlap (S3);
* ``topview_group``: one to three people side by side at a counter, each with their own sizes,
  clothes (dark or bright) and motions, seen from 2.7-3.2 m with 0.5-2 times the sensor noise.

:func:`render_topview` writes a take folder that :func:`partlab.labelling.take.open_take` reads::

    take.json, calibration.json      one stream cam0 and its camera (K, R, t in world mm, Z up)
    clip.mp4, clip_depth/NNNNNN.png  colour video and 16-bit depth PNGs in millimetres
    truth3d.csv                      frame,track_id,part,X,Y,Z (head, shoulders, elbows, hands)
    angles.csv                       frame,track_id and the 17 degrees of freedom
    truth.csv, init.csv              tracks CSV of the joints (boxes + X,Y,Z); init = frame 0
    labels.npz                       person (T,H,W) uint8 track id (0 = none) and part (T,H,W)
                                     uint8 weighting part + 1 (1 head .. 5 left arm, 0 = none)
    scene.json                       seed, camera height, every person's body sizes and colours
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from os import PathLike
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from partlab.labelling.synth.background import smooth_noise
from partlab.tracking.camera import Camera
from partlab.tracking.core.box import Box
from partlab.tracking.topview.likelihood import self_intersection
from partlab.tracking.topview.model import (
    DOF,
    JOINT_LIMITS,
    JOINTS,
    KINDS,
    N_DOF,
    PART_OF,
    PRIMITIVES,
    RECTANGLE,
    SPHERE,
    Body,
    joints,
    primitives,
)
from partlab.tracking.tracks import TrackRecord, records_to_frame

TOPVIEW_SCENARIOS: tuple[str, ...] = ("topview_s1", "topview_s2", "topview_s3", "topview_group")
#: camera height (mm) and sensor noise factor ranges: the paper's 2.9 m for S1-S3; a group is seen
#: from 2.7-3.2 m (ceilings differ) with a sensor 0.5-2 times as noisy as the reference one
CAMERA_HEIGHT_MM = {"topview_group": (2700.0, 3200.0)}
NOISE_FACTOR = {"topview_group": (0.5, 2.0)}
FPS = 25.0
#: world size (mm) of the box drawn around each joint's image
JOINT_BOX_MM = {"head": 190.0, "right_shoulder": 120.0, "left_shoulder": 120.0, "right_elbow": 110.0,
                "left_elbow": 110.0, "right_hand": 160.0, "left_hand": 160.0}


def topview_camera(width: int, height: int, camera_height: float, name: str = "cam0") -> Camera:
    """A Kinect-like camera (57 degree horizontal field of view) ``camera_height`` mm above the
    world origin looking straight down: image x along world X, image y along world -Y."""
    f = 0.5 * width / np.tan(np.radians(57.0) / 2)
    K = np.array([[f, 0, width / 2 - 0.5], [0, f, height / 2 - 0.5], [0, 0, 1]])
    R = np.diag([1.0, -1.0, -1.0])
    t = -R @ np.array([0.0, 0.0, camera_height])
    return Camera(name, K, (width, height), np.zeros(5), R, t)


# -- people: sizes, looks and motion ----------------------------------------------------------

@dataclass(frozen=True)
class Person:
    body: Body
    colours: dict[str, tuple[int, int, int]]  # primitive name -> BGR
    states: np.ndarray                         # (T, 17)


def _body(rng: np.random.Generator, stature: float | None = None) -> Body:
    b = Body().scaled(stature if stature is not None else rng.uniform(1600, 1900))
    w = rng.uniform(0.9, 1.15)
    arm = rng.uniform(0.94, 1.06)
    return replace(b, torso_half_width=b.torso_half_width * w,
                   torso_half_depth=b.torso_half_depth * rng.uniform(0.9, 1.2),
                   shoulder_offset=b.shoulder_offset * w, upper_arm_length=b.upper_arm_length * arm,
                   forearm_length=b.forearm_length * arm)


def _colour(rng, bright: bool) -> tuple[int, int, int]:
    if bright:  # flashy: saturated hue, high value
        hsv = np.uint8([[[rng.integers(0, 180), rng.integers(170, 256), rng.integers(180, 256)]]])
    else:       # dark clothes: low value, little saturation
        hsv = np.uint8([[[rng.integers(0, 180), rng.integers(0, 90), rng.integers(25, 75)]]])
    return tuple(int(v) for v in cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR)[0, 0])


def _looks(rng, bright: bool) -> dict[str, tuple[int, int, int]]:
    skin = np.array([(160, 185, 228), (130, 165, 215), (105, 145, 195), (85, 115, 165), (60, 85, 125)])
    sk = tuple(int(v) for v in np.clip(skin[rng.integers(len(skin))] + rng.integers(-12, 13, 3), 0, 255))
    hair = tuple(int(v) for v in np.clip(np.array([(25, 25, 30), (25, 40, 60), (40, 70, 110), (100, 165, 205),
                                                   (150, 150, 152)])[rng.integers(5)] + rng.integers(-8, 9, 3), 0, 255))
    shirt = _colour(rng, bright)
    sleeve = _colour(rng, bright) if bright and rng.random() < 0.5 else shirt
    short = rng.random() < 0.5
    return {"head": hair, "shoulders": shirt, "torso": shirt,
            "right_upper_arm": sleeve, "left_upper_arm": sleeve,
            "right_forearm": sk if short else sleeve, "left_forearm": sk if short else sleeve,
            "right_hand": sk, "left_hand": sk}


def _wave(rng, t: np.ndarray, centre: tuple[float, float], amp: tuple[float, float],
          freq: tuple[float, float] = (0.12, 0.45)) -> np.ndarray:
    """A smooth random signal: a centre plus two sines of random frequency and phase."""
    c = rng.uniform(*centre)
    a = rng.uniform(*amp)
    f1, f2 = rng.uniform(*freq, 2)
    p1, p2 = rng.uniform(0, 2 * np.pi, 2)
    return c + a * (0.7 * np.sin(2 * np.pi * f1 * t + p1) + 0.3 * np.sin(2 * np.pi * f2 * t + p2))


def _motion(rng, n: int, body: Body, x: float, y: float, yaw: float,
            reach: tuple[bool, bool] = (False, False)) -> np.ndarray:
    """``(n, 17)`` states of a person standing near ``(x, y)`` facing ``yaw``, moving both arms
    (``reach``: right/left arm reaches well forward, towards someone in front)."""
    t = np.arange(n) / FPS
    s = np.zeros((n, N_DOF))
    s[:, 0] = x + _wave(rng, t, (0, 0), (0, 60), (0.05, 0.15))
    s[:, 1] = y + _wave(rng, t, (0, 0), (0, 60), (0.05, 0.15))
    s[:, 3] = yaw + _wave(rng, t, (0, 0), (0.05, 0.3), (0.05, 0.15))
    # now and then a bend towards a low shelf
    bend = np.full(n, rng.uniform(0.0, 0.1))
    if rng.random() < 0.6 and n > 20:
        c, w = rng.uniform(0.2, 0.8) * t[-1], rng.uniform(0.6, 1.5)
        bend += rng.uniform(0.2, 0.5) * np.exp(-0.5 * ((t - c) / w) ** 2)
    s[:, 4] = bend
    s[:, 2] = body.pelvis_height - 30.0 * bend  # the hips sink a little as one bends
    s[:, 5] = _wave(rng, t, (-0.1, 0.3), (0.0, 0.2))
    s[:, 6] = _wave(rng, t, (-0.2, 0.2), (0.0, 0.5))
    for base, reaching in ((7, reach[0]), (12, reach[1])):
        if reaching:
            s[:, base] = _wave(rng, t, (1.1, 1.4), (0.35, 0.5), (0.15, 0.35))
            s[:, base + 1] = _wave(rng, t, (0.0, 0.2), (0.0, 0.15))
            s[:, base + 3] = _wave(rng, t, (0.1, 0.4), (0.1, 0.3))
        else:
            s[:, base] = _wave(rng, t, (0.3, 0.9), (0.4, 0.9))
            s[:, base + 1] = _wave(rng, t, (0.15, 0.5), (0.1, 0.45))
            s[:, base + 3] = _wave(rng, t, (0.5, 1.2), (0.3, 0.8))
        s[:, base + 2] = _wave(rng, t, (-0.3, 0.3), (0.0, 0.3))
        s[:, base + 4] = _wave(rng, t, (-0.3, 0.3), (0.0, 0.3))
    lo, hi = JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1]
    return _out_of_the_body(np.clip(s, lo, hi), body)


def _out_of_the_body(s: np.ndarray, body: Body, step: float = 0.05, rounds: int = 30) -> np.ndarray:
    """The sines know nothing of the body: where a forearm or hand would go into the person's
    own torso or head (:func:`partlab.tracking.topview.likelihood.self_intersection`), the
    shoulder's abduction, else the elbow's flexion, moves to the nearest value (``step`` rad at a
    time, either way, within the joint's limits) that keeps them out, as the torso would stop
    the arm. Frames where nothing goes in are left as they are."""
    for base, part in ((7, PART_OF[4]), (12, PART_OF[7])):  # right arm, left arm
        for dof in (base + 1, base + 3):  # abduction, elbow flexion
            lo, hi = JOINT_LIMITS[dof]
            todo = np.flatnonzero(self_intersection(primitives(s, body), 1000.0)[:, part] > 0)
            value = s[todo, dof].copy()
            for k in range(1, rounds + 1):
                for sign in (-1.0, 1.0):
                    if not len(todo):
                        break
                    trial = s[todo].copy()
                    trial[:, dof] = np.clip(value + sign * k * step, lo, hi)
                    out = self_intersection(primitives(trial, body), 1000.0)[:, part] <= 0
                    s[todo[out], dof] = trial[out, dof]
                    todo, value = todo[~out], value[~out]
    return s


def _people(name: str, rng, n: int) -> list[Person]:
    if name in ("topview_s1", "topview_s2"):
        body = _body(rng)
        return [Person(body, _looks(rng, name == "topview_s2"),
                       _motion(rng, n, body, rng.uniform(-250, 250), rng.uniform(-150, 150),
                               rng.uniform(-np.pi, np.pi)))]
    if name == "topview_s3":
        tall = rng.random() < 0.5
        a = _body(rng, rng.uniform(1780, 1900) if tall else rng.uniform(1600, 1700))
        b = _body(rng, rng.uniform(1600, 1700) if tall else rng.uniform(1780, 1900))
        gap = rng.uniform(850, 1000)
        axis = rng.uniform(-0.4, 0.4)  # the line between them, a little off the image's x axis
        ux, uy = np.cos(axis), np.sin(axis)
        yaw_a = axis - np.pi / 2  # A faces along +u (body y axis), B faces A
        # A reaches with the right arm, B with the left: both are on the same side of the line
        sa = _motion(rng, n, a, -ux * gap / 2, -uy * gap / 2, yaw_a, reach=(True, False))
        sb = _motion(rng, n, b, ux * gap / 2, uy * gap / 2, yaw_a + np.pi, reach=(False, True))
        return [Person(a, _looks(rng, rng.random() < 0.5), sa), Person(b, _looks(rng, rng.random() < 0.5), sb)]
    if name == "topview_group":
        return _group(rng, n)
    raise ValueError(f"unknown top-view scenario {name!r}; expected one of {', '.join(TOPVIEW_SCENARIOS)}")


def _group(rng, n: int) -> list[Person]:
    """One to three people side by side (shoulder to shoulder 0.75-0.9 m apart), facing about the
    same way, each moving both arms."""
    count = int(rng.integers(1, 4))
    gap = rng.uniform(750, 900)
    axis = rng.uniform(-0.5, 0.5)
    ux, uy = np.cos(axis), np.sin(axis)
    people = []
    for k in range(count):
        off = (k - (count - 1) / 2) * gap
        body = _body(rng)
        yaw = axis + rng.uniform(-0.3, 0.3) + (np.pi if rng.random() < 0.5 else 0.0)
        x, y = off * ux + rng.uniform(-60, 60), off * uy + rng.uniform(-60, 60)
        people.append(Person(body, _looks(rng, rng.random() < 0.5), _motion(rng, n, body, x, y, yaw)))
    return people


# -- ray casting ------------------------------------------------------------------------------

def _quadratic_first(A, B, C):
    disc = B * B - 4 * A * C
    ok = (disc >= 0) & (A > 1e-12)
    sq = np.sqrt(np.where(ok, disc, 0.0))
    A2 = np.where(ok, 2 * A, 1.0)
    return np.where(ok, (-B - sq) / A2, np.inf), np.where(ok, (-B + sq) / A2, np.inf)


def ray_cast(origin: np.ndarray, dirs: np.ndarray, prim: np.ndarray, kind: int) -> np.ndarray:
    """Ray parameter ``t`` of the first hit of rays ``origin + t dirs`` (``dirs (N, 3)``) with one
    packed primitive (:mod:`partlab.tracking.topview.model`); ``inf`` where a ray misses."""
    O = prim[0:3].astype(np.float64)
    a, b, L = float(prim[12]), float(prim[13]), float(prim[14])
    o = origin - O
    if kind == SPHERE:
        t1, _ = _quadratic_first((dirs * dirs).sum(1), 2 * dirs @ o, o @ o - a * a)
        return np.where(t1 > 0, t1, np.inf)
    E = np.stack([prim[3:6], prim[6:9], prim[9:12]]).astype(np.float64)  # rows e1, e2, e3
    lo, lv = E @ o, dirs @ E.T
    if kind == RECTANGLE:
        with np.errstate(divide="ignore", invalid="ignore"):
            t = -lo[1] / lv[:, 1]
        q1, q3 = lo[0] + t * lv[:, 0], lo[2] + t * lv[:, 2]
        return np.where((t > 0) & (np.abs(q1) <= a) & (np.abs(q3) <= L), t, np.inf)
    s = np.array([1 / a, 1 / b])
    o2, v2 = lo[:2] * s, lv[:, :2] * s
    t1, t2 = _quadratic_first((v2 * v2).sum(1), 2 * v2 @ o2, o2 @ o2 - 1)
    best = np.full(len(dirs), np.inf)
    for t in (t1, t2):
        z = lo[2] + t * lv[:, 2]
        best = np.minimum(best, np.where((t > 0) & (z >= 0) & (z <= L), t, np.inf))
    for cap in (0.0, L):
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (cap - lo[2]) / lv[:, 2]
        q = (lo[:2] + t[:, None] * lv[:, :2]) * s
        best = np.minimum(best, np.where((t > 0) & ((q * q).sum(1) <= 1), t, np.inf))
    return best


def _pixels_near(camera: Camera, prim: np.ndarray, kind: int) -> np.ndarray:
    """Flat indexes of the pixels whose rays can hit a primitive: the image box of its bounding
    sphere (ray casting only there keeps a frame to a few milliseconds)."""
    O, a, b, L = prim[0:3].astype(np.float64), float(prim[12]), float(prim[13]), float(prim[14])
    if kind == SPHERE:
        c, r = O, a
    elif kind == RECTANGLE:
        c, r = O, float(np.hypot(a, L))
    else:
        c, r = O + prim[9:12] * L / 2, float(np.hypot(max(a, b), L / 2))
    w, h = camera.size
    z = float(camera.to_camera(c[None])[0, 2])
    if z - r <= 1.0:
        return np.arange(w * h)
    u, v = camera.project(c[None])[0]
    rp = camera.K[0, 0] * r / (z - r) + 2
    x0, x1 = int(max(np.floor(u - rp), 0)), int(min(np.ceil(u + rp), w - 1))
    y0, y1 = int(max(np.floor(v - rp), 0)), int(min(np.ceil(v + rp), h - 1))
    if x1 < x0 or y1 < y0:
        return np.zeros(0, np.int64)
    ys, xs = np.mgrid[y0:y1 + 1, x0:x1 + 1]
    return (ys * w + xs).ravel()


def _pixel_rays(camera: Camera) -> np.ndarray:
    """``(H*W, 3)`` world directions scaled so that ``t`` along them is the depth (camera z)."""
    w, h = camera.size
    u, v = np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64))
    pix = np.stack([u.ravel(), v.ravel(), np.ones(u.size)], 1)
    return (pix @ np.linalg.inv(camera.K).T) @ camera.R  # R^T d per row


# -- the scene --------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class TopViewScene:
    """A rendered top-view take. ``color (T, H, W, 3) uint8`` BGR, ``depth (T, H, W) float32`` mm
    (NaN = unmeasured), ``person``/``part (T, H, W) uint8`` truth labels (see module doc),
    ``people``: each track's :class:`Person` (track ``k`` is ``people[k - 1]``), ``truth3d``:
    frame,track_id,part,X,Y,Z, ``truth``: the same joints as a tracks table with boxes."""

    name: str
    seed: int
    camera: Camera
    color: np.ndarray
    depth: np.ndarray
    person: np.ndarray
    part: np.ndarray
    people: list[Person]
    truth3d: pd.DataFrame
    truth: pd.DataFrame
    fps: float = FPS

    @property
    def init(self) -> pd.DataFrame:
        return self.truth[self.truth["frame"] == 0].reset_index(drop=True)


def joint_box(camera: Camera, point: np.ndarray, size_mm: float) -> Box:
    """The square image box around a joint's projection, ``size_mm`` across at its depth."""
    uv = camera.project(point[None])[0]
    z = float(camera.to_camera(point[None])[0, 2])
    side = max(camera.K[0, 0] * size_mm / max(z, 1.0), 2.0)
    return Box(float(uv[0] - side / 2), float(uv[1] - side / 2), float(side), float(side))


def make_topview(name: str, seed: int = 0, n_frames: int = 150, width: int = 320, height: int = 240) -> TopViewScene:
    """Render scenario ``name`` (one of :data:`TOPVIEW_SCENARIOS`)."""
    rng = np.random.default_rng([seed, 17])
    cam_h = rng.uniform(*CAMERA_HEIGHT_MM.get(name, (2850.0, 2950.0)))
    camera = topview_camera(width, height, cam_h)
    people = _people(name, rng, n_frames)
    dirs = _pixel_rays(camera)
    origin = camera.centre
    n_pix = width * height
    # the room: a floor with a faint texture and a low basket (below any person's hips)
    floor_tex = smooth_noise(rng, height, width, max(4, width // 24))
    floor_col = np.array(rng.integers(90, 170, 3), np.float32)
    bx, by = rng.uniform(-1200, 1200), rng.uniform(-900, 900)
    basket = (bx, by, rng.uniform(200, 350), rng.uniform(150, 250), rng.uniform(350, 600))  # x, y, half w, half d, top
    basket_col = np.array(rng.integers(20, 230, 3), np.float32)
    noise_scale = rng.uniform(*NOISE_FACTOR.get(name, (0.6, 1.4)))
    step = 2.85e-6 * noise_scale  # disparity step (1/mm): about 6 mm at 1.5 m, 24 mm at 2.9 m
    color = np.zeros((n_frames, height, width, 3), np.uint8)
    depth = np.zeros((n_frames, height, width), np.float32)
    person_lab = np.zeros((n_frames, height, width), np.uint8)
    part_lab = np.zeros((n_frames, height, width), np.uint8)
    rows3d, records = [], []
    # floor and basket do not move: cast once
    t_bg = (origin[2] - 0.0) / -dirs[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        t_top = (origin[2] - basket[4]) / -dirs[:, 2]
    hit = origin[:2] + t_top[:, None] * dirs[:, :2]
    on_basket = (np.abs(hit[:, 0] - bx) <= basket[2]) & (np.abs(hit[:, 1] - by) <= basket[3])
    t_bg = np.where(on_basket, t_top, t_bg)
    bg_col = np.where(on_basket[:, None], basket_col, floor_col * (1 + 0.12 * floor_tex.reshape(-1, 1)))
    colours = [np.array([p.colours[nm] for nm, _, _ in PRIMITIVES], np.float32) for p in people]
    for f in range(n_frames):
        best = t_bg.copy()
        who = np.zeros(n_pix, np.uint8)
        which = np.full(n_pix, -1, np.int64)
        col = bg_col.copy()
        for k, p in enumerate(people):
            prims = primitives(p.states[f][None], p.body)[0]
            for j in range(len(prims)):
                sub = _pixels_near(camera, prims[j], int(KINDS[j]))
                t = ray_cast(origin, dirs[sub], prims[j], int(KINDS[j]))
                closer = t < best[sub]
                idx = sub[closer]
                best[idx] = t[closer]
                who[idx] = k + 1
                which[idx] = j
                col[idx] = colours[k][j]
            pts = joints(p.states[f][None], p.body)[0]
            for jn, X in zip(JOINTS, pts):
                rows3d.append((f, k + 1, jn, *X))
                records.append(TrackRecord(f, k + 1, jn, joint_box(camera, X, JOINT_BOX_MM[jn]), source="truth",
                                           X=float(X[0]), Y=float(X[1]), Z=float(X[2])))
        z = best.reshape(height, width)
        # sensor: disparity quantisation, noise, and lost pixels at depth edges and at random
        zq = 1.0 / (np.round(1.0 / (z * step)) * step)
        zq = zq + rng.normal(0, 1, z.shape) * 0.3 * step * z * z
        edge = (np.abs(cv2.Laplacian(z.astype(np.float32), cv2.CV_32F, ksize=3)) > 150.0)
        drop = (edge & (rng.random(z.shape) < 0.5)) | (rng.random(z.shape) < 0.01)
        zq[drop | (zq < 800) | (zq > 3500)] = np.nan
        depth[f] = zq
        person_lab[f] = who.reshape(height, width)
        part_lab[f] = np.where(which >= 0, PART_OF[np.maximum(which, 0)] + 1, 0).reshape(height, width)
        img = col.reshape(height, width, 3) + rng.normal(0, 5, (height, width, 3))
        color[f] = np.clip(cv2.GaussianBlur(img.astype(np.float32), (3, 3), 0.7), 0, 255).astype(np.uint8)
    truth3d = pd.DataFrame(rows3d, columns=["frame", "track_id", "part", "X", "Y", "Z"])
    return TopViewScene(name, seed, camera, color, depth, person_lab, part_lab, people, truth3d,
                        records_to_frame(records))


def render_topview(name: str, outdir: str | PathLike, seed: int = 0, n_frames: int = 150, width: int = 320,
                   height: int = 240, *, progress: bool = False) -> Path:
    """Render scenario ``name`` into the take folder ``outdir`` (module docstring)."""
    from partlab.labelling.calibration import write_calibration
    from partlab.labelling.video import write_video
    from partlab.tracking.tracks import write_tracks_csv

    scene = make_topview(name, seed, n_frames, width, height)
    out = Path(outdir)
    (out / "clip_depth").mkdir(parents=True, exist_ok=True)
    write_video(out / "clip.mp4", scene.color, scene.fps)
    for f, d in enumerate(scene.depth):
        mm = np.where(np.isfinite(d), np.round(d), 0).astype(np.uint16)
        cv2.imwrite(str(out / "clip_depth" / f"{f:06d}.png"), mm)
    write_calibration({"cam0": scene.camera}, out / "calibration.json")
    (out / "take.json").write_text(json.dumps(
        {"fps": scene.fps, "streams": [{"name": "cam0", "color": "clip.mp4", "depth": "clip_depth"}]}, indent=1) + "\n")
    scene.truth3d.to_csv(out / "truth3d.csv", index=False, float_format="%.1f", lineterminator="\n")
    angles = []
    for k, p in enumerate(scene.people):
        a = pd.DataFrame(p.states, columns=list(DOF))
        a.insert(0, "track_id", k + 1)
        a.insert(0, "frame", np.arange(len(p.states)))
        angles.append(a)
    pd.concat(angles).sort_values(["frame", "track_id"]).to_csv(out / "angles.csv", index=False,
                                                                 float_format="%.5f", lineterminator="\n")
    write_tracks_csv(scene.truth, out / "truth.csv")
    write_tracks_csv(scene.init, out / "init.csv")
    np.savez_compressed(out / "labels.npz", person=scene.person, part=scene.part)
    meta = {"name": name, "seed": seed, "fps": scene.fps, "width": width, "height": height, "n_frames": n_frames,
            "camera_height_mm": round(float(scene.camera.centre[2]), 1), "tracks": len(scene.people),
            "people": [{"track_id": k + 1, "body": {kk: round(v, 1) for kk, v in p.body.__dict__.items()},
                        "colours": p.colours} for k, p in enumerate(scene.people)]}
    (out / "scene.json").write_text(json.dumps(meta, indent=2) + "\n")
    return out
