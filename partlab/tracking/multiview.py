"""One world point seen in several calibrated views: triangulation, and the point a corrected view
fixes on its line of sight.

Used by the 3D head-and-hands tracker (starting targets from boxes in two or more views) and by
the app's multi-view correction (a box moved in one view moves the 3D point, and the other views'
boxes follow it by reprojection). Cameras are :class:`~partlab.tracking.camera.Camera` (world mm,
OpenCV's distortion); pixels are distorted image pixels as the views show them.
"""

from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.camera import Camera


def _undistorted(camera: Camera, pixel) -> np.ndarray:
    """A pixel with the lens distortion taken out, in the same pixel units (``(2, 1)``, for ``P``)."""
    uv = np.asarray(pixel, float).reshape(1, 1, 2)
    return cv2.undistortPoints(uv, camera.K, camera.dist, P=camera.K).reshape(2, 1)


def triangulate(cameras: list[Camera], pixels: list[np.ndarray]) -> np.ndarray:
    """A world point ``(3,)`` mm from its pixels in two or more views: ``cv2.triangulatePoints``
    (linear, on undistorted pixels) on each pair of views, averaged."""
    if len(cameras) < 2 or len(cameras) != len(pixels):
        raise ValueError(f"triangulation needs a pixel in each of 2+ views, got {len(cameras)} views, "
                         f"{len(pixels)} pixels")
    pts = []
    for i in range(len(cameras)):
        for j in range(i + 1, len(cameras)):
            h = cv2.triangulatePoints(cameras[i].P, cameras[j].P, _undistorted(cameras[i], pixels[i]),
                                      _undistorted(cameras[j], pixels[j])).ravel()
            pts.append(h[:3] / h[3])
    return np.mean(pts, axis=0)


def point_on_line_of_sight(camera: Camera, pixel, others: list[Camera], other_pixels: list[np.ndarray],
                           near: np.ndarray | None = None) -> np.ndarray | None:
    """The point of ``camera``'s line of sight through ``pixel`` that the other views agree with
    best: nearest (least squares over the views, 3D distance) to the lines of sight of
    ``other_pixels`` in ``others``. With one other view it is the corrected line's end of the two
    lines' common perpendicular (3D tracking of the hands and head..., eq. 22-23), so the corrected
    view keeps exactly the pixel it was given. Without other views: the point of the line nearest
    ``near`` (the point before the correction), or None without it; None too when the best point
    lies behind the camera.
    """
    p = camera.centre
    v = camera.rays(np.asarray(pixel, float).reshape(1, 2))[0]
    num = den = 0.0
    for cam, px in zip(others, other_pixels):
        w = cam.rays(np.asarray(px, float).reshape(1, 2))[0]
        M = np.eye(3) - np.outer(w, w)  # projects onto the plane normal to the other line
        num += float(v @ M @ (p - cam.centre))
        den += float(v @ M @ v)
    if den > 1e-9:
        s = -num / den
    elif near is not None and np.all(np.isfinite(near)):
        s = float(v @ (np.asarray(near, float) - p))
    else:
        return None
    return p + s * v if s > 0 else None
