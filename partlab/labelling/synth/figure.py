"""An articulated person drawn with OpenCV primitives, one mask per body part.

The body is a handful of 3-D solids in the person's own frame (lateral ``l`` to the
person's left, forward ``f``, up ``u``; metres, the origin on the floor between the
feet), projected with the :class:`~partlab.labelling.synth.camera.LocalView` around the person:

- head: an ellipsoid of skin (the face, on the side the head faces) under a cap of
  hair (top and back; long hair falls behind the head to the shoulders); the head
  part is hair + face (the neck, in the chin's shadow, belongs to the person only);
- torso: a box from the top of the shoulders (0.83 H) to the waist (0.53 H), drawn as
  the convex hull of its projected corners; the torso part does NOT include the arms;
- hip-leg: the pelvis box (0.53 H .. 0.45 H) plus two two-segment legs (thigh, shin,
  tapered capsules) and shoes; the hip-leg part spans waist to feet;
- arms: upper arm and forearm capsules in the shirt colour (the forearm in skin for
  short sleeves) ending in a round hand in skin colour; the arms belong to the person
  only, each hand is its own part (``left_hand`` = the person's own left).

Walking swings the legs and, in opposition, the arms; ``bend`` pitches the upper body
about the hips; ``wave`` raises the right forearm above the shoulder; hand targets
(the desk scene) place the hands by two-link inverse kinematics. Solids are drawn far
to near (their depth along the camera axis), so the near arm covers the torso and the
far leg is hidden by the near one. Each part's mask is its whole drawn shape,
including pixels that the person's own other parts cover; the label image tells
which of them stay visible (:data:`PART_LABELS`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from partlab.labelling.synth.appearance import Appearance
from partlab.labelling.synth.camera import LocalView

SHIFT = 4  # cv2 sub-pixel bits: coordinates are drawn to 1/16 px
ONE = 1 << SHIFT

#: Part masks kept per figure (the person mask is the union of all drawn pixels).
FIGURE_PARTS: tuple[str, ...] = ("head", "torso", "hipleg", "left_hand", "right_hand")

# Label values of the label image (colour index); 0 = nothing drawn.
(HAIR, FACE, SHIRT, SLEEVE, SLEEVE_FAR, TROUSERS, TROUSERS_FAR, SHOES, HAND_LEFT, HAND_RIGHT, FOREARM,
 NECK) = range(1, 13)
N_LABELS = 13
#: The labels each part is drawn with (its pixels the person's own other parts leave visible).
PART_LABELS: dict[str, tuple[int, ...]] = {
    "head": (HAIR, FACE),
    "torso": (SHIRT,),
    "hipleg": (TROUSERS, TROUSERS_FAR, SHOES),
    "left_hand": (HAND_LEFT,),
    "right_hand": (HAND_RIGHT,),
}

# Body proportions as fractions of the height H (adult proportions, ~7.5 heads tall).
HEAD_U, HEAD_RL, HEAD_RF, HEAD_RU = 0.935, 0.050, 0.058, 0.065
SHOULDER_TOP_U, SHOULDER_U, WAIST_U = 0.83, 0.805, 0.53
TORSO_HALF_W, TORSO_HALF_D, WAIST_HALF_W, WAIST_HALF_D = 0.100, 0.068, 0.086, 0.062
PELVIS_TOP_U, PELVIS_BOTTOM_U, PELVIS_HALF_W, PELVIS_HALF_D = 0.53, 0.45, 0.090, 0.064
HIP_U, HIP_L = 0.49, 0.052
THIGH, SHIN, ANKLE_U = 0.225, 0.225, 0.04
THIGH_R, KNEE_R, ANKLE_R = 0.042, 0.032, 0.024
SHOE_BACK, SHOE_FRONT, SHOE_R = 0.035, 0.095, 0.020
ARM_L, UPPER_ARM, FOREARM_LEN, ARM_R, WRIST_R, HAND_R = 0.118, 0.17, 0.15, 0.027, 0.020, 0.026
LEG_SWING, ARM_SWING = 0.42, 0.38  # radians at full gait


@dataclass(frozen=True)
class FigurePose:
    """What the figure does at one frame (see :class:`partlab.labelling.synth.motion.Motion`)."""

    facing: float
    phase: float = 0.0
    gait: float = 0.0
    wave: float = 0.0
    wave_phase: float = 0.0
    bend: float = 0.0
    head_yaw: float = 0.0
    hands: np.ndarray | None = None  # (2, 3) targets [left, right] x (l, f, u) or None
    seated: bool = False
    seat_cut: float | None = None  # seated: torso drawn down to this height (the desk edge), metres


@dataclass(frozen=True, eq=False)
class Figure:
    """A drawn person: a label image and part masks over the region ``origin + (h, w)``.

    ``labels: (h, w) uint8`` colour labels (0 empty); ``masks: dict part -> (h, w) bool``
    whole shapes of the parts in :data:`FIGURE_PARTS` (missing when not drawn, e.g. the
    hip-leg of a seated person); ``origin``: image ``(x, y)`` of the top-left pixel;
    ``front: dict hand part -> (h, w) bool``: the pixels the person's own solids nearer than that
    hand cover (the torso over a far hand at rest behind the body), so what the hand holds can be
    drawn at the hand's depth (:func:`partlab.labelling.synth.scene._draw_objects`).
    """

    labels: np.ndarray
    masks: dict
    origin: tuple[int, int]
    front: dict = field(default_factory=dict)


class _Solid:
    """One drawn solid: its image geometry, colour label, part and depth."""

    __slots__ = ("kind", "geom", "label", "part", "depth")

    def __init__(self, kind, geom, label, part, depth):
        self.kind, self.geom, self.label, self.part, self.depth = kind, geom, label, part, depth


def _dir(side_angle: float, swing: float, side: float) -> np.ndarray:
    """Unit vector (l, f, u) of a limb abducted by ``side_angle`` and swung forward by ``swing``."""
    return np.array([side * np.sin(side_angle), np.cos(side_angle) * np.sin(swing),
                     -np.cos(side_angle) * np.cos(swing)])


def _ik_elbow(shoulder, target, l1, l2, bend_dir) -> tuple[np.ndarray, np.ndarray]:
    """Elbow and hand of a two-link arm reaching for ``target`` (clamped to the arm's reach)."""
    d = target - shoulder
    dist = float(np.linalg.norm(d))
    dist_c = min(max(dist, abs(l1 - l2) + 1e-3), (l1 + l2) * 0.999)
    axis = d / dist if dist > 1e-9 else np.array([0.0, 0.0, -1.0])
    hand = shoulder + axis * dist_c
    a = (l1 * l1 - l2 * l2 + dist_c * dist_c) / (2 * dist_c)
    h = np.sqrt(max(l1 * l1 - a * a, 0.0))
    perp = bend_dir - axis * np.dot(bend_dir, axis)
    n = np.linalg.norm(perp)
    perp = perp / n if n > 1e-9 else np.array([0.0, 0.0, -1.0])
    return shoulder + axis * a + perp * h, hand


def _pitch(points: np.ndarray, pivot_u: float, angle: float) -> np.ndarray:
    """Rotate ``(N, 3)`` body points forward by ``angle`` about the lateral axis at height ``pivot_u``."""
    if angle == 0.0:
        return points
    out = points.copy()
    f, u = points[:, 1], points[:, 2] - pivot_u
    c, s = np.cos(angle), np.sin(angle)
    out[:, 1] = f * c + u * s
    out[:, 2] = pivot_u + u * c - f * s
    return out


def _box_corners(u_top, hw_top, hd_top, u_bot, hw_bot, hd_bot) -> np.ndarray:
    corners = []
    for u, hw, hd in ((u_top, hw_top, hd_top), (u_bot, hw_bot, hd_bot)):
        for sl in (-1, 1):
            for sf in (-1, 1):
                corners.append((sl * hw, sf * hd, u))
    return np.array(corners, float)


def _leg_joints(pose: FigurePose, H: float) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]:
    """``(side, hip, knee, ankle)`` of both legs of a walking (or standing) figure, in body
    coordinates (left, forward, up) of a figure ``H`` metres tall, before it is lowered."""
    legs = []
    swing = pose.gait * LEG_SWING * np.sin(pose.phase)
    for side, sign in ((1, 1.0), (-1, -1.0)):  # left leg swings with +sin(phase)
        a = sign * swing
        # the knee bends most while the leg swings forward
        flex = pose.gait * (0.12 + 0.6 * max(0.0, sign * np.cos(pose.phase)))
        hip = np.array([side * HIP_L * H, 0.0, HIP_U * H])
        knee = hip + THIGH * H * np.array([0.0, np.sin(a), -np.cos(a)])
        ankle = knee + SHIN * H * np.array([0.0, np.sin(a - flex), -np.cos(a - flex)])
        legs.append((side, hip, knee, ankle))
    return legs


def _arm_joints(pose: FigurePose, side: int, sh: np.ndarray, H: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(elbow, wrist, hand)`` of the arm from shoulder ``sh`` (side 1: left): reaching for the
    pose's hand target when it has one, else swinging with the gait (and the right one waving)."""
    hand_t = None if pose.hands is None else pose.hands[0 if side == 1 else 1]
    if hand_t is not None and np.all(np.isfinite(hand_t)):
        elbow, wrist = _ik_elbow(sh, np.asarray(hand_t, float), UPPER_ARM * H, (FOREARM_LEN + HAND_R) * H,
                                 np.array([side * 0.8, -0.1, -0.6]))
        hand = wrist
        wrist = elbow + (hand - elbow) * FOREARM_LEN / (FOREARM_LEN + HAND_R)
        return elbow, wrist, hand
    sign = -1.0 if side == 1 else 1.0  # left arm swings against the left leg
    g = pose.gait * ARM_SWING * np.sin(pose.phase) * sign
    up = _dir(0.07, g, side)
    fore = _dir(0.05, g + 0.15 + pose.gait * 0.25 * max(0.0, np.sin(pose.phase) * sign), side)
    if side == -1 and pose.wave > 0:  # right arm waving: upper arm out, forearm up
        w = pose.wave
        up = (1 - w) * up + w * _dir(1.25, 0.25, side)
        a2 = 0.15 + 0.45 * np.sin(pose.wave_phase)
        fore_up = np.array([side * np.sin(a2), 0.15, np.cos(a2)])
        fore = (1 - w) * fore + w * fore_up
    up /= np.linalg.norm(up)
    fore /= np.linalg.norm(fore)
    elbow = sh + UPPER_ARM * H * up
    wrist = elbow + FOREARM_LEN * H * fore
    hand = wrist + HAND_R * H * 0.9 * fore
    return elbow, wrist, hand


def _leg_solids(legs, drop: float, project, depth, scale: float, H: float) -> list[_Solid]:
    """Both legs (thigh to ankle) and shoes of a figure lowered by ``drop``; ``scale`` = pixels
    per metre times ``H``. The leg stepping towards the camera is in front, the other darker."""
    out = []
    leg_depths = [depth(np.stack(leg[1:])) for leg in legs]
    far = int(np.argmax(leg_depths)) if abs(leg_depths[0] - leg_depths[1]) > 0.02 else -1
    for i, (_side, hip, knee, ankle) in enumerate(legs):
        hip, knee, ankle = (p - np.array([0.0, 0.0, drop]) for p in (hip, knee, ankle))
        pts = project(np.stack([hip, knee, ankle]))
        r = scale * np.array([THIGH_R, KNEE_R, ANKLE_R])
        label = TROUSERS_FAR if i == far else TROUSERS
        out.append(_Solid("limb", (pts, r), label, "hipleg", leg_depths[i] + 0.03))
        heel = ankle + np.array([0.0, -SHOE_BACK * H, -0.018 * H])
        toe = ankle + np.array([0.0, SHOE_FRONT * H, -0.018 * H])
        out.append(_Solid("limb", (project(np.stack([heel, toe])), np.full(2, scale * SHOE_R)),
                          SHOES, "hipleg", leg_depths[i] + 0.029))
    return out


def _arm_solids(pose: FigurePose, shoulders: np.ndarray, project, depth, scale: float, H: float,
                short_sleeves: bool) -> list[_Solid]:
    """Both arms (sleeve, forearm) and hands; the arm farther from the camera is darker."""
    out: list[_Solid] = []
    arm_depths = []
    for side, hand_part, sh in ((1, "left_hand", shoulders[0]), (-1, "right_hand", shoulders[1])):
        elbow, wrist, hand = _arm_joints(pose, side, sh, H)
        pts = project(np.stack([sh, elbow, wrist]))
        d = depth(np.stack([elbow, wrist]))
        arm_depths.append(d)
        r = scale * np.array([ARM_R * 1.15, ARM_R, WRIST_R])
        hand_px = project(hand)[0]
        out.append(_Solid("arm", (pts, r, short_sleeves), SLEEVE, None, d))
        hand_label = HAND_LEFT if side == 1 else HAND_RIGHT
        out.append(_Solid("circle", (hand_px, scale * HAND_R), hand_label, hand_part, d - 0.001))
    if abs(arm_depths[0] - arm_depths[1]) > 0.03:
        for s in out:
            if s.kind == "arm" and s.depth == max(arm_depths):
                s.label = SLEEVE_FAR
    return out


def _leg_heights(u: np.ndarray, height_m: float, legs: float) -> np.ndarray:
    """Heights ``u`` (metres) with the waist moved to ``legs`` x its built-in height, the feet and
    the crown kept: the legs stretched by ``legs``, the body above shortened to match."""
    if legs == 1.0:
        return u
    waist = WAIST_U * height_m
    return np.where(u <= waist, u * legs, waist * legs + (u - waist) * (height_m - waist * legs) / (height_m - waist))


def figure_solids(pose: FigurePose, height_m: float, view: LocalView, short_sleeves: bool = False,
                  long_hair: bool = False, anchors: dict | None = None, girth: float = 1.0,
                  head_scale: float = 1.0, legs: float = 1.0) -> list[_Solid]:
    """The solids of the figure in image coordinates, sorted far to near; ``girth`` scales the body
    across (lateral offsets), ``head_scale`` the head's radii, ``legs`` the waist's height (leg
    length against the built-in proportions; the body above is shortened or stretched to keep the
    person's height).

    ``anchors``, when given, receives the floor offsets and height ``(dx, dz, u)`` (metres, the
    view's floor frame) of the head's centre and of each hand's centre, keyed by part name: the
    3D truth of the multi-camera scenes (:mod:`partlab.labelling.synth.multiview`)."""
    H = height_m
    F = np.array([np.cos(pose.facing), np.sin(pose.facing)])  # forward on the floor (X, Z)
    L = np.array([-F[1], F[0]])  # the person's left

    leg_scale = float(legs)  # (``legs`` below are the leg joints)

    def up(u):
        return _leg_heights(u, H, leg_scale)

    def to_world(p: np.ndarray):
        p = np.atleast_2d(p)
        lat = p[:, 0] * girth
        dx = lat * L[0] + p[:, 1] * F[0]
        dz = lat * L[1] + p[:, 1] * F[1]
        return dx, dz, up(p[:, 2])

    def project(p):
        dx, dz, u = to_world(p)
        return view.project(dx, dz, u)

    def depth(p):
        return float(np.mean(to_world(p)[1]))

    solids: list[_Solid] = []
    drop = 0.0
    if pose.seated:
        drop = 0.24 * H  # hips from standing height to a chair seat
    # ---- legs (with the body lowered so that the lower ankle stays on the floor)
    legs = [] if pose.seated else _leg_joints(pose, H)
    if not pose.seated:
        lowest = min(leg[3][2] for leg in legs)
        drop = lowest - ANKLE_U * H
    pivot_u = HIP_U * H - drop
    # ---- torso, head and shoulders, pitched about the hips when bending
    torso_bottom = WAIST_U * H - drop
    if pose.seat_cut is not None:
        torso_bottom = max(pose.seat_cut, torso_bottom)
    torso = _box_corners(SHOULDER_TOP_U * H - drop, TORSO_HALF_W * H, TORSO_HALF_D * H,
                         torso_bottom, WAIST_HALF_W * H, WAIST_HALF_D * H)
    shoulders = np.array([[ARM_L * H, 0.0, SHOULDER_U * H - drop], [-ARM_L * H, 0.0, SHOULDER_U * H - drop]])
    head_c = np.array([[0.0, 0.0, HEAD_U * H - drop]])
    torso, shoulders, head_c = (_pitch(p, pivot_u, pose.bend) for p in (torso, shoulders, head_c))
    if pose.bend:  # the head keeps looking ahead of the bent body a little
        head_c = head_c + np.array([[0.0, 0.02 * H * np.sin(pose.bend), 0.0]])
    solids.append(_Solid("poly", project(torso), SHIRT, "torso", depth(torso) + 0.02))
    # ---- pelvis and legs
    if not pose.seated:
        pelvis = _box_corners(PELVIS_TOP_U * H - drop, PELVIS_HALF_W * H, PELVIS_HALF_D * H,
                              PELVIS_BOTTOM_U * H - drop, PELVIS_HALF_W * H * 0.95, PELVIS_HALF_D * H)
        solids.append(_Solid("poly", project(pelvis), TROUSERS, "hipleg", depth(pelvis) + 0.035))
        solids.extend(_leg_solids(legs, drop, project, depth, view.s * H, H))
    # ---- head: hair cap (top and back) under the face (front), turned by head_yaw
    yaw = pose.facing + pose.head_yaw
    Fh = np.array([np.cos(yaw), np.sin(yaw)])
    Lh = np.array([-Fh[1], Fh[0]])

    def head_ellipse(offset_f, offset_u, rl, rf, ru):
        rl, rf, ru = rl * head_scale, rf * head_scale, ru * head_scale
        c = head_c[0] + np.array([0.0, 0.0, offset_u * H])
        dx = c[0] * L[0] + c[1] * F[0] + offset_f * H * Fh[0]
        dz = c[0] * L[1] + c[1] * F[1] + offset_f * H * Fh[1]
        centre = view.project(np.array([dx]), np.array([dz]), up(np.array([c[2]])))[0]
        ax = view.s * H * np.hypot(rl * Lh[0], rf * Fh[0])
        ay = view.s * H * np.hypot(ru, view.k * 0.3 * np.hypot(rl * Lh[1], rf * Fh[1]))
        return centre, (ax, ay), dz

    hc, hax, hdz = head_ellipse(-0.012, 0.010, HEAD_RL * 1.06, HEAD_RF * 1.07, HEAD_RU * 0.9)
    head_depth = depth(head_c)
    solids.append(_Solid("ellipse", (hc, hax), HAIR, "head", head_depth + 0.001))
    if long_hair:  # hair falling behind the head to the shoulders: behind the torso when facing the camera
        lc, lax, ldz = head_ellipse(-0.025, -0.04, HEAD_RL * 1.12, HEAD_RF * 0.9, HEAD_RU * 1.2)
        solids.append(_Solid("ellipse", (lc, lax), HAIR, "head", float(ldz) + 0.002))
    # the neck (person only, like the arms): under the chin, in front of the torso's top
    neck = np.array([[0.0, 0.0, (HEAD_U - 0.03) * H - drop], [0.0, 0.0, (SHOULDER_TOP_U - 0.01) * H - drop]])
    neck = _pitch(neck, pivot_u, pose.bend)
    solids.append(_Solid("limb", (project(neck), np.full(2, view.s * H * 0.027)), NECK, None, head_depth + 0.003))
    if Fh[1] < 0.45:  # the face is on the camera's side or in profile
        fc, fax, _ = head_ellipse(0.014, -0.012, HEAD_RL * 0.9, HEAD_RF * 0.86, HEAD_RU * 0.8)
        solids.append(_Solid("ellipse", (fc, fax), FACE, "head", head_depth))
    # ---- arms
    solids.extend(_arm_solids(pose, shoulders, project, depth, view.s * H, H, short_sleeves))
    if anchors is not None:
        anchors["head"] = np.concatenate([np.ravel(v) for v in to_world(head_c)])
        for side, part, sh in ((1, "left_hand", shoulders[0]), (-1, "right_hand", shoulders[1])):
            anchors[part] = np.concatenate([np.ravel(v) for v in to_world(_arm_joints(pose, side, sh, H)[2])])
    solids.sort(key=lambda s: -s.depth)
    return solids


def _pts(p: np.ndarray) -> np.ndarray:
    return np.round(np.asarray(p, float) * ONE).astype(np.int32)


def _capsule(img: np.ndarray, p1, p2, r1: float, r2: float, value: int) -> None:
    """A tapered capsule from ``p1`` (radius ``r1``) to ``p2`` (radius ``r2``), rounded ends."""
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    d = p2 - p1
    n = np.hypot(*d)
    cv2.circle(img, tuple(_pts(p1)), int(round(r1 * ONE)), value, -1, cv2.LINE_8, SHIFT)
    cv2.circle(img, tuple(_pts(p2)), int(round(r2 * ONE)), value, -1, cv2.LINE_8, SHIFT)
    if n < 1e-6:
        return
    nrm = np.array([-d[1], d[0]]) / n
    quad = np.array([p1 + nrm * r1, p2 + nrm * r2, p2 - nrm * r2, p1 - nrm * r1])
    cv2.fillConvexPoly(img, _pts(quad), value, cv2.LINE_8, SHIFT)


def _draw(img: np.ndarray, solid: _Solid, offset: np.ndarray, value: int, forearm_value: int | None = None) -> None:
    kind, g = solid.kind, solid.geom
    if kind == "poly":
        hull = cv2.convexHull((g - offset).astype(np.float32)).reshape(-1, 2)
        cv2.fillConvexPoly(img, _pts(hull), value, cv2.LINE_8, SHIFT)
    elif kind == "ellipse":
        c, (ax, ay) = g
        cv2.ellipse(img, tuple(_pts(c - offset)), (int(round(ax * ONE)), int(round(ay * ONE))), 0, 0, 360,
                    value, -1, cv2.LINE_8, SHIFT)
    elif kind == "circle":
        c, r = g
        cv2.circle(img, tuple(_pts(c - offset)), int(round(r * ONE)), value, -1, cv2.LINE_8, SHIFT)
    elif kind == "limb":
        pts, r = g
        pts = pts - offset
        for i in range(len(pts) - 1):
            _capsule(img, pts[i], pts[i + 1], r[i], r[i + 1], value)
    elif kind == "arm":
        pts, r, short = g
        pts = pts - offset
        _capsule(img, pts[0], pts[1], r[0], r[1], value)
        _capsule(img, pts[1], pts[2], r[1], r[2], forearm_value if (short and forearm_value is not None) else value)
        if short and forearm_value is not None:  # the sleeve ends at the elbow
            cv2.circle(img, tuple(_pts(pts[1])), int(round(r[1] * ONE)), value, -1, cv2.LINE_8, SHIFT)
    else:  # pragma: no cover - programming error
        raise ValueError(kind)


def _extent(solid: _Solid) -> np.ndarray:
    """Image bounding box ``[x1, y1, x2, y2]`` of a solid (with its radii)."""
    kind, g = solid.kind, solid.geom
    if kind == "poly":
        return np.concatenate([g.min(0), g.max(0)])
    if kind == "ellipse":
        c, (ax, ay) = g
        return np.array([c[0] - ax, c[1] - ay, c[0] + ax, c[1] + ay])
    if kind == "circle":
        c, r = g
        return np.array([c[0] - r, c[1] - r, c[0] + r, c[1] + r])
    pts, r = g[0], g[1]
    rm = float(np.max(r))
    return np.concatenate([pts.min(0) - rm, pts.max(0) + rm])


def draw_figure(pose: FigurePose, appearance: Appearance, view: LocalView, anchors: dict | None = None) -> Figure:
    """Draw one person: the label image and the part masks over its bounding region."""
    solids = figure_solids(pose, appearance.height_m, view, appearance.short_sleeves, appearance.long_hair,
                           anchors, appearance.girth, appearance.head_scale, appearance.legs)
    ext = np.array([_extent(s) for s in solids])
    x1, y1 = np.floor(ext[:, :2].min(0)).astype(int) - 2
    x2, y2 = np.ceil(ext[:, 2:].max(0)).astype(int) + 2
    offset = np.array([x1, y1], float)
    shape = (int(y2 - y1), int(x2 - x1))
    labels = np.zeros(shape, np.uint8)
    masks: dict[str, np.ndarray] = {}
    front: dict[str, np.ndarray] = {}  # hand part -> what is drawn after it (nearer, solids go far to near)
    for s in solids:
        _draw(labels, s, offset, s.label, FOREARM)
        for m in front.values():
            _draw(m, s, offset, 1, 1)
        if s.part is not None:
            m = masks.get(s.part)
            if m is None:
                m = masks[s.part] = np.zeros(shape, np.uint8)
            _draw(m, s, offset, 1)
            if s.part in ("left_hand", "right_hand"):
                front[s.part] = np.zeros(shape, np.uint8)
    return Figure(labels, {k: v.astype(bool) for k, v in masks.items()}, (int(x1), int(y1)),
                  {k: v.astype(bool) for k, v in front.items()})


def colour_table(appearance: Appearance) -> np.ndarray:
    """``(N_LABELS, 3) uint8`` BGR colour of every label; far limbs are shaded darker."""
    lut = np.zeros((N_LABELS, 3), np.float64)
    lut[HAIR] = appearance.hair
    lut[FACE] = appearance.skin
    lut[SHIRT] = appearance.shirt
    lut[SLEEVE] = np.asarray(appearance.shirt) * 0.93
    lut[SLEEVE_FAR] = np.asarray(appearance.shirt) * 0.78
    lut[TROUSERS] = appearance.trousers
    lut[TROUSERS_FAR] = np.asarray(appearance.trousers) * 0.8
    lut[SHOES] = appearance.shoes
    lut[HAND_LEFT] = appearance.skin
    lut[HAND_RIGHT] = appearance.skin
    lut[FOREARM] = np.asarray(appearance.skin) * 0.95
    lut[NECK] = np.asarray(appearance.skin) * 0.85  # in the chin's shadow
    return np.clip(np.round(lut), 0, 255).astype(np.uint8)
