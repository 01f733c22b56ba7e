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


def test_while_the_camera_pans_only_what_moves_in_the_scene_is_in_the_moving_mask():
    scene = _scene(3, size=(300, 800))
    cm = CameraMotion(MotionSettings(residual=10.0))
    assert cm.moving_mask() is None  # no frame yet
    for i in range(6):  # the camera pans right 3 px a frame; a dark square walks right 5 px a frame
        frame = _crop(scene, 40 + 3 * i, 30)
        mover = (60 + 2 * i, 80)           # in the image: 5 - 3 px a frame
        still = (250 - 3 * i, 60)           # fixed in the scene: carried along by the pan
        cv2.rectangle(frame, mover, (mover[0] + 30, mover[1] + 70), (30, 30, 30), -1)
        cv2.rectangle(frame, still, (still[0] + 30, still[1] + 70), (30, 30, 30), -1)
        cm.update(frame)
    mask = cm.moving_mask() > 0
    on_mover = mask[mover[1]:mover[1] + 70, mover[0]:mover[0] + 30].mean()
    on_still = mask[still[1]:still[1] + 70, still[0]:still[0] + 30].mean()
    rest = mask.copy()
    rest[mover[1] - 10:mover[1] + 80, mover[0] - 10:mover[0] + 40] = False
    assert on_mover > 0.15 and on_still < 0.02 and rest.mean() < 0.01
    assert CameraMotion().moving_mask() is None  # residual 0: off


def _panning_scene(n: int = 120, seed: int = 0):
    """The camera pans right 3 px a frame after a walker (nearly still in the image). A sign and,
    ahead of it, a still figure of the walker's colours are fixed in the scene: the figure passes
    behind the walker, then the sign hides the walker (frames ~55-70), who shows again on the sign's
    other side while the figure is carried away (OTB Human3's litter bin)."""
    from tests.tracking.walkers import draw_walker

    W, H = 320, 200
    rng = np.random.default_rng(seed)
    small = rng.integers(60, 180, (H // 8 + 1, (W + 3 * n) // 8 + 1, 3), dtype=np.uint8)
    world = cv2.GaussianBlur(cv2.resize(small, (small.shape[1] * 8, small.shape[0] * 8)), (0, 0), 2)
    shirt, trousers = (40, 40, 160), (120, 60, 30)
    frames, truths = [], []
    for t in range(n):
        f = world[:H, 3 * t:3 * t + W].copy()
        sign = 330 - 3 * t
        draw_walker(f, sign - 44, 50, 110, shirt, trousers)
        truths.append(draw_walker(f, 120 + 0.4 * t, 50, 110, shirt, trousers, phase=t / 3))
        cv2.rectangle(f, (sign - 16, 40), (sign + 16, 170), (235, 235, 235), -1)
        frames.append(np.clip(f.astype(np.int16) + rng.integers(-6, 7, f.shape), 0, 255).astype(np.uint8))
    return frames, truths


def _torso_right_after_the_sign(params: BodyParams, frames, truths, seed: int) -> float:
    import pandas as pd

    from partlab.tracking.core.background import BackgroundModel
    from partlab.tracking.core.box import Box
    from partlab.tracking.measures import right_box_one
    from partlab.tracking.tracks import records_to_frame

    b = truths[0]["person"]
    init = pd.DataFrame([dict(frame=0, track_id=1, part="person", x=b.x, y=b.y, w=b.w, h=b.h)])
    tracker = BodyTracker(params, np.random.default_rng(seed), init=init)
    model, records = BackgroundModel(params), []
    for i, f in enumerate(frames):
        records.extend(tracker.step(i, f, model.apply(f)))
    rows = records_to_frame(tracker.finish(records))
    torso = rows[rows.part == "torso"].set_index("frame")
    right = [f in torso.index and right_box_one(Box(*torso.loc[f, ["x", "y", "w", "h"]]), truths[f]["torso"])
             for f in range(85, len(frames))]
    return float(np.mean(right))


def test_a_track_a_still_figure_took_while_the_camera_panned_comes_back_to_the_walker():
    """``background.camera_residual`` and ``camera_rewind``: the track goes onto the still figure
    while the sign hides the walker; the figure does not move in the scene, so the track loses its
    support, coasts from where it had it and is found again on the walker. Without the scene's
    motion as support it rides the figure out of the frame."""
    frames, truths = _panning_scene()
    for seed in (0, 1, 2):
        assert _torso_right_after_the_sign(BodyParams(), frames, truths, seed) >= 0.9
    blind = BodyParams().updated({"background.camera_residual": 0.0})
    assert _torso_right_after_the_sign(blind, frames, truths, 0) < 0.3


def test_while_the_camera_pans_people_are_looked_for_where_the_scene_moves():
    """Found automatically, a panning camera gave nobody: the detector scanned only the foreground
    mask's regions, which a moving camera does not have. Now it scans the regions where the scene
    moves (``moving_mask``): here the walker's."""
    frames, truths = _panning_scene(n=40)
    tracker = BodyTracker(BodyParams(), np.random.default_rng(0))
    scanned = []
    detect = tracker.cue.detector.detect

    def recording(frame, regions):
        scanned.append((len(scanned), list(regions)))
        return detect(frame, regions)

    tracker.cue.detector.detect = recording
    from partlab.tracking.core.background import BackgroundModel

    model = BackgroundModel(tracker.params)
    seen = []
    for i, f in enumerate(frames):
        n = len(scanned)
        tracker.step(i, f, model.apply(f))
        if len(scanned) > n and i >= 3:
            walker = truths[i]["person"]
            seen.append(any(r.intersection(walker) >= 0.5 * walker.area for r in scanned[-1][1]))
    assert tracker.camera.moving and len(seen) >= 10
    assert np.mean(seen) >= 0.8


def test_while_the_camera_pans_a_measurement_that_leaves_the_walker_for_still_ground_is_undone():
    """``background.camera_keep_motion``: the camera pans after a walker (nearly still in the image,
    walking in the scene); a colour measurement that slid the track 40 px off him onto still
    background (OTB Human3 frame 99: towards a crosser, across the ground between them) leaves
    less of its box moving in the scene than his own scene motion would: it is undone, the parts
    coast from where they were and stay on him. A measurement on him is kept; off, nothing is undone."""
    import pandas as pd

    from partlab.tracking.core.background import BackgroundModel
    from partlab.tracking.measures import right_box_one

    frames, truths = _panning_scene(n=30)  # the still figure and the sign come in from the right, ahead
    b = truths[0]["person"]
    init = pd.DataFrame([dict(frame=0, track_id=1, part="person", x=b.x, y=b.y, w=b.w, h=b.h)])
    for margin, undone in ((0.2, True), (0.0, False)):
        tracker = BodyTracker(BodyParams().updated({"background.camera_keep_motion": margin}),
                              np.random.default_rng(0), init=init)
        model = BackgroundModel(tracker.params)
        for i, f in enumerate(frames):
            tracker.step(i, f, model.apply(f))
        person = tracker.people[1]
        assert tracker.camera.moving and right_box_one(person.box(), truths[-1]["person"])
        v = tracker.scene_velocity(person.centres)
        assert v is not None and 2.5 < v[0] < 4.5  # he walks right in the scene; the pan carries the image left
        person.prev = {n: f.state.copy() for n, f in person.filters.items()}
        assert not tracker._keeps_scene_motion(person)  # measured on him: kept
        for f in person.filters.values():
            f.shift(np.array([40.0, 0.0]))  # slid off him onto the still background
        assert tracker._keeps_scene_motion(person) is undone
        moved_back = person.filters["torso"].state[0] - person.prev["torso"][0]
        if undone:
            assert abs(moved_back) < 3  # coasted on from where it was: his image motion ~0.4 px a frame
            assert right_box_one(person.box(), truths[-1]["person"])
        else:
            assert moved_back == 40.0
            assert not right_box_one(person.box(), truths[-1]["person"])
