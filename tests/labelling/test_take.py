"""Takes: a video is a one-stream take; folders of several streams, calibration and depth."""

import json

import cv2
import numpy as np
import pytest

from partlab.labelling.calibration import write_calibration
from partlab.labelling.take import TakeError, open_take
from partlab.labelling.video import VideoClip, write_video
from partlab.tracking.camera import Camera


def _frames(n, w=64, h=48, shift=0):
    return [np.full((h, w, 3), (10 * i + shift) % 250, np.uint8) for i in range(n)]


def _camera(name, x):
    return Camera(name, K=[[100, 0, 32], [0, 100, 24], [0, 0, 1]], size=(64, 48), t=[x, 0, 0])


def test_a_video_is_a_take_of_one_stream(tmp_path):
    clip = write_video(tmp_path / "c.mp4", _frames(6), fps=12)
    with open_take(clip) as take, VideoClip(clip) as video:
        assert take.streams == ("cam0",) and take.frame_count == 6 and take.fps == pytest.approx(12)
        sets = list(take.frames(2, 5))
        assert [s.index for s in sets] == [2, 3, 4]
        assert np.array_equal(sets[0].first.color, video.read(2))
        assert sets[0].first.camera is None and sets[0].first.depth is None


def test_folder_with_streams_calibration_and_depth(tmp_path):
    for k, name in enumerate(("left", "right")):
        write_video(tmp_path / f"{name}.mp4", _frames(4, shift=k), fps=25)
    depth = tmp_path / "left_depth"
    depth.mkdir()
    for i in range(4):
        d = np.full((48, 64), 1500 + i, np.uint16)
        d[0, 0] = 0  # unmeasured
        cv2.imwrite(str(depth / f"{i:06d}.png"), d)
    write_calibration([_camera("left", 0.0), _camera("right", -100.0)], tmp_path / "calibration.json")
    with open_take(tmp_path) as take:
        assert take.streams == ("left", "right") and take.has_depth
        assert take.cameras["right"].centre == pytest.approx([100.0, 0, 0])
        fs = next(iter(take.frames(3)))
        left = fs.views["left"]
        assert np.isnan(left.depth[0, 0]) and left.depth[5, 5] == pytest.approx(1503.0)
        assert fs.views["right"].depth is None and fs.views["right"].camera.name == "right"


def test_take_json_names_streams_and_mismatches_are_refused(tmp_path):
    write_video(tmp_path / "a.mp4", _frames(5), fps=25)
    write_video(tmp_path / "b.mp4", _frames(4), fps=25)
    (tmp_path / "take.json").write_text(json.dumps({"streams": [{"name": "top", "color": "a.mp4"},
                                                                {"name": "side", "color": "b.mp4"}]}))
    with pytest.raises(TakeError, match="differ in frame count .*top 5, side 4"):
        open_take(tmp_path)
    (tmp_path / "take.json").write_text(json.dumps({"streams": [{"name": "top"}]}))
    with pytest.raises(TakeError, match=r"streams\[0\] has neither 'color' nor 'depth'"):
        open_take(tmp_path)


def test_depth_of_the_wrong_kind_is_refused(tmp_path):
    write_video(tmp_path / "clip.mp4", _frames(3), fps=25)
    bad = tmp_path / "clip_depth"
    bad.mkdir()
    for i in range(3):
        cv2.imwrite(str(bad / f"{i:06d}.png"), np.full((48, 64), 200, np.uint8))  # 8-bit
    with pytest.raises(TakeError, match="16-bit"):
        open_take(tmp_path)
    for f in bad.iterdir():
        f.unlink()
    bad.rmdir()
    np.save(tmp_path / "clip_depth.npy", np.full((2, 48, 64), 1000, np.uint16))
    with pytest.raises(TakeError, match="3 colour frames but 2 depth frames"):
        open_take(tmp_path)


# -- depth input: stereo pairs and bad depth ---------------------------------------------------

def _depth_pngs(folder, n, shape=(48, 64), value=1500, dtype=np.uint16, odd=None):
    folder.mkdir()
    for i in range(n):
        size = odd if (odd is not None and i == n - 1) else shape
        cv2.imwrite(str(folder / f"{i:06d}.png"), np.full(size, value, dtype))


def test_depth_of_the_wrong_size_is_refused_naming_the_stream(tmp_path):
    write_video(tmp_path / "clip.mp4", _frames(3), fps=25)
    _depth_pngs(tmp_path / "clip_depth", 3, shape=(24, 32))
    with pytest.raises(TakeError, match=r"stream 'cam0' depth is 32x24 but its colour is 64x48"):
        open_take(tmp_path)


def test_a_depth_frame_of_another_size_is_refused_when_read(tmp_path):
    write_video(tmp_path / "clip.mp4", _frames(3), fps=25)
    _depth_pngs(tmp_path / "clip_depth", 3, odd=(40, 64))
    with open_take(tmp_path) as take:
        with pytest.raises(TakeError, match=r"000002.png: depth frame is 64x40, the first was 64x48"):
            list(take.frames())


def test_8_bit_depth_stacks_are_refused(tmp_path):
    write_video(tmp_path / "clip.mp4", _frames(3), fps=25)
    np.save(tmp_path / "clip_depth.npy", np.full((3, 48, 64), 200, np.uint8))
    with pytest.raises(TakeError, match=r"clip_depth.npy: depth stack is 8-bit \(uint8\)"):
        open_take(tmp_path)


def test_npz_depth_in_mm_with_zero_missing(tmp_path):
    write_video(tmp_path / "clip.mp4", _frames(2), fps=25)
    d = np.full((2, 48, 64), 900.0, np.float32)
    d[1, 3, 4] = 0.0
    np.savez(tmp_path / "clip_depth.npz", depth=d)
    with open_take(tmp_path) as take:
        f = list(take.frames())[1].first
        assert np.isnan(f.depth[3, 4]) and f.depth[0, 0] == pytest.approx(900.0)


@pytest.fixture(scope="module")
def stereo_scene():
    from partlab.labelling.synth.depth_scene import make_depth_scene

    return make_depth_scene("desk_depth", seed=5, n_frames=3)


def _stereo_take(folder, scene, right_camera="cam0_right", cameras=None, right_frames=None):
    write_video(folder / "left.mp4", scene.frames, 25)
    write_video(folder / "right.mp4", scene.right[:right_frames], 25)
    write_calibration(cameras if cameras is not None else scene.cameras, folder / "calibration.json")
    (folder / "take.json").write_text(json.dumps({"streams": [
        {"name": "cam0", "stereo": {"left": "left.mp4", "right": "right.mp4", "right_camera": right_camera}}]}))


def test_a_stereo_pair_gives_depth_aligned_to_the_left_image(tmp_path, stereo_scene):
    _stereo_take(tmp_path, stereo_scene)
    with open_take(tmp_path) as take:
        assert take.has_depth and take.frame_count == 3
        f = list(take.frames(1, 2))[0].first
    truth = stereo_scene.depth[1]
    person = (stereo_scene.labels[1] > 0) & (stereo_scene.labels[1] != 9)
    err = np.abs(f.depth - truth)[person]
    assert f.depth.shape == truth.shape and f.color.shape[:2] == truth.shape
    assert np.isfinite(err).mean() > 0.9  # matched almost everywhere on the person
    assert np.nanmedian(err) < 40.0  # mm, at 1.1-1.6 m through the mp4 codec


def test_stereo_without_the_right_camera_or_with_uneven_videos_is_refused(tmp_path, stereo_scene):
    _stereo_take(tmp_path, stereo_scene, right_camera="cam9")
    with pytest.raises(TakeError, match="stereo depth needs both cameras calibrated; cam9 is not in calibration.json"):
        open_take(tmp_path)
    _stereo_take(tmp_path, stereo_scene, right_frames=2)
    with pytest.raises(TakeError, match=r"stereo pair differs in frame count \(left.mp4 3, right.mp4 2\)"):
        open_take(tmp_path)
    (tmp_path / "take.json").write_text(json.dumps({"streams": [{"name": "cam0", "stereo": {"left": "left.mp4"}}]}))
    with pytest.raises(TakeError, match=r"streams\[0\].stereo must be an object with 'left' and 'right'"):
        open_take(tmp_path)
