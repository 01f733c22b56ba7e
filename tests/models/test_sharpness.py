import numpy as np

from models.sharpness import fit_lam


def test_fit_lam_recovers_the_sharpness_of_sampled_distances():
    rng = np.random.default_rng(0)
    for lam in (3.0, 20.0):
        d = rng.uniform(0, 1, 400_000)
        d = d[rng.uniform(0, 1, d.size) < np.exp(-lam * d * d)][:4000]
        assert abs(fit_lam(d * d) - lam) / lam < 0.1
    # small distances: close to 1 / (2 mean d^2)
    d2 = np.full(100, 0.01)
    assert abs(fit_lam(d2) - 50.0) / 50.0 < 0.05
    assert np.isnan(fit_lam(np.array([])))
