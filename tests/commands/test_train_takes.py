"""``partlab train --take``: the limbs3d prior variances from a corrected take, used by ``--model``."""

import json

from partlab.cli import main
from partlab.labelling.synth.multiview import render_take
from partlab.models.bundle import load_bundle
from partlab.tracking.limbs3d.params import Limbs3DParams
from partlab.tracking.run import model_params
from partlab.tracking.tracks import read_tracks_csv


def test_train_on_a_take_fits_sigmas_that_track_uses(tmp_path, capsys):
    take = render_take("seated", tmp_path / "take", 3, seed=3, n_frames=12, chessboard=False)
    bundle = tmp_path / "b"
    assert main(["train", "--take", str(take), "--truth", str(take / "truth.csv"), "-o", str(bundle)]) == 0
    assert "sigma_d" in capsys.readouterr().out
    fitted = load_bundle(bundle).params["limbs3d"].priors
    default = Limbs3DParams().priors
    assert fitted.sigma_d < default.sigma_d and fitted.sigma_v < default.sigma_v  # true pairs are tighter
    record = json.loads((bundle / "bundle.json").read_text())["summary"]["limbs3d_sigmas"]
    assert {r["term"] for r in record} == {"sigma_v", "sigma_d", "sigma_s"}
    assert model_params(load_bundle(bundle), "limbs3d") == load_bundle(bundle).params["limbs3d"]  # what track reads


def test_train_refuses_a_take_without_3d_truth_and_mixed_inputs(tmp_path, capsys):
    take = render_take("standing", tmp_path / "take", 2, seed=1, n_frames=2, width=320, height=240, chessboard=False)
    flat = tmp_path / "flat.csv"
    truth = read_tracks_csv(take / "truth.csv").drop(columns=["X", "Y", "Z"])
    truth.to_csv(flat, index=False)
    assert main(["train", "--take", str(take), "--truth", str(flat), "-o", str(tmp_path / "b")]) == 2
    assert "X, Y, Z" in capsys.readouterr().err
    assert not (tmp_path / "b").exists()
    assert main(["train", "--take", str(take), "--clip", "x.mp4", "--truth", str(flat), "-o", str(tmp_path / "b")]) == 2
