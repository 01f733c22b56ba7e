"""``partlab track VIDEO|TAKE_DIR -o TRACKS.csv``: run a tracker over a clip or take, write a tracks CSV."""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

from partlab.cli import CommandError, describe_os_error, seed


def add_arguments(p) -> None:
    from partlab.tracking import registry

    p.add_argument("video", metavar="VIDEO|TAKE_DIR",
                   help="input clip (any format OpenCV decodes) or a take folder (docs/formats.md)")
    p.add_argument("-o", "--output", metavar="TRACKS.csv", required=True, help="tracks CSV to write")
    p.add_argument("--tracker", choices=registry.names(), default="body",
                   help="; ".join(f"{e.name}: {e.summary}" for e in registry.TRACKERS.values()))
    p.add_argument("--init", metavar="INIT.csv", help="start tracks from these boxes instead of detecting people")
    p.add_argument("--keyframes", metavar="KEYS.csv",
                   help="boxes drawn on some frames (any tracks, any parts): each track is tracked forward and "
                        "backward between its consecutive keyframes and the two blended, meeting every keyframe "
                        "exactly; frames to look at are flagged (failure column, state 'review')")
    p.add_argument("--model", metavar="BUNDLE_DIR",
                   help="model bundle from partlab train, or 'default' for the one shipped with partlab "
                        "(failure detection and adjustment on); without it: the built-in parameters, no "
                        "failure detection")
    p.add_argument("--seed", type=seed, default=0, help="random seed; the same seed gives the same output")
    p.add_argument("--events", metavar="EVENTS.csv",
                   help="write the events the tracker recognises (limbs/all: joins and separations)")
    p.add_argument("--occluders", metavar="FILE",
                   help="CSV with columns x,y,w,h: fixed regions (pillars, doors) that can hide people")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=True,
                   help="show a progress bar (default: on; --no-progress to hide it)")


def read_occluders(path: str | Path):
    """Occluder regions from a CSV with a header containing x,y,w,h (pixels)."""
    from partlab.tracking.core.box import Box

    p = Path(path)
    if not p.is_file():
        raise CommandError(f"{p}: no such occluders file")
    out = []
    with p.open(newline="", encoding="utf-8-sig") as fh:
        reader = csv.DictReader(fh)
        cols = [c.strip() for c in (reader.fieldnames or [])]
        missing = [c for c in ("x", "y", "w", "h") if c not in cols]
        if missing:
            raise CommandError(f"{p} line 1: missing column(s) {', '.join(missing)}; expected a header x,y,w,h")
        for lineno, row in enumerate(reader, start=2):
            row = {k.strip(): v for k, v in row.items() if k is not None}
            try:
                x, y, w, h = (float(row[c]) for c in ("x", "y", "w", "h"))
            except (TypeError, ValueError):
                raise CommandError(f"{p} line {lineno}: x,y,w,h must be numbers, got "
                                   f"{','.join(str(row.get(c)) for c in ('x', 'y', 'w', 'h'))}") from None
            if w <= 0 or h <= 0:
                raise CommandError(f"{p} line {lineno}: occluder size must be positive, got {w:g} x {h:g}")
            out.append(Box(x, y, w, h))
    return out


def load_model(path: str | Path):
    """A model bundle by directory, or the shipped one by the name ``default``."""
    from partlab.models import bundle

    try:
        if str(path) == "default" and not Path(path).exists():
            return bundle.default_bundle()
        return bundle.load_bundle(path)
    except (OSError, ValueError) as exc:
        raise CommandError(f"{path}: cannot load model bundle: {exc}") from None


def write_events(events, args) -> None:
    """``--events``: the tracker's events table, written atomically."""
    if events is None:
        raise CommandError(f"--events: tracker {args.tracker!r} recognises no events "
                           "(limbs and all write the hands' activities)")
    from partlab.files import replacing

    try:
        with replacing(args.events) as tmp:
            events.to_csv(tmp, index=False, lineterminator="\n")
    except OSError as exc:
        raise CommandError(f"{args.events}: cannot write: {describe_os_error(exc)}") from None
    kinds = events["kind"].value_counts().to_dict() if len(events) else {}
    print(f"wrote {len(events)} event(s) to {args.events}"
          + (f" ({', '.join(f'{v} {k}' for k, v in kinds.items())})" if kinds else ""))


def run(args) -> int:
    from partlab.app.pipeline import track_path
    from partlab.tracking.tracks import (
        TracksCSVError,
        read_track_records,
        read_tracks_csv,
        write_track_records,
        write_tracks_csv,
    )

    init = None
    if args.init:
        try:
            init = read_track_records(args.init)  # rows, not a table: a short run need not import pandas
        except TracksCSVError as exc:
            raise CommandError(str(exc)) from None
        if not init:
            raise CommandError(f"{args.init}: no boxes to start from")
    keyframes = None
    if args.keyframes:
        if args.init:
            raise CommandError("--keyframes and --init: give one of them (a track's first keyframe is its start)")
        try:
            keyframes = read_tracks_csv(args.keyframes)
        except TracksCSVError as exc:
            raise CommandError(str(exc)) from None
        if keyframes.empty:
            raise CommandError(f"{args.keyframes}: no keyframe boxes")
    occluders = read_occluders(args.occluders) if args.occluders else ()
    model = load_model(args.model) if args.model else None
    bar = None

    def progress(done: int, total: int) -> None:
        nonlocal bar
        if bar is None:
            from tqdm import tqdm  # only with --progress

            bar = tqdm(total=total, unit="frame", desc="tracking")
        bar.update(done - bar.n)

    try:
        if keyframes is not None:
            from partlab.labelling.take import open_take
            from partlab.tracking.keyframes import track_with_keyframes

            with open_take(args.video) as take:
                result = track_with_keyframes(take, keyframes, tracker=args.tracker, model=model, seed=args.seed,
                                              progress=progress if args.progress else None)
        else:
            result = track_path(args.video, args.tracker, init=init, model=model, occluders=occluders,
                                seed=args.seed, progress=progress if args.progress else None)
    finally:
        if bar is not None:
            bar.close()
    records = result.records  # a single-view run's rows: written without making the table
    try:
        if records is not None:
            write_track_records(records, args.output)
        else:
            write_tracks_csv(result.tracks, args.output)
    except OSError as exc:
        raise CommandError(f"{args.output}: cannot write: {describe_os_error(exc)}") from None
    ids = [r.track_id for r in records] if records is not None else result.tracks["track_id"].tolist()
    print(f"wrote {len(ids)} boxes of {len(set(ids))} track(s) to {args.output}")
    if args.events:
        write_events(result.events, args)
    return 0
