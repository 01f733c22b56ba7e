"""Parquet and CSV of every box and flag (``tracks.parquet``, ``tracks.csv``) for pandas users.

Both files hold the tracks table exactly (the tracks CSV contract columns); Parquet
keeps the dtypes, the CSV is the same file ``partlab track`` writes.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from partlab.labelling.formats.base import ExportManifest, FormatError, prepare_tracks, select_frames
from partlab.labelling.video import VideoInfo
from partlab.tracking.tracks import TracksCSVError, normalise_tracks, read_tracks_csv, write_tracks_csv

NAME = "parquet"
PARQUET_NAME = "tracks.parquet"
CSV_NAME = "tracks.csv"


def export(df: pd.DataFrame, out_dir: Path, info: VideoInfo, video_path=None, every: int = 1,
           frames: bool = False) -> Path:
    """Write the boxes (frames are never written: use another format for images)."""
    df = prepare_tracks(df, info, video_path)
    df = df[df["frame"].isin(select_frames(df, every))].reset_index(drop=True)
    out_dir.mkdir(parents=True, exist_ok=True)
    df.to_parquet(out_dir / PARQUET_NAME, index=False)
    write_tracks_csv(df, out_dir / CSV_NAME)
    ExportManifest.for_video(NAME, info, every, False).write(out_dir)
    return out_dir


def import_(path: Path, mapping=None) -> pd.DataFrame:
    if path.is_dir():
        path = path / PARQUET_NAME if (path / PARQUET_NAME).is_file() else path / CSV_NAME
    if not path.is_file():
        raise FormatError(f"{path}: expected {PARQUET_NAME} or {CSV_NAME} of a partlab export")
    try:
        if path.suffix == ".parquet":
            df = normalise_tracks(pd.read_parquet(path))
        else:
            df = read_tracks_csv(path)
    except (TracksCSVError, OSError, ValueError) as exc:
        raise FormatError(f"{path}: not a partlab tracks table ({exc})") from None
    df.attrs["skipped"] = {}
    return df
