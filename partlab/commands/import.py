"""``partlab import PATH --format FMT -o TRACKS.csv``."""

from __future__ import annotations

import sys

from partlab.cli import CommandError

FORMATS = ["mot", "cvat", "coco", "parquet", "labelstudio"]


def add_arguments(p) -> None:
    p.add_argument("path", metavar="PATH",
                   help="the format's file or directory, our export directory, or a zip/tar of one")
    p.add_argument("--format", choices=FORMATS, required=True)
    p.add_argument("-o", "--output", metavar="TRACKS.csv", required=True)
    p.add_argument("--mapping", metavar="MAP", default=None,
                   help="their labels (or class ids) to our parts: 'face=head,1=person', a JSON object or a .json file")
    p.add_argument("--video", metavar="VIDEO", default=None,
                   help="the clip annotated: refuse a different frame count or boxes past its last frame, and "
                        "line the frames up by the dataset's images when it has them")
    p.add_argument("--frame-offset", type=int, default=0, metavar="K",
                   help="add K to every frame read (-1 for files numbered from 1 that are not MOT)")


def run(args) -> int:
    from partlab.labelling.formats import FormatError, import_dataset
    from partlab.labelling.video import VideoError
    from partlab.tracking.tracks import write_tracks_csv

    try:
        df = import_dataset(args.path, args.format, mapping=args.mapping, video=args.video,
                            frame_offset=args.frame_offset)
    except (FormatError, VideoError) as exc:
        raise CommandError(str(exc)) from None
    write_tracks_csv(df, args.output)
    if df.attrs.get("frame_shift"):
        print(f"partlab import: frames shifted by {df.attrs['frame_shift']:+d} to match the clip "
              f"({df.attrs.get('frame_check', '')})", file=sys.stderr)
    for label, n in sorted(df.attrs.get("skipped", {}).items()):
        print(f"partlab import: skipped {n} boxes labelled {label!r} (no matching part; see --mapping)",
              file=sys.stderr)
    print(f"imported {len(df)} boxes of {df['track_id'].nunique()} tracks, frames "
          f"{int(df['frame'].min())}..{int(df['frame'].max())}, to {args.output}")
    return 0
