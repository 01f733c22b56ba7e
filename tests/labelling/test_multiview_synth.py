"""Multi-camera synthetic takes: exact 3D truth seen through exact calibrations."""

import numpy as np

from partlab.labelling.calibration import read_calibration
from partlab.labelling.synth.multiview import SCENARIOS_3D, make_multiview_scene, render_take
from partlab.labelling.take import open_take
from partlab.tracking.tracks import read_tracks_csv


def test_3d_truth_projects_inside_every_views_boxes():
    for name in SCENARIOS_3D:
        s = make_multiview_scene(name, 2, seed=3, n_frames=4, width=320, height=240)
        cams = {c.name: c for c in s.cameras}
        assert set(s.truth["camera"]) == set(cams)
        assert len(s.truth3d) == 4 * 3 * (2 if name == "handshake" else 1)
        rows = s.truth.dropna(subset=["X"])
        rows = rows[rows["occluded"] < 0.5]
        assert len(rows) > 0
        for cam, g in rows.groupby("camera"):
            uv = cams[cam].project(g[["X", "Y", "Z"]].to_numpy())
            inside = ((uv[:, 0] >= g.x - 2) & (uv[:, 0] <= g.x + g.w + 2) & (uv[:, 1] >= g.y - 2)
                      & (uv[:, 1] <= g.y + g.h + 2))
            assert inside.mean() > 0.95, (name, cam)
        # a higher point has a smaller row in every camera (the paper's p_o assumption, sec. 6.4)
        head, hand = s.truth3d.iloc[0], s.truth3d.iloc[1]
        assert head.Z > hand.Z
        for c in s.cameras:
            assert c.project(head[["X", "Y", "Z"]].to_numpy(float))[0, 1] < c.project(
                hand[["X", "Y", "Z"]].to_numpy(float))[0, 1]


def test_scenes_differ_by_seed_and_repeat_by_seed():
    a = make_multiview_scene("standing", 2, seed=1, n_frames=2, width=160, height=120)
    b = make_multiview_scene("standing", 2, seed=1, n_frames=2, width=160, height=120)
    c = make_multiview_scene("standing", 2, seed=2, n_frames=2, width=160, height=120)
    assert np.array_equal(a.frames["cam0"], b.frames["cam0"])
    assert not np.allclose(a.cameras[0].centre, c.cameras[0].centre)
    assert a.appearances[0] != c.appearances[0]


def test_render_take_writes_a_take_the_trackers_can_open(tmp_path):
    out = render_take("handshake", tmp_path / "take", 2, seed=0, n_frames=3, width=160, height=120,
                      chessboard=False)
    take = open_take(out)
    assert take.streams == ("cam0", "cam1") and take.frame_count == 3
    cams = read_calibration(out / "calibration.json")
    assert all(take.cameras[n] is not None and np.allclose(take.cameras[n].P, cams[n].P) for n in cams)
    assert set(take.backgrounds) == {"cam0", "cam1"}
    truth = read_tracks_csv(out / "truth.csv")
    assert set(truth["camera"]) == {"cam0", "cam1"} and truth["X"].notna().any()
    init = read_tracks_csv(out / "init.csv")
    assert set(init["frame"]) == {0} and set(init["track_id"]) == {1, 2}


def test_limbs3d_runs_through_the_run_loop_and_refuses_one_view(tmp_path):
    import pytest

    from partlab.errors import UserError
    from partlab.tracking.run import track

    out = render_take("standing", tmp_path / "take", 2, seed=5, n_frames=3, width=320, height=240, chessboard=False)
    take = open_take(out)
    result = track(take, "limbs3d", init=read_tracks_csv(out / "init.csv"), seed=1)
    rows = result.tracks
    assert set(rows["camera"]) == {"cam0", "cam1"} and set(rows["frame"]) == {0, 1, 2}
    assert set(rows["part"]) == {"head", "left_hand", "right_hand"} and rows["X"].notna().all()
    again = track(open_take(out), "limbs3d", init=read_tracks_csv(out / "init.csv"), seed=1).tracks
    assert rows.equals(again)  # the same seed, the same output
    (out / "cam1.mp4").unlink()
    with pytest.raises(UserError, match="at least 2 streams"):
        track(open_take(out), "limbs3d", init=read_tracks_csv(out / "init.csv"))


def test_partlab_track_of_a_take_with_limbs3d_writes_its_activities(tmp_path, capsys):
    """``--tracker limbs3d --events`` recognises the take's activities (sec. 7 over the 3D hands),
    as ``limbs`` does in one camera: the standing take's clap (truth frames 63-79) is found and
    ``partlab eval --events`` matches it."""
    import pandas as pd

    from partlab.cli import main

    take = render_take("standing", tmp_path / "take", 3, seed=0, n_frames=90, width=320, height=240,
                       chessboard=False)
    found = tmp_path / "events.csv"
    assert main(["track", str(take), "--tracker", "limbs3d", "--init", str(take / "init.csv"), "--seed", "1",
                 "--events", str(found), "-o", str(tmp_path / "tracks.csv")]) == 0
    events = pd.read_csv(found)
    assert list(events["kind"]) == ["clap"]
    clap = events.iloc[0]
    assert 60 <= clap.start_frame <= 70 and 75 <= clap.end_frame <= 85
    capsys.readouterr()
    assert main(["eval", str(take / "events.csv"), str(found), "--events"]) == 0
    assert "clap      1          1        1        1.0     1.0" in capsys.readouterr().out
