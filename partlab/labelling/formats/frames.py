"""Writing the exported frames as JPEG files, decoded once in order by decoder index."""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable, Iterable
from pathlib import Path

import cv2
import numpy as np
from tqdm import tqdm

from partlab.labelling.formats.base import FormatError
from partlab.labelling.video import VideoClip, VideoInfo

JPEG_QUALITY = 95  # high enough that detectors trained on the frames see no block artefacts


def frame_name(frame: int) -> str:
    """File stem of an exported frame: ``frame_000042`` for decoder index 42."""
    return f"frame_{int(frame):06d}"


def all_frames(info: VideoInfo, every: int = 1) -> np.ndarray:
    """Every ``every``-th decoder index of the clip: the frames of a MOT sequence or CVAT task.
    (COCO, YOLO and VOC write only annotated frames: an unannotated frame is unlabelled, not empty.)"""
    return np.arange(0, info.frame_count, every)


def write_frames(video_path, info: VideoInfo, frames: np.ndarray, out_dir: Path,
                 name: Callable[[int], str] = frame_name, ext: str = ".jpg") -> dict[int, Path]:
    """Decode ``video_path`` once and write the listed frames to ``out_dir/name(frame)+ext``.

    ``frames`` are decoder indices (sorted). Returns frame -> written path. The clip's
    decoded frame count must be ``info.frame_count`` (checked by the caller).
    """
    if video_path is None:
        raise FormatError("frames were requested but no video was given (use --video, or --no-frames)")
    out_dir.mkdir(parents=True, exist_ok=True)
    wanted = set(int(f) for f in frames)
    written: dict[int, Path] = {}
    if not wanted:
        return written
    clip = VideoClip(video_path, info)
    stop = max(wanted) + 1
    params = [int(cv2.IMWRITE_JPEG_QUALITY), JPEG_QUALITY] if ext.lower() in (".jpg", ".jpeg") else []
    for index, image in tqdm(clip.frames(0, stop), total=stop, desc="writing frames", unit="frame",
                             leave=False, disable=None):
        if index in wanted:
            path = out_dir / f"{name(index)}{ext}"
            if not cv2.imwrite(str(path), image, params):
                raise FormatError(f"{path}: could not write the frame")
            written[index] = path
    missing = wanted - set(written)
    if missing:
        raise FormatError(f"{video_path}: could not decode frame(s) {sorted(missing)[:5]}; the clip is shorter "
                          "than the one annotated")
    return written


def link_or_copy(src: Path, dest: Path) -> Path:
    """``dest`` as a hard link to ``src`` (no extra disk space), or a copy where links are refused.

    Used where two peers want the same files under different names (Datumaro's ``images/`` and
    FiftyOne's ``data/``); symbolic links are avoided because zip archives drop what they point to.
    """
    dest.parent.mkdir(parents=True, exist_ok=True)
    if dest.exists():
        dest.unlink()
    try:
        os.link(src, dest)
    except OSError:
        shutil.copyfile(src, dest)
    return dest


def link_tree(files: Iterable[Path], out_dir: Path) -> None:
    """Hard-link (or copy) each of ``files`` into ``out_dir`` under its own name."""
    out_dir.mkdir(parents=True, exist_ok=True)
    for f in files:
        link_or_copy(Path(f), out_dir / Path(f).name)
