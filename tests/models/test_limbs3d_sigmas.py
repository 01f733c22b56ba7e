"""Fitting the multi-camera prior variances (sec. 6.4) from true pairs."""

import numpy as np
import pytest

from partlab.labelling.synth.multiview import make_multiview_scene
from partlab.models.limbs3d import MIN_PAIRS, PairErrors, fit_sigmas, true_pair_errors
from partlab.tracking.limbs3d.params import Limbs3DParams


def test_fit_is_the_rms_of_each_error_and_keeps_defaults_without_samples():
    rng = np.random.default_rng(0)
    dv = rng.normal(0, 40.0, 5000)
    d = np.abs(rng.normal(0, 6.0, 5000))
    fitted, table = fit_sigmas(PairErrors(dv, d, np.zeros(MIN_PAIRS - 1)))
    assert fitted.priors.sigma_v == pytest.approx(40.0, rel=0.03)
    assert fitted.priors.sigma_d == pytest.approx(6.0, rel=0.03)
    assert fitted.priors.sigma_s == Limbs3DParams().priors.sigma_s  # too few samples: the default
    assert table.set_index("term").loc["sigma_s", "samples"] == MIN_PAIRS - 1
    # a perfect take would give 0: the floor keeps a usable Gaussian
    assert fit_sigmas(PairErrors(np.zeros(100), np.zeros(100), np.zeros(100)))[0].priors.sigma_d == 2.0


def test_true_pairs_of_a_rendered_take_give_tight_sigmas():
    scene = make_multiview_scene("seated", 3, seed=3, n_frames=16)
    cams = {c.name: c for c in scene.cameras}
    err = true_pair_errors({c: scene.frames[c] for c in cams}, cams, scene.truth3d, backgrounds=scene.backgrounds)
    assert len(err.d) >= 3 * 8  # 3 parts x 8 frames, each seen by at least one pair of views
    fitted, _ = fit_sigmas(err)
    # true pairs' lines of sight pass within a few mm; their Dv agree within ~a hand
    assert 2.0 <= fitted.priors.sigma_d < 12.0
    assert 10.0 <= fitted.priors.sigma_v < 120.0
    assert len(err.ds) == len(err.d)  # three views: one other view per pair
    assert np.median(err.ds) < 2.0  # a true pair projects onto the third view's silhouette
