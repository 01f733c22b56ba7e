"""Camera motion from sparse optical flow: a pan is measured and held, walkers in a static scene
are not camera motion, and the body tracker stops trusting the mask while the camera moves."""

import cv2
import numpy as np

from partlab.tracking.body.tracker import BodyTracker
from partlab.tracking.core.camera_motion import CameraMotion, MotionSettings
from partlab.tracking.params import BodyParams


def _scene(seed: int = 0, size=(400, 600)) -> np.ndarray:
    """A textured background (blurred noise: every grid point has something to follow)."""
    rng = np.random.default_rng(seed)
    img = rng.integers(0, 256, (*size, 3), dtype=np.uint8)
    return cv2.GaussianBlur(img, (0, 0), 3)


def _crop(scene: np.ndarray, x: float, y: float, w: int = 320, h: int = 240) -> np.ndarray:
    m = np.float32([[1, 0, -x], [0, 1, -y]])
    return cv2.warpAffine(scene, m, (w, h), flags=cv2.INTER_LINEAR)


def test_a_pan_is_measured_in_full_frame_pixels_and_held_after_it_stops():
    scene = _scene()
    cm = CameraMotion(MotionSettings(hold=5))
    shifts = []
    for i in range(8):  # the camera pans right by 3 px a frame, up by 1: content moves left, down
        shifts.append(cm.update(_crop(scene, 40 + 3 * i, 40 - i)))
    assert np.allclose(shifts[0], 0)
    assert np.allclose(np.median(shifts[1:], axis=0), [-3, 1], atol=0.3)
    assert cm.moving
    for _ in range(4):  # the camera stops: still "moving" for hold frames, then not
        cm.update(_crop(scene, 61, 33))
    assert cm.moving
    cm.update(_crop(scene, 61, 33))
    cm.update(_crop(scene, 61, 33))
    assert not cm.moving


def test_people_walking_through_a_static_scene_are_not_camera_motion():
    scene = _crop(_scene(1), 0, 0)
    cm = CameraMotion()
    for i in range(10):  # two "walkers" (dark boxes) crossing a fifth of the frame each
        frame = scene.copy()
        cv2.rectangle(frame, (20 + 6 * i, 60), (60 + 6 * i, 180), (20, 20, 20), -1)
        cv2.rectangle(frame, (250 - 5 * i, 50), (290 - 5 * i, 170), (200, 40, 40), -1)
        shift = cm.update(frame)
        assert np.hypot(*shift) < 0.2
    assert not cm.moving


def test_the_body_tracker_ignores_the_mask_and_follows_the_pan_while_the_camera_moves():
    scene = _scene(2)
    tracker = BodyTracker(BodyParams().updated({"detector.enabled": False}), np.random.default_rng(0))
    full = np.full((240, 320), 255, np.uint8)  # a panning camera's mask: everything "moves"
    assert tracker._follow_camera(_crop(scene, 40, 40), full) is full  # first frame: no motion known
    assert tracker._follow_camera(_crop(scene, 44, 40), full) is None
    off = BodyTracker(BodyParams().updated({"detector.enabled": False, "background.camera_motion": 0.0}))
    assert off._follow_camera(_crop(scene, 48, 40), full) is full
