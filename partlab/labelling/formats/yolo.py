"""YOLO for detector training: ``data.yaml`` and ``train/{images,labels,classes.txt}``.

This is the layout Roboflow and Ultralytics write, and the one every YOLO reader finds by default:
Ultralytics (``data.yaml`` with ``train: train/images``; it finds each label by replacing
``images`` with ``labels`` in the image path), Datumaro (detected as ``roboflow_yolo`` with the
names of ``data.yaml``; a flat ``labels/`` would match two of its YOLO readers at once) and
label-studio-converter's ``yolo`` import pointed at ``train/`` (``classes.txt``, ``images/``,
``labels/``) and FiftyOne's ``YOLOv5Dataset`` (``dataset.yaml``, a hard link to ``data.yaml``).

One text file per exported frame, a line ``class cx cy w h`` per box with the centre
and size divided by the frame size; class ``k`` is ``BOX_PARTS[k]``. Boxes are clipped
to the frame first (YOLO coordinates must lie in [0, 1]) and boxes with nothing inside
the frame are left out. Track ids and flags are not representable: export CVAT or
Parquet to keep them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from partlab.labelling.formats.base import ExportManifest, thinned_tracks
from partlab.labelling.formats.frames import frame_name, link_or_copy, write_frames
from partlab.labelling.video import VideoInfo
from partlab.tracking.parts import BOX_PARTS

NAME = "yolo"
SUBSET = "train"
CLASSES_FILE = "classes.txt"


def clipped_xyxy(df: pd.DataFrame, width: int, height: int) -> np.ndarray:
    """``(N, 4)`` corners ``x1, y1, x2, y2`` of the boxes clipped to a ``width`` x ``height`` frame."""
    x1 = np.clip(df["x"].to_numpy(float), 0, width)
    y1 = np.clip(df["y"].to_numpy(float), 0, height)
    x2 = np.clip((df["x"] + df["w"]).to_numpy(float), 0, width)
    y2 = np.clip((df["y"] + df["h"]).to_numpy(float), 0, height)
    return np.stack([x1, y1, x2, y2], axis=1).reshape(-1, 4)


def export(df: pd.DataFrame, out_dir: Path, info: VideoInfo, video_path=None, every: int = 1,
           frames: bool = True) -> Path:
    df, keep = thinned_tracks(df, info, video_path, every, out_dir)
    df = df[df["part"].isin(BOX_PARTS)]  # YOLO holds boxes; 3D joints are not boxes
    labels_dir = out_dir / SUBSET / "labels"
    labels_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / SUBSET / "images").mkdir(parents=True, exist_ok=True)
    cls = df["part"].map({p: i for i, p in enumerate(BOX_PARTS)}).to_numpy()
    xyxy = clipped_xyxy(df, info.width, info.height)
    cx = (xyxy[:, 0] + xyxy[:, 2]) / 2 / info.width
    cy = (xyxy[:, 1] + xyxy[:, 3]) / 2 / info.height
    bw = (xyxy[:, 2] - xyxy[:, 0]) / info.width
    bh = (xyxy[:, 3] - xyxy[:, 1]) / info.height
    lines: dict[int, list[str]] = {int(f): [] for f in keep}
    for f, c, a, b, w, h in zip(df["frame"].to_numpy(), cls, cx, cy, bw, bh):
        if w > 0 and h > 0:
            lines[int(f)].append(f"{c} {a:.6f} {b:.6f} {w:.6f} {h:.6f}\n")
    for f, ls in lines.items():
        (labels_dir / f"{frame_name(f)}.txt").write_text("".join(ls), encoding="utf-8")
    data = {"path": ".", "train": f"{SUBSET}/images", "val": f"{SUBSET}/images",
            "nc": len(BOX_PARTS), "names": {i: p for i, p in enumerate(BOX_PARTS)}}
    (out_dir / "data.yaml").write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    link_or_copy(out_dir / "data.yaml", out_dir / "dataset.yaml")  # FiftyOne's YOLOv5Dataset default name
    (out_dir / SUBSET / CLASSES_FILE).write_text("".join(f"{p}\n" for p in BOX_PARTS), encoding="utf-8")
    if frames:
        write_frames(video_path, info, keep, out_dir / SUBSET / "images", name=frame_name)
    ExportManifest.for_video(NAME, info, every, frames).write(out_dir)
    return out_dir
