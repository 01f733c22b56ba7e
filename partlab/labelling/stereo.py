"""Depth from a calibrated stereo pair, aligned to the left (colour) image.

Xu, Deng & Jia (sec. 2) build their depth from two calibrated webcams and block matching. partlab
does the same with OpenCV: the pair is rectified (:func:`cv2.stereoRectify`,
:func:`cv2.initUndistortRectifyMap`), matched by semi-global block matching
(:class:`cv2.StereoSGBM`), the disparities are turned into 3D points with
:func:`cv2.reprojectImageTo3D` and ``Q``, and every pixel of the *original* left image reads the
point its rectified position sees (nearest neighbour, so no depth is blended across an edge),
rotated back into the left camera: the depth is millimetres along the left camera's axis, on the
left image's grid, so it lines up with the colour the trackers see.

Rectification keeps every pixel of the original images (``alpha = 1``, edges replicated), so every
left pixel has a rectified position to read. A match counts only if it passes the left-right check
(the pair matched again with the right image as the reference must land back on it). What stays
unmeasured is NaN: mostly the band along the left image's left edge that the right camera does not
see (as wide as the disparity: ~30 px for a hand at 1 m at 320x240), and pixels with no valid
match at all along their row. Holes
*between* two matched pixels of a row are occlusions (background the left camera sees past an
object's edge that the right camera's view of that object hides) or textureless patches; they take
the farther of the two matched ends (:func:`fill_occlusions`), the usual rule for an occluded pixel
(it lies behind the object that hides it in the other view). Without it such holes on a skin-hued
wall next to an arm read as "unmeasured", and a tracker that lets colour decide where depth is
missing followed the hands onto them.
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
    # OpenCV's 3-way SGBM (8 paths folded into 3 passes): faster than the 5-path default and, on the
    # synthetic desk scenes, a third of its depth error on the oblique desk top (7 vs 26 mm median)
    three_way: bool = True
    # left-right consistency: match the pair again with the right image as the reference (the
    # mirrored pair) and keep a left match only if the right pixel it lands on matches back within
    # this many pixels (< 0: no check). Without it, pixels the right camera cannot see (the band
    # along the left edge) get a wrong, farther match instead of none (45-55 % of them off by over
    # 100 mm on synthetic scenes): a hand there read as background and vanished
    left_right: float = 1.0
    # fill row holes between two matches with the farther one (see the module docstring)
    fill_occlusions: bool = True

    def matcher(self, width: int) -> cv2.StereoSGBM:
        nd = self.num_disparities or 16 * int(np.ceil(width / 5 / 16))
        b = self.block_size
        mode = cv2.STEREO_SGBM_MODE_SGBM_3WAY if self.three_way else cv2.STEREO_SGBM_MODE_SGBM
        return cv2.StereoSGBM_create(minDisparity=0, numDisparities=nd, blockSize=b, P1=8 * b * b,
                                     P2=32 * b * b, uniquenessRatio=self.uniqueness,
                                     speckleWindowSize=self.speckle_window, speckleRange=self.speckle_range,
                                     mode=mode)


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
                                                     flags=cv2.CALIB_ZERO_DISPARITY, alpha=1)
        self.R1, self.Q = R1, Q
        self._maps = [cv2.initUndistortRectifyMap(c.K, c.dist, Ri, Pi, size, cv2.CV_32FC1)
                      for c, Ri, Pi in ((left, R1, P1), (right, R2, P2))]
        # where each original left pixel lands in the rectified left image
        w, h = size
        uv = np.stack(np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32)), -1)
        rect = cv2.undistortPoints(uv.reshape(-1, 1, 2), left.K, left.dist, R=R1, P=P1).reshape(h, w, 2)
        self._back = (rect[..., 0].astype(np.float32), rect[..., 1].astype(np.float32))
        self._sgbm = matching.matcher(w)
        self._fill = matching.fill_occlusions
        self._lr = matching.left_right
        self._pad = int(self._sgbm.getNumDisparities())
        self.size = size

    def rectify(self, left_bgr: np.ndarray, right_bgr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return tuple(cv2.remap(img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
                     for img, (mx, my) in zip((left_bgr, right_bgr), self._maps))

    def _consistent(self, disp: np.ndarray, gl: np.ndarray, gr: np.ndarray) -> np.ndarray:
        """``disp`` with the matches that fail the left-right check set to -1 (unmatched): the
        right view's disparities come from the mirrored pair (right image as the reference)."""
        pad = self._pad
        fr = cv2.copyMakeBorder(cv2.flip(gr, 1), 0, 0, pad, 0, cv2.BORDER_REPLICATE)
        fl = cv2.copyMakeBorder(cv2.flip(gl, 1), 0, 0, pad, 0, cv2.BORDER_REPLICATE)
        right = cv2.flip(self._sgbm.compute(fr, fl)[:, pad:], 1).astype(np.float32) / 16.0
        h, w = disp.shape
        xr = np.arange(w)[None, :] - np.round(disp).astype(int)  # where each left match lands
        inside = (xr >= 0) & (disp > 0)
        back = right[np.arange(h)[:, None], np.clip(xr, 0, w - 1)]
        ok = inside & (back > 0) & (np.abs(back - disp) <= self._lr)
        return np.where(ok, disp, -1.0).astype(np.float32)

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
        if self._lr >= 0:
            disp = self._consistent(disp, gl[:, pad:], gr[:, pad:])
        if self._fill:
            disp = fill_occlusions(disp)
        pts = cv2.reprojectImageTo3D(disp, self.Q, handleMissingValues=False)
        invalid = disp <= 0
        pts[invalid] = np.nan
        # rectified left -> original left grid (nearest), then undo the rectifying rotation
        back = cv2.remap(pts, *self._back, cv2.INTER_NEAREST, borderMode=cv2.BORDER_CONSTANT, borderValue=np.nan)
        z = back.reshape(-1, 3) @ self.R1[:, 2]  # z_left = (R1^T X_rect)_z = R1[:, 2] . X_rect
        z = z.reshape(back.shape[:2]).astype(np.float32)
        z[~np.isfinite(z) | (z <= 0)] = np.nan
        return z


def fill_occlusions(disp: np.ndarray) -> np.ndarray:
    """``(H, W)`` disparities (``<= 0`` = unmatched) with every run of unmatched pixels that has a
    match at *both* ends of its row set to the smaller (farther) of the two; runs that reach the
    image's edge stay unmatched (nothing on one side says what is there)."""
    h, w = disp.shape
    valid = disp > 0
    cols = np.arange(w)[None, :]
    left = np.maximum.accumulate(np.where(valid, cols, -1), axis=1)  # last match at or before x
    right = np.minimum.accumulate(np.where(valid, cols, w)[:, ::-1], axis=1)[:, ::-1]  # first at or after
    inside = (left >= 0) & (right < w)
    rows = np.arange(h)[:, None]
    far = np.minimum(disp[rows, np.clip(left, 0, w - 1)], disp[rows, np.clip(right, 0, w - 1)])
    return np.where(valid, disp, np.where(inside, far, -1.0)).astype(disp.dtype)
