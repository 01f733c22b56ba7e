"""Maximum-likelihood sharpness ``lam`` of the colour likelihood, from corrected boxes on frames.

The body tracker weighs a candidate box by ``exp(-lam * d^2)``, ``d^2 = 1 - rho`` the
Bhattacharyya distance between the candidate's equalized YCbCr histogram and the
target's reference (seed 002 sec. 3.1, Nummiaro et al.). Read as the density of the
distance the *true* box shows,

    p(d) = exp(-lam d^2) / Z(lam),   Z(lam) = int_0^1 exp(-lam u^2) du = sqrt(pi / lam) erf(sqrt(lam)) / 2,

the ML ``lam`` solves ``mean(d^2) = E_lam[d^2]`` (about ``1 / (2 mean d^2)`` when the
distances are small). The distances are measured the way the tracker sees them: the
reference starts from the part's first corrected box and is updated by eq. (1)
(``H_t = 0.9 H_{t-1} + 0.1 Q_t``) with every later corrected box, and each box is
binned with the reference's equalization map before it is compared. Rows hidden by
more than ``max_occluded`` are skipped (their colours are someone else's).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pandas as pd
from scipy.optimize import minimize_scalar
from scipy.special import erf

from partlab.tracking.params import BodyParams

SHARPNESS_PARTS: tuple[str, ...] = ("head", "torso", "hipleg", "person")


def fit_lam(d2: np.ndarray) -> float:
    """ML ``lam`` of ``p(d) ~ exp(-lam d^2)`` on ``[0, 1]`` from squared distances ``d2``."""
    d2 = np.clip(np.asarray(d2, dtype=np.float64), 0.0, 1.0)
    if d2.size == 0:
        return float("nan")
    m = float(np.mean(d2))

    def nll(log_lam: float) -> float:
        lam = np.exp(log_lam)
        log_z = 0.5 * np.log(np.pi / lam) + np.log(erf(np.sqrt(lam))) - np.log(2.0)
        return lam * m + log_z

    res = minimize_scalar(nll, bounds=(np.log(1e-3), np.log(1e4)), method="bounded", options={"xatol": 1e-6})
    return float(np.exp(res.x))


def colour_distances(frames: Callable[[], Iterator[tuple[int, np.ndarray]]], truth: pd.DataFrame,
                     params: BodyParams | None = None, stride: int = 1,
                     max_occluded: float = 0.2) -> dict[str, np.ndarray]:
    """Squared Bhattacharyya distances of every part's corrected box to its running reference."""
    params = params or BodyParams()
    from partlab.tracking.core import histogram as H  # the body tracker's observation model

    truth = truth[truth["part"].isin(SHARPNESS_PARTS)]
    by_frame = {f: g for f, g in truth.groupby("frame")}
    refs: dict[tuple[int, str], np.ndarray] = {}
    out: dict[str, list[float]] = {p: [] for p in SHARPNESS_PARTS}
    bins = params.appearance.bins_per_channel
    for index, frame in frames():
        rows = by_frame.get(index)
        if rows is None:
            continue
        ycc = H.to_ycc(frame)
        for r in rows.itertuples(index=False):
            if r.w < 2 or r.h < 2 or r.occluded > max_occluded:
                continue
            key = (int(r.track_id), str(r.part))
            obs = H.level_histogram(ycc, (r.x, r.y, r.w, r.h))
            ref = refs.get(key)
            if ref is None:
                refs[key] = obs
                continue
            if index % stride == 0:
                mapping = H.equalization_map(ref, bins)
                rho = H.bhattacharyya(H.binned_histogram(obs, mapping, bins),
                                      H.binned_histogram(ref, mapping, bins), bins)
                out[key[1]].append(float(1.0 - rho))
            refs[key] = H.update_reference(ref, obs, params.appearance.model_update)
    return {p: np.asarray(v) for p, v in out.items()}
