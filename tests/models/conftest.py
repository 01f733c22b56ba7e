"""Small truth tables of people walking, made here (the synthetic scenes are for benchmarks)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from walkers import walking_truth


@pytest.fixture
def truth_df() -> pd.DataFrame:
    return walking_truth()


@pytest.fixture(scope="session")
def trained_svms():
    """The four SVMs trained once on perturbed walking truth (small: a few seconds)."""
    from partlab.models.failure_svm import train_failure_svms
    from partlab.models.features import person_histories
    from partlab.models.perturb import perturbed_samples

    rng = np.random.default_rng(0)
    xs, ys = [], []
    for _tid, (frames, hist) in person_histories(walking_truth(3, 80, seed=1)).items():
        x, y = perturbed_samples(frames, hist, 25.0, 300, rng)
        xs.append(x)
        ys.append(y)
    x, y = np.concatenate(xs), np.concatenate(ys)
    models, reports = train_failure_svms(x, y, seed=0, max_samples=700)
    return x, y, models, reports
