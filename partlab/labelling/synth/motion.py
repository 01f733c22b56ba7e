"""Per-frame motion of a synthetic person: where they stand, where they face, what they do.

A :class:`Motion` holds one value per frame for each degree of freedom the figure
(``partlab.labelling.synth.figure``) understands. Paths are given as keyframes in clip time
(fraction of the clip in [0, 1]) so that a scenario keeps its story at any frame count;
events such as a clap "around frames 40-60" are placed at 40/150 .. 60/150 of the clip.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Walking: one full gait cycle (two steps of about 0.4 H each) per this many body heights travelled.
STRIDE_PER_HEIGHT = 0.8
#: Speed (metres per frame) at which the gait reaches its full amplitude.
FULL_GAIT_SPEED = 0.035


@dataclass(frozen=True, eq=False)
class Motion:
    """Arrays of shape ``(T,)`` unless noted.

    ``x, z``: floor position of the feet (metres); ``facing``: body heading in the floor
    plane (radians, 0 = towards +x / image right, -pi/2 = towards the camera);
    ``phase``: gait phase (radians); ``gait``: gait amplitude in [0, 1] (0 = standing);
    ``wave``: right-arm wave in [0, 1]; ``bend``: forward torso pitch about the hips
    (radians); ``head_yaw``: head turn relative to the body (radians, positive = to the
    person's left); ``hands``: ``(T, 2, 3)`` hand targets ``[left, right] x (lateral,
    forward, up)`` in metres in the body frame, NaN where the arms swing freely.
    """

    x: np.ndarray
    z: np.ndarray
    facing: np.ndarray
    phase: np.ndarray
    gait: np.ndarray
    wave: np.ndarray
    bend: np.ndarray
    head_yaw: np.ndarray
    hands: np.ndarray
    seated: bool = False

    @property
    def n_frames(self) -> int:
        return len(self.x)


def clip_time(n_frames: int) -> np.ndarray:
    """Frame times as fractions of the clip, ``(T,)`` in [0, 1]."""
    return np.linspace(0.0, 1.0, n_frames) if n_frames > 1 else np.zeros(1)


def bump(t: np.ndarray, start: float, end: float, ramp: float = 0.04) -> np.ndarray:
    """1 inside ``[start, end]`` with smooth (cosine) ramps of width ``ramp`` either side, else 0."""
    up = np.clip((t - (start - ramp)) / ramp, 0, 1)
    down = np.clip(((end + ramp) - t) / ramp, 0, 1)
    return 0.5 - 0.5 * np.cos(np.pi * np.minimum(up, down))


def _turn_target(prev: float, nxt: float) -> float:
    """``nxt`` unwrapped next to ``prev``; a turn of more than 120 degrees goes through facing the camera."""
    best = prev + (nxt - prev + np.pi) % (2 * np.pi) - np.pi
    if abs(best - prev) > 2 * np.pi / 3:
        other = best - np.sign(best - prev) * 2 * np.pi
        best = min((best, other), key=lambda c: np.sin((prev + c) / 2))
    return float(best)


def walk(camera, n_frames: int, keys, height_m: float = 1.75, smooth: int = 7) -> Motion:
    """A walk through keyframes ``[(t, xr, z), ...]`` (``xr`` in [-1, 1] of the half frame width).

    Between two keyframes at the same place the person stands and turns towards the
    next leg of the path; the heading follows the velocity, smoothed over ``smooth``
    frames so that turns take a few steps.
    """
    keys = sorted(keys)
    t = clip_time(n_frames)
    kt = np.array([k[0] for k in keys], float)
    kz = np.array([k[2] for k in keys], float)
    kx = camera.x_from_fraction(np.array([k[1] for k in keys], float), kz)
    x = np.interp(t, kt, kx)
    z = np.interp(t, kt, kz)
    vx = np.gradient(x) if n_frames > 1 else np.zeros(1)
    vz = np.gradient(z) if n_frames > 1 else np.zeros(1)
    speed = np.hypot(vx, vz)
    moving = speed > 1e-4
    raw = np.where(moving, np.arctan2(vz, vx), np.nan)
    facing = np.empty(n_frames)
    idx = np.flatnonzero(moving)
    if len(idx) == 0:
        facing[:] = -np.pi / 2
    else:
        # unwrap the moving frames, interpolating standing stretches through the camera
        unwrapped = np.empty(len(idx))
        unwrapped[0] = raw[idx[0]]
        for j in range(1, len(idx)):
            unwrapped[j] = _turn_target(unwrapped[j - 1], raw[idx[j]])
        facing = np.interp(np.arange(n_frames), idx, unwrapped)
    if smooth > 1 and n_frames > smooth:
        pad = smooth // 2
        kernel = np.ones(smooth) / smooth
        facing = np.convolve(np.pad(facing, pad, mode="edge"), kernel, mode="valid")
    dist = np.concatenate([[0.0], np.cumsum(speed[1:])]) if n_frames > 1 else np.zeros(1)
    phase = 2 * np.pi * dist / (STRIDE_PER_HEIGHT * height_m)
    gait = np.clip(speed / FULL_GAIT_SPEED, 0, 1)
    zeros = np.zeros(n_frames)
    return Motion(x, z, facing, phase, gait, zeros.copy(), zeros.copy(), zeros.copy(),
                  np.full((n_frames, 2, 3), np.nan))


def with_changes(m: Motion, **arrays) -> Motion:
    """A copy of ``m`` with some arrays replaced."""
    fields = {k: getattr(m, k) for k in m.__dataclass_fields__}
    fields.update(arrays)
    return Motion(**fields)
