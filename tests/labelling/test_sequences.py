"""Image sequences as clips: a folder of frames, a zip of them, a %06d pattern (MOT, OTB, CVAT tasks)."""

from __future__ import annotations

import zipfile
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

from partlab.cli import main
from partlab.labelling.take import open_take
from partlab.labelling.video import VideoClip, VideoError, probe
from partlab.tracking.tracks import read_tracks_csv, write_tracks_csv
from tests.tracking.walkers import background, draw_walker

ROOT = Path(__file__).resolve().parents[2]
#: ../shared/data beside the repository (or beside a worktree's folder)
DATA = next((p / "shared" / "data" for p in (ROOT.parent, ROOT.parent.parent) if (p / "shared" / "data").is_dir()),
            ROOT.parent / "shared" / "data")


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    """24 frames of a walker as 1-based PNG files (OTB style), the same frames in a zip and as a
    lossless FFV1 video, and an init box."""
    rng = np.random.default_rng(1)
    d = tmp_path_factory.mktemp("seq")
    bg = background(rng, 320, 200)
    frames = []
    for t in range(24):
        f = bg.copy()
        truth = draw_walker(f, 60 + 3 * t, 50, 110, (40, 40, 160), (120, 60, 30), phase=t / 3)
        if t == 0:
            b = truth["person"]
        frames.append(f)
    (d / "img").mkdir()
    for t, f in enumerate(frames):
        cv2.imwrite(str(d / "img" / f"{t + 1:04d}.png"), f)
    with zipfile.ZipFile(d / "frames.zip", "w") as zf:
        for t in range(24):
            zf.write(d / "img" / f"{t + 1:04d}.png", f"seq/{t + 1:04d}.png")
    writer = cv2.VideoWriter(str(d / "walk.mkv"), cv2.VideoWriter_fourcc(*"FFV1"), 25.0, (320, 200))
    for f in frames:
        writer.write(f)
    writer.release()
    write_tracks_csv(pd.DataFrame([dict(frame=0, track_id=2, part="person", x=b.x, y=b.y, w=b.w, h=b.h)]),
                     d / "init.csv")
    return d, frames


def test_folder_zip_and_pattern_read_the_same_frames_in_number_order(walk):
    d, frames = walk
    for src in (d / "img", d / "frames.zip", d / "img" / "%04d.png", d / "walk.mkv"):
        info = probe(src)
        assert (info.frame_count, info.width, info.height, info.fps) == (24, 320, 200, 25.0), src
        with VideoClip(src) as clip:
            assert np.array_equal(clip.read(13), frames[13]), src  # 0014.png is frame 13
            got = [f for _, f in clip.frames(20)]
            assert len(got) == 4 and np.array_equal(got[-1], frames[23])
    with open_take(d / "frames.zip") as take:
        assert take.streams == ("cam0",) and take.frame_count == 24


def test_track_on_frames_gives_the_rows_of_the_lossless_video(walk, tmp_path):
    d, _ = walk
    rows = {}
    for name, src in (("folder", d / "img"), ("zip", d / "frames.zip"), ("video", d / "walk.mkv")):
        out = tmp_path / f"{name}.csv"
        assert main(["track", str(src), "-o", str(out), "--init", str(d / "init.csv"), "--no-progress",
                     "--seed", "5"]) == 0
        rows[name] = read_tracks_csv(out)
    assert len(rows["video"]) == 24 * 4 and set(rows["video"]["track_id"]) == {2}
    pd.testing.assert_frame_equal(rows["folder"], rows["video"])
    pd.testing.assert_frame_equal(rows["zip"], rows["video"])


def test_gaps_repeats_and_empty_folders_are_refused(tmp_path):
    img = np.zeros((8, 8, 3), np.uint8)
    (tmp_path / "gap").mkdir()
    for k in (1, 2, 4):
        cv2.imwrite(str(tmp_path / "gap" / f"{k:06d}.jpg"), img)
    with pytest.raises(VideoError, match="jump from number 2 to 4"):
        probe(tmp_path / "gap")
    (tmp_path / "rep").mkdir()
    for name in ("1.png", "001.png"):
        cv2.imwrite(str(tmp_path / "rep" / name), img)
    with pytest.raises(VideoError, match="two frames are numbered 1"):
        probe(tmp_path / "rep")
    (tmp_path / "empty").mkdir()
    with pytest.raises(VideoError, match="is a directory with no frames"):
        probe(tmp_path / "empty")
    with pytest.raises(VideoError, match="no frames"):
        probe(tmp_path / "empty" / "%06d.jpg")


def test_mot_seqinfo_gives_the_fps(tmp_path):
    (tmp_path / "img1").mkdir()
    for k in (1, 2):
        cv2.imwrite(str(tmp_path / "img1" / f"{k:06d}.jpg"), np.zeros((8, 8, 3), np.uint8))
    (tmp_path / "seqinfo.ini").write_text("[Sequence]\nframeRate=14\n")
    assert probe(tmp_path / "img1").fps == 14.0


@pytest.mark.parametrize("name, frames", [("otb_couple_jwlim", 140), ("otb_crossing_eco", 120),
                                          ("otb_human3_strcf", 199), ("otb_football1_jwlim", 81)])
def test_the_otb_jpeg_folders_open_as_clips(name, frames):
    folder = DATA / name / "img"
    if not folder.is_dir():
        pytest.skip(f"{folder}: the shared data is not on this machine")
    info = probe(folder)
    assert info.frame_count == frames and info.fps == 25.0
    with open_take(folder) as take:
        first = next(take.frames())
        assert first.views["cam0"].color.shape == (info.height, info.width, 3)
