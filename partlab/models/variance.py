"""Variance parameters fitted by maximum likelihood from corrected trajectories.

**Body parts** (seed 002 sec. 3, the constant-velocity particle filter; the
``PartNoise`` of :mod:`partlab.tracking.params`). Per part, the box centre follows

    x_t = x_{t-1} + v_{t-1} + a_t,    v_t = v_{t-1} + b_t,    a ~ N(0, s_x^2), b ~ N(0, s_vx^2)

(same for y). On a corrected trajectory the velocity is not observed, but the
second difference ``e_t = x_t - 2 x_{t-1} + x_{t-2}`` (the residual of
``x_t - (x_{t-1} + v_{t-1})`` with ``v_{t-1} = x_{t-1} - x_{t-2}``) equals
``b_{t-1} + a_t - a_{t-1}``: a moving average with variance ``s_v^2 + 2 s_x^2`` and
lag-one covariance ``-s_x^2``. Its exact Gaussian likelihood (tridiagonal covariance,
one block per contiguous segment) is maximised over ``(s_x, s_v)``, which separates
position jitter (negatively correlated residuals) from velocity changes. Width and
height are random walks, ``w_t = w_{t-1} + c_t``: the ML std is the RMS of ``w_t - w_{t-1}``.
All in pixels per frame, on the box centre. When the tracker's own output on the
training clips is given, position and size stds are instead fitted to how far the
truth lands from the tracker's prediction (:func:`prediction_residuals`): on smooth
synthetic walkers the truth-only fit gives ~1 px, with which the filter cannot keep
up (measured: the ``single`` scene is lost), while the prediction error the filter
really has to cover is several pixels.

``lam`` (the colour likelihood's sharpness) needs the tracker's histograms on the
frames and is **not fitted here**: it keeps its default (say so in reports).

**Limbs** (seed 000 eq. 25-27 in one camera). ``sigma_d`` (eq. 26, the distance error
of a candidate) becomes the 2D error of a limb's constant-velocity prediction,
``|p_t - (2 p_{t-1} - p_{t-2})|``, fitted as an isotropic 2D Gaussian (ML: ``mean |r|^2 / 2``);
``sigma_v`` (eq. 25, agreement of the relative v coordinate) becomes the frame-to-frame
change of the limb's v coordinate relative to the top of its person's box;
``sigma_s`` (eq. 27, distance to the silhouette) becomes the distance of the limb's
centre to its person's box (zero inside), half-normal ML ``sqrt(mean d^2)``. Terms
need the ``person`` rows; without them the defaults stay. Every fitted position or
size std is floored at :data:`MIN_STD` = 1 px (velocity stds at 0.1 px/frame):
corrected boxes are drawn to about a pixel, so smaller
values are not measured, and a smooth synthetic path must not give a filter whose
particles cannot spread.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd
from scipy.linalg import cho_solve_banded, cholesky_banded
from scipy.optimize import minimize

from partlab.tracking.params import BodyParams, LimbParams, PartNoise

MIN_STD: float = 1.0
#: Floor of velocity-noise stds (px/frame): labelling precision does not limit those.
MIN_VEL_STD: float = 0.1
#: Fewer residuals than this and a parameter keeps its default.
MIN_SAMPLES: int = 10
BODY_NOISE_PARTS: tuple[str, ...] = ("head", "torso", "hipleg", "person")
LIMB_PARTS: tuple[str, ...] = ("head", "left_hand", "right_hand")
#: The limb sigmas a tracker reads today: ``sigma_v`` and ``sigma_d`` (eq. 25-26) compare two
#: cameras; they are fitted and saved for the multi-camera tracker, and the table's ``applied``
#: says ``-`` for them, since nothing applies them in one camera.
LIMB_SIGMAS_READ: frozenset[str] = frozenset({"sigma_s"})


def _segments(frames: np.ndarray, values: np.ndarray) -> list[np.ndarray]:
    """Split ``values (T, ...)`` at gaps in the sorted ``frames``."""
    if len(frames) == 0:
        return []
    breaks = np.flatnonzero(np.diff(frames) != 1) + 1
    return [s for s in np.split(values, breaks) if len(s)]


def _ma1_negloglik(log_params: np.ndarray, residuals: list[np.ndarray]) -> float:
    """Negative log-likelihood of second differences under the constant-velocity model:
    tridiagonal covariance ``g0 = s_v^2 + 2 s_x^2`` on the diagonal, ``g1 = -s_x^2`` beside it."""
    sx2, sv2 = np.exp(2 * log_params)
    g0, g1 = sv2 + 2 * sx2, -sx2
    total = 0.0
    for e in residuals:
        n = e.size
        ab = np.empty((2, n))
        ab[0, :] = g1
        ab[1, :] = g0
        try:
            c = cholesky_banded(ab, lower=False)
        except np.linalg.LinAlgError:
            return 1e300
        sol = cho_solve_banded((c, False), e)
        logdet = 2.0 * np.sum(np.log(c[1]))
        total += 0.5 * (logdet + float(e @ sol) + n * np.log(2 * np.pi))
    return total


def fit_constant_velocity(paths: list[np.ndarray]) -> tuple[float, float, int]:
    """ML ``(s_pos, s_vel, n_residuals)`` of the constant-velocity model from 1D paths
    (each a contiguous ``(T,)`` series; paths shorter than 4 are skipped)."""
    residuals = [np.diff(np.asarray(p, dtype=np.float64), n=2) for p in paths if len(p) >= 4]
    n = int(sum(r.size for r in residuals))
    if n < MIN_SAMPLES:
        return float("nan"), float("nan"), n
    allr = np.concatenate(residuals)
    g0 = float(np.mean(allr ** 2))
    lag = [r[1:] * r[:-1] for r in residuals if r.size > 1]
    g1 = float(np.mean(np.concatenate(lag))) if lag else 0.0
    sx2 = min(max(-g1, 0.05 * g0), 0.45 * g0)  # method of moments as the starting point
    sv2 = max(g0 - 2 * sx2, 0.05 * g0)
    x0 = 0.5 * np.log(np.array([sx2, sv2]) + 1e-12)
    res = minimize(_ma1_negloglik, x0, args=(residuals,), method="Nelder-Mead",
                   options={"xatol": 1e-4, "fatol": 1e-6, "maxiter": 400})
    sx, sv = np.exp(res.x)
    return float(sx), float(sv), n


def fit_random_walk(paths: list[np.ndarray]) -> tuple[float, int]:
    """ML std of the steps of a zero-mean random walk, and the number of steps."""
    steps = [np.diff(np.asarray(p, dtype=np.float64)) for p in paths if len(p) >= 2]
    n = int(sum(s.size for s in steps))
    if n < MIN_SAMPLES:
        return float("nan"), n
    return float(np.sqrt(np.mean(np.concatenate(steps) ** 2))), n


def _part_paths(truths: list[pd.DataFrame], part: str) -> dict[str, list[np.ndarray]]:
    """Contiguous per-track series of ``cx, cy, w, h`` of one part over all tables."""
    out: dict[str, list[np.ndarray]] = {"cx": [], "cy": [], "w": [], "h": []}
    for df in truths:
        d = df[df["part"] == part]
        for _, g in d.groupby("track_id"):
            g = g.drop_duplicates("frame").sort_values("frame")
            vals = np.stack([(g["x"] + g["w"] / 2).to_numpy(), (g["y"] + g["h"] / 2).to_numpy(),
                          g["w"].to_numpy(), g["h"].to_numpy()], axis=1)
            for seg in _segments(g["frame"].to_numpy(), vals):
                for i, c in enumerate(("cx", "cy", "w", "h")):
                    out[c].append(seg[:, i])
    return out


def _floor(v: float, default: float, floor: float = MIN_STD) -> float:
    return default if not np.isfinite(v) else max(float(v), floor)


def prediction_residuals(tracked: pd.DataFrame, truth: pd.DataFrame, part: str) -> dict[str, np.ndarray]:
    """How far the truth lands from the tracker's own constant-velocity prediction.

    For every frame ``t`` where the tracker had ``part`` right at ``t-1`` and ``t-2``
    (:func:`partlab.models.labels.label_states`), ``truth_t - (2 est_{t-1} - est_{t-2})`` for the
    centre and ``truth_t - est_{t-1}`` for the size. Returns arrays per ``cx, cy, w, h``.
    """
    from partlab.models.labels import POSITIVE, label_states

    def centres(df):
        d = df[df["part"] == part].drop_duplicates(["track_id", "frame"])
        return pd.DataFrame({"track_id": d["track_id"], "frame": d["frame"], "cx": d["x"] + d["w"] / 2,
                             "cy": d["y"] + d["h"] / 2, "w": d["w"], "h": d["h"]})

    est, tru = centres(tracked), centres(truth)
    both = est.merge(tru, on=["track_id", "frame"], suffixes=("", "_t"))
    cols = ["cx", "cy", "w", "h"]
    ok = label_states(both[cols].to_numpy(), both[[c + "_t" for c in cols]].to_numpy()) == POSITIVE
    good = both.loc[ok, ["track_id", "frame"] + cols]
    e1 = good.assign(frame=good["frame"] + 1)
    e2 = good.assign(frame=good["frame"] + 2)
    m = tru.merge(e1, on=["track_id", "frame"], suffixes=("", "_1")).merge(
        e2, on=["track_id", "frame"], suffixes=("", "_2"))
    if m.empty:
        return {c: np.zeros(0) for c in cols}
    return {
        "cx": (m["cx"] - (2 * m["cx_1"] - m["cx_2"])).to_numpy(),
        "cy": (m["cy"] - (2 * m["cy_1"] - m["cy_2"])).to_numpy(),
        "w": (m["w"] - m["w_1"]).to_numpy(),
        "h": (m["h"] - m["h_1"]).to_numpy(),
    }


def fit_body_noise(truths: list[pd.DataFrame], defaults: BodyParams | None = None,
                   tracked: list[pd.DataFrame] | None = None,
                   keep_defaults_as_floor: bool = True) -> tuple[BodyParams, pd.DataFrame]:
    """Fitted :class:`BodyParams` (``part_noise`` replaced) and a table of
    ``tracker, part, parameter, default, fitted, applied, n, source`` (``fitted`` NaN
    where nothing could be fitted).

    ``keep_defaults_as_floor`` (the default): the tracker gets ``max(default, fitted)``.
    The ML fit describes how the *true* boxes move; the filter's noise must also cover
    its own estimation error, which the defaults were tuned for. Measured on the
    synthetic suite (6 scenarios x 3 seeds, per-part rate at frame 105, head/torso/
    hip-leg): defaults 0.80/0.97/0.87, truth fit alone 0.63/0.73/0.70, truth fit x2
    0.77/0.90/0.80, fit to the tracker's prediction errors 0.47/0.80/0.60. So a fit
    only ever widens the noise (faster or jerkier motion than the defaults assume).

    With ``tracked`` (the tracker's output on the same clips, one table per truth) the
    position and size stds are the ML (Gaussian, mean removed: inner rectangles may sit
    off the truth's centre or be smaller) spread of :func:`prediction_residuals`: the
    noise the filter must add so that its prediction covers where the part really
    goes, which includes the filter's own estimation error. The truth alone gives the
    smooth motion of the part (much smaller on synthetic walkers, and too small for the
    filter to keep up); velocity stds always come from the truth's MA(1) fit.
    """
    defaults = defaults or BodyParams()
    noise = dict(defaults.dynamics.noise)
    rows = []
    for part in BODY_NOISE_PARTS:
        base = noise.get(part, PartNoise())
        paths = _part_paths(truths, part)
        sx, svx, nx = fit_constant_velocity(paths["cx"])
        sy, svy, ny = fit_constant_velocity(paths["cy"])
        sw, nw = fit_random_walk(paths["w"])
        sh, nh = fit_random_walk(paths["h"])
        fitted = {"x": (sx, nx), "vx": (svx, nx), "y": (sy, ny), "vy": (svy, ny), "w": (sw, nw), "h": (sh, nh)}
        source = {k: "truth" for k in fitted}
        if tracked:
            res = [prediction_residuals(t, tt, part) for t, tt in zip(tracked, truths)]
            for k, c in (("x", "cx"), ("y", "cy"), ("w", "w"), ("h", "h")):
                r = np.concatenate([d[c] for d in res])
                if r.size >= MIN_SAMPLES:
                    fitted[k] = (float(np.std(r)), int(r.size))
                    source[k] = "tracker"
        new = {k: _floor(v, getattr(base, k), MIN_VEL_STD if k.startswith("v") else MIN_STD)
               for k, (v, _) in fitted.items()}
        applied = {k: max(v, getattr(base, k)) if keep_defaults_as_floor else v for k, v in new.items()}
        noise[part] = replace(base, **applied)
        for k in ("x", "y", "w", "h", "vx", "vy"):
            v, n = fitted[k]
            rows.append(dict(tracker="body", part=part, parameter=k, default=getattr(base, k),
                             fitted=new[k] if np.isfinite(v) else np.nan, applied=applied[k], n=n,
                             source=source[k]))
        rows.append(dict(tracker="body", part=part, parameter="lam", default=base.lam, fitted=np.nan,
                         applied=base.lam, n=0, source="frames"))
    return defaults.updated({"dynamics.noise": noise}), pd.DataFrame(rows)


def _limb_residuals(truths: list[pd.DataFrame]) -> dict[str, np.ndarray]:
    pred, dv, ds = [], [], []
    for df in truths:
        person = df[df["part"] == "person"][["track_id", "frame", "x", "y", "w", "h"]]
        for part in LIMB_PARTS:
            d = df[df["part"] == part]
            for tid, g in d.groupby("track_id"):
                g = g.drop_duplicates("frame").sort_values("frame")
                c = np.stack([(g["x"] + g["w"] / 2).to_numpy(), (g["y"] + g["h"] / 2).to_numpy()], axis=1)
                for seg in _segments(g["frame"].to_numpy(), c):
                    if len(seg) >= 3:
                        pred.append(seg[2:] - (2 * seg[1:-1] - seg[:-2]))
                p = g.merge(person[person["track_id"] == tid], on="frame", suffixes=("", "_p"))
                if p.empty:
                    continue
                cx = (p["x"] + p["w"] / 2).to_numpy()
                cy = (p["y"] + p["h"] / 2).to_numpy()
                rel = cy - p["y_p"].to_numpy()
                for seg in _segments(p["frame"].to_numpy(), rel):
                    dv.append(np.diff(seg))
                ox = np.maximum(p["x_p"].to_numpy() - cx, 0) + np.maximum(cx - (p["x_p"] + p["w_p"]).to_numpy(), 0)
                oy = np.maximum(p["y_p"].to_numpy() - cy, 0) + np.maximum(cy - (p["y_p"] + p["h_p"]).to_numpy(), 0)
                ds.append(np.hypot(ox, oy))
    cat = lambda xs, shape: np.concatenate(xs) if xs else np.zeros(shape)  # noqa: E731
    return {"d": cat(pred, (0, 2)), "v": cat(dv, (0,)), "s": cat(ds, (0,))}


def fit_limb_sigmas(truths: list[pd.DataFrame], defaults: LimbParams | None = None,
                    keep_defaults_as_floor: bool = True) -> tuple[LimbParams, pd.DataFrame]:
    """Fitted :class:`LimbParams` (``sigma_d, sigma_v, sigma_s``) and the comparison table.

    As for the body noise, the tracker gets ``max(default, fitted)`` unless
    ``keep_defaults_as_floor`` is false: corrected boxes are cleaner than the skin blobs
    and foreground the priors are applied to (on synthetic truth every hand lies inside
    its person's box, so the ML ``sigma_s`` is the 1 px floor)."""
    defaults = defaults or LimbParams()
    r = _limb_residuals(truths)
    est = {
        "sigma_d": (np.sqrt(np.mean(np.sum(r["d"] ** 2, axis=1)) / 2) if len(r["d"]) else np.nan, len(r["d"])),
        "sigma_v": (np.sqrt(np.mean(r["v"] ** 2)) if len(r["v"]) else np.nan, len(r["v"])),
        "sigma_s": (np.sqrt(np.mean(r["s"] ** 2)) if len(r["s"]) else np.nan, len(r["s"])),
    }
    new, rows = {}, []
    for name, (v, n) in est.items():
        default = getattr(defaults.priors, name)
        fitted = max(float(v), MIN_STD) if np.isfinite(v) and n >= MIN_SAMPLES else np.nan
        value = default if np.isnan(fitted) else fitted
        if keep_defaults_as_floor:
            value = max(value, default)
        read = name in LIMB_SIGMAS_READ
        rows.append(dict(tracker="limbs", part="*", parameter=name, default=default, fitted=fitted,
                         applied=value if read else np.nan,
                         n=n, source="truth" if read else "truth; saved, not read by the one-camera tracker"))
        new[f"priors.{name}"] = value
    return defaults.updated(new), pd.DataFrame(rows)


def fit_variances(truths: list[pd.DataFrame], body: BodyParams | None = None,
                  limb: LimbParams | None = None,
                  tracked: list[pd.DataFrame] | None = None) -> tuple[BodyParams, LimbParams, pd.DataFrame]:
    """Both fits at once: ``(BodyParams, LimbParams, table)``."""
    b, tb = fit_body_noise(truths, body, tracked)
    lp, tl = fit_limb_sigmas(truths, limb)
    return b, lp, pd.concat([tb, tl], ignore_index=True)


def comparison_table(table: pd.DataFrame) -> str:
    """The fitted-vs-default table as aligned text (``-`` where the default was kept)."""
    lines = [f"{'tracker':7} {'part':10} {'param':8} {'default':>8} {'fitted':>8} {'applied':>8} {'n':>6}  from"]
    for r in table.itertuples(index=False):
        fitted = f"{r.fitted:8.2f}" if r.fitted is not None and np.isfinite(r.fitted) else f"{'-':>8}"
        applied = getattr(r, "applied", r.default)
        applied = f"{applied:8.2f}" if applied is not None and np.isfinite(applied) else f"{'-':>8}"
        lines.append(f"{r.tracker:7} {r.part:10} {r.parameter:8} {r.default:8.2f} {fitted} {applied} {int(r.n):6d}  "
                     f"{getattr(r, 'source', '')}")
    return "\n".join(lines)


def comparison_figure(table: pd.DataFrame):
    """Plotly grouped bar chart of default, fitted and applied value per parameter."""
    import plotly.graph_objects as go

    label = table["tracker"] + "/" + table["part"] + "/" + table["parameter"]
    fig = go.Figure([
        go.Bar(name="default", x=label, y=table["default"]),
        go.Bar(name="fitted", x=label, y=table["fitted"]),
        go.Bar(name="applied", x=label, y=table.get("applied", table["fitted"])),
    ])
    fig.update_layout(barmode="group", title="Variance parameters: fitted vs default",
                      yaxis_title="std (pixels per frame) / sharpness", xaxis_tickangle=-45)
    return fig
