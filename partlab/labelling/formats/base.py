"""What every format module shares: the export manifest, input checks and label mapping.

Frame numbering is one rule everywhere: the decoder's 0-based frame index
(:mod:`partlab.labelling.video`). Every export directory holds ``partlab.json`` stating the
fps, frame size and frame count of the clip it was made from, so an import can refuse
a clip whose frame count differs from the one annotated. Formats that count from 1
(MOTChallenge frames and ids, COCO image ids) add 1 on export and subtract it on import.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from partlab.labelling.video import VideoInfo, probe
from partlab.tracking.parts import PART_NAMES
from partlab.tracking.tracks import TracksCSVError, check_rows, normalise_tracks

MANIFEST_NAME = "partlab.json"
MANIFEST_VERSION = 1

#: Label names other tools commonly use for our parts (lower-cased); ``--mapping`` adds more.
DEFAULT_ALIASES: dict[str, str] = {
    **{p: p for p in PART_NAMES},
    "pedestrian": "person",
    "human": "person",
    "body": "person",
    "face": "head",
    "hip-leg": "hipleg",
    "hip_leg": "hipleg",
    "legs": "hipleg",
    "left hand": "left_hand",
    "left-hand": "left_hand",
    "right hand": "right_hand",
    "right-hand": "right_hand",
}


class FormatError(ValueError):
    """A file or directory that is not what a format expects; the message names what was expected."""


@dataclass(frozen=True)
class ExportManifest:
    """The clip an export was made from (``partlab.json`` in every export directory)."""

    format: str
    fps: float
    width: int
    height: int
    frame_count: int
    every: int = 1
    frames_written: bool = False
    video: str = ""
    frame_numbering: str = "0-based decoder frame index"
    parts: tuple[str, ...] = field(default_factory=lambda: PART_NAMES)
    notes: str = ""
    version: int = MANIFEST_VERSION
    #: top-level entries of the directory this export wrote (a later export removes only these)
    files: tuple[str, ...] = ()

    @classmethod
    def for_video(cls, fmt: str, info: VideoInfo, every: int, frames_written: bool,
                  notes: str = "") -> ExportManifest:
        return cls(fmt, float(info.fps), int(info.width), int(info.height), int(info.frame_count),
                   int(every), bool(frames_written), Path(info.path).name if info.path else "", notes=notes)

    def write(self, out_dir: Path) -> Path:
        path = Path(out_dir) / MANIFEST_NAME
        d = asdict(self)
        d["parts"] = list(self.parts)
        d["files"] = list(self.files)
        path.write_text(json.dumps(d, indent=2) + "\n", encoding="utf-8")
        return path

    @classmethod
    def read(cls, directory: Path) -> ExportManifest | None:
        """The manifest in ``directory``, or None when it is not one of our exports."""
        path = Path(directory) / MANIFEST_NAME
        if not path.is_file():
            return None
        try:
            d = json.loads(path.read_text(encoding="utf-8"))
            d["parts"] = tuple(d.get("parts", PART_NAMES))
            d["files"] = tuple(str(f) for f in d.get("files", ()))
            known = {k: v for k, v in d.items() if k in cls.__dataclass_fields__}
            return cls(**known)
        except (ValueError, TypeError, AttributeError, RecursionError) as exc:
            raise FormatError(f"{path}: not a readable partlab export manifest ({type(exc).__name__}: "
                              f"{str(exc)[:120]})") from None

    def check_video(self, info: VideoInfo) -> None:
        """Refuse a clip whose decoded frame count or size differs from the one annotated."""
        if info.frame_count != self.frame_count:
            raise FormatError(f"{info.path}: the clip has {info.frame_count} frames but the annotations were "
                              f"made on a clip of {self.frame_count} frames ({self.video or 'unnamed'}); "
                              "frame numbers would not line up")
        if (info.width, info.height) != (self.width, self.height):
            raise FormatError(f"{info.path}: the clip is {info.width}x{info.height} but the annotations were "
                              f"made on {self.width}x{self.height} frames")


def check_frame_count(annotated_frame_count: int, info: VideoInfo, what: str = "the annotations") -> None:
    """Refuse a clip whose frame count differs from the one ``what`` states."""
    if int(annotated_frame_count) != int(info.frame_count):
        raise FormatError(f"{info.path}: the clip has {info.frame_count} decoded frames but {what} state "
                          f"{annotated_frame_count}; frame numbers would not line up")


def prepare_tracks(tracks_df: pd.DataFrame, info: VideoInfo, video_path=None) -> pd.DataFrame:
    """Validate a tracks table for export against its clip; returns it normalised and sorted.

    Refuses duplicate (frame, track_id, part) rows, frames outside the clip, and a
    ``video_path`` whose decoded frame count differs from ``info`` (the clip annotated).
    """
    try:
        df = normalise_tracks(tracks_df)
    except TracksCSVError as exc:
        raise FormatError(str(exc)) from None
    unknown = sorted(set(df["part"]) - set(PART_NAMES))
    if unknown:
        raise FormatError(f"unknown part(s) {', '.join(unknown)}; expected one of {', '.join(PART_NAMES)}")
    dup = df.duplicated(["frame", "track_id", "part"], keep=False)
    if dup.any():
        first = df[dup].iloc[0]
        raise FormatError(f"{int(dup.sum())} rows repeat a (frame, track_id, part), e.g. frame {first.frame}, "
                          f"track {first.track_id}, part {first.part}; keep one box per part per frame")
    if len(df) and (df["frame"].max() >= info.frame_count or df["frame"].min() < 0):
        raise FormatError(f"frames {int(df['frame'].min())}..{int(df['frame'].max())} are outside the clip's "
                          f"{info.frame_count} frames (0..{info.frame_count - 1}); is this the clip annotated?")
    if video_path is not None:
        actual = probe(video_path)
        check_frame_count(info.frame_count, actual, "the clip annotated has")
    order = {p: i for i, p in enumerate(PART_NAMES)}
    df = df.assign(_p=df["part"].map(order)).sort_values(["frame", "track_id", "_p"], kind="stable")
    return df.drop(columns="_p").reset_index(drop=True)


def select_frames(df: pd.DataFrame, every: int) -> np.ndarray:
    """Sorted annotated frames ``f`` with ``f % every == 0`` (thinning keeps decoder indices)."""
    if every < 1:
        raise FormatError(f"--every must be at least 1, got {every}")
    frames = np.unique(df["frame"].to_numpy())
    return frames[frames % every == 0]


def thinned_tracks(tracks_df: pd.DataFrame, info: VideoInfo, video_path, every: int, out_dir
                   ) -> tuple[pd.DataFrame, np.ndarray]:
    """What every exporter starts with: the checked tracks of the kept frames, the kept frame
    indexes, and the output directory made."""
    df = prepare_tracks(tracks_df, info, video_path)
    keep = select_frames(df, every)
    out_dir.mkdir(parents=True, exist_ok=True)
    return df[df["frame"].isin(keep)], keep


def parse_mapping(mapping: str | dict | None) -> dict[str, str]:
    """Label mapping from a dict, a JSON object or ``"their=ours,..."``; values must be part names.

    The result maps lower-cased foreign labels (names or class ids as text) to part
    names and includes :data:`DEFAULT_ALIASES` unless overridden.
    """
    out = dict(DEFAULT_ALIASES)
    if mapping is None or mapping == "":
        return out
    if isinstance(mapping, str):
        text = mapping.strip()
        if Path(text).suffix == ".json" and Path(text).is_file():
            text = Path(text).read_text(encoding="utf-8")
        if text.startswith("{"):
            try:
                mapping = json.loads(text)
            except ValueError as exc:
                raise FormatError(f"--mapping: not a JSON object ({exc})") from None
        else:
            pairs = {}
            for item in filter(None, (s.strip() for s in text.split(","))):
                if "=" not in item:
                    raise FormatError(f"--mapping: {item!r} is not THEIR_LABEL=PART (e.g. face=head,1=person)")
                k, v = item.split("=", 1)
                pairs[k.strip()] = v.strip()
            mapping = pairs
    if not isinstance(mapping, dict):
        raise FormatError("--mapping must map label names to part names")
    for k, v in mapping.items():
        if v not in PART_NAMES:
            raise FormatError(f"--mapping: {k!r} maps to {v!r}, which is not a part; "
                              f"expected one of {', '.join(PART_NAMES)}")
        out[str(k).strip().lower()] = v
    return out


def map_label(label, mapping: dict[str, str]) -> str | None:
    """Our part name for a foreign label (name or class id), or None when it has none."""
    return mapping.get(str(label).strip().lower())


def finish_import(rows: list[dict], skipped: dict[str, int], source: str, text_numbers: bool = True) -> pd.DataFrame:
    """Tracks table from imported rows (raw values, checked by the tracks CSV's rules,
    :func:`~partlab.tracking.tracks.check_value`; a row's ``_where`` names its place in the file);
    ``df.attrs['skipped']`` counts rows of unmapped labels."""
    if not rows:
        found = ", ".join(f"{k} ({n})" for k, n in sorted(skipped.items())) or "none"
        raise FormatError(f"{source}: no boxes with a label that maps to our parts "
                          f"({', '.join(PART_NAMES)}); labels found: {found}. Use --mapping THEIRS=PART")
    try:  # the tracks CSV reader's rules: what is imported, partlab's own reader reads back
        rows = check_rows(rows, source, text_numbers)
    except TracksCSVError as exc:
        raise FormatError(str(exc)) from None
    df = normalise_tracks(pd.DataFrame(rows))
    order = {p: i for i, p in enumerate(PART_NAMES)}
    df = df.assign(_p=df["part"].map(order)).sort_values(["frame", "track_id", "_p"], kind="stable")
    df = df.drop(columns="_p").reset_index(drop=True)
    df.attrs["skipped"] = dict(skipped)
    return df
