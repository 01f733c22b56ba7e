"""The raised camera of the synthetic scenes: a pinhole over a flat floor.

A point on the floor at lateral position ``X`` and depth ``Z`` (metres, ``Z`` away from
the camera) lands at ``x = cx + f X / Z`` and ``y = horizon + f h_cam / Z``: farther
people stand higher in the image and are drawn smaller (``f / Z`` pixels per metre).
The defaults put a 1.75 m person 100 px tall at ``Z = 12`` and 220 px tall at
``Z = 5.5`` in a 720x480 frame, the sizes of seed 002 sec. 5 (over 100 px tall, over
30 px wide). Around one person the projection is linearised (:class:`LocalView`).

That image is what a camera with a vertical image plane sees (a shift lens: the horizon row set
by moving the principal point). A real camera mounted high *tilts* down to see the floor:
its image plane is pitched, so vertical lines converge towards the nadir below the frame and a
person at the frame's side leans outwards, and a camera is rarely level, so it rolls too. A
pure rotation of the camera is a homography of the image (:meth:`Camera.image_warp`): the
randomized scenes are drawn on the shift-lens image and warped by it, frames and truth alike.
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
    # Tilt (None: a vertical image plane). ``pitch``: the image plane looks down at the horizon
    # row from a principal point at the frame centre; ``roll``: radians about the optical axis.
    pitch: bool = False
    roll: float = 0.0

    @classmethod
    def for_frame(cls, width: int, height: int) -> Camera:
        """The scenes' camera at any frame size (sizes scale with the frame height)."""
        return cls(width, height, f=1.46 * height, horizon=0.14 * height)

    @classmethod
    def random(cls, rng: np.random.Generator, width: int, height: int) -> Camera:
        """A camera of any plausible mounting: 2.2-5.5 m up, pitched down so that the horizon lies
        anywhere from above the frame to a third of the way down it (vertical lines converging,
        :meth:`image_warp`), rolled by up to 4 degrees either way, focal length 1.1-1.9 frame
        heights (the randomized suite of issue 13)."""
        return cls(width, height, f=float(rng.uniform(1.1, 1.9)) * height,
                   horizon=float(rng.uniform(-0.15, 0.3)) * height, cam_height=float(rng.uniform(2.2, 5.5)),
                   pitch=True, roll=float(np.radians(rng.uniform(-4.0, 4.0))))

    def drawing(self) -> tuple[Camera, np.ndarray | None]:
        """Where to draw this camera's image: ``(canvas camera, homography)``. An untilted camera
        draws its own frame (homography None). A tilted one draws on a larger vertical-image-plane
        canvas (the same focal length, horizon and floor; the frame's corners seen back through the
        tilt lie inside it) and ``H (3, 3)`` maps canvas pixels to this camera's frame:
        ``H = K_t R_roll R_pitch K_s^-1 T^-1``, ``K_s`` the drawing's intrinsics (principal point on
        the horizon row), ``R_pitch`` the rotation by ``atan((cy - horizon) / f)`` that keeps the
        horizon where it was drawn, ``K_t`` the tilted camera's (principal point at the centre),
        ``T`` the canvas's shift against the frame."""
        if not self.pitch and self.roll == 0.0:
            return self, None
        cy = self.height / 2.0
        ks = np.array([[self.f, 0, self.cx], [0, self.f, self.horizon], [0, 0, 1.0]])
        th = float(np.arctan2(cy - self.horizon, self.f)) if self.pitch else 0.0
        c, s = np.cos(th), np.sin(th)
        rp = np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])
        c, s = np.cos(self.roll), np.sin(self.roll)
        rr = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
        kt = np.array([[self.f, 0, self.cx], [0, self.f, cy], [0, 0, 1.0]])
        h0 = kt @ rr @ rp @ np.linalg.inv(ks)
        corners = np.array([[0, 0, 1], [self.width, 0, 1], [0, self.height, 1], [self.width, self.height, 1.0]]).T
        back = np.linalg.inv(h0) @ corners
        x, y = back[0] / back[2], back[1] / back[2]
        half = float(np.ceil(np.max(np.abs(x - self.cx)))) + 2
        top, bottom = float(np.floor(y.min())) - 2, float(np.ceil(y.max())) + 2
        canvas = Camera(int(2 * half), int(bottom - top), self.f, self.horizon - top, self.cam_height)
        shift = np.array([[1.0, 0, half - self.cx], [0, 1, -top], [0, 0, 1]])
        return canvas, h0 @ np.linalg.inv(shift)

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
