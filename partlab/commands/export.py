"""``partlab export TRACKS.csv --video VIDEO --format FMT -o OUT``."""

from __future__ import annotations

from partlab.cli import CommandError

FORMATS = ["mot", "cvat", "coco", "yolo", "voc", "parquet", "labelstudio"]


def add_arguments(p) -> None:
    p.add_argument("tracks", metavar="TRACKS.csv")
    p.add_argument("--video", metavar="VIDEO", required=True,
                   help="the clip the boxes were made on (its decoded frame count and fps go into the export)")
    p.add_argument("--format", choices=FORMATS, required=True)
    p.add_argument("-o", "--output", metavar="OUT", required=True, help="output directory")
    p.add_argument("--events", metavar="EVENTS.csv",
                   help="activities to export with the boxes (events.csv; CVAT: events.xml tags; COCO: an events list; "
                        "parquet: events.parquet)")
    p.add_argument("--every", type=int, default=1, metavar="N",
                   help="keep only frames whose index is a multiple of N (default 1: all)")
    p.add_argument("--frames", action=__import__("argparse").BooleanOptionalAction, default=True,
                   help="write the annotated frames as JPEG (default: yes; parquet and labelstudio never write frames)")


def run(args) -> int:
    from partlab.labelling.events import EventsError, read_events
    from partlab.labelling.formats import FormatError, export_dataset
    from partlab.labelling.video import VideoError, probe
    from partlab.tracking.tracks import TracksCSVError, read_tracks_csv

    if args.every < 1:
        raise CommandError(f"--every must be at least 1, got {args.every}")
    try:
        tracks = read_tracks_csv(args.tracks)
        events = read_events(args.events) if args.events else None
        info = probe(args.video)
        out = export_dataset(tracks, args.format, args.output, info, video_path=args.video, every=args.every,
                             frames=args.frames, events=events)
    except (TracksCSVError, VideoError, FormatError, EventsError) as exc:
        raise CommandError(str(exc)) from None
    print(f"exported {len(tracks)} boxes of {tracks['track_id'].nunique()} tracks as {args.format} to {out} "
          f"({info.frame_count} frames at {info.fps:g} fps)")
    return 0
