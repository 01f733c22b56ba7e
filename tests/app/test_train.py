import sys
from pathlib import Path

import numpy as np

from partlab.cli import main
from partlab.labelling.video import write_video
from partlab.models.bundle import load_bundle
from partlab.tracking.tracks import write_tracks_csv

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "models"))
from walkers import walking_truth  # noqa: E402


def _clip(tmp_path, name, seed):
    video = write_video(tmp_path / f"{name}.mp4", (np.full((96, 128, 3), 90, np.uint8) for _ in range(30)), 25.0)
    truth = walking_truth(2, 30, seed=seed)
    # a user flagged one torso as failed by hand
    mask = (truth["frame"] == 20) & (truth["track_id"] == 1) & (truth["part"] == "torso")
    truth.loc[mask, ["x", "failure", "source"]] = [truth.loc[mask, "x"].iloc[0] + 80, True, "human"]
    write_tracks_csv(truth, tmp_path / f"{name}.csv")
    return str(video), str(tmp_path / f"{name}.csv")


def test_train_writes_a_bundle_and_prints_the_tables(tmp_path, capsys):
    v1, t1 = _clip(tmp_path, "a", 1)
    v2, t2 = _clip(tmp_path, "b", 2)
    out = tmp_path / "bundle"
    assert main(["train", "--clip", v1, "--truth", t1, "--clip", v2, "--truth", t2, "-o", str(out),
                 "--no-tracker", "--seed", "3"]) == 0
    text = capsys.readouterr().out
    assert "TNR" in text and "sigma_d" in text and "hipleg" in text
    b = load_bundle(out)
    assert set(b.failure_detector.models) == {"head", "torso", "hipleg", "multi"}
    s = b.summary["samples"]
    assert s["human_flags"] == 2 and s["perturbed"] == 4 * 300 and s["tracker"] == 0
    assert [c["name"] for c in b.summary["clips"]] == ["a.mp4", "b.mp4"]
    assert b.summary["svms"]["torso"]["tnr"] >= 0.95


def test_train_refuses_bad_arguments(tmp_path, capsys):
    v1, t1 = _clip(tmp_path, "a", 1)
    assert main(["train", "--clip", v1, "--clip", v1, "--truth", t1, "-o", str(tmp_path / "o")]) == 2
    assert "one --truth per --clip" in capsys.readouterr().err
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "notes.txt").write_text("mine")
    assert main(["train", "--clip", v1, "--truth", t1, "-o", str(tmp_path / "docs")]) == 2
    assert "not a model bundle" in capsys.readouterr().err
    assert (tmp_path / "docs" / "notes.txt").read_text() == "mine"
    assert main(["train", "--clip", str(tmp_path / "nope.mp4"), "--truth", t1, "-o", str(tmp_path / "o")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_training_that_learns_nothing_says_so_and_writes_no_bundle(tmp_path, capsys):
    v1, t1 = _clip(tmp_path, "a", 1)
    import pandas as pd

    truth = pd.read_csv(t1)
    for name, rows in (("one frame", truth[truth.frame == 0]),
                       ("person boxes only", truth.assign(part="person").drop_duplicates(["frame", "track_id"]))):
        path = tmp_path / f"{name}.csv"
        rows.to_csv(path, index=False)
        out = tmp_path / name.replace(" ", "_")
        assert main(["train", "--clip", v1, "--truth", str(path), "-o", str(out), "--no-tracker"]) == 2, name
        err = capsys.readouterr().err
        assert "learnt nothing from a.mp4" in err and "no bundle written" in err, (name, err)
        assert not out.exists(), name
