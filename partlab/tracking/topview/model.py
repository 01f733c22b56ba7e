"""The articulated upper-body model (Migniot & Ababsa sec. 2.3, Fig. 2).

Six rigid parts: the head, the torso with the shoulders, each arm and each forearm with its hand.
The pose is 17 degrees of freedom (:data:`DOF`): the pelvis position ``x_t, y_t, z_t`` (world mm,
Z up from the floor), the torso's yaw ``theta_z`` and forward bend at the pelvis ``theta_x^to``
(the text's state vector omits the bend, Table 1 lists it), the neck's 2, each shoulder's 3 and
each elbow's 2 angles (radians). Volumes (Fig. 2(b)): arms and forearms are truncated (finite)
cylinders, the torso an elliptic cylinder, the hands rectangular planes; the head, whose shape
the text does not give, is a sphere.

The torso's elliptic cylinder is cut in two stacked slabs so that the *top part of the
shoulders* (Table 1's second weighting part, what a camera above sees of a torso) is a part of
its own; together they are one elliptic cylinder.

Body frame: ``x`` the person's right, ``y`` forward, ``z`` up. Positive angles: bend and nod
forward, shoulder flexion raises the arm forward, abduction raises it sideways (away from the
body), elbow flexion bends the forearm forward; ``*_z`` angles twist about the segment's axis
(the neck's turns the head). Arms hang down at zero.

Primitives are packed as ``(..., K, 16) float32`` rows ``[O(3), e1(3), e2(3), e3(3), a, b, L, 0]``:
an origin and an orthonormal frame, with ``kind`` per primitive (:data:`KINDS`):

* ``SPHERE``: centre ``O``, radius ``a``;
* ``CYLINDER``: axis from ``O`` along ``e3`` for ``L``, semi-axes ``a`` along ``e1`` and ``b``
  along ``e2`` (``a == b`` for arms);
* ``RECTANGLE``: centre ``O``, half-width ``a`` along ``e1``, half-length ``L`` along ``e3``,
  normal ``e2``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

#: the 17 degrees of freedom, in state-vector order
DOF: tuple[str, ...] = (
    "x_t", "y_t", "z_t", "theta_z", "theta_x_to", "ne_x", "ne_z",
    "r_sh_x", "r_sh_y", "r_sh_z", "r_el_x", "r_el_z",
    "l_sh_x", "l_sh_y", "l_sh_z", "l_el_x", "l_el_z",
)
N_DOF = len(DOF)

#: Table 1: the five weighting parts and the degrees of freedom each one owns
WEIGHT_PARTS: tuple[str, ...] = ("head", "shoulders", "torso", "right_arm", "left_arm")
PART_DOFS: dict[str, tuple[int, ...]] = {
    "head": (5, 6),
    "shoulders": (0, 1, 2),
    "torso": (4, 3),
    "right_arm": (7, 8, 9, 10, 11),
    "left_arm": (12, 13, 14, 15, 16),
}
N_PARTS = len(WEIGHT_PARTS)
ARM_PARTS = (WEIGHT_PARTS.index("right_arm"), WEIGHT_PARTS.index("left_arm"))

SPHERE, CYLINDER, RECTANGLE = 0, 1, 2
#: the primitives, in packing order: (name, kind, weighting part index)
PRIMITIVES: tuple[tuple[str, int, int], ...] = (
    ("head", SPHERE, 0),
    ("shoulders", CYLINDER, 1),
    ("torso", CYLINDER, 2),
    ("right_upper_arm", CYLINDER, 3),
    ("right_forearm", CYLINDER, 3),
    ("right_hand", RECTANGLE, 3),
    ("left_upper_arm", CYLINDER, 4),
    ("left_forearm", CYLINDER, 4),
    ("left_hand", RECTANGLE, 4),
)
KINDS = np.array([k for _, k, _ in PRIMITIVES], np.int64)
PART_OF = np.array([p for _, _, p in PRIMITIVES], np.int64)
N_PRIMITIVES = len(PRIMITIVES)

#: the joints written as tracks rows (partlab.tracking.parts names), in :func:`joints` order
JOINTS: tuple[str, ...] = ("head", "right_shoulder", "left_shoulder", "right_elbow", "left_elbow",
                           "right_hand", "left_hand")


@dataclass(frozen=True)
class Body:
    """A person's sizes in millimetres (defaults: an adult of 1.75 m, rounded anthropometric
    proportions). ``pelvis_height`` is where ``z_t`` stands when upright."""

    torso_length: float = 520.0      # pelvis to the top of the shoulders
    shoulder_slab: float = 130.0     # top band of the torso that is Table 1's "shoulders" part
    torso_half_width: float = 165.0  # elliptic cylinder semi-axis, left-right
    torso_half_depth: float = 105.0  # elliptic cylinder semi-axis, front-back
    shoulder_offset: float = 185.0   # shoulder joint from the spine, sideways
    shoulder_drop: float = 45.0      # shoulder joint below the top of the torso
    neck_length: float = 70.0
    head_radius: float = 95.0
    upper_arm_length: float = 290.0
    upper_arm_radius: float = 48.0
    forearm_length: float = 250.0
    forearm_radius: float = 38.0
    hand_length: float = 180.0
    hand_half_width: float = 45.0
    pelvis_height: float = 930.0

    def scaled(self, stature_mm: float) -> Body:
        """These proportions for a person ``stature_mm`` tall (every length times stature / 1750)."""
        s = float(stature_mm) / 1750.0
        return Body(**{k: v * s for k, v in self.__dict__.items()})

    @property
    def stature(self) -> float:
        return self.pelvis_height + self.torso_length + self.neck_length + 2 * self.head_radius

    def with_arms(self, upper_arm: float, forearm_and_half_hand: float) -> Body:
        """Arm lengths measured from joints (shoulder-elbow, elbow-hand centre)."""
        fore = max(forearm_and_half_hand - self.hand_length / 2, 0.3 * forearm_and_half_hand)
        return replace(self, upper_arm_length=float(upper_arm), forearm_length=float(fore))


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def _apply(R, v):
    """``R (..., 3, 3)`` times ``v (..., 3)`` or a constant ``(3,)``."""
    if np.ndim(v) == 1:
        return R @ v
    return (R @ v[..., None])[..., 0]


@dataclass(frozen=True)
class Pose:
    """Forward kinematics of ``(P, 17)`` states: joint positions ``(P, 3)`` and segment frames
    ``(P, 3, 3)`` (columns = the segment's x, y, z axes in the world)."""

    pelvis: np.ndarray
    body_R: np.ndarray
    neck: np.ndarray
    head_centre: np.ndarray
    shoulders: tuple[np.ndarray, np.ndarray]   # right, left
    elbows: tuple[np.ndarray, np.ndarray]
    wrists: tuple[np.ndarray, np.ndarray]
    hands: tuple[np.ndarray, np.ndarray]       # hand centres
    upper_R: tuple[np.ndarray, np.ndarray]
    fore_R: tuple[np.ndarray, np.ndarray]


def kinematics(states: np.ndarray, body: Body) -> Pose:
    s = np.asarray(states, np.float64).reshape(-1, N_DOF)
    pelvis = s[:, 0:3]
    body_R = _rz(s[:, 3]) @ _rx(-s[:, 4])  # yaw, then the bend forward about the body's x axis
    top = body.torso_length
    neck = pelvis + _apply(body_R, np.array([0.0, 0.0, top]))
    head_R = body_R @ _rz(s[:, 6]) @ _rx(-s[:, 5])
    head_centre = neck + _apply(head_R, np.array([0.0, 0.0, body.neck_length + body.head_radius]))
    out = {"shoulders": [], "elbows": [], "wrists": [], "hands": [], "upper_R": [], "fore_R": []}
    for side, base in ((1.0, 7), (-1.0, 12)):  # right arm (+x), left arm (mirrored)
        sh = pelvis + _apply(body_R, np.array([side * body.shoulder_offset, 0.0, top - body.shoulder_drop]))
        upper_R = body_R @ _rx(s[:, base]) @ _ry(-side * s[:, base + 1]) @ _rz(side * s[:, base + 2])
        down_u = -upper_R[..., :, 2]
        elbow = sh + body.upper_arm_length * down_u
        fore_R = upper_R @ _rx(s[:, base + 3]) @ _rz(side * s[:, base + 4])
        down_f = -fore_R[..., :, 2]
        wrist = elbow + body.forearm_length * down_f
        hand = wrist + 0.5 * body.hand_length * down_f
        for k, v in zip(out, (sh, elbow, wrist, hand, upper_R, fore_R)):
            out[k].append(v)
    return Pose(pelvis, body_R, neck, head_centre, **{k: tuple(v) for k, v in out.items()})


def joints(states: np.ndarray, body: Body) -> np.ndarray:
    """``(P, 7, 3)`` world positions of :data:`JOINTS` (head centre, shoulders, elbows, hand centres)."""
    p = kinematics(states, body)
    return np.stack([p.head_centre, p.shoulders[0], p.shoulders[1], p.elbows[0], p.elbows[1],
                     p.hands[0], p.hands[1]], axis=1)


def _pack(O, e1, e2, e3, a, b, L):
    n = O.shape[0]
    row = np.zeros((n, 16))
    row[:, 0:3], row[:, 3:6], row[:, 6:9], row[:, 9:12] = O, e1, e2, e3
    row[:, 12], row[:, 13], row[:, 14] = a, b, L
    return row


def primitives(states: np.ndarray, body: Body) -> np.ndarray:
    """``(P, K, 16) float32`` packed primitives (module docstring) of each state's model."""
    p = kinematics(states, body)
    R = p.body_R
    ex, ey, ez = R[..., :, 0], R[..., :, 1], R[..., :, 2]
    n = p.pelvis.shape[0]
    zero = np.zeros((n, 3))
    lower = body.torso_length - body.shoulder_slab
    rows = [
        _pack(p.head_centre, zero, zero, zero, body.head_radius, 0.0, 0.0),
        _pack(p.pelvis + lower * ez, ex, ey, ez, body.torso_half_width, body.torso_half_depth, body.shoulder_slab),
        _pack(p.pelvis, ex, ey, ez, body.torso_half_width, body.torso_half_depth, lower),
    ]
    for i in (0, 1):
        u, f = p.upper_R[i], p.fore_R[i]
        # the cylinders run from the joint down the segment (e3 = -z of the segment's frame)
        rows.append(_pack(p.shoulders[i], u[..., :, 0], u[..., :, 1], -u[..., :, 2],
                          body.upper_arm_radius, body.upper_arm_radius, body.upper_arm_length))
        rows.append(_pack(p.elbows[i], f[..., :, 0], f[..., :, 1], -f[..., :, 2],
                          body.forearm_radius, body.forearm_radius, body.forearm_length))
        rows.append(_pack(p.hands[i], f[..., :, 0], f[..., :, 1], -f[..., :, 2],
                          body.hand_half_width, 0.0, 0.5 * body.hand_length))
    return np.stack(rows, axis=1).astype(np.float32)


def neutral_state(x: float, y: float, body: Body, yaw: float = 0.0) -> np.ndarray:
    """Standing upright at floor position ``(x, y)`` facing ``yaw`` with the arms hanging down."""
    s = np.zeros(N_DOF)
    s[0:3] = x, y, body.pelvis_height
    s[3] = yaw
    s[[8, 13]] = 0.15  # arms a little away from the body, as people stand
    return s


def fit_state(targets: dict[str, np.ndarray], body: Body, start: np.ndarray | None = None) -> np.ndarray:
    """See :func:`_fit_state`; the same joints and body give the same state, fitted once."""
    key = (tuple((k, tuple(np.round(np.asarray(v, np.float64), 3))) for k, v in sorted(targets.items())), body,
           None if start is None else tuple(np.round(np.asarray(start, np.float64), 6)))
    return np.array(_fit_cached(key))


@lru_cache(maxsize=64)
def _fit_cached(key) -> tuple[float, ...]:
    targets = {k: np.array(v) for k, v in key[0]}
    start = None if key[2] is None else np.array(key[2])
    return tuple(_fit_state(targets, key[1], start))


def _fit_state(targets: dict[str, np.ndarray], body: Body, start: np.ndarray | None = None) -> np.ndarray:
    """The state whose :func:`joints` best match ``targets`` (joint name -> ``(3,)`` mm; any subset
    of :data:`JOINTS`), by least squares (``scipy.optimize.least_squares``) from ``start`` (default:
    standing under the mean of the targets, facing the way the shoulders say)."""
    from scipy.optimize import least_squares

    names = [j for j in JOINTS if j in targets]
    if not names:
        raise ValueError("no joints to fit the model to")
    idx = [JOINTS.index(j) for j in names]
    goal = np.array([targets[j] for j in names], np.float64)
    if start is None:
        centre = goal.mean(axis=0)
        yaw = 0.0
        if "right_shoulder" in targets and "left_shoulder" in targets:
            d = np.asarray(targets["right_shoulder"]) - np.asarray(targets["left_shoulder"])
            yaw = float(np.arctan2(d[1], d[0]))  # the body's x axis points to the right shoulder
        start = neutral_state(centre[0], centre[1], body, yaw)
        if "head" in targets:
            start[0:2] = np.asarray(targets["head"])[:2]
            start[2] = targets["head"][2] - body.torso_length - body.neck_length - body.head_radius
    scale = np.array([1000.0] * 3 + [1.0] * (N_DOF - 3))

    def residual(u):
        return (joints(u * scale, body)[0, idx] - goal).ravel()

    lo, hi = JOINT_LIMITS[:, 0] / scale, JOINT_LIMITS[:, 1] / scale
    x0 = np.clip(np.asarray(start, np.float64) / scale, lo + 1e-6, hi - 1e-6)
    sol = least_squares(residual, x0, bounds=(lo, hi), x_scale="jac", max_nfev=400)
    return sol.x * scale


#: plausible range of every degree of freedom (positions in mm are unbounded)
JOINT_LIMITS = np.array([
    (-np.inf, np.inf), (-np.inf, np.inf), (-np.inf, np.inf),
    (-np.inf, np.inf),        # yaw: any direction
    (-0.2, 1.3),              # bend: a little back to well forward (picking from a low shelf)
    (-0.6, 0.9), (-1.3, 1.3),  # nod, head turn
    (-0.9, 2.8), (-0.2, 2.4), (-1.2, 1.2), (0.0, 2.5), (-1.2, 1.2),  # right shoulder x,y,z, elbow x,z
    (-0.9, 2.8), (-0.2, 2.4), (-1.2, 1.2), (0.0, 2.5), (-1.2, 1.2),  # left
])
