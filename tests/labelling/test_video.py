import numpy as np
import pytest

from partlab.labelling.video import VideoError, open_video, probe, store_by_hash, write_video


def _clip(path, n=12, w=64, h=48):
    frames = []
    for i in range(n):
        f = np.zeros((h, w, 3), np.uint8)
        f[:, : (i + 1) * 4] = 200  # a bar whose width encodes the frame index
        frames.append(f)
    return write_video(path, frames, fps=10)


def _bar_width(frame):
    return int((frame[:, :, 0].mean(axis=0) > 100).sum())


def test_probe_and_seek(tmp_path):
    path = _clip(tmp_path / "c.mp4")
    info = probe(path)
    assert (info.width, info.height, info.frame_count) == (64, 48, 12)
    assert info.fps == pytest.approx(10)
    clip = open_video(path)
    assert abs(_bar_width(clip.read(7)) - 32) <= 2
    assert abs(_bar_width(clip.read(2)) - 12) <= 2  # backwards seek
    idx = [i for i, _ in clip.frames(start=9)]
    assert idx == [9, 10, 11]


@pytest.mark.parametrize("content,message", [(b"", "empty"), (b"this is not a video" * 50, "not a video")])
def test_bad_files(tmp_path, content, message):
    p = tmp_path / "bad.mp4"
    p.write_bytes(content)
    with pytest.raises(VideoError, match=message):
        probe(p)
    with pytest.raises(VideoError, match="no such file"):
        probe(tmp_path / "missing.mp4")


def test_store_by_hash_is_idempotent(tmp_path):
    path = _clip(tmp_path / "c.avi")
    a, h1 = store_by_hash(path, tmp_path / "clips")
    b, h2 = store_by_hash(path, tmp_path / "clips")
    assert a == b and h1 == h2 and a.name == f"{h1}.avi"
    assert len(list((tmp_path / "clips").iterdir())) == 1
