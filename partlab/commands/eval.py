"""``partlab eval TRUTH.csv TRACKS.csv [--at 105] [--json] [--plot OUT.html] [--truth3d TRUTH3D.csv]``, and
``partlab eval TRUTH_EVENTS.csv EVENTS.csv --events``: per-kind precision and recall of activities.

For a take of several views (truth and tracks with a ``camera`` column) the 2D rates are reported
per view; with ``--truth3d`` (or a ``truth3d.csv`` beside TRUTH.csv) also the mean 3D error in mm
per part."""

from __future__ import annotations

from pathlib import Path

from partlab.cli import CommandError


def add_arguments(p) -> None:
    p.add_argument("truth", metavar="TRUTH.csv")
    p.add_argument("tracks", metavar="TRACKS.csv")
    p.add_argument("--at", type=int, default=105, metavar="I",
                   help="frame offset after initialisation for the headline rate (seed 002 uses 105)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--plot", metavar="OUT.html", default=None,
                   help="write the rate-against-frame-offset figure (self-contained HTML)")
    p.add_argument("--match", choices=["auto", "id", "iou"], default="auto",
                   help="match tracks to truth by track_id, by mean IoU (Hungarian), or auto (default)")
    p.add_argument("--truth3d", metavar="TRUTH3D.csv", default=None,
                   help="3D truth (frame,track_id,part,X,Y,Z mm): report the mean 3D error per part "
                        "(default: truth3d.csv beside TRUTH.csv when the tracks carry X,Y,Z)")
    p.add_argument("--events", action="store_true",
                   help="the two files are events (truth, then found: partlab track --events): per-kind "
                        "precision and recall at temporal IoU >= --event-iou")
    p.add_argument("--event-iou", type=float, default=0.5, metavar="IOU",
                   help="temporal IoU an event needs to match the truth (default 0.5)")


def _format(report) -> str:
    import pandas as pd

    with pd.option_context("display.width", 120, "display.max_columns", 20, "display.float_format",
                           "{:.3f}".format):
        mot = report.mot.copy()
        for c in ("num_switches", "num_false_positives", "num_misses", "num_objects"):
            if c in mot:
                mot[c] = mot[c].astype(int)
        return (f"{report.note}\n\ntracking rate (seed 002): rate_at = at frame offset {report.at}, "
                f"rate_mean = averaged over offsets\n{report.summary}\n\nMOT metrics (motmetrics, IoU >= 0.5)\n"
                f"{mot}\n")


def _run_events(args) -> int:
    from partlab.labelling.events import evaluate_events, read_events

    if not 0 < args.event_iou <= 1:
        raise CommandError(f"--event-iou must be in (0, 1], got {args.event_iou}")
    table = evaluate_events(read_events(args.truth), read_events(args.tracks), iou=args.event_iou)
    if args.json:
        print(table.reset_index().to_json(orient="records"))
    else:
        print(f"events matched at temporal IoU >= {args.event_iou:g} (same kind, one to one)\n"
              f"{table.round(3).to_string()}")
    return 0


def run(args) -> int:
    if args.events:
        return _run_events(args)
    from partlab.labelling.evaluation import EvaluationError, evaluate, rate_curve_figure
    from partlab.tracking.tracks import TracksCSVError, read_tracks_csv

    if args.at < 0:
        raise CommandError(f"--at must be a frame offset >= 0, got {args.at}")
    try:
        truth = read_tracks_csv(args.truth)
        tracks = read_tracks_csv(args.tracks)
        if (truth["camera"] != "").any() and (tracks["camera"] != "").any():
            return _run_take(args, truth, tracks)
        report = evaluate(truth, tracks, at=args.at, matching=args.match)
    except (TracksCSVError, EvaluationError) as exc:
        raise CommandError(str(exc)) from None
    if args.plot:
        out = Path(args.plot)
        out.parent.mkdir(parents=True, exist_ok=True)
        rate_curve_figure(report).write_html(str(out), include_plotlyjs=True)
    print(report.to_json() if args.json else _format(report), end="\n" if args.json else "")
    return 0


def _run_take(args, truth, tracks) -> int:
    """Several views: 2D rates per view and, with 3D truth, the mean 3D error per part."""
    import json

    import pandas as pd

    from partlab.labelling.evaluation import error_3d, evaluate_views, read_truth3d

    views = evaluate_views(truth, tracks, at=args.at)
    path3d = Path(args.truth3d) if args.truth3d else Path(args.truth).with_name("truth3d.csv")
    err = None
    if args.truth3d or (path3d.is_file() and tracks[["X", "Y", "Z"]].notna().any(axis=None)):
        err = error_3d(tracks, read_truth3d(path3d))
    if args.json:
        print(json.dumps({"views": {c: json.loads(r.to_json()) for c, r in views.items()},
                          "error_3d": None if err is None else err.reset_index().to_dict(orient="records")}))
        return 0
    with pd.option_context("display.width", 120, "display.float_format", "{:.3f}".format):
        if err is not None:
            print(f"3D error per part (mm, {path3d.name})\n{err}\n")
        parts = set(tracks["part"])
        for cam, r in views.items():
            summary = r.summary[r.summary.index.isin(parts)]  # the parts this tracker writes
            print(f"view {cam}: tracking rate (rate_at = at frame offset {r.at})\n{summary}\n")
    return 0
