"""Starting a person from given joints (``--init``, or a joint the user dragged in the app).

Migniot & Ababsa start their filter from a model placed on the person; partlab's init gives the
3D joints of the first frame (head, shoulders, elbows, hands). Joints alone leave three things
open that the depth points settle:

* **the bend** at the pelvis: the head and shoulders of a person bent over a shelf are lower
  and forward, which the joints equally explain by an upright torso moved forward with the
  head nodded. Fitting that wrong start put the whole model 100-300 mm off on the takes whose
  first frame is a bend, and the filter never came back (a random walk of 12 mm a frame does
  not undo a 0.6 rad bend while the arms are judged against a misplaced torso);
* **the stature** (torso, neck and head sizes): the head's height gives it only for people who
  stand upright; the head-to-shoulders distance and the arms give it whatever the pose;
* **the pelvis**, which the camera above does not see: people stand, so it is held near the
  standing pelvis height of the stature (``StartParams.stand_sd_mm``).

:func:`fit_person` fits the 17 degrees of freedom and the stature together by least squares
(``scipy.optimize.least_squares``, soft-L1 loss): the joints, the standing prior, and the mean
distance of the person's depth points to the model (eq. 1's distance, :func:`nearest`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from partlab.tracking.topview.likelihood import nearest
from partlab.tracking.topview.model import JOINT_LIMITS, JOINTS, N_DOF, Body, fit_state, joints, primitives
from partlab.tracking.topview.params import StartParams

_POS_SCALE = 1000.0  # mm per unit of the least-squares variables' positions (angles are radians)
_STEP = 1e-3  # forward-difference step of the variables (1 mm, 1 mrad, 0.1 % of the stature)


def body_from_joints(joints_mm: Mapping[str, np.ndarray], stature: float | None = None) -> Body:
    """A person's sizes from their joints: the default proportions scaled to ``stature`` (default:
    from the head's height, right for people standing upright), then the shoulder width (and the
    torso's width with it) and the arm lengths as measured."""
    base = Body()
    j = {k: np.asarray(v, np.float64) for k, v in joints_mm.items()}
    if stature is None:
        stature = 1750.0
        if "head" in j:
            stature = float(j["head"][2]) / (1 - base.head_radius / base.stature)
    body = base.scaled(stature)
    if "right_shoulder" in j and "left_shoulder" in j:
        half = float(np.linalg.norm(j["right_shoulder"] - j["left_shoulder"]) / 2)
        wide = half / body.shoulder_offset  # broad shoulders, broad torso
        body = replace(body, shoulder_offset=half, torso_half_width=body.torso_half_width * wide)
    ups, fores = [], []
    for side in ("right", "left"):
        s, e, h = j.get(f"{side}_shoulder"), j.get(f"{side}_elbow"), j.get(f"{side}_hand")
        if s is not None and e is not None:
            ups.append(np.linalg.norm(e - s))
        if e is not None and h is not None:
            fores.append(np.linalg.norm(h - e))
    if ups and fores:
        body = body.with_arms(float(np.mean(ups)), float(np.mean(fores)))
    return body


def _standing_stature(j: Mapping[str, np.ndarray]) -> float:
    """Stature from the head's centre above the shoulders' midpoint: the neck, the head's radius and
    the shoulders' drop below the top of the torso, whatever the bend (1750 mm if not given)."""
    base = Body()
    if "head" not in j or "right_shoulder" not in j or "left_shoulder" not in j:
        return base.stature
    mid = (np.asarray(j["right_shoulder"]) + np.asarray(j["left_shoulder"])) / 2
    span = float(np.linalg.norm(np.asarray(j["head"]) - mid))
    return base.stature * span / (base.shoulder_drop + base.neck_length + base.head_radius)


def fit_person(targets: Mapping[str, np.ndarray], points: np.ndarray | None = None,
               params: StartParams | None = None) -> tuple[Body, np.ndarray]:
    """The body and the ``(17,)`` state that best explain ``targets`` (joint name -> ``(3,)`` mm,
    any subset of :data:`JOINTS`) and, if given, the person's depth points ``(M, 3)`` (module doc)."""
    sp = params or StartParams()
    names = [n for n in JOINTS if n in targets]
    if not names:
        raise ValueError("no joints to fit the model to")
    idx = [JOINTS.index(n) for n in names]
    goal = np.array([targets[n] for n in names], np.float64)
    s0 = _standing_stature(targets)
    body0 = body_from_joints(targets, s0)
    start = fit_state(targets, body0)  # the joints alone: a start close to them
    if points is None or len(points) < 10:
        return body0, start
    pts = np.asarray(points, np.float64)
    if len(pts) > sp.fit_points:
        pts = pts[np.linspace(0, len(pts) - 1, sp.fit_points).astype(int)]
    scale = np.array([_POS_SCALE] * 3 + [1.0] * (N_DOF - 3))
    w_points = np.sqrt(sp.points_weight * goal.size / len(pts))

    def unpack(u):
        return body_from_joints(targets, s0 * np.exp(u[-1])), u[:-1] * scale

    def batch(states, body):
        """``(P, R)`` residuals of ``(P, 17)`` states of one body: joints, standing, points."""
        r_joint = (joints(states, body)[:, idx] - goal).reshape(len(states), -1)
        stand = body.pelvis_height - sp.bend_sink_mm * states[:, 4]
        r_stand = (states[:, 2:3] - stand[:, None]) * sp.joint_sd_mm / sp.stand_sd_mm
        prims = primitives(states, body)
        d = np.stack([nearest(pts, p)[0] for p in prims])
        return np.concatenate([r_joint, r_stand, w_points * d], axis=1)

    def residual(u):
        body, state = unpack(u)
        return batch(state[None], body)[0]

    def jacobian(u):
        """Forward differences with the 17 states' perturbations in one batch (kinematics is
        vectorised over states) and the stature's own."""
        body, state = unpack(u)
        h = np.full(N_DOF, _STEP)
        states = np.vstack([state, state + np.diag(h * scale)])
        r = batch(states, body)
        r_size = residual(u + np.append(np.zeros(N_DOF), _STEP))
        return np.column_stack([(r[1:] - r[0]).T / h, (r_size - r[0]) / _STEP])

    from scipy.optimize import least_squares

    lo = np.append(JOINT_LIMITS[:, 0] / scale, np.log(sp.stature_range[0]))
    hi = np.append(JOINT_LIMITS[:, 1] / scale, np.log(sp.stature_range[1]))
    best = None
    # two starts: the joints' own fit, and the same bent forward (the ambiguity the points settle)
    for bend in (None, 0.5):
        x0 = np.append(start / scale, 0.0)
        if bend is not None:
            x0[4] = bend
        x0 = np.clip(x0, lo + 1e-6, hi - 1e-6)
        sol = least_squares(residual, x0, jac=jacobian, bounds=(lo, hi), loss="soft_l1",
                            f_scale=sp.fit_scale_mm, max_nfev=sp.fit_evaluations)
        if best is None or sol.cost < best.cost:
            best = sol
    return unpack(best.x)
