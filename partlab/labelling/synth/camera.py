"""The raised camera of the synthetic scenes: a pinhole over a flat floor.

A point on the floor at lateral position ``X`` and depth ``Z`` (metres, ``Z`` away from
the camera) lands at ``x = cx + f X / Z`` and ``y = horizon + f h_cam / Z``: farther
people stand higher in the image and are drawn smaller (``f / Z`` pixels per metre).
The defaults put a 1.75 m person 100 px tall at ``Z = 12`` and 220 px tall at
``Z = 5.5`` in a 720x480 frame, the sizes of seed 002 sec. 5 (over 100 px tall, over
30 px wide). Around one person the projection is linearised (:class:`LocalView`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Camera:
    width: int
    height: int
    f: float  # focal length in pixels
    horizon: float  # image row of the horizon (camera tilted down: above the frame centre)
    cam_height: float = 3.1  # metres above the floor

    @classmethod
    def for_frame(cls, width: int, height: int) -> Camera:
        """The scenes' camera at any frame size (sizes scale with the frame height)."""
        return cls(width, height, f=1.46 * height, horizon=0.14 * height)

    @classmethod
    def random(cls, rng: np.random.Generator, width: int, height: int) -> Camera:
        """A camera of any plausible mounting: 2.2-5.5 m up, tilted so that the horizon lies
        anywhere from above the frame to a third of the way down it, focal length 1.1-1.9 frame
        heights (the randomized suite of issue 13)."""
        return cls(width, height, f=float(rng.uniform(1.1, 1.9)) * height,
                   horizon=float(rng.uniform(-0.15, 0.3)) * height, cam_height=float(rng.uniform(2.2, 5.5)))

    def depth_range(self, height_m: float = 1.75, min_px: float = 0.22, margin: float = 0.03) -> tuple[float, float]:
        """Depths at which a standing person's feet are in the frame (``margin`` of its height above
        the bottom) and who is at least ``min_px`` of the frame height tall."""
        near = self.f * self.cam_height / ((1 - margin) * self.height - self.horizon)
        far = self.f * height_m / (min_px * self.height)
        return float(near), float(max(far, near * 1.15))

    @property
    def cx(self) -> float:
        return self.width / 2.0

    def scale(self, z) -> np.ndarray:
        """Pixels per metre at depth ``z``."""
        return self.f / np.asarray(z, dtype=float)

    def floor_point(self, x, z) -> tuple[np.ndarray, np.ndarray]:
        """Image position of the floor point ``(x, z)``."""
        s = self.scale(z)
        return self.cx + s * np.asarray(x, float), self.horizon + s * self.cam_height

    def x_from_fraction(self, xr, z) -> np.ndarray:
        """Lateral floor position seen at ``xr`` in [-1, 1] of the half frame width at depth ``z``."""
        return np.asarray(xr, float) * self.cx / self.scale(z)

    def depth_of_row(self, y) -> np.ndarray:
        """Depth of the floor seen at image row ``y`` (below the horizon)."""
        return self.f * self.cam_height / (np.asarray(y, float) - self.horizon)

    def local_view(self, x: float, z: float) -> LocalView:
        """The projection linearised around the floor point ``(x, z)``."""
        x0, y0 = self.floor_point(x, z)
        return LocalView(float(x0), float(y0), float(self.scale(z)), self.cam_height / z)


@dataclass(frozen=True)
class LocalView:
    """Linear projection around one person: ``x = x0 + s dX``, ``y = y0 - s u - s k dZ``.

    ``(dX, dZ)`` is the floor offset from the person's foot point and ``u`` the height
    above the floor (metres); ``k`` is how far up a step away from the camera moves a
    point (the floor's slope in the image, ``h_cam / Z``).
    """

    x0: float
    y0: float
    s: float
    k: float

    def project(self, dx: np.ndarray, dz: np.ndarray, u: np.ndarray) -> np.ndarray:
        """``(N,)`` offsets -> ``(N, 2)`` image points."""
        x = self.x0 + self.s * dx
        y = self.y0 - self.s * u - self.s * self.k * dz
        return np.stack([x, y], axis=-1)
