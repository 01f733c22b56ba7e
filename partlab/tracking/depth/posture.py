"""Xu, Deng & Jia sec. 5: the 3D upper-body posture from the 2D tracks, the depth map and the
calibration.

Head and hands: the box centre back-projected at the median depth of the box's near pixels, pushed
back by the part's radius (the depth map sees the surface; the part's centre is behind it). Torso:
a rectangle under the head, in the face's depth plane (constraint 1 of sec. 4), its upper corners
the shoulders. Sizes are in proportion to the head (sec. 5: "the size of torso, upper arm and
forearm are in a fixed proportion to that of head"), the head's size being its box width at its
depth. Elbows: the possible elbows of an arm with a given upper-arm and forearm length form a
circle around the shoulder-hand line; the candidate whose image point's depth best matches it is
the elbow; when none matches (the hand covers the elbow) the elbow is put at ``(X_h, Y_h, Z_h +
l_f)``, behind the hand, as in the paper.

Points are millimetres in the camera's world frame (``Camera.back_project``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from partlab.tracking.camera import Camera
from partlab.tracking.depth.params import Posture


@dataclass(frozen=True)
class Pose3D:
    """World points ``(3,)`` in mm; ``head_width`` the size unit (mm); elbows_matched: per arm,
    whether the elbow came from the depth map (False: the occlusion fallback)."""

    head: np.ndarray
    left_hand: np.ndarray | None
    right_hand: np.ndarray | None
    torso: np.ndarray
    torso_size: tuple[float, float]
    left_shoulder: np.ndarray
    right_shoulder: np.ndarray
    left_elbow: np.ndarray | None
    right_elbow: np.ndarray | None
    head_width: float
    elbows_matched: tuple[bool, bool] = (False, False)


def surface_depth(depth: np.ndarray, box, nearer_than: float = np.inf) -> float | None:
    """Median of the nearer half of the measured depths in ``box`` (the part, not what shows past
    its edges), counting only depths under ``nearer_than`` (a hand is in front of the face, sec. 4
    constraint 1: a hand's box at the image's edge may hold more wall than hand); None when
    nothing is measured there."""
    x, y, w, h = (int(round(v)) for v in box)
    hgt, wid = depth.shape
    patch = depth[max(y, 0):min(y + h, hgt), max(x, 0):min(x + w, wid)]
    with np.errstate(invalid="ignore"):
        vals = patch[np.isfinite(patch) & (patch < nearer_than)]
    if vals.size == 0:
        return None
    near = vals[vals <= np.median(vals)]
    return float(np.median(near))


def _centre_point(camera: Camera, box, z: float, behind: float) -> np.ndarray:
    """The box centre at depth ``z`` moved ``behind`` mm further along its line of sight."""
    x, y, w, h = box
    centre = np.array([[x + w / 2, y + h / 2]])
    surf = camera.back_project(centre, np.array([z]))[0]
    ray = camera.rays(centre)[0]
    return surf + behind * ray / max(float(ray @ camera.R[2]), 1e-6)


def head_width(camera: Camera, depth: np.ndarray, head_box, p: Posture) -> float | None:
    """The head's width in mm from its box and depth, at the depth of its silhouette (its centre:
    the surface plus its radius, itself ``head_depth`` head widths): ``w = px (z_s + head_depth w) / f``."""
    zh = surface_depth(depth, head_box)
    if zh is None:
        return None
    fx = float(camera.K[0, 0])
    return float(head_box[2]) * zh / max(fx - float(head_box[2]) * p.head_depth, 1e-6)


class ArmFit:
    """The arms' lengths of one person (our addition to sec. 5's arm model): the paper fixes them in
    proportion to the head; people's arms differ from the average by several per cent, and a
    stretched arm 5 % shorter than the model puts the elbow ~50 mm off its line. Each frame, every
    factor of ``Posture.arm_scales`` is tried on both arms (:func:`arm_cost` of its best elbow, or
    1 when the hand is farther from the shoulder than that arm reaches); the factor with the least
    summed cost so far gives the lengths (both arms: people are symmetric)."""

    def __init__(self, p: Posture):
        self.scales = np.asarray(p.arm_scales, float)
        self.cost = np.zeros(len(self.scales))

    @property
    def scale(self) -> float:
        return float(self.scales[int(np.argmin(self.cost))]) if self.cost.any() else 1.0

    def update(self, camera: Camera, depth: np.ndarray, shoulder, hand, upper, fore, arm_depth, tolerance,
               n, in_range, samples: int) -> None:
        reach = float(np.linalg.norm(hand - shoulder))
        for k, f in enumerate(self.scales):
            if reach > 0.999 * f * (upper + fore):
                self.cost[k] += 1.0
                continue
            cands = elbow_circle(shoulder, hand, f * upper, f * fore, n)
            c = arm_cost(camera, depth, shoulder, cands, hand, arm_depth, tolerance, samples)
            c[~in_range(cands)] = np.inf
            self.cost[k] += min(float(c.min()), 1.0)


def recover(camera: Camera, depth: np.ndarray, head_box, hand_boxes, p: Posture,
            head_mm: float | None = None, arms: ArmFit | None = None) -> Pose3D | None:
    """The posture of one person: ``hand_boxes`` ``[left, right]``, each a box or None; ``head_mm``:
    the head's width measured once (a head does not change size; the filter's alpha does), else
    from this box; ``arms``: the person's arm lengths, updated with this frame (else the
    proportions as they are)."""
    zh = surface_depth(depth, head_box)
    if zh is None:
        return None
    head_w = head_mm if head_mm is not None else head_width(camera, depth, head_box, p)
    head = _centre_point(camera, head_box, zh, p.head_depth * head_w)
    hands: list[np.ndarray | None] = []
    for box in hand_boxes:
        z = surface_depth(depth, box, nearer_than=zh) if box is not None else None
        hands.append(None if z is None else _centre_point(camera, box, z, p.hand_depth * head_w))
    # the torso's plane: the face surface (constraint 1) plus the shoulders' depth behind it
    down = camera.R[1]  # the camera's image-down axis in the world (the body is upright, sec. 4)
    right = camera.R[0]
    back = camera.R[2]
    face_surface_z = head - p.head_depth * head_w * back
    shoulder_mid = face_surface_z + p.shoulder_depth * head_w * back + p.shoulder_drop * head_w * down
    # the person faces the camera: their left is the image's right
    left_sh = shoulder_mid + p.shoulder_half * head_w * right
    right_sh = shoulder_mid - p.shoulder_half * head_w * right
    tw, th = p.torso_size[0] * head_w, p.torso_size[1] * head_w
    torso = shoulder_mid + 0.5 * th * down
    upper, fore = p.upper_arm * head_w, p.forearm * head_w
    arm_depth, tol = p.arm_depth * head_w, p.elbow_tolerance * head_w
    sides = []
    for shoulder, hand, outward in ((left_sh, hands[0], right), (right_sh, hands[1], -right)):
        def in_range(c, s=shoulder, o=outward):  # sec. 5's kinetic range: not above, not medial of it
            return (((c - s) @ down) > -p.elbow_above * head_w) & (((c - s) @ o) > -p.elbow_medial * head_w)

        sides.append((shoulder, hand, in_range))
        if arms is not None and hand is not None:
            arms.update(camera, depth, shoulder, hand, upper, fore, arm_depth, tol, p.elbow_candidates, in_range,
                        p.arm_samples)
    scale = arms.scale if arms is not None else 1.0
    elbows, matched = [], []
    for shoulder, hand, in_range in sides:
        if hand is None:
            elbows.append(None)
            matched.append(False)
            continue
        e, ok = elbow(camera, depth, shoulder, hand, scale * upper, scale * fore, arm_depth, tol,
                      p.elbow_candidates, in_range=in_range, samples=p.arm_samples)
        elbows.append(e)
        matched.append(ok)
    return Pose3D(head, hands[0], hands[1], torso, (tw, th), left_sh, right_sh, elbows[0], elbows[1], head_w,
                  (matched[0], matched[1]))


def elbow_circle(shoulder: np.ndarray, hand: np.ndarray, upper: float, fore: float, n: int) -> np.ndarray:
    """``(n, 3)`` points where an upper arm of length ``upper`` from ``shoulder`` meets a forearm of
    length ``fore`` from ``hand`` (the circle of possible elbows; one point on the line when the
    arm is stretched beyond its length)."""
    d = hand - shoulder
    dist = float(np.linalg.norm(d))
    u = d / max(dist, 1e-9)
    reach = min(max(dist, 1e-6), 0.999 * (upper + fore))
    a = (upper**2 - fore**2 + reach**2) / (2 * reach)
    r = np.sqrt(max(upper**2 - a**2, 0.0))
    # two unit vectors perpendicular to the arm's line
    helper = np.array([0.0, 1.0, 0.0]) if abs(u[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(u, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return shoulder + a * u + r * (np.cos(t)[:, None] * e1 + np.sin(t)[:, None] * e2)


def arm_cost(camera: Camera, depth: np.ndarray, shoulder: np.ndarray, cands: np.ndarray, hand: np.ndarray,
             arm_depth: float, tolerance: float, samples: int) -> np.ndarray:
    """``(n,)`` how badly the arm through each elbow candidate ``cands (n, 3)`` fits the depth map.

    The upper arm (shoulder to candidate) and the forearm (candidate to hand) are sampled at
    ``samples`` points each; a point's surface lies ``arm_depth`` in front of its axis. Per point:
    0 when the depth map sees it there (within ``tolerance``), 1 when the map sees *farther* (free
    space where the arm would be: the arm cannot be there), 1/2 when it sees nearer (the point may
    be hidden, by the hand or the other arm) or nothing; the cost is the mean. Only the arm as a
    whole tells the elbows apart: many points of the circle, the elbow among them, see a depth
    near their own (the chest behind them, the forearm in front).
    """
    s = (np.arange(samples) + 0.5) / samples
    upper = shoulder + s[None, :, None] * (cands[:, None, :] - shoulder)
    fore = cands[:, None, :] + s[None, :, None] * (hand - cands[:, None, :])
    pts = np.concatenate([upper, fore], axis=1).reshape(-1, 3)
    uv = camera.project(pts)
    hgt, wid = depth.shape
    col, row = np.round(uv[:, 0]).astype(int), np.round(uv[:, 1]).astype(int)
    inside = (col >= 0) & (col < wid) & (row >= 0) & (row < hgt)
    seen = np.full(len(pts), np.nan)
    seen[inside] = depth[row[inside], col[inside]]
    r = seen - (camera.to_camera(pts)[:, 2] - arm_depth)
    with np.errstate(invalid="ignore"):
        cost = np.where(np.abs(r) <= tolerance, 0.0, np.where(r > tolerance, 1.0, 0.5))
    return cost.reshape(len(cands), -1).mean(axis=1)


def elbow(camera: Camera, depth: np.ndarray, shoulder: np.ndarray, hand: np.ndarray, upper: float, fore: float,
          arm_depth: float, tolerance: float, n: int, in_range=None, samples: int = 8,
          max_cost: float = 0.4, arc: float = 0.07) -> tuple[np.ndarray, bool]:
    """Sec. 5's kinematic search: among the candidates on :func:`elbow_circle` within the kinetic
    range (``in_range(points) -> bool mask``), the one whose arm best matches the depth map
    (:func:`arm_cost`: the paper matches the elbow's point; partlab matches the two segments through
    it, the arm model); the paper's fallback ``(X_h, Y_h, Z_h + l_f)`` when no arm fits (cost over
    ``max_cost``: most of it hidden, e.g. behind the hand)."""
    cands = elbow_circle(shoulder, hand, upper, fore, n)
    cost = arm_cost(camera, depth, shoulder, cands, hand, arm_depth, tolerance, samples)
    if in_range is not None:
        cost[~in_range(cands)] = np.inf
    best = int(np.argmin(cost))
    if not np.isfinite(cost[best]) or cost[best] > max_cost:
        return hand + fore * camera.R[2], False  # (X_h, Y_h, Z_h + l_f) along the camera's axis
    # the arm is thick: the candidates next to the elbow fit too, an arc around it. Its middle,
    # not its best point, is the elbow (the best point wanders along the arc with the noise)
    near, close = [best], cost[best] + arc
    for step in (1, -1):
        k = best
        for _ in range(n // 2):
            k = (k + step) % n
            if cost[k] > close or k in near:
                break
            near.append(k)
    centre = cands.mean(axis=0)  # the circle's centre (the candidates are evenly spaced on it)
    mid = cands[near].mean(axis=0) - centre
    radius = float(np.linalg.norm(cands[0] - centre))
    norm = float(np.linalg.norm(mid))
    return (centre + mid * radius / norm if norm > 1e-9 else cands[best]), True
