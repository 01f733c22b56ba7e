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
from partlab.tracking.keyframes import blend_runs, track_between, track_with_keyframes
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
