"""A calibrated camera: OpenCV's pinhole model with distortion, placed in one world frame.

A world point ``X`` (millimetres) is seen at ``x_cam = R X + t`` in the camera and projected
by ``K`` after OpenCV's distortion (``cv2.projectPoints``). Every stream of a take is placed in
the same world frame, so a point triangulated from two views is one point for all of them.
The JSON form (see docs/formats.md, "Calibration") is what :mod:`partlab.labelling.calibration`
reads and writes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np


def _matrix(value, shape: tuple[int, ...], what: str) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64)
    if array.size != int(np.prod(shape)):
        raise ValueError(f"{what}: expected {'x'.join(map(str, shape))} numbers, got {array.size}")
    array = array.reshape(shape)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{what}: holds a value that is not a finite number")
    return array


@dataclass(frozen=True, eq=False)
class Camera:
    """``K``: ``(3, 3)`` intrinsics; ``dist``: OpenCV distortion ``(k1, k2, p1, p2[, k3, ...])``;
    ``R``: ``(3, 3)`` world-to-camera rotation; ``t``: ``(3,)`` translation in mm;
    ``size``: ``(width, height)`` of the images the intrinsics are for."""

    name: str
    K: np.ndarray
    size: tuple[int, int]
    dist: np.ndarray = field(default_factory=lambda: np.zeros(5))
    R: np.ndarray = field(default_factory=lambda: np.eye(3))
    t: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        object.__setattr__(self, "K", _matrix(self.K, (3, 3), f"camera {self.name!r} K"))
        object.__setattr__(self, "R", _matrix(self.R, (3, 3), f"camera {self.name!r} R"))
        object.__setattr__(self, "t", _matrix(self.t, (3,), f"camera {self.name!r} t"))
        dist = np.asarray(self.dist, dtype=np.float64).ravel()
        if dist.size not in (0, 4, 5, 8, 12, 14) or not np.all(np.isfinite(dist)):
            raise ValueError(f"camera {self.name!r} dist: expected 4, 5, 8, 12 or 14 finite numbers")
        object.__setattr__(self, "dist", dist)
        w, h = (int(v) for v in self.size)
        if w <= 0 or h <= 0:
            raise ValueError(f"camera {self.name!r} size: {w}x{h} is not a picture size")
        object.__setattr__(self, "size", (w, h))
        if abs(np.linalg.det(self.R) - 1.0) > 1e-3:
            raise ValueError(f"camera {self.name!r} R: not a rotation (determinant {np.linalg.det(self.R):.4f})")

    # -- geometry ---------------------------------------------------------------------------
    @property
    def P(self) -> np.ndarray:
        """``(3, 4)`` projection matrix ``K [R | t]`` (no distortion), for ``cv2.triangulatePoints``."""
        return self.K @ np.hstack([self.R, self.t[:, None]])

    @property
    def centre(self) -> np.ndarray:
        """``(3,)`` the optical centre in world millimetres, ``-R^T t``."""
        return -self.R.T @ self.t

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """``(N, 3)`` world points -> camera coordinates (z = depth along the optical axis)."""
        return np.asarray(points, dtype=np.float64).reshape(-1, 3) @ self.R.T + self.t

    def project(self, points: np.ndarray) -> np.ndarray:
        """``(N, 3)`` world points -> ``(N, 2)`` pixels, with distortion (``cv2.projectPoints``)."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if not len(pts):
            return np.zeros((0, 2))
        rvec, _ = cv2.Rodrigues(self.R)
        uv, _ = cv2.projectPoints(pts, rvec, self.t, self.K, self.dist)
        return uv.reshape(-1, 2)

    def rays(self, pixels: np.ndarray) -> np.ndarray:
        """``(N, 2)`` pixels -> ``(N, 3)`` unit directions of their lines of sight in the world
        frame (each line passes through :attr:`centre`); distortion is undone first."""
        uv = np.asarray(pixels, dtype=np.float64).reshape(-1, 1, 2)
        if not len(uv):
            return np.zeros((0, 3))
        norm = cv2.undistortPoints(uv, self.K, self.dist).reshape(-1, 2)
        d = np.hstack([norm, np.ones((len(norm), 1))]) @ self.R  # R^T d for each row
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def back_project(self, pixels: np.ndarray, depth: np.ndarray) -> np.ndarray:
        """``(N, 2)`` pixels with their depth (mm along the optical axis) -> ``(N, 3)`` world points."""
        uv = np.asarray(pixels, dtype=np.float64).reshape(-1, 1, 2)
        norm = cv2.undistortPoints(uv, self.K, self.dist).reshape(-1, 2)
        z = np.asarray(depth, dtype=np.float64).reshape(-1, 1)
        cam = np.hstack([norm * z, z])
        return (cam - self.t) @ self.R

    # -- serialisation ----------------------------------------------------------------------
    def to_dict(self) -> dict:
        return {"name": self.name, "image_size": list(self.size), "K": self.K.tolist(),
                "dist": self.dist.tolist(), "R": self.R.tolist(), "t": self.t.tolist()}

    @classmethod
    def from_dict(cls, data: dict, name: str | None = None) -> Camera:
        """From :meth:`to_dict`'s form; ``rvec`` (Rodrigues, 3 numbers) may stand for ``R``."""
        if not isinstance(data, dict):
            raise ValueError(f"camera {name!r}: expected an object, got {type(data).__name__}")
        name = str(data.get("name", name or "cam0"))
        for key in ("K", "image_size"):
            if key not in data:
                raise ValueError(f"camera {name!r}: missing {key!r}")
        if "R" in data:
            R = data["R"]
        elif "rvec" in data:
            R = cv2.Rodrigues(_matrix(data["rvec"], (3,), f"camera {name!r} rvec"))[0]
        else:
            R = np.eye(3)
        size = data["image_size"]
        if not isinstance(size, (list, tuple)) or len(size) != 2:
            raise ValueError(f"camera {name!r} image_size: expected [width, height]")
        return cls(name=name, K=data["K"], size=tuple(size), dist=data.get("dist", np.zeros(5)), R=R,
                   t=data.get("t", np.zeros(3)))
