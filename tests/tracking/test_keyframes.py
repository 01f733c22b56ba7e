"""Keyframe-guided tracking (partlab.tracking.keyframes): blending, exact keyframes, the CLI."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from partlab.cli import main
from partlab.errors import UserError
from partlab.labelling.evaluation import count_edits, interpolate_keyframes
from partlab.labelling.video import write_video
from partlab.tracking.frame import MemoryTake
from partlab.tracking.keyframes import (
    blend_runs,
    stretch_proposer,
    stretch_region,
    track_between,
    track_stretch,
    track_with_keyframes,
)
from partlab.tracking.tracks import read_tracks_csv, write_tracks_csv
from tests.tracking.walkers import background, draw_walker


def _run(frames, xs, score=1.0, failure=False):
    return pd.DataFrame({"frame": frames, "x": xs, "y": 0.0, "w": 10.0, "h": 20.0, "score": score,
                         "failure": failure, "occluded": 0.0}).set_index("frame")


def test_blend_meets_keyframes_and_leans_on_the_surer_run():
    key_a = pd.Series({"x": 0.0, "y": 0.0, "w": 10.0, "h": 20.0})
    key_b = pd.Series({"x": 20.0, "y": 0.0, "w": 10.0, "h": 20.0})
    frames = np.arange(0, 11)
    fwd = _run(frames, 2.0 * frames, score=0.9)
    bwd = _run(frames, 2.0 * frames + 1.0, score=0.1)  # a less sure run one pixel off
    out = blend_runs(fwd, bwd, key_a, key_b, 0, 10).set_index("frame")
    assert out.loc[0, "x"] == 0.0 and out.loc[10, "x"] == 20.0
    assert list(out.loc[[0, 10], "state"]) == ["keyframe", "keyframe"]
    # frame 5: weights 0.5*0.9 and 0.5*0.1 -> x = 10 + 0.1
    assert out.loc[5, "x"] == pytest.approx(10.1)
    assert not out["failure"].any()


def test_blend_flags_disagreement_and_falls_back_to_the_line_when_one_run_is_lost():
    key_a = pd.Series({"x": 0.0, "y": 0.0, "w": 10.0, "h": 20.0})
    key_b = pd.Series({"x": 20.0, "y": 0.0, "w": 10.0, "h": 20.0})
    frames = np.arange(0, 11)
    fwd = _run(frames, 2.0 * frames)
    xs = 2.0 * frames
    xs[4] += 4.0   # IoU 6/14 = 0.43: disagree, blended, flagged
    xs[6] += 30.0  # far off: one of them is lost -> the straight line
    bwd = _run(frames, xs, failure=frames == 8)
    out = blend_runs(fwd, bwd, key_a, key_b, 0, 10).set_index("frame")
    assert out.loc[4, "state"] == "review" and out.loc[4, "failure"]
    assert out.loc[6, "state"] == "interpolated" and out.loc[6, "x"] == pytest.approx(12.0)
    assert out.loc[8, "failure"] and out.loc[8, "state"] == "review"  # the failure detector fired
    assert out["failure"].sum() == 3
    fwd2 = fwd.drop(index=[3])
    bwd2 = bwd.drop(index=[3, 7])
    out2 = blend_runs(fwd2, bwd2, key_a, key_b, 0, 10).set_index("frame")
    assert out2.loc[3, "state"] == "interpolated" and out2.loc[3, "x"] == pytest.approx(6.0)
    assert out2.loc[7, "x"] == pytest.approx(14.0)  # only the forward run: used as it is


@pytest.fixture(scope="module")
def walk():
    """A walker that speeds up: linear interpolation between keyframes 0 and 30 lags behind."""
    rng = np.random.default_rng(1)
    bg = background(rng, 360, 200)
    frames, rows = [], []
    x = 50.0
    for t in range(31):
        f = bg.copy()
        b = draw_walker(f, x, 50, 110, (40, 40, 160), (120, 60, 30), phase=t / 3)["person"]
        rows.append(dict(frame=t, track_id=3, part="person", x=b.x, y=b.y, w=b.w, h=b.h))
        frames.append(f)
        x += 2.0 if t < 15 else 12.0
    return frames, pd.DataFrame(rows)


def test_track_between_meets_both_keyframes_and_beats_the_straight_line(walk):
    frames, truth = walk
    keys = truth[truth.frame.isin([0, 30])]
    out = track_between(MemoryTake(frames), keys, 3, seed=0)
    assert out["frame"].tolist() == list(range(31)) and set(out["part"]) == {"person"}
    for f in (0, 30):
        got = out[out.frame == f][["x", "y", "w", "h"]].to_numpy(float)
        assert np.allclose(got, keys[keys.frame == f][["x", "y", "w", "h"]].to_numpy(float))
    ours = count_edits(truth, out, keyframes=2)
    line = count_edits(truth, interpolate_keyframes(keys), keyframes=2)
    assert ours.edits < line.edits and ours.edits <= 2 + 3
    with pytest.raises(UserError, match="not two keyframes"):
        track_between(MemoryTake(frames), keys, 3, 0, 12)


def test_keyframes_command_writes_every_frame_between_keyframes(walk, tmp_path, capsys):
    frames, truth = walk
    video = write_video(tmp_path / "walk.avi", frames, 25)
    keys = truth[truth.frame.isin([0, 15, 30])]
    write_tracks_csv(keys, tmp_path / "keys.csv")
    out = tmp_path / "tracks.csv"
    assert main(["track", str(video), "-o", str(out), "--keyframes", str(tmp_path / "keys.csv"),
                 "--no-progress"]) == 0
    tracks = read_tracks_csv(out)
    person = tracks[tracks.part == "person"]
    assert person["frame"].tolist() == list(range(31))  # the shared keyframe 15 once
    assert (person[person.frame.isin([0, 15, 30])]["state"] == "keyframe").all()
    again = track_with_keyframes(MemoryTake(frames), keys, seed=0).tracks
    assert len(again) == len(tracks)
    assert main(["track", str(video), "-o", str(out), "--keyframes", str(tmp_path / "keys.csv"),
                 "--init", str(tmp_path / "keys.csv")]) == 2
    assert "--keyframes and --init" in capsys.readouterr().err


def test_track_stretch_tracks_inside_the_tracks_region_and_answers_in_frame_coordinates(walk):
    frames, truth = walk
    # the walker's strip placed at (200, 150) of a larger frame; the rest is a second, untouched scene
    big = [np.concatenate([np.zeros((150, 360, 3), np.uint8), f, np.full((100, 360, 3), 90, np.uint8)]) for f in frames]
    big = [np.concatenate([np.full((450, 200, 3), 60, np.uint8), f, np.zeros((450, 120, 3), np.uint8)], axis=1)
           for f in big]
    moved = truth.assign(x=truth.x + 200, y=truth.y + 150)
    keys = moved[moved.frame.isin([0, 30])]
    x0, y0, x1, y1 = stretch_region(keys, 680, 450)
    assert (x1 - x0) * (y1 - y0) < 0.5 * 680 * 450  # a crop, not the frame
    assert x0 <= keys.x.min() and x1 >= (keys.x + keys.w).max() and y0 <= keys.y.min()
    out = track_stretch(big, keys, 3, 0, 30, parts=["person"])
    assert out["frame"].tolist() == list(range(31))
    for f in (0, 30):
        got = out[out.frame == f][["x", "y", "w", "h"]].to_numpy(float)
        assert np.allclose(got, keys[keys.frame == f][["x", "y", "w", "h"]].to_numpy(float))
    ours = count_edits(moved, out, keyframes=2)
    line = count_edits(moved, interpolate_keyframes(keys), keyframes=2)
    assert ours.edits < line.edits


def test_stretch_proposer_reads_only_the_stretch_and_draws_a_line_for_parts_it_cannot_track(walk):
    frames, truth = walk
    read = []
    propose = stretch_proposer(lambda i: read.append(i) or frames[i])
    hand = truth.assign(part="left_hand", w=6.0, h=6.0)
    keys = pd.concat([truth, hand])
    keys = keys[keys.frame.isin([5, 25])]
    line = propose(keys, 3, "left_hand", 5, 25)
    assert read == [] and line["frame"].tolist() == list(range(6, 25)) and set(line["state"]) == {"interpolated"}
    a, b = hand.set_index("frame").loc[5], hand.set_index("frame").loc[25]
    assert line.set_index("frame").loc[15, "x"] == pytest.approx((a.x + b.x) / 2)
    person = propose(keys, 3, "person", 5, 25)
    assert read == list(range(5, 26)) and person["frame"].tolist() == list(range(6, 25))
    assert set(person["part"]) == {"person"} and set(person["state"]) <= {"tracked", "review", "interpolated"}
