"""Depth from a calibrated stereo pair, aligned to the left (colour) image.

Xu, Deng & Jia (sec. 2) build their depth from two calibrated webcams and block matching. partlab
does the same with OpenCV: the pair is rectified (:func:`cv2.stereoRectify`,
:func:`cv2.initUndistortRectifyMap`), matched by semi-global block matching
(:class:`cv2.StereoSGBM`), the disparities are turned into 3D points with
:func:`cv2.reprojectImageTo3D` and ``Q``, and every pixel of the *original* left image reads the
point its rectified position sees (nearest neighbour, so no depth is blended across an edge),
rotated back into the left camera: the depth is millimetres along the left camera's axis, on the
left image's grid, so it lines up with the colour the trackers see. Unmatched pixels are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from partlab.tracking.camera import Camera


@dataclass(frozen=True)
class StereoMatching:
    """Block-matching settings (OpenCV's StereoSGBM). ``num_disparities`` 0 = the frame width / 5
    rounded up to 16 (64 at 320 px: with f ~ 300 px and a 120 mm baseline, down to 0.55 m)."""

    num_disparities: int = 0
    # 5x5 blocks: small enough for a hand ~15 px across at 320x240, large enough to match on skin
    block_size: int = 5
    uniqueness: int = 10
    speckle_window: int = 60
    speckle_range: int = 2

    def matcher(self, width: int) -> cv2.StereoSGBM:
        nd = self.num_disparities or 16 * int(np.ceil(width / 5 / 16))
        b = self.block_size
        return cv2.StereoSGBM_create(minDisparity=0, numDisparities=nd, blockSize=b, P1=8 * b * b,
                                     P2=32 * b * b, uniquenessRatio=self.uniqueness,
                                     speckleWindowSize=self.speckle_window, speckleRange=self.speckle_range,
                                     mode=cv2.STEREO_SGBM_MODE_SGBM)


class StereoRig:
    """A calibrated pair: :meth:`depth` of a left/right image pair, on the left image's grid."""

    def __init__(self, left: Camera, right: Camera, matching: StereoMatching = StereoMatching()):
        if tuple(left.size) != tuple(right.size):
            raise ValueError(f"stereo cameras {left.name!r} and {right.name!r} differ in image size "
                             f"({left.size[0]}x{left.size[1]} vs {right.size[0]}x{right.size[1]})")
        self.left, self.right = left, right
        size = tuple(int(v) for v in left.size)
        # the pair's relative pose: x_right = R x_left + T
        R = right.R @ left.R.T
        T = right.t - R @ left.t
        if np.linalg.norm(T) < 1e-6:
            raise ValueError(f"stereo cameras {left.name!r} and {right.name!r} share one centre (no baseline)")
        R1, R2, P1, P2, Q, _, _ = cv2.stereoRectify(left.K, left.dist, right.K, right.dist, size, R, T,
                                                     flags=cv2.CALIB_ZERO_DISPARITY, alpha=0)
        self.R1, self.Q = R1, Q
        self._maps = [cv2.initUndistortRectifyMap(c.K, c.dist, Ri, Pi, size, cv2.CV_32FC1)
                      for c, Ri, Pi in ((left, R1, P1), (right, R2, P2))]
        # where each original left pixel lands in the rectified left image
        w, h = size
        uv = np.stack(np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32)), -1)
        rect = cv2.undistortPoints(uv.reshape(-1, 1, 2), left.K, left.dist, R=R1, P=P1).reshape(h, w, 2)
        self._back = (rect[..., 0].astype(np.float32), rect[..., 1].astype(np.float32))
        self._sgbm = matching.matcher(w)
        self._pad = int(self._sgbm.getNumDisparities())
        self.size = size

    def rectify(self, left_bgr: np.ndarray, right_bgr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return tuple(cv2.remap(img, mx, my, cv2.INTER_LINEAR)
                     for img, (mx, my) in zip((left_bgr, right_bgr), self._maps))

    def depth(self, left_bgr: np.ndarray, right_bgr: np.ndarray) -> np.ndarray:
        """``(H, W) float32`` mm along the left camera's axis on the left image's grid, NaN = unmatched."""
        for name, img in (("left", left_bgr), ("right", right_bgr)):
            if img.shape[1::-1] != self.size:
                raise ValueError(f"stereo {name} image is {img.shape[1]}x{img.shape[0]}, "
                                 f"calibrated for {self.size[0]}x{self.size[1]}")
        rl, rr = self.rectify(left_bgr, right_bgr)
        gl = cv2.cvtColor(rl, cv2.COLOR_BGR2GRAY) if rl.ndim == 3 else rl
        gr = cv2.cvtColor(rr, cv2.COLOR_BGR2GRAY) if rr.ndim == 3 else rr
        # pad on the left by the disparity range, so SGBM's blind band (the first numDisparities
        # columns) falls on the padding and only pixels the right camera cannot see stay unmatched
        pad = self._pad
        gl = cv2.copyMakeBorder(gl, 0, 0, pad, 0, cv2.BORDER_REPLICATE)
        gr = cv2.copyMakeBorder(gr, 0, 0, pad, 0, cv2.BORDER_REPLICATE)
        disp = self._sgbm.compute(gl, gr)[:, pad:].astype(np.float32) / 16.0  # fixed point, 4 fractional bits
        pts = cv2.reprojectImageTo3D(disp, self.Q, handleMissingValues=False)
        invalid = disp <= 0
        pts[invalid] = np.nan
        # rectified left -> original left grid (nearest), then undo the rectifying rotation
        back = cv2.remap(pts, *self._back, cv2.INTER_NEAREST, borderMode=cv2.BORDER_CONSTANT, borderValue=np.nan)
        z = back.reshape(-1, 3) @ self.R1[:, 2]  # z_left = (R1^T X_rect)_z = R1[:, 2] . X_rect
        z = z.reshape(back.shape[:2]).astype(np.float32)
        z[~np.isfinite(z) | (z <= 0)] = np.nan
        return z
