"""Learning the multi-camera tracker's prior variances from corrected takes (*3D tracking of the
hands and head of interacting people from several cameras*, sec. 6.4: "all these terms are defined
as zero-mean Gaussian functions ... and tune the variances based on a set of training videos").

On a take whose heads and hands are known in 3D (corrected, or a synthetic take's
``truth3d.csv``), the tracker is run with the truth as its targets, and every candidate point
(eq. 16) lying within ``match_mm`` of a true head or hand is a *true pair*. The terms of eq. 25-27
are zero-mean Gaussians of the errors of true pairs, so each variance's maximum-likelihood estimate
is the root mean square of its error over the true pairs: ``Dv`` differences (mm, eq. 25), the
distance between the lines of sight ``d`` (eq. 24, 26), and the silhouette distance ``Ds`` in the
views *other* than the pair's own two (eq. 27; in its own two views a candidate lies on its blobs,
which lie on the silhouette, so those distances say nothing).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from partlab.tracking.camera import Camera
from partlab.tracking.frame import Frame, FrameSet
from partlab.tracking.limbs3d.params import Limbs3DParams
from partlab.tracking.limbs3d.tracker import LIMB_PARTS, Limbs3DTracker

#: a candidate this near a true head or hand (mm) is a true pair: a hand's radius
MATCH_MM = 40.0
#: below this many true pairs a variance is not fitted (the default is kept)
MIN_PAIRS = 30
#: fitted variances are kept within these bounds (a take with perfect blobs would give ~0)
FLOORS = {"sigma_v": 10.0, "sigma_d": 2.0, "sigma_s": 1.0}


@dataclass(frozen=True)
class PairErrors:
    """The raw errors of the true pairs of one or more takes: ``dv (N,)`` mm, ``d (N,)`` mm,
    ``ds (M,)`` pixels (one per true pair and view other than its own two)."""

    dv: np.ndarray
    d: np.ndarray
    ds: np.ndarray

    @staticmethod
    def concat(items: Iterable[PairErrors]) -> PairErrors:
        items = list(items)
        return PairErrors(*(np.concatenate([getattr(i, k) for i in items] or [np.zeros(0)]) for k in ("dv", "d", "ds")))


def true_pair_errors(frames: Mapping[str, Iterable[np.ndarray]], cameras: Mapping[str, Camera], truth3d: pd.DataFrame,
                     params: Limbs3DParams | None = None, backgrounds: Mapping[str, np.ndarray] | None = None,
                     every: int = 2, match_mm: float = MATCH_MM) -> PairErrors:
    """Run the tracker over a take (``frames``: per stream an iterable of BGR frames) with the truth's
    first frame as its init and collect the raw errors of the true pairs of every ``every``-th frame."""
    params = params or Limbs3DParams()
    truth = truth3d[truth3d["part"].isin(LIMB_PARTS)]
    first = int(truth["frame"].min())
    init = truth[truth["frame"] == first]
    tr = Limbs3DTracker(params, np.random.default_rng(0), cameras, init=init, backgrounds=backgrounds)
    by_frame = {f: g[["X", "Y", "Z"]].to_numpy(float) for f, g in truth.groupby("frame")}
    dv, d, ds = [], [], []
    streams = list(cameras)
    for i, images in enumerate(zip(*(frames[s] for s in streams))):
        tr.step(FrameSet(i, {s: Frame(i, img, None, s, cameras[s]) for s, img in zip(streams, images)}),
                {s: None for s in streams})
        if i % every or i not in by_frame or not tr.last:
            continue
        cands, raw = tr.last["candidates"], tr.last["raw"]
        if not len(cands):
            continue
        near = np.linalg.norm(cands.points[:, None] - by_frame[i][None], axis=-1).min(axis=1) < match_mm
        dv.append(raw["dv"][near])
        d.append(raw["d"][near])
        other = np.ones(raw["ds"].shape, bool)
        other[np.arange(len(cands)), cands.views[:, 0]] = False
        other[np.arange(len(cands)), cands.views[:, 1]] = False
        ds.append(raw["ds"][near][other[near]])
    return PairErrors(_cat(dv), _cat(d), _cat(ds))


def _cat(parts: list[np.ndarray]) -> np.ndarray:
    return np.concatenate(parts) if parts else np.zeros(0)


def fit_sigmas(errors: PairErrors, defaults: Limbs3DParams | None = None) -> tuple[Limbs3DParams, pd.DataFrame]:
    """The fitted parameters (``priors.sigma_v``, ``sigma_d``, ``sigma_s`` by maximum likelihood,
    the RMS of each error; a term with under :data:`MIN_PAIRS` samples keeps its default) and a
    table ``term, default, fitted, samples``."""
    defaults = defaults or Limbs3DParams()
    rows, changes = [], {}
    for name, x in (("sigma_v", errors.dv), ("sigma_d", errors.d), ("sigma_s", errors.ds)):
        x = x[np.isfinite(x)]
        default = getattr(defaults.priors, name)
        fitted = max(float(np.sqrt(np.mean(x**2))), FLOORS[name]) if len(x) >= MIN_PAIRS else None
        if fitted is not None:
            changes[f"priors.{name}"] = fitted
        rows.append({"term": name, "default": default, "fitted": fitted, "samples": int(len(x))})
    return defaults.updated(changes), pd.DataFrame(rows)
