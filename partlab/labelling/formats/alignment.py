"""Lining imported frame numbers up with the clip: by the images' content where the dataset has
them, by range where it has not.

Other tools number frames their own way: MOTChallenge from 1, COCO exports by image id or file name,
Datumaro and FiftyOne by item order or by the names of the files they were given (``000001.jpg`` for
a clip's first frame). A count check cannot see a one-frame shift (the counts agree); the pixels can.
:func:`align_frames` compares a few imported images with the clip's decoded frames at nearby offsets
and shifts the boxes by the offset whose frames match, or refuses when none does; without images it
refuses boxes on frames the clip does not have.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from partlab.labelling.formats.base import FormatError
from partlab.labelling.video import VideoClip, VideoInfo

#: offsets tried: an image named N is compared with clip frames N + k, |k| <= MAX_SHIFT
MAX_SHIFT = 2
#: frames sampled (spread over the annotated ones): enough that one look-alike pair cannot decide
SAMPLES = 4
#: thumbnail size compared (grey, area-averaged): JPEG noise averages out, a moved person does not
THUMB = (64, 48)
#: an offset is chosen only when its mean difference is under this fraction of the next best one
#: (a static shot matches every offset equally, and then the content cannot tell)
DECISIVE = 0.5
#: and under this many grey levels on average (JPEG at quality 75 stays under ~3 on thumbnails)
MATCH_LEVEL = 6.0


def _thumb(image: np.ndarray) -> np.ndarray:
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image
    return cv2.resize(grey, THUMB, interpolation=cv2.INTER_AREA).astype(np.float32)


def content_offset(images: dict[int, Path], clip_path, info: VideoInfo) -> tuple[int | None, str]:
    """The offset ``k`` such that imported image ``f`` is clip frame ``f + k``, or None when the
    content cannot decide; with a sentence saying what was compared."""
    frames = sorted(f for f in images if 0 <= f < info.frame_count)
    inner = [f for f in frames if MAX_SHIFT <= f < info.frame_count - MAX_SHIFT]  # every offset exists there
    frames = inner or frames
    if not frames:
        return None, "no imported image names a frame of the clip"
    picks = [frames[int(i)] for i in np.unique(np.linspace(0, len(frames) - 1, min(SAMPLES, len(frames))).round())]
    offsets = np.arange(-MAX_SHIFT, MAX_SHIFT + 1)
    cost = np.zeros(len(offsets))
    used = np.zeros(len(offsets))
    with VideoClip(clip_path, info) as clip:
        for f in picks:
            img = cv2.imread(str(images[f]), cv2.IMREAD_COLOR)
            if img is None:
                continue
            t = _thumb(img)
            for j, k in enumerate(offsets):
                if 0 <= f + k < info.frame_count:
                    cost[j] += float(np.abs(_thumb(clip.read(int(f + k))) - t).mean())
                    used[j] += 1
    if not used.any():
        return None, "the imported images could not be read"
    mean = np.where(used == len(picks), cost / np.maximum(used, 1), np.inf)
    order = np.argsort(mean)
    best, second = mean[order[0]], mean[order[1]]
    what = f"{len(picks)} images compared with the clip at offsets {-MAX_SHIFT}..{MAX_SHIFT}"
    if best <= MATCH_LEVEL and best < DECISIVE * second:
        return int(offsets[order[0]]), what
    return None, what + f" (best mean difference {best:.1f} grey levels, next {second:.1f}: undecided)"


def align_frames(df: pd.DataFrame, info: VideoInfo, clip_path=None, source: str = "the annotations") -> pd.DataFrame:
    """``df`` with its frames lined up with the clip ``info`` (see the module docstring).

    ``df.attrs['images']`` (frame -> image file), when present and ``clip_path`` is given, decides
    the offset by content; ``df.attrs['frame_shift']`` records the shift applied (0 when none).
    Raises :class:`FormatError` when the frames cannot be the clip's.
    """
    images = df.attrs.get("images") or {}
    shift, how = 0, "not checked by content (no images)"
    if images and clip_path is not None:
        found, how = content_offset(images, clip_path, info)
        if found is not None:
            shift = found
    out = df.assign(frame=df["frame"] + shift) if shift else df.copy()
    out.attrs = dict(df.attrs, frame_shift=shift, frame_check=how)
    if len(out) and (out["frame"].max() >= info.frame_count or out["frame"].min() < 0):
        origin = df.attrs.get("frame_origin", "")
        hint = (" Its frames come from 1-based file names or ids: pass --frame-offset -1 if the first "
                "file is the clip's first frame." if out["frame"].max() == info.frame_count else "")
        raise FormatError(f"{source}: boxes on frames {int(out['frame'].min())}..{int(out['frame'].max())} but the "
                          f"clip {Path(info.path).name} has frames 0..{info.frame_count - 1}"
                          f"{f' (frames read from {origin})' if origin else ''}; is this the clip annotated?{hint}")
    return out
