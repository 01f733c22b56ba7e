"""Limits: oversized inputs are refused quickly with a sentence naming the limit and its variable."""

import numpy as np
import pytest

from partlab import cli
from partlab.labelling.video import VideoError, probe, write_video
from partlab.tracking.tracks import TracksCSVError, read_tracks_csv

HEADER = "frame,track_id,part,x,y,w,h\n"


def test_a_frame_over_the_pixel_limit_is_refused_before_decoding(tmp_path, monkeypatch):
    clip = write_video(tmp_path / "c.mp4", [np.zeros((48, 64, 3), np.uint8)] * 3, fps=25)
    assert probe(clip).width == 64
    monkeypatch.setenv("PARTLAB_MAX_FRAME_PIXELS", "1000")
    with pytest.raises(VideoError, match="64x48 are larger than the limit of 1000 pixels .*PARTLAB_MAX_FRAME_PIXELS"):
        probe(clip)


def test_a_clip_over_the_frame_limit_is_refused(tmp_path, monkeypatch):
    clip = write_video(tmp_path / "c.mp4", [np.zeros((48, 64, 3), np.uint8)] * 6, fps=25)
    monkeypatch.setenv("PARTLAB_MAX_FRAMES", "4")
    with pytest.raises(VideoError, match="more than the limit of 4 frames"):
        probe(clip)


@pytest.mark.parametrize("row,message", [
    ("0,1,head,1e308,2,3,4", "beyond the limit of 1e\\+06"),
    ("0,9223372036854775808,head,1,2,3,4", "larger than the limit of 2147483647"),
    ("0,1,head,1,2,3,4,nan", "column 'occluded': 'nan' is not a fraction"),
])
def test_numbers_a_later_step_cannot_use_are_refused(tmp_path, row, message):
    path = tmp_path / "t.csv"
    path.write_text(HEADER.strip() + (",occluded" if row.count(",") == 7 else "") + "\n" + row + "\n")
    with pytest.raises(TracksCSVError, match=message):
        read_tracks_csv(path)


def test_rows_over_the_limit_stop_the_reader(tmp_path, monkeypatch):
    monkeypatch.setenv("PARTLAB_MAX_CSV_ROWS", "3")
    path = tmp_path / "t.csv"
    path.write_text(HEADER + "".join(f"{i},1,head,1,2,3,4\n" for i in range(5)))
    with pytest.raises(TracksCSVError, match="more than the limit of 3 rows"):
        read_tracks_csv(path)


def test_a_negative_seed_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["track", "x.mp4", "-o", "t.csv", "--seed", "-1"])
    assert exit_.value.code == 2 and "-1 is outside 0..4294967295" in capsys.readouterr().err
