"""The scenario scripts: who walks where, what they do, and what stands in the room.

Each ``_name(rng, camera, n_frames, fps)`` returns a :class:`Script`. Paths are
keyframes ``(clip time in [0, 1], x as a fraction of the half frame width, depth in
metres)`` with small per-seed jitter, so every seed tells the same story a little
differently. Depths 5.5 .. 12 m give people 220 .. 100 px tall in a 720x480 frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from partlab.labelling.synth.appearance import Appearance, random_appearances, sample_appearances
from partlab.labelling.synth.background import WALL_DEPTH, Prop
from partlab.labelling.synth.camera import Camera, LocalView
from partlab.labelling.synth.figure import HAND_R, WAIST_HALF_D
from partlab.labelling.synth.motion import Motion, bump, clip_time, walk, with_changes
from partlab.tracking.core.box import Box


@dataclass(frozen=True, eq=False)
class Actor:
    """One person: looks, motion, and (for scenes not on the floor camera) a fixed view."""

    appearance: Appearance
    motion: Motion
    view: LocalView | None = None
    seat_cut: float | None = None


@dataclass(frozen=True, eq=False)
class Occluder:
    """A fixed object in front of everybody (drawn last): its box and colour."""

    box: Box
    colour: tuple[int, int, int]


@dataclass(frozen=True, eq=False)
class Script:
    """``objects``: carried objects (:class:`partlab.labelling.synth.activities.CarriedObject`);
    ``events``: the activity truth (:class:`partlab.labelling.synth.activities.EventTruth`)."""

    actors: list[Actor]
    props: list[Prop] = field(default_factory=list)
    occluders: list[Occluder] = field(default_factory=list)
    objects: list = field(default_factory=list)
    events: list = field(default_factory=list)
    lighting: np.ndarray | None = None  # (H, W, 3) float32 gain on the whole frame (None: as drawn)


def _j(rng: np.random.Generator, scale: float) -> float:
    return float(rng.uniform(-scale, scale))


def _glances(rng: np.random.Generator, n_frames: int, fps: float, amount: float = 0.35) -> np.ndarray:
    """Head yaw of a walker looking around now and then: a slow smooth random signal (radians)."""
    frames = np.arange(n_frames) / fps
    f1, f2 = rng.uniform(0.15, 0.35, 2)
    p1, p2 = rng.uniform(0, 2 * np.pi, 2)
    return amount * (0.6 * np.sin(2 * np.pi * f1 * frames + p1) + 0.4 * np.sin(2 * np.pi * f2 * frames + p2))


def _single(rng, camera, n_frames, fps) -> Script:
    (app,) = sample_appearances(rng, 1)
    z1, z2, z3 = 8.0 + _j(rng, 0.4), 6.6 + _j(rng, 0.3), 8.4 + _j(rng, 0.3)
    # about 1.4 m/s across the room, a stop to turn back (waving at the camera), then back and away
    m = walk(camera, n_frames, [(0.0, -0.8, z1), (0.63, 0.6, z2), (0.76, 0.6, z2), (1.0, 0.05, z3)],
             app.height_m)
    t = clip_time(n_frames)
    wave = bump(t, 0.68, 0.73)  # the right hand waves (about 2 Hz) while facing the camera
    return Script([Actor(app, with_changes(m, wave=wave, head_yaw=_glances(rng, n_frames, fps)))])


def _pair_cross(rng, camera, n_frames, fps) -> Script:
    a, b = sample_appearances(rng, 2)
    # a tall near walker and a short far one: seen from 3.1 m up, the far head then stays behind the near one
    a = replace(a, height_m=float(rng.uniform(1.80, 1.86)))
    b = replace(b, height_m=float(rng.uniform(1.60, 1.64)))
    za = 7.0 + _j(rng, 0.2)
    zb = za + 0.55 + _j(rng, 0.05)  # close behind: at the crossing little more than the far head shows
    xa = 0.85 + _j(rng, 0.05)
    ma = walk(camera, n_frames, [(0.0, -xa, za), (1.0, xa, za)], a.height_m)
    mb = walk(camera, n_frames, [(0.0, xa, zb), (1.0, -xa, zb)], b.height_m)
    ma = with_changes(ma, head_yaw=_glances(rng, n_frames, fps))
    mb = with_changes(mb, head_yaw=_glances(rng, n_frames, fps))
    return Script([Actor(a, ma), Actor(b, mb)])


def _pillar(rng, camera, n_frames, fps) -> Script:
    (app,) = sample_appearances(rng, 1)
    m = walk(camera, n_frames, [(0.0, -0.85, 9.2 + _j(rng, 0.3)), (1.0, 0.85, 8.9 + _j(rng, 0.3))], app.height_m)
    w = 0.12 * camera.width  # a column 0.75 m wide, 5.8 m from the camera: hides the walker for a while
    x = camera.cx - w / 2 + _j(rng, 0.03 * camera.width)
    _, bottom = camera.floor_point(0.0, 5.8)
    grey = int(rng.integers(150, 175))
    return Script([Actor(app, m)], occluders=[Occluder(Box(round(x), 0.0, round(w), round(float(bottom))),
                                                       (grey - 6, grey, grey + 4))])


def _floor_rect(camera: Camera, x: float, z: float, w_m: float, h_m: float) -> tuple[float, float, float, float]:
    """Image box of an upright rectangle standing on the floor at ``(x, z)``."""
    s = float(camera.scale(z))
    fx, fy = camera.floor_point(x, z)
    return (float(fx) - s * w_m / 2, float(fy) - s * h_m, s * w_m, s * h_m)


def _distractors(rng, camera, n_frames, fps) -> Script:
    (app,) = sample_appearances(rng, 1)
    z = 8.0 + _j(rng, 0.3)
    m = walk(camera, n_frames, [(0.0, -0.85, z), (0.5, 0.0, z - 0.4), (1.0, 0.85, z)], app.height_m)

    def near(c, a=6):
        return tuple(int(v) for v in np.clip(np.asarray(c) + rng.integers(-a, a + 1, 3), 0, 255))

    props = []
    s_wall = float(camera.scale(WALL_DEPTH))
    _, wall_y = camera.floor_point(0.0, WALL_DEPTH)
    # posters on the back wall, clear of the door
    for xr, kind in ((-0.28, "poster_person"), (0.02, "rect"), (0.32, "poster_person"), (0.62, "rect")):
        x = float(camera.x_from_fraction(xr + _j(rng, 0.05), WALL_DEPTH))
        fx, _ = camera.floor_point(x, WALL_DEPTH)
        w, h = 0.9 * s_wall, 1.3 * s_wall
        box = (float(fx) - w / 2, float(wall_y) - 1.6 * s_wall, w, h)  # at head height behind the path
        if kind == "poster_person":
            props.append(Prop(kind, box, ((200, 200, 196), near(app.shirt), near(app.skin))))
        else:
            props.append(Prop(kind, box, (near(app.shirt),)))
    zb = z + 1.5
    for xr, colour, size in ((-0.45, app.trousers, (0.7, 0.55)), (0.15, app.skin, (0.45, 0.45)),
                             (0.55, app.shirt, (0.6, 0.8)), (0.85, app.trousers, (0.5, 0.5))):
        x = float(camera.x_from_fraction(xr + _j(rng, 0.04), zb))
        box = _floor_rect(camera, x, zb + _j(rng, 0.3), *size)
        kind = "ellipse" if colour is app.skin else "rect"
        props.append(Prop(kind, box, (near(colour),)))
    return Script([Actor(app, m)], props=props)


def _crowd(rng, camera, n_frames, fps) -> Script:
    apps = sample_appearances(rng, 4)
    t = clip_time(n_frames)
    ma = walk(camera, n_frames, [(0.0, -0.84, 6.6 + _j(rng, 0.2)), (1.0, 0.8, 6.9)], apps[0].height_m)
    mb = walk(camera, n_frames, [(0.0, 0.9, 8.4 + _j(rng, 0.2)), (1.0, -0.85, 8.0)], apps[1].height_m)
    mc = walk(camera, n_frames, [(0.0, -0.55, 9.6), (0.6, 0.45, 9.0 + _j(rng, 0.3)), (1.0, 0.85, 9.4)],
              apps[2].height_m)
    md = walk(camera, n_frames, [(0.0, 0.55, 9.6), (0.35, 0.3, 9.4), (0.6, 0.3, 9.4), (1.0, -0.55, 8.8)],
              apps[3].height_m)
    wave = bump(t, 0.4, 0.55)
    md = with_changes(md, wave=wave)
    motions = [with_changes(m, head_yaw=_glances(rng, n_frames, fps)) for m in (ma, mb, mc, md)]
    return Script([Actor(a, m) for a, m in zip(apps, motions)])


def _bend(rng, camera, n_frames, fps) -> Script:
    (app,) = sample_appearances(rng, 1)
    z = 7.4 + _j(rng, 0.3)
    m = walk(camera, n_frames, [(0.0, -0.85, z), (0.35, -0.05, z), (0.72, -0.05, z), (1.0, 0.65, z + 0.2)],
             app.height_m)
    t = clip_time(n_frames)
    bend = 1.25 * bump(t, 0.45, 0.6, ramp=0.08)
    return Script([Actor(app, with_changes(m, bend=bend))])


def _desk(rng, camera, n_frames, fps) -> Script:
    (app,) = sample_appearances(rng, 1)
    H = app.height_m
    W, Hi = camera.width, camera.height
    s = 0.62 * Hi  # pixels per metre: head, torso and arms about 200-230 px tall at 480 rows
    k = 0.3
    head_top = (1.0 - 0.24) * H
    y0 = 0.2 * Hi + s * head_top
    x0 = W / 2 + _j(rng, 0.05 * W)
    view = LocalView(x0, y0, s, k)
    desk_h, desk_far, desk_near = 0.75, 0.25, 0.95  # metres: height, near/far edge in front of the person
    seat_cut = desk_h - k * (desk_far - WAIST_HALF_D * H)  # the torso's front ends at the desk's far edge
    # the desk seen from the camera: far edge row, near edge row
    far_y = y0 - s * desk_h + s * k * desk_far
    near_y = y0 - s * desk_h + s * k * desk_near
    desk_w = 1.7 * s
    wood = (int(rng.integers(60, 90)), int(rng.integers(95, 125)), int(rng.integers(130, 165)))
    props = [Prop("desk", (x0 - desk_w / 2, far_y, desk_w, near_y - far_y), (wood, tuple(int(c * 0.7) for c in wood)))]
    # the object to reach for (at the person's right, i.e. image left)
    obj = np.array([-0.6, 0.5, desk_h])
    ox = x0 + s * obj[0]  # facing the camera, the lateral (left) axis is image +x: the right hand reaches image left
    oy = y0 - s * obj[2] + s * k * obj[1]
    cw, ch = 0.08 * s, 0.11 * s
    props.append(Prop("cup", (ox - cw / 2, oy - ch, cw, ch), ((40, 40, 170),)))

    n = n_frames
    t = clip_time(n)
    frames = np.arange(n)
    hr = HAND_R * H
    rest = np.array([[0.19, 0.33, desk_h + hr], [-0.19, 0.33, desk_h + hr]])
    hands = np.repeat(rest[None], n, axis=0)
    # fidgeting: slow smooth wander of each hand on the desk
    for i in range(2):
        for d, amp in ((0, 0.05), (1, 0.05)):
            ph, fr = rng.uniform(0, 6.3, 2), rng.uniform(0.2, 0.5, 2)
            hands[:, i, d] += amp * 0.5 * (np.sin(2 * np.pi * fr[0] * frames / fps + ph[0])
                                           + np.sin(2 * np.pi * fr[1] * frames / fps + ph[1]))
    # clap around frames 40-60 of 150: hands meet in front of the chest three times
    t0, t1 = 40 / 149, 60 / 149  # clip time of frames 40 and 60 of a 150-frame clip
    c = bump(t, t0, t1, ramp=0.04)
    u = np.clip((t - t0) / (t1 - t0), 0, 1)
    sep = hr * 1.05 + 0.11 * (0.5 - 0.5 * np.cos(2 * np.pi * 3 * u))
    clap = np.stack([np.stack([sep, np.full(n, 0.3), np.full(n, 0.98)], 1),
                     np.stack([-sep, np.full(n, 0.3), np.full(n, 0.98)], 1)], 1)
    hands = hands * (1 - c)[:, None, None] + clap * c[:, None, None]
    # reach around frames 80-110: the right hand goes to the cup and back
    r = bump(t, 85 / 149, 105 / 149, ramp=0.035)
    target = obj + np.array([0.0, 0.0, 0.06])
    hands[:, 1] = hands[:, 1] * (1 - r)[:, None] + target[None] * r[:, None]
    yaw = 0.3 * np.sin(2 * np.pi * frames / (fps * 3.5) + rng.uniform(0, 6.3)) * (1 - r) - 0.55 * r
    zeros = np.zeros(n)
    motion = Motion(x=zeros.copy(), z=np.full(n, 3.0), facing=np.full(n, -np.pi / 2), phase=zeros.copy(),
                    gait=zeros.copy(), wave=zeros.copy(), bend=zeros.copy(), head_yaw=yaw, hands=hands, seated=True)
    return Script([Actor(app, motion, view=view, seat_cut=seat_cut)], props=props)


def random_lighting(rng: np.random.Generator, width: int, height: int) -> np.ndarray:
    """``(H, W, 3)`` gain: overall brightness 0.55-1.25, a colour cast of up to 20 % per channel
    (warm lamps, cold daylight) and light falling off across the frame from a random side."""
    level = rng.uniform(0.55, 1.25)
    cast = rng.uniform(0.8, 1.2, 3)
    angle = rng.uniform(0, 2 * np.pi)
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    ramp = ((xx / width - 0.5) * np.cos(angle) + (yy / height - 0.5) * np.sin(angle))
    fall = 1.0 + rng.uniform(0.0, 0.5) * ramp
    return (level * fall[..., None] * cast[None, None, :]).astype(np.float32)


def _random(rng, camera, n_frames, fps) -> Script:
    """Randomized scene (issue 13): 1-12 people of any look and size walking across at their own
    depths, speeds and times (some enter late, some leave), seen by a random camera
    (:meth:`Camera.random`) under random lighting. Nothing here was tuned against."""
    n = int(rng.integers(1, 13))
    apps = random_appearances(rng, n)
    near, far = camera.depth_range()
    actors = []
    for app in apps:
        z0, z1 = rng.uniform(near, far, 2)
        d = 1.0 if rng.random() < 0.5 else -1.0  # walking towards image right (+1) or left
        # 0.9-1.7 m/s over the clip, in half frame widths at the mean depth
        half = float(camera.cx / camera.scale(0.5 * (z0 + z1)))
        dist = rng.uniform(0.9, 1.7) * (n_frames / fps) / half
        if rng.random() < 0.3:  # off the frame until t0, then walks in
            t0 = float(rng.uniform(0.05, 0.3))
            keys = [(0.0, -d * 1.25, z0), (t0, -d * 1.25, z0), (1.0, -d * 1.25 + d * dist * (1 - t0), z1)]
        else:
            x0 = d * rng.uniform(-0.9, 0.6)
            keys = [(0.0, x0, z0), (1.0, x0 + d * dist, z1)]
        m = walk(camera, n_frames, keys, app.height_m)
        actors.append(Actor(app, with_changes(m, head_yaw=_glances(rng, n_frames, fps))))
    return Script(actors, lighting=random_lighting(rng, camera.width, camera.height))


BUILDERS = {
    "single": _single,
    "pair_cross": _pair_cross,
    "pillar": _pillar,
    "distractors": _distractors,
    "crowd": _crowd,
    "bend": _bend,
    "desk": _desk,
    "random": _random,
}
