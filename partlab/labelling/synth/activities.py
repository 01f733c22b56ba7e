"""Scenes of the activities of the multi-camera head-and-hands paper (sec. 7), with exact event truth.

* ``pick_place``: a seated person picks a box up from the desk with the right hand, carries it
  and places it elsewhere on the desk (a *pick* and a *place*);
* ``exchange``: two people standing face to face; one passes an object from hand to hand;
* ``handshake``: the same two people shake hands, no object;
* ``clap``: a standing person claps three times.

Each builder returns a :class:`~partlab.labelling.synth.scenarios.Script` with ``objects``
(what is carried and where it rests) and ``events`` (the truth: kind, start and end frame, the
tracks and hands involved, the object's colour). Timings are fractions of the clip drawn per seed
(when an activity starts and how long it lasts vary by a factor of two or more); people, clothes,
skin and object colours come from the seed too.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import cv2
import numpy as np

from partlab.labelling.synth.appearance import sample_appearances
from partlab.labelling.synth.background import Prop
from partlab.labelling.synth.camera import LocalView
from partlab.labelling.synth.figure import HAND_R, WAIST_HALF_D
from partlab.labelling.synth.motion import Motion, bump, clip_time
from partlab.labelling.synth.scenarios import Actor, Script

#: object colours far from skin and from the room (BGR): green, blue, magenta, yellow, cyan
OBJECT_COLOURS = ((60, 190, 40), (200, 90, 30), (170, 40, 190), (30, 200, 220), (200, 200, 40))
HANDS = ("left_hand", "right_hand")


@dataclass(frozen=True, eq=False)
class CarriedObject:
    """An object that is held or rests. ``holder``: ``(T,)`` int, ``2 * actor + hand`` (hand 0 =
    left, 1 = right) while held, -1 while resting at ``rest`` ``(T, 2)`` image points (NaN while
    held); ``radius``: in units of the holder's hand radius; ``rest_radius_px``: its radius while
    resting; ``colour``: BGR."""

    holder: np.ndarray
    rest: np.ndarray
    colour: tuple[int, int, int]
    radius: float = 1.5
    rest_radius_px: float = 8.0


@dataclass(frozen=True)
class EventTruth:
    kind: str
    start_frame: int
    end_frame: int
    track_id_a: int
    part_a: str
    track_id_b: int = 0
    part_b: str = ""
    colour: tuple[int, int, int] | None = None


def _j(rng, scale: float) -> float:
    return float(rng.uniform(-scale, scale))


def _frame(t: float, n: int) -> int:
    return int(round(t * (n - 1)))


def _hue_sat(bgr) -> tuple[int, int]:
    h, s, _ = cv2.cvtColor(np.uint8([[bgr]]), cv2.COLOR_BGR2HSV)[0, 0]
    return int(h), int(s)


def object_colour(rng, people=()) -> tuple[int, int, int]:
    """An object colour whose hue is at least 30 degrees from every saturated colour the people wear:
    the paper's colour analysis cannot tell an object from a sleeve of its own hue (docs state the
    limitation), and the scenes measure the recognition, not that coincidence."""
    worn = [h for a in people for h, sat in (_hue_sat(a.shirt), _hue_sat(a.trousers)) if sat >= 60]
    far = [c for c in OBJECT_COLOURS
           if all(min(abs(_hue_sat(c)[0] - h), 180 - abs(_hue_sat(c)[0] - h)) >= 15 for h in worn)]
    pool = far or list(OBJECT_COLOURS)
    c = pool[int(rng.integers(len(pool)))]
    return tuple(int(np.clip(v + rng.integers(-12, 13), 0, 255)) for v in c)


def _seated_view(rng, camera, app):
    H = app.height_m
    W, Hi = camera.width, camera.height
    s = 0.62 * Hi
    k = 0.3
    y0 = 0.2 * Hi + s * (1.0 - 0.24) * H
    x0 = W / 2 + _j(rng, 0.05 * W)
    return LocalView(x0, y0, s, k), s, k


def pick_place(rng, camera, n_frames, fps) -> Script:
    (app,) = sample_appearances(rng, 1)
    H = app.height_m
    view, s, k = _seated_view(rng, camera, app)
    desk_h, desk_far, desk_near = 0.75, 0.25, 0.95
    seat_cut = desk_h - k * (desk_far - WAIST_HALF_D * H)
    far_y = view.y0 - s * desk_h + s * k * desk_far
    near_y = view.y0 - s * desk_h + s * k * desk_near
    desk_w = 1.7 * s
    wood = (int(rng.integers(60, 90)), int(rng.integers(95, 125)), int(rng.integers(130, 165)))
    props = [Prop("desk", (view.x0 - desk_w / 2, far_y, desk_w, near_y - far_y),
                  (wood, tuple(int(c * 0.7) for c in wood)))]
    n = n_frames
    t = clip_time(n)
    hr = HAND_R * H
    rest = np.array([[0.19, 0.33, desk_h + hr], [-0.19, 0.33, desk_h + hr]])
    hands = np.repeat(rest[None], n, axis=0)
    # the right hand (image left) picks the box at p1 and places it at p2, stopping a moment at each
    p1 = np.array([-0.55 + _j(rng, 0.05), 0.5 + _j(rng, 0.05), desk_h + 1.2 * hr])
    p2 = np.array([-0.3 + _j(rng, 0.04), 0.82 + _j(rng, 0.03), desk_h + 1.2 * hr])
    # at p1 between a0 and a1 (reach in, still, ...), at p2 between b0 and b1: each still 18 to 48 frames of 150
    # (one draw each, as when they were jittered by 0.02: the people and rooms of a seed are unchanged)
    a0, a1 = rng.uniform(0.10, 0.22), rng.uniform(0.34, 0.42)
    b0, b1 = rng.uniform(0.52, 0.62), rng.uniform(0.74, 0.86)
    w1 = bump(t, a0, a1, ramp=0.06)
    carry = np.clip((t - a1) / max(b0 - a1, 1e-6), 0, 1) * ((t > a1) & (t < b0))
    w2 = bump(t, b0, b1, ramp=0.06)
    target = np.where((t <= a1)[:, None], p1[None], np.where((t >= b0)[:, None], p2[None],
                                                           p1[None] + (p2 - p1)[None] * carry[:, None]))
    weight = np.maximum.reduce([w1, w2, ((t > a1) & (t < b0)).astype(float)])
    hands[:, 1] = hands[:, 1] * (1 - weight)[:, None] + target * weight[:, None]
    pick_f = _frame((a0 + a1) / 2, n)
    place_f = _frame((b0 + b1) / 2, n)
    holder = np.full(n, -1)
    holder[pick_f:place_f] = 1  # actor 0, right hand
    restp = np.full((n, 2), np.nan)
    box_off = np.array([0.0, 0.0, -0.2 * hr])
    for lo, hi, p in ((0, pick_f, p1), (place_f, n, p2)):
        q = p + box_off
        restp[lo:hi] = (view.x0 + s * q[0], view.y0 - s * q[2] + s * k * q[1])
    colour = object_colour(rng, (app,))
    obj = CarriedObject(holder, restp, colour, radius=1.6, rest_radius_px=1.6 * s * hr)
    zeros = np.zeros(n)
    yaw = -0.4 * np.maximum(w1, w2) + 0.2 * np.sin(2 * np.pi * np.arange(n) / (fps * 4.0) + rng.uniform(0, 6.3))
    motion = Motion(x=zeros.copy(), z=np.full(n, 3.0), facing=np.full(n, -np.pi / 2), phase=zeros.copy(),
                    gait=zeros.copy(), wave=zeros.copy(), bend=zeros.copy(), head_yaw=yaw, hands=hands, seated=True)
    # truth: the still moment at each place (the hand at the object), where the paper's climax point lies
    events = [EventTruth("pick", _frame(a0, n), _frame(a1, n), 1, "right_hand", colour=colour),
              EventTruth("place", _frame(b0, n), _frame(b1, n), 1, "right_hand", colour=colour)]
    return Script([Actor(app, motion, view=view, seat_cut=seat_cut)], props=props, objects=[obj], events=events)


def _face_to_face(rng, camera, n_frames, with_object: bool) -> Script:
    a, b = sample_appearances(rng, 2)
    a = replace(a, height_m=float(rng.uniform(1.66, 1.84)))
    b = replace(b, height_m=float(rng.uniform(1.62, 1.80)))
    n = n_frames
    t = clip_time(n)
    z = 4.6 + _j(rng, 0.2)
    gap = 0.62 + _j(rng, 0.04)  # metres between the two people's feet
    xa, xb = -gap / 2 + _j(rng, 0.05), gap / 2 + _j(rng, 0.05)
    # a faces +x (image right), b faces -x: each one's right hand is on the camera's side for one of them
    t0, t1 = rng.uniform(0.24, 0.42), rng.uniform(0.52, 0.68)  # hands together between t0 and t1
    w = bump(t, t0, t1, ramp=0.08)
    meet_u = 1.0 + _j(rng, 0.04)

    def motion(app, x, facing):
        H = app.height_m
        hands = np.full((n, 2, 3), np.nan)
        # both hands rest low at the sides when not reaching (NaN = free swing would change their look)
        hands[:, 0] = (0.2 * H, 0.02, 0.5 * H)
        hands[:, 1] = (-0.2 * H, 0.02, 0.5 * H)
        reach = np.array([-0.02, gap / 2 - 0.01, meet_u])  # the right hands meet in the middle
        hands[:, 1] = hands[:, 1] * (1 - w)[:, None] + reach[None] * w[:, None]
        if not with_object:  # a shake: small up-down movements while together
            hands[:, 1, 2] += 0.03 * np.sin(2 * np.pi * 3 * np.clip((t - t0) / (t1 - t0), 0, 1)) * w
        zeros = np.zeros(n)
        return Motion(x=np.full(n, x), z=np.full(n, z), facing=np.full(n, facing), phase=zeros.copy(),
                      gait=zeros.copy(), wave=zeros.copy(), bend=zeros.copy(), head_yaw=zeros.copy(), hands=hands)

    actors = [Actor(a, motion(a, xa, 0.0)), Actor(b, motion(b, xb, np.pi))]
    objects, events = [], []
    start, end = _frame(t0, n), _frame(t1, n)  # the hands together
    if with_object:
        colour = object_colour(rng, (a, b))
        holder = np.full(n, 1)  # a's right hand, then b's right hand from the middle of the meeting
        holder[(start + end) // 2:] = 3
        objects.append(CarriedObject(holder, np.full((n, 2), np.nan), colour, radius=1.5))
        events.append(EventTruth("exchange", start, end, 1, "right_hand", 2, "right_hand", colour=colour))
    else:
        events.append(EventTruth("handshake", start, end, 1, "right_hand", 2, "right_hand"))
    return Script(actors, objects=objects, events=events)


def exchange(rng, camera, n_frames, fps) -> Script:
    return _face_to_face(rng, camera, n_frames, with_object=True)


def handshake(rng, camera, n_frames, fps) -> Script:
    return _face_to_face(rng, camera, n_frames, with_object=False)


def clap(rng, camera, n_frames, fps) -> Script:
    (app,) = sample_appearances(rng, 1)
    H = app.height_m
    n = n_frames
    t = clip_time(n)
    z = 4.4 + _j(rng, 0.2)
    x = _j(rng, 0.4)
    hands = np.full((n, 2, 3), np.nan)
    hands[:, 0] = (0.2 * H, 0.03, 0.5 * H)
    hands[:, 1] = (-0.2 * H, 0.03, 0.5 * H)
    t0, t1 = rng.uniform(0.18, 0.40), rng.uniform(0.50, 0.66)
    c = bump(t, t0, t1, ramp=0.06)
    u = np.clip((t - t0) / (t1 - t0), 0, 1)
    hr = HAND_R * H
    sep = hr * 0.8 + 0.12 * (0.5 - 0.5 * np.cos(2 * np.pi * 3 * u))  # the palms touch three times
    chest = 0.72 * H + _j(rng, 0.03)
    together = np.stack([np.stack([sep, np.full(n, 0.3), np.full(n, chest)], 1),
                         np.stack([-sep, np.full(n, 0.3), np.full(n, chest)], 1)], 1)
    hands = hands * (1 - c)[:, None, None] + together * c[:, None, None]
    zeros = np.zeros(n)
    m = Motion(x=np.full(n, x), z=np.full(n, z), facing=np.full(n, -np.pi / 2), phase=zeros.copy(),
               gait=zeros.copy(), wave=zeros.copy(), bend=zeros.copy(), head_yaw=zeros.copy(), hands=hands)
    events = [EventTruth("clap", _frame(t0, n), _frame(t1, n), 1, "left_hand", 1, "right_hand")]
    return Script([Actor(app, m)], events=events)


BUILDERS = {"pick_place": pick_place, "exchange": exchange, "handshake": handshake, "clap": clap}
