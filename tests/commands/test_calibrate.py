"""partlab calibrate: rendered chessboards give back the cameras; no board, a clear refusal."""

import numpy as np
import pytest

from partlab.cli import CommandError, main
from partlab.commands.calibrate import calibrate_clips
from partlab.labelling.calibration import read_calibration
from partlab.labelling.synth.multiview import look_at, render_chessboard
from partlab.labelling.video import write_video


def test_chessboards_recover_the_cameras(tmp_path):
    cams = [look_at("cam0", [2600.0, -1500.0, 2100.0], [300.0, 200.0, 1000.0], 560.0, (640, 480)),
            look_at("cam1", [300.0, -3000.0, 2400.0], [300.0, 200.0, 1000.0], 600.0, (640, 480))]
    folder = render_chessboard(cams, tmp_path, seed=1, n_frames=14)
    found, errors = calibrate_clips(sorted(folder.glob("*.avi")), (9, 6), 100.0)
    for cam, est in zip(cams, found):
        assert est.name == cam.name
        assert np.linalg.norm(est.centre - cam.centre) < 10.0  # mm
        assert errors[cam.name][0] < 0.5  # px, calibrateCamera's rms
        assert abs(est.K[0, 0] - cam.K[0, 0]) < 5.0
    assert main(["calibrate", str(folder), "-o", str(tmp_path / "c.json")]) == 0
    assert set(read_calibration(tmp_path / "c.json")) == {"cam0", "cam1"}


def test_no_board_is_refused_with_the_clip_named(tmp_path, capsys):
    clip = tmp_path / "camX.avi"
    write_video(clip, [np.full((120, 160, 3), 128, np.uint8)] * 4, 25)
    with pytest.raises(CommandError, match=r"camX.avi: chessboard 9x6 .* found in 0 frame"):
        calibrate_clips([clip], (9, 6), 100.0)
    assert main(["calibrate", str(clip), "-o", str(tmp_path / "c.json")]) == 2
    assert "found in 0 frame(s)" in capsys.readouterr().err
    assert not (tmp_path / "c.json").exists()
