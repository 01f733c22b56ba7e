"""Formats and evaluation on a synthetic scene of partlab.labelling.synth (every part, hands included)."""

import pandas as pd
import pytest

from partlab.labelling.evaluation import evaluate
from partlab.labelling.formats import export_dataset, import_dataset
from partlab.labelling.video import probe, write_video


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    from partlab.labelling.synth import make_scene

    s = make_scene("pair_cross", seed=1, n_frames=12, width=160, height=120)
    path = write_video(tmp_path_factory.mktemp("synth") / "clip.avi", list(s.frames), fps=s.fps)
    return s, path, probe(path)


def test_synthetic_truth_survives_cvat_and_mot(scene, tmp_path):
    s, path, info = scene
    assert info.frame_count == 12 and set(s.truth["part"]) >= {"left_hand", "right_hand"}
    cvat = import_dataset(export_dataset(s.truth, "cvat", tmp_path / "c", info, video_path=path), "cvat")
    key = ["frame", "track_id", "part"]
    a = cvat.set_index(key).sort_index()
    b = s.truth.set_index(key).sort_index()
    pd.testing.assert_frame_equal(a, b)
    mot = import_dataset(export_dataset(s.truth, "mot", tmp_path / "m", info, frames=False), "mot")
    pd.testing.assert_frame_equal(mot.set_index(key).sort_index()[["x", "y", "w", "h", "occluded"]],
                                  b[["x", "y", "w", "h", "occluded"]])


def test_synthetic_init_only_run_scores_low_after_start(scene):
    """A 'tracker' that stays where each person was initialised: right at offset 0 only."""
    s, _, _ = scene
    frozen = pd.concat([s.init.assign(frame=f) for f in range(12)], ignore_index=True)
    r = evaluate(s.truth, frozen, at=0, hota=False)
    assert r.matching == "track_id"
    assert (r.summary["rate_at"] == 1.0).all()
    # at 160x120 the walkers move about 10 px a frame with boxes 12-26 px wide: lost from offset 1 on
    assert (r.rates.loc[1:] == 0.0).all().all()
    # person boxes: 2 matches at frame 0, then 22 misses and 22 false positives over 24 true boxes
    assert r.mot.loc["person", "mota"] == pytest.approx(1 - 44 / 24)
