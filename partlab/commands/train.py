"""``partlab train --clip VIDEO --truth TRUTH.csv [...] -o BUNDLE_DIR``
(or ``--take TAKE --truth TRUTH.csv [...]``: the multi-camera tracker's prior variances).

Fits the four failure SVMs and the variance parameters from corrected clips
(:func:`partlab.models.training.train_bundle`), writes a model bundle and prints the
cross-validation table, the fitted-vs-default variances and which fitted components
validation on the training clips kept (:mod:`partlab.models.selection`).
"""

from __future__ import annotations

from pathlib import Path

from partlab.cli import CommandError, seed


def add_arguments(p) -> None:
    p.add_argument("--clip", metavar="VIDEO", action="append", help="a corrected clip (repeatable)")
    p.add_argument("--take", metavar="TAKE", action="append",
                   help="a corrected multi-camera take (repeatable; instead of --clip): fits the limbs3d "
                        "tracker's prior variances sigma_v, sigma_d, sigma_s from its heads' and hands' X, Y, Z")
    p.add_argument("--truth", metavar="TRUTH.csv", action="append", required=True,
                   help="its corrected boxes, one per --clip (or --take) in the same order")
    p.add_argument("-o", "--output", metavar="BUNDLE_DIR", required=True, help="model bundle directory to write")
    p.add_argument("--seed", type=seed, default=0)
    p.add_argument("--from", dest="start", metavar="MODEL", default="default",
                   help="the model to improve on: 'default' (partlab's shipped bundle), a bundle directory, or "
                        "'none' (the built-in parameters without a failure detector). Its parameters are the "
                        "defaults the fits widen; its detector is kept unless the new one does no worse on "
                        "these clips (default: default)")
    p.add_argument("--no-tracker", action="store_true",
                   help="learn from the corrected boxes only (perturbed truth and failure flags), "
                        "without running the body tracker on the clips")


def _tracker_runner():
    """The body tracker as a training runner, or None when it is not available."""
    try:
        from partlab.models.runner import body_tracker_runner
    except ImportError:
        return None
    return body_tracker_runner


def run(args) -> int:
    if args.take:
        return _train_takes(args)
    if not args.clip:
        raise CommandError("give --clip VIDEO (or --take TAKE) with each --truth")
    return _train_clips(args)


def _train_clips(args) -> int:
    from tqdm import tqdm

    from partlab.labelling.video import VideoClip, VideoError
    from partlab.models.bundle import BundleError, save_bundle
    from partlab.models.training import NothingLearnt, train_bundle, training_steps
    from partlab.tracking.tracks import TracksCSVError, read_tracks_csv

    if len(args.clip) != len(args.truth):
        raise CommandError(f"{len(args.clip)} --clip but {len(args.truth)} --truth; give one --truth per --clip")
    out = Path(args.output)
    if out.exists() and (not out.is_dir() or (any(out.iterdir()) and not (out / "bundle.json").is_file())):
        raise CommandError(f"{out}: exists and is not a model bundle; choose another --output")
    clips, names = [], []
    for video, truth_path in zip(args.clip, args.truth):
        try:
            clip = VideoClip(video)
            truth = read_tracks_csv(truth_path)
        except (VideoError, TracksCSVError) as exc:
            raise CommandError(str(exc)) from None
        if truth.empty:
            raise CommandError(f"{truth_path}: no boxes")
        clips.append((clip.frames, clip.info.fps, truth))
        names.append(Path(video).name)
    start = None
    if args.start != "none":
        from partlab.commands.track import load_model

        start = load_model(args.start)
    runner = None if args.no_tracker else _tracker_runner()
    if runner is None and not args.no_tracker:
        print("partlab train: the body tracker is not available; learning from corrected boxes only")
    with tqdm(total=training_steps(len(clips), runner is not None), desc="training", unit="step") as bar:
        def progress(msg: str) -> None:
            bar.set_postfix_str(msg)
            bar.update(1)
        try:
            bundle = train_bundle(clips, seed=args.seed, progress=progress, tracker_runner=runner, names=names,
                                  start=start)
        except NothingLearnt as exc:
            raise CommandError(f"learnt nothing from {', '.join(names)}: {exc}; no bundle written to {out}") from None
        except ValueError as exc:
            raise CommandError(str(exc)) from None
    if bundle.summary["nothing_learnt"]:
        raise CommandError(f"learnt nothing from {', '.join(names)}: {bundle.summary['nothing_learnt']}; "
                           f"no bundle written to {out}")
    try:
        save_bundle(bundle, out)
    except BundleError as exc:
        raise CommandError(str(exc)) from None
    print(f"wrote {out}  ({bundle.summary['samples']}); learnt: {', '.join(bundle.summary['learnt'])}")
    _print_summary(bundle, args.start)
    return 0


def _print_summary(bundle, start: str) -> None:
    """What training printed after writing the bundle: the SVMs, variances, extents, validation."""
    import pandas as pd

    from partlab.models.failure_svm import SVMReport, report_table
    from partlab.models.variance import comparison_table

    reports = {n: SVMReport.from_dict(d) for n, d in bundle.summary["svms"].items()}
    if any(r.trained or r.n_positive or r.n_negative for r in reports.values()):
        print("\nfailure SVMs (5-fold cross-validation; negative = failure):")
        print(report_table(reports))
    else:
        print("\nfailure SVMs: none trained (no head, torso and hip-leg boxes in the corrections)")
    if "person" in bundle.summary:
        from partlab.models.person import person_table

        print("\nfrom the person boxes (fitted vs start; each kept only if it lowers the edits on these clips):")
        print(person_table(bundle.summary["person"]))
    print("\nvariance parameters (fitted vs default; '-' = default kept):")
    print(comparison_table(pd.DataFrame(bundle.summary["variances"])))
    if "output_extent" in bundle.summary:
        from partlab.models.extent import extent_table
        from partlab.tracking.params import BodyParams

        print("\nreported box extent per part (fitted vs default: scale of the tracked inner rectangle, "
              "shift in its size):")
        fitted = bundle.summary.get("selection", {}).get("fitted_output_extent", bundle.body_params.output.extent)
        table = extent_table({k: tuple(v) for k, v in fitted.items()}, BodyParams().output.extent)
        print(table.pivot(index="part", columns="term", values="fitted").round(3).to_string())
    if "selection" in bundle.summary:
        from partlab.models.selection import selection_table

        print(f"\nvalidation on the training clips, starting from {start!r} (tracking rate per part; noise "
              "and extent are kept only if they raise the mean, the new detector unless it lowers it):")
        print(selection_table(bundle.summary["selection"]))


def _train_takes(args) -> int:
    """The limbs3d prior variances from corrected takes (:func:`partlab.models.limbs3d.fit_from_takes`),
    written as a bundle whose other parameters are the defaults."""
    from partlab.labelling.take import open_take
    from partlab.models.bundle import Bundle, BundleError, save_bundle
    from partlab.models.limbs3d import fit_from_takes
    from partlab.tracking.tracks import TracksCSVError, read_tracks_csv

    if args.clip:
        raise CommandError("give either --clip or --take, not both")
    if len(args.take) != len(args.truth):
        raise CommandError(f"{len(args.take)} --take but {len(args.truth)} --truth; give one --truth per --take")
    out = Path(args.output)
    if out.exists() and (not out.is_dir() or (any(out.iterdir()) and not (out / "bundle.json").is_file())):
        raise CommandError(f"{out}: exists and is not a model bundle; choose another --output")
    try:
        truths = [read_tracks_csv(t) for t in args.truth]
    except TracksCSVError as exc:
        raise CommandError(str(exc)) from None
    takes = [open_take(t) for t in args.take]
    try:
        params, table = fit_from_takes(takes, truths)
    except ValueError as exc:
        raise CommandError(str(exc)) from None
    finally:
        for take in takes:
            take.close()
    if table["fitted"].isna().all():
        raise CommandError(f"learnt nothing from {', '.join(args.take)}: too few true candidate pairs; "
                           f"no bundle written to {out}")
    summary = {"learnt": ["limbs3d sigmas"], "limbs3d_sigmas": table.to_dict("records")}
    try:
        save_bundle(Bundle(summary=summary, more_params={"limbs3d": params}), out)
    except BundleError as exc:
        raise CommandError(str(exc)) from None
    print(f"wrote {out}; limbs3d prior variances (sec. 6.4, maximum likelihood over true candidate pairs):")
    print(table.to_string(index=False))
    return 0
