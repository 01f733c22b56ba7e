"""Training a model bundle from corrected clips (seed 002 sec. 4.2, seed 000 sec. 6.4).

Samples for the four SVMs come from three sources:

1. **the tracker's own output**: each clip is tracked from the truth's first boxes
   (``tracker_runner``) and every tracked part is labelled against the corrected
   box (:func:`partlab.models.labels.label_tracks`), as the paper does by hand;
2. **hand-set failure flags**: truth rows with ``failure`` set and ``source == "human"``
   are tracker boxes a user marked as failed without moving them; they are
   negatives (the other parts of that person and frame are positives) and are left
   out of everything else;
3. **perturbed states** (:mod:`partlab.models.perturb`): simulated single and multi-part
   failures, so that a few clips give enough failures of every kind. With the
   tracker, its own output is perturbed (so the SVMs learn its box geometry) and
   labelled against the truth; without it, the truth is.

The variance parameters are fitted from the truth (:mod:`partlab.models.variance`), the
colour likelihood's sharpness ``lam`` from the corrected boxes on the frames
(:mod:`partlab.models.sharpness`; only where the body tracker's histograms are installed).

With the tracker, every fitted component (noise and ``lam``, output extent, SVM
detector) is then validated on the training clips (:mod:`partlab.models.selection`) and kept
only if it raises the tracking rate there; the summary's ``selection`` records the
scores and decisions.

Person boxes teach what part boxes are not needed for (:mod:`partlab.models.person`): the person
box's extent around the parts, the people detector's threshold and window, when an undetected
track ends, and the person's motion noise. With the tracker, and truth holding person rows, those
are fitted on the earlier corrected frames of each clip and each kept only if it lowers the edits
of the person boxes on the later ones (``TrainingOptions.holdout``; the summary's ``person``). Truth
of person boxes alone (no part box: no SVM sample) therefore still trains a bundle, as long as one
of those is kept.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from partlab.models.bundle import Bundle
from partlab.models.failure_svm import TNR_TARGETS, SVMFailureDetector, train_failure_svms
from partlab.models.features import BODY_PARTS, DEFAULT_DT, features_from_tracks, person_histories
from partlab.models.labels import NEGATIVE, POSITIVE, SVM_NAMES, label_tracks, labels_for_keys
from partlab.models.perturb import PerturbConfig, perturbed_samples
from partlab.models.variance import fit_variances
from partlab.tracking.params import BodyParams, LimbParams
from partlab.tracking.tracks import normalise_tracks

FramesFactory = Callable[[], Iterator[tuple[int, np.ndarray]]]
Clip = tuple[FramesFactory, float, pd.DataFrame]
#: ``runner(frames_factory, fps, init, seed, params=None, failure_detector=None) -> tracks DataFrame``
#: of the body tracker (``params=None``: built-in parameters).
TrackerRunner = Callable[[FramesFactory, float, pd.DataFrame, int], pd.DataFrame]


def first_boxes(truth: pd.DataFrame) -> pd.DataFrame:
    """The truth rows of every track at its first frame (the tracker's ``init``)."""
    truth = normalise_tracks(truth)
    first = truth.groupby("track_id")["frame"].transform("min")
    return truth[truth["frame"] == first].reset_index(drop=True)


def split_human_flags(truth: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``(truth without flagged rows, flagged rows)``; flagged = failure set by a human."""
    truth = normalise_tracks(truth)
    flagged = truth["failure"] & (truth["source"] == "human")
    return truth[~flagged].reset_index(drop=True), truth[flagged].reset_index(drop=True)


def human_flag_samples(truth: pd.DataFrame, fps: float, dt: float = DEFAULT_DT) -> tuple[np.ndarray, np.ndarray]:
    """Features and labels of every person and frame where a user flagged a part as failed."""
    truth = normalise_tracks(truth)
    flagged = truth["failure"] & (truth["source"] == "human") & truth["part"].isin(BODY_PARTS)
    if not flagged.any():
        return np.zeros((0, 24)), np.zeros((0, 3), dtype=np.int8)
    keys, x = features_from_tracks(truth, fps, dt)
    flags = truth[flagged][["track_id", "frame", "part"]]
    wanted = pd.MultiIndex.from_frame(keys).isin(pd.MultiIndex.from_frame(flags[["track_id", "frame"]]))
    keys, x = keys[wanted].reset_index(drop=True), x[wanted]
    labels = np.full((len(keys), 3), POSITIVE, dtype=np.int8)
    for k, part in enumerate(BODY_PARTS):
        f = flags[flags["part"] == part]
        labels[pd.MultiIndex.from_frame(keys).isin(pd.MultiIndex.from_frame(f[["track_id", "frame"]])), k] = NEGATIVE
    return x, labels


def tracker_samples(tracked: pd.DataFrame, truth: pd.DataFrame, fps: float,
                    dt: float = DEFAULT_DT) -> tuple[np.ndarray, np.ndarray]:
    """Features of the tracker's output and its part labels against the truth."""
    tracked = normalise_tracks(tracked)
    keys, x = features_from_tracks(tracked, fps, dt)
    if len(keys) == 0:
        return x, np.zeros((0, 3), dtype=np.int8)
    labels = labels_for_keys(label_tracks(tracked, truth), keys)
    return x, labels


def sharpness_available() -> bool:
    """Whether ``lam`` can be fitted (it needs the body tracker's ``partlab.tracking.core.histogram``)."""
    try:
        import partlab.tracking.core.histogram  # noqa: F401  (only whether it imports)
    except ImportError:
        return False
    return True


def training_steps(n_clips: int, with_tracker: bool, with_sharpness: bool | None = None) -> int:
    """Number of ``progress`` calls :func:`train_bundle` makes (for a progress bar's total)."""
    if with_sharpness is None:
        with_sharpness = sharpness_available()
    person = (1 + n_clips + 5) * int(with_tracker)  # learning from person boxes: start, detections, validations
    return (n_clips * (1 + int(with_tracker) + int(with_sharpness)) + len(SVM_NAMES) + 1 + 4 * int(with_tracker)
            + person)


def _apply_lam(body: BodyParams, table: pd.DataFrame,
               d2: dict[str, list[np.ndarray]]) -> tuple[BodyParams, pd.DataFrame]:
    """Put the ML ``lam`` of every part with enough distances into ``body`` and the table."""
    from partlab.models.sharpness import fit_lam
    from partlab.models.variance import MIN_SAMPLES

    noise = dict(body.dynamics.noise)
    table = table.copy()
    for part, chunks in d2.items():
        values = np.concatenate(chunks) if chunks else np.zeros(0)
        row = (table["tracker"] == "body") & (table["part"] == part) & (table["parameter"] == "lam")
        table.loc[row, "n"] = len(values)
        if len(values) < MIN_SAMPLES or part not in noise:
            continue
        lam = fit_lam(values)
        noise[part] = replace(noise[part], lam=lam)
        table.loc[row, "fitted"] = lam
        table.loc[row, "applied"] = lam
    return body.updated({"dynamics.noise": noise}), table


@dataclass(frozen=True)
class TrainingOptions:
    """How :func:`train_bundle` trains (everything but the data and where it starts).

    ``seed``: the random stream of perturbation and SVM cross-validation (clip ``i`` is tracked
    with ``seed + i``); ``perturbed_per_person``: simulated failures per person and clip;
    ``dt``: the failure features' time step (Zhao & Lee sec. 4.2: 0.5 s); ``fit_sharpness``
    (None: when available) decodes each clip once more to fit ``lam``; ``validate`` (with a
    tracker): keep each fitted component only if it does not lower the tracking rate on the
    training clips (:func:`partlab.models.selection.select_components`; up to three more tracker
    runs per clip); without it, everything fitted is used. ``person`` (None: when the truth has
    person rows and the tracker runs): learn from the person boxes too
    (:mod:`partlab.models.person`: one detector pass and up to five more tracker runs per clip);
    ``validation_seeds``: how many tracker seeds each person-box component is validated over, each run
    from the corrected boxes where the validated frames begin, the same seeds for the models compared;
    ``validation_margin``: a component is kept only if its mean paired gain in soft edits
    (:func:`partlab.models.person.select_person`) reaches this many standard errors of it (one seed's
    edits on PETS09 vary by 5-15 per 100 boxes for the same model, so one run, or "lower on every
    seed", decides by chance);
    ``holdout``: the share of each clip's corrected frames (its last ones) the person-box components
    are validated on and not fitted on, so that what is kept is what carries over to later frames
    (0: fitted and validated on the same frames)."""

    seed: int = 0
    perturbed_per_person: int = 300
    dt: float = DEFAULT_DT
    fit_sharpness: bool | None = None
    validate: bool = True
    person: bool | None = None
    validation_seeds: int = 8
    validation_margin: float = 1.0
    holdout: float = 0.35


@dataclass
class _Samples:
    """What the clips gave: SVM samples, clean truths, per-clip records, tracker runs, colour distances."""

    xs: list = field(default_factory=list)
    ys: list = field(default_factory=list)
    truths: list = field(default_factory=list)
    clip_info: list = field(default_factory=list)
    tracked_runs: list = field(default_factory=list)
    counts: dict = field(default_factory=lambda: {"tracker": 0, "human_flags": 0, "perturbed": 0})
    d2: dict = field(default_factory=dict)


def train_bundle(clips: list[Clip], options: TrainingOptions | None = None, *,
                 progress: Callable[[str], None] | None = None, tracker_runner: TrackerRunner | None = None,
                 names: Iterable[str] | None = None, start=None, body: BodyParams | None = None,
                 limb: LimbParams | None = None, **option_values) -> Bundle:
    """Fit the four failure SVMs and the variance parameters from corrected clips.

    ``clips``: ``(frames_factory, fps, truth_df)`` each; ``frames_factory()`` yields
    ``(index, frame)``. Without ``tracker_runner`` (or where it fails on a clip) only
    perturbed-truth and hand-flag samples are used; the summary records how many of
    each. ``progress`` is called once per step with a short description. ``options``
    (:class:`TrainingOptions`; its fields may also be given as keywords: ``seed=3``).
    ``start``: the bundle training starts from (e.g. :func:`partlab.models.bundle.default_bundle`):
    its body parameters are the defaults the fits widen, and validation starts from its
    parameters *and* its failure detector, which the new detector replaces only if that does
    not lower the rate, so retraining never scores below ``start`` on the training clips.
    None: the built-in parameters without a detector (or ``body`` / ``limb``).
    """
    opts = replace(options or TrainingOptions(), **option_values)
    if not clips:
        raise ValueError("no clips to train from")
    start_detector = None
    if start is not None:
        body = body or start.body_params
        limb = limb or start.limb_params
        start_detector = start.failure_detector
    names = list(names) if names is not None else [f"clip{i}" for i in range(len(clips))]
    if len(names) != len(clips):
        raise ValueError(f"{len(names)} names for {len(clips)} clips")
    from partlab.models.person import has_person_rows, person_only

    if all(person_only(normalise_tracks(t)) for _f, _fps, t in clips):
        opts = replace(opts, fit_sharpness=False)  # lam is a part's: person boxes cannot give it
    if opts.fit_sharpness is None:
        opts = replace(opts, fit_sharpness=sharpness_available())
    check_span(clips, names, opts.dt)
    clips = [(_until(factory, truth), fps, truth) for factory, fps, truth in clips]
    step = progress or (lambda _msg: None)
    rng = np.random.default_rng(opts.seed)
    got = _Samples()
    for i, ((factory, fps, truth), name) in enumerate(zip(clips, names)):
        _clip_samples(got, i, factory, fps, truth, name, opts, rng, step, tracker_runner, body)
    x_all = np.concatenate(got.xs, axis=0) if got.xs else np.zeros((0, 0))
    y_all = np.concatenate(got.ys, axis=0) if got.ys else np.zeros(0)
    with_person = (opts.person is not False and bool(got.tracked_runs)
                   and any(has_person_rows(t) for t in got.truths))
    if len(x_all) == 0 and not with_person:
        raise NothingLearnt("no training samples: the truth has no person with head, torso and hip-leg boxes "
                            "(person boxes alone teach the failure SVMs nothing"
                            + (", and what they teach the tracker needs it: train without --no-tracker)"
                               if tracker_runner is None else ")"))
    models, reports = ({}, {}) if len(x_all) == 0 else train_failure_svms(
        x_all, y_all, seed=opts.seed, progress=lambda n: step(f"SVM {n}"))
    body_p, limb_p, table = _fit_parameters(got, body, limb, opts, step)
    detector = SVMFailureDetector(models, dt=opts.dt) if models else None
    selection = None
    parts = not all(person_only(t) for t in got.truths)
    if got.tracked_runs and opts.validate and parts:
        body_p, detector, table, selection = _validate(clips, got, body, body_p, detector, table, opts, step,
                                                       tracker_runner, start, start_detector)
    elif not parts:  # person boxes only: the parts' fits have nothing to go on, the start stays
        body_p, detector = (body or BodyParams()), start_detector
        body_rows = table["tracker"] == "body"
        table.loc[body_rows, "applied"] = table.loc[body_rows, "default"]
    person = None
    if with_person:
        body_p, person = _learn_from_people(clips, got, body_p, detector, table, opts, step, tracker_runner)
    summary = {
        "seed": opts.seed,
        "clips": got.clip_info,
        "samples": {**got.counts, "total": int(len(x_all))},
        "svms": {n: r.to_dict() for n, r in reports.items()},
        "tnr_targets": dict(TNR_TARGETS),
        "thresholds": {n: r.threshold for n, r in reports.items()},
        "variances": table.to_dict(orient="records"),
        "output_extent": {k: list(v) for k, v in body_p.output.extent.items()},
        "notes": [] if opts.fit_sharpness else ["lam (colour likelihood sharpness) not fitted: defaults kept"],
    }
    if selection is not None:
        summary["selection"] = selection
    if person is not None:
        summary["person"] = person
    new_detector = detector is not None and detector is not start_detector
    summary["learnt"], summary["nothing_learnt"] = learnt(summary, new_detector)
    return Bundle(body_p, limb_p, detector, summary)


def _until(factory: FramesFactory, truth: pd.DataFrame) -> FramesFactory:
    """``factory``'s frames up to the truth's last frame: frames nobody corrected teach nothing
    (a user who corrected frames 0-200 of a long clip trains on those, not on the whole clip)."""
    frames = normalise_tracks(truth)["frame"]
    last = int(frames.max()) if len(frames) else -1

    def frames_until():
        for index, frame in factory():
            if index > last:
                return
            yield index, frame
    return frames_until


def _learn_from_people(clips, got: _Samples, body_p: BodyParams, detector, table: pd.DataFrame,
                       opts: TrainingOptions, step, tracker_runner) -> tuple[BodyParams, dict]:
    """The person-box fits of :mod:`partlab.models.person` on top of ``body_p`` (what the parts
    gave), each kept only where it lowers the person boxes' error on the training clips:
    ``(params, the summary's "person" record)``."""
    from partlab.models.person import before_cut, fit_person, select_person

    n = len(clips)
    inits = [first_boxes(g) for g in got.truths]
    # fit on each clip's earlier corrected frames, validate on its later ones: the user tracks the
    # rest of the clip with what is kept, so a component must carry over in time, not only fit the
    # frames it was fitted on (PETS09 frames 0-199: the detector window and the ending won on the
    # frames they were fitted on and cost edits on frames 200-794, docs/measurements)
    cuts = [holdout_cut(g, opts.holdout if opts.validate else 0.0) for g in got.truths]
    fit_truths = [before_cut(g, c) for g, c in zip(got.truths, cuts)]
    fit_clips = [_window(clips[i][0], -np.inf, c if np.isfinite(c) else np.inf) for i, c in enumerate(cuts)]

    def fit_runs(params) -> list[pd.DataFrame]:
        return [before_cut(tracker_runner(fit_clips[i], clips[i][1], inits[i], opts.seed + i, params=params,
                                          failure_detector=detector), cuts[i]) for i in range(n)]

    step("tracking with the start")
    base_fit_tracks = fit_runs(body_p)
    fit = fit_person(clips, fit_truths, base_fit_tracks, body_p, table, progress=step)
    if not opts.validate:
        chosen = body_p
        for changes in fit.components.values():
            chosen = chosen.updated(changes)
        return chosen, {**fit.record, "fitted": sorted(fit.components), "kept": {c: True for c in fit.components},
                        "fields": sorted(f for changes in fit.components.values() for f in changes)}
    if not fit.components:
        return body_p, {**fit.record, "fitted": [], "kept": {}, "fields": []}
    # validation runs start where the user's tracking of the rest would: from the corrected boxes at
    # the cut (and each later person's first), with the background model starting there too, over
    # several tracker seeds paired between the models compared. Run from the clip's first boxes, a
    # walker lost before the cut cost edits on every scored frame, whatever the component did after it
    val_truths = [g[g["frame"] >= c] for g, c in zip(got.truths, cuts)]
    val_inits = [first_boxes(g) for g in val_truths]
    val_clips = [_window(clips[i][0], c, np.inf) for i, c in enumerate(cuts)]
    n_seeds = max(int(opts.validation_seeds), 1)
    jobs = [(i, k) for k in range(n_seeds) for i in range(n)]

    def run(j, params):
        i, k = jobs[j]
        return tracker_runner(val_clips[i], clips[i][1], val_inits[i], opts.seed + i + 1000 * (k + 1), params=params,
                              failure_detector=detector)

    def refit_runs(params):
        return base_fit_tracks if params is body_p else fit_runs(params)

    chosen, record = select_person(run, [val_truths[i] for i, _k in jobs], body_p, fit, progress=step,
                                   groups=[k for _i, k in jobs], cuts=[cuts[i] for i, _k in jobs],
                                   fit_runs=refit_runs, fit_truths=fit_truths, margin=opts.validation_margin)
    return chosen, {**fit.record, "fitted": sorted(fit.components), **record}


def _window(factory: FramesFactory, first: float, stop: float) -> FramesFactory:
    """``factory``'s frames from ``first`` up to (not including) ``stop``."""
    def frames():
        for index, frame in factory():
            if index >= stop:
                return
            if index >= first:
                yield index, frame
    return frames


def holdout_cut(truth: pd.DataFrame, share: float) -> float:
    """The first frame of ``truth``'s last ``share`` of corrected frames (what validation scores
    and the fits do not see); ``-inf`` (all frames both fitted and scored) for ``share`` 0 or a
    stretch too short to split (fewer than :data:`MIN_HOLDOUT_FRAMES` on either side)."""
    frames = np.sort(normalise_tracks(truth)["frame"].unique())
    k = int(round(len(frames) * (1.0 - share)))
    if share <= 0 or min(k, len(frames) - k) < MIN_HOLDOUT_FRAMES:
        return -np.inf
    return float(frames[k])


#: frames each side of the holdout split needs (fewer: the person boxes are fitted and validated on
#: all corrected frames)
MIN_HOLDOUT_FRAMES = 10


def check_span(clips: list[Clip], names: list[str], dt: float) -> None:
    """Refuse truth too short to learn from: the failure features compare each frame with the
    one ``dt`` seconds before, and the variances need consecutive frames."""
    spans = []
    for _factory, fps, truth in clips:
        frames = normalise_tracks(truth)["frame"]
        spans.append(int(frames.max() - frames.min()) + 1 if len(frames) else 0)
        if spans[-1] > dt * fps:
            return
    need = max(int(np.ceil(dt * clips[0][1])) + 1, 2)
    raise NothingLearnt(f"the corrections span {max(spans)} frame(s) ({', '.join(names)}): that teaches neither "
                        f"the dynamics nor the failures; correct at least {need} consecutive frames ({dt:g} s)")


def _differs(a, b) -> bool:
    try:
        return bool(np.isfinite(a) and np.isfinite(b) and abs(float(a) - float(b)) > 1e-9)
    except TypeError:
        return False


#: how :func:`learnt` names the person-box components (:mod:`partlab.models.person`)
PERSON_COMPONENTS = {"extent": "person box extent", "detector": "detector threshold and window",
                     "steer": "detection steering gain", "velocity": "detection velocity gain",
                     "ending": "undetected-track ending", "noise": "part noise from person motion"}


class NothingLearnt(ValueError):
    """Training ran but the bundle would be its start again: nothing to save or make a default."""


def learnt(summary: dict, new_detector: bool) -> tuple[list[str], str]:
    """What a trained bundle holds beyond the model it started from, and, when that is nothing,
    why (in a sentence). Validation decides where it ran; without it, every fitted component
    (a trained SVM, a noise or ``lam`` other than its default) counts."""
    got = []
    got += [f"{PERSON_COMPONENTS.get(c, c)} (validated, from person boxes)"
            for c, kept in summary.get("person", {}).get("kept", {}).items() if kept]
    selection = summary.get("selection")
    if selection is not None:
        got += [f"{c} (validated)" for c, kept in selection.get("kept", {}).items() if kept and c != "detector"]
        if selection.get("detector") == "new":
            got.append("failure detector (validated)")
    else:
        got += [f"SVM {n}" for n, r in summary.get("svms", {}).items() if r.get("trained")] if new_detector else []
        got += sorted({f"{r['tracker']} {r['part']} {r['parameter']}" for r in summary.get("variances", [])
                       if r.get("n") and _differs(r.get("applied"), r.get("default"))})
    if got:
        return got, ""
    samples = summary.get("samples", {})
    untrained = [n for n, r in summary.get("svms", {}).items() if not r.get("trained")]
    why = []
    if untrained:
        counts = ", ".join(f"{n} {summary['svms'][n].get('n_positive', 0)}/{summary['svms'][n].get('n_negative', 0)}"
                           for n in untrained)
        why.append(f"too few samples for the failure SVMs (right/failed: {counts}; 5 of each are needed)")
    if not any(r.get("n") for r in summary.get("variances", [])):
        why.append("too few corrected frames per track to fit the variances")
    person = summary.get("person")
    if person is not None:
        why.append("nothing fitted from the person boxes (" + (", ".join(person.get("fitted", [])) or "none fitted")
                   + ") lowered the person boxes' error on the training clips beyond the tracker seeds' "
                   "spread" if person.get("fitted") else
                   "the person boxes gave nothing to fit (too few frames where the tracker or the detector "
                   "was on a corrected person)")
    if selection is not None and not why:
        why.append("nothing fitted tracked the training clips better than the model it started from")
    if not why:
        why.append(f"every fitted value equals the model it started from ({samples.get('total', 0)} samples)")
    return [], "; ".join(why)


def _clip_samples(got: _Samples, i: int, factory: FramesFactory, fps: float, truth: pd.DataFrame, name: str,
                  opts: TrainingOptions, rng: np.random.Generator, step, tracker_runner, body) -> None:
    """One clip's samples: the tracker's own output labelled against the truth, the colour
    distances for ``lam``, the hand-set flags and perturbed states (see the module docstring)."""
    truth_clean, _ = split_human_flags(truth)
    got.truths.append(truth_clean)
    info = {"name": name, "fps": float(fps), "people": int(truth_clean["track_id"].nunique()),
            "frames": int(truth_clean["frame"].nunique())}
    tracked = None
    from partlab.models.person import person_only

    parts = not person_only(truth_clean)  # person boxes alone label no part: no SVM sample
    if tracker_runner is not None:
        step(f"tracking {name}")
        tracked = tracker_runner(factory, fps, first_boxes(truth_clean), opts.seed + i)
        got.tracked_runs.append((tracked, truth_clean))
        x, y = tracker_samples(tracked, truth_clean, fps, opts.dt) if parts else (np.zeros((0, 24)),
                                                                                  np.zeros((0, 3), np.int8))
        got.xs.append(x)
        got.ys.append(y)
        got.counts["tracker"] += len(x)
        info["tracker_samples"] = len(x)
        info["tracker_failures"] = int(np.sum(np.any(y == NEGATIVE, axis=1)))
    if opts.fit_sharpness:
        from partlab.models.sharpness import colour_distances
        step(f"colours of {name}")
        for part, values in colour_distances(factory, truth_clean, body or BodyParams()).items():
            got.d2.setdefault(part, []).append(values)
    step(f"samples of {name}")
    x, y = human_flag_samples(truth, fps, opts.dt)
    got.xs.append(x)
    got.ys.append(y)
    got.counts["human_flags"] += len(x)
    n_pert = 0
    for x, y in _perturbed(truth_clean, tracked, fps, opts, rng) if parts else ():
        got.xs.append(x)
        got.ys.append(y)
        n_pert += len(x)
    got.counts["perturbed"] += n_pert
    got.clip_info.append(info)


def _perturbed(truth: pd.DataFrame, tracked: pd.DataFrame | None, fps: float, opts: TrainingOptions,
               rng: np.random.Generator) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Simulated failures: on the tracker's own boxes (its geometry) labelled against the truth
    when it ran, else on the truth."""
    true_hist = person_histories(truth)
    if tracked is None:
        for _tid, (frames, hist) in true_hist.items():
            yield perturbed_samples(frames, hist, fps, opts.perturbed_per_person, rng, PerturbConfig(), dt=opts.dt)
        return
    for tid, (frames, hist) in person_histories(tracked).items():
        aligned = np.full(hist.shape, np.nan)
        if tid in true_hist:
            tf, th = true_hist[tid]
            pos = np.searchsorted(tf, frames)
            hit = (pos < len(tf)) & (tf[np.minimum(pos, len(tf) - 1)] == frames)
            aligned[hit] = th[pos[hit]]
        yield perturbed_samples(frames, hist, fps, opts.perturbed_per_person, rng, PerturbConfig(), dt=opts.dt,
                                truth=aligned)


def _fit_parameters(got: _Samples, body, limb, opts: TrainingOptions, step):
    """Variance parameters from the truth, ``lam`` from the frames, the output extent from the
    tracker's runs: ``(BodyParams, LimbParams, table)``."""
    step("variance parameters")
    # the tracker's prediction errors are not used for the noise (measured worse, see partlab.models.variance)
    body_p, limb_p, table = fit_variances(got.truths, body, limb)
    if opts.fit_sharpness:
        body_p, table = _apply_lam(body_p, table, got.d2)
    if got.tracked_runs:
        from partlab.models.extent import fit_output_extent

        step("output extent")
        current = (body or BodyParams()).output.extent
        body_p = body_p.updated({"output.extent": fit_output_extent([t for t, _ in got.tracked_runs],
                                                                    [g for _, g in got.tracked_runs], current)})
    return body_p, limb_p, table


def _validate(clips, got: _Samples, body, body_p: BodyParams, detector, table: pd.DataFrame, opts: TrainingOptions,
              step, tracker_runner, start, start_detector):
    """Keep each fitted component only where it does not lower the rate on the training clips
    (:mod:`partlab.models.selection`): ``(body params, detector, table, selection record)``."""
    from partlab.models.selection import select_components

    base = body or BodyParams()
    inits = [first_boxes(g) for g in got.truths]

    def run(i, params, det):
        return tracker_runner(clips[i][0], clips[i][1], inits[i], opts.seed + i, params=params, failure_detector=det)

    fitted = base.updated({"dynamics.noise": body_p.dynamics.noise, "output.extent": body_p.output.extent})
    chosen = select_components(run, got.truths, base, fitted, detector,
                               base_tracks=[t for t, _ in got.tracked_runs] if body is None else None,
                               progress=step, base_detector=start_detector)
    body_p = body_p.updated({"dynamics.noise": chosen.body_params.dynamics.noise,
                             "output.extent": chosen.body_params.output.extent})
    new_detector = detector
    detector = chosen.failure_detector
    selection = chosen.to_dict()
    selection["fitted_output_extent"] = {k: list(v) for k, v in fitted.output.extent.items()}
    selection["started_from"] = "a bundle" if start is not None else "built-in"
    selection["start_detector"] = start_detector is not None
    selection["detector"] = ("new" if detector is not None and detector is new_detector else
                             "start's" if detector is not None else "none")
    if not chosen.kept["noise"]:  # the table's "applied" says what the bundle uses
        body_rows = table["tracker"] == "body"
        table.loc[body_rows, "applied"] = table.loc[body_rows, "default"]
    return body_p, detector, table, selection


def iterate_frames(frames: np.ndarray) -> FramesFactory:
    """A frames factory over an in-memory ``(T, H, W, 3)`` array (synthetic scenes)."""
    def factory():
        return ((i, frames[i]) for i in range(len(frames)))
    return factory
