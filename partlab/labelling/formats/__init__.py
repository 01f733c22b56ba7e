"""Dataset export and import in the formats other tools read, one module per format.

``export_dataset`` and ``import_dataset`` are what the CLI and the app call; both take
and return a tracks table (the tracks CSV contract, :func:`partlab.tracking.tracks.normalise_tracks`).
The registry :data:`FORMATS` maps a format name to its module's ``export`` and
(where the format carries tracks) ``import_``.
"""

from __future__ import annotations

import dataclasses
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from partlab.labelling.archive import ArchiveError, is_archive, safe_extract
from partlab.labelling.formats import coco, cvat, labelstudio, mot, parquet, voc, yolo
from partlab.labelling.formats.alignment import align_frames
from partlab.labelling.formats.base import MANIFEST_NAME, ExportManifest, FormatError, check_frame_count
from partlab.labelling.formats.events import export_events
from partlab.labelling.video import VideoInfo, probe

__all__ = ["FORMATS", "IMPORT_FORMATS", "FormatError", "Format", "export_dataset", "import_dataset", "export_clip",
           "export_project"]


@dataclass(frozen=True)
class Format:
    """One dataset format: how to write it and, when it carries tracks, how to read it."""

    name: str
    description: str
    export: Callable[..., Path]
    import_: Callable[..., pd.DataFrame] | None = None
    frame_count: Callable[[Path], int | None] | None = None  # frame count the files state


FORMATS: dict[str, Format] = {
    "mot": Format("mot", "MOTChallenge: seqinfo.ini, gt/gt.txt, labels.txt, img1/", mot.export, mot.import_,
                  mot.annotated_frame_count),
    "cvat": Format("cvat", "CVAT for video 1.1 XML (lossless)", cvat.export, cvat.import_,
                   cvat.annotated_frame_count),
    "coco": Format("coco", "COCO detection JSON with frames in images/", coco.export, coco.import_,
                   coco.annotated_frame_count),
    "yolo": Format("yolo", "YOLO (Ultralytics): data.yaml, images/, labels/", yolo.export),
    "voc": Format("voc", "Pascal VOC: Annotations/, JPEGImages/, ImageSets/", voc.export),
    "parquet": Format("parquet", "Parquet and CSV of every box and flag", parquet.export, parquet.import_),
    "labelstudio": Format("labelstudio", "Label Studio video tracks: tasks.json (videorectangle), labeling_config.xml",
                          labelstudio.export, labelstudio.import_, labelstudio.annotated_frame_count),
}
#: formats whose files carry no frames (the clip itself goes to the other tool)
NO_FRAMES = ("parquet", "labelstudio")
IMPORT_FORMATS: tuple[str, ...] = tuple(n for n, f in FORMATS.items() if f.import_ is not None)


def _format(fmt: str) -> Format:
    if fmt not in FORMATS:
        raise FormatError(f"unknown format {fmt!r}; expected one of {', '.join(FORMATS)}")
    return FORMATS[fmt]


def export_dataset(tracks_df: pd.DataFrame, fmt: str, out_dir, video_info: VideoInfo, video_path=None,
                   every: int = 1, frames: bool = True, events: pd.DataFrame | None = None) -> Path:
    """Write ``tracks_df`` as a ``fmt`` dataset in the directory ``out_dir``; returns it.

    ``video_info`` is the clip the boxes were annotated on (fps, size, frame count);
    ``video_path``, when given, is probed and refused if its decoded frame count
    differs. Frames are written as JPEG (``frames=True``, needs ``video_path``) for
    formats with images; ``every`` keeps frames whose index is a multiple of it. ``events`` (the
    events CSV's table) go next to it: :mod:`~partlab.labelling.formats.events`.
    """
    f = _format(fmt)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise FormatError(f"{out}: exists and is not a directory; -o names the output directory")
    if frames and video_path is None and fmt not in NO_FRAMES:
        raise FormatError(f"writing frames for {fmt} needs the video (or pass frames=False / --no-frames)")
    if out.is_dir() and any(out.iterdir()):
        _remove_previous_export(out)
    kept = {c.name for c in out.iterdir()} if out.is_dir() else set()
    result = f.export(tracks_df, out, video_info, video_path=video_path, every=every,
                      frames=frames and fmt not in NO_FRAMES)
    export_events(events, out, fmt, video_info, every)
    manifest = ExportManifest.read(out)
    if manifest is not None:  # record what this export wrote, so the next one removes only that
        written = sorted(c.name for c in out.iterdir() if c.name not in kept) + [MANIFEST_NAME]
        dataclasses.replace(manifest, files=tuple(dict.fromkeys(written))).write(out)
    return result


def _remove_previous_export(out: Path) -> None:
    """Remove the files an earlier partlab export in ``out`` listed; leave everything else."""
    manifest = ExportManifest.read(out)
    if manifest is None:
        raise FormatError(f"{out}: the directory is not empty and holds no partlab export; choose a new or "
                          "empty directory (a previous partlab export there is replaced)")
    if not manifest.files:
        raise FormatError(f"{out}: holds an export from an older partlab that did not list its files; "
                          "remove it or choose another directory (nothing was deleted)")
    for name in manifest.files:
        child = out / name
        if Path(name).name != name or name in ("", ".", ".."):
            continue  # a tampered list never reaches outside the directory
        if child.is_dir() and not child.is_symlink():
            shutil.rmtree(child)
        elif child.exists() or child.is_symlink():
            child.unlink()


def _import_dir(path: Path, f: Format, mapping, video, frame_offset: int) -> pd.DataFrame:
    info = None
    if video is not None:
        info = video if isinstance(video, VideoInfo) else probe(video)
        stated = f.frame_count(path) if f.frame_count else None
        root = path if path.is_dir() else path.parent
        manifest = ExportManifest.read(root)
        if manifest is not None:
            manifest.check_video(info)
        elif stated is not None:
            check_frame_count(stated, info, f"the {f.name} annotations")
    try:
        if f.name == "labelstudio":  # percentages of the frame: the clip gives the size when the file does not
            df = f.import_(path, mapping, size=(info.width, info.height) if info is not None else None)
        else:
            df = f.import_(path, mapping)
    except (TypeError, AttributeError, KeyError, IndexError, ValueError, OverflowError, RecursionError,
            UnicodeDecodeError) as exc:
        if isinstance(exc, FormatError):
            raise
        # the safety net: a shape of file no check above foresaw is still a refusal naming the file
        detail = " ".join(str(exc).split())[:120]
        raise FormatError(f"{path}: not a {f.name} file partlab can read ({type(exc).__name__}: {detail})") from None
    if frame_offset:
        attrs = df.attrs
        if len(df) and int(df["frame"].min()) + int(frame_offset) < 0:
            raise FormatError(f"{path}: --frame-offset {frame_offset} moves frame {int(df['frame'].min())} "
                              "before the clip's first frame (0)")
        df = df.assign(frame=df["frame"] + int(frame_offset))
        df.attrs = dict(attrs, images={k + int(frame_offset): v for k, v in attrs.get("images", {}).items()})
    if info is not None:
        df = align_frames(df, info, clip_path=None if isinstance(video, VideoInfo) else video, source=str(path))
    df.attrs.pop("images", None)  # paths into a temporary extraction are of no use to the caller
    return df


def import_dataset(path, fmt: str, mapping=None, video=None, frame_offset: int = 0) -> pd.DataFrame:
    """Read a ``fmt`` dataset (our export directory, the format's own file, or a zip/tar of
    either) as a tracks table. ``mapping`` maps foreign label names or class ids to part
    names (dict, JSON text or ``"face=head,1=person"``). ``frame_offset`` is added to the frames
    read (``-1`` for files numbered from 1 that our readers cannot tell are).

    With ``video`` (path or :class:`VideoInfo`) the clip's frame count must match the one the
    files state, and the frames are lined up with the clip by :func:`~.alignment.align_frames`:
    by the images' content when the dataset holds its frames (a shift of up to two frames is
    corrected and recorded in ``df.attrs['frame_shift']``), and boxes on frames the clip does not
    have are refused. ``df.attrs['skipped']`` counts boxes whose labels map to no part.
    """
    f = _format(fmt)
    if f.import_ is None:
        raise FormatError(f"{fmt} is export-only; import one of {', '.join(IMPORT_FORMATS)}")
    p = Path(path)
    if not p.exists():
        raise FormatError(f"{p}: no such file or directory")
    if is_archive(p):
        with tempfile.TemporaryDirectory(prefix="partlab-import-") as tmp:
            try:
                safe_extract(p, tmp)
            except ArchiveError as exc:
                raise FormatError(str(exc)) from None
            root = Path(tmp)
            entries = [e for e in root.iterdir() if not e.name.startswith(("__MACOSX", "."))]
            if len(entries) == 1 and entries[0].is_dir():
                root = entries[0]
            return _import_dir(root, f, mapping, video, frame_offset)
    return _import_dir(p, f, mapping, video, frame_offset)


def _clip_dir_name(clip) -> str:
    stem = "".join(c if c.isalnum() or c in "-_." else "_" for c in Path(clip.name).stem) or "clip"
    return f"{clip.id:04d}_{stem}"


def export_clip(store, clip_id: int, fmt: str, out_dir, every: int = 1, frames: bool = True,
                accepted_only: bool = False) -> Path:
    """Export a clip of the annotation store (its effective boxes: tracker boxes under human
    edits) against the frame count and fps recorded when the clip was added; marks it exported.
    ``accepted_only``: only the boxes of tracks at frames a reviewer accepted (``Store.accepted``).
    The clip's events go with it (:func:`partlab.labelling.events.from_store`)."""
    from partlab.labelling.events import from_store

    clip = store.clip(clip_id)
    info = VideoInfo(clip.path, clip.fps, clip.width, clip.height, clip.frame_count)
    tracks = store.tracks(clip_id)
    if accepted_only:
        ok = store.accepted(clip_id)
        tracks = tracks.merge(ok, on=["frame", "track_id"], how="inner")
    out = export_dataset(tracks, fmt, out_dir, info, video_path=clip.path, every=every, frames=frames,
                         events=from_store(store.events(clip_id)))
    store.mark_exported(clip_id)
    return out


def export_project(store, project_id: int, fmt: str, out_dir, every: int = 1, frames: bool = True) -> list[Path]:
    """Export every clip of a project, each into ``out_dir/<clip id>_<clip name>/``."""
    out = Path(out_dir)
    return [export_clip(store, c.id, fmt, out / _clip_dir_name(c), every=every, frames=frames)
            for c in store.clips(project_id)]
