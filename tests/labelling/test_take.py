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
