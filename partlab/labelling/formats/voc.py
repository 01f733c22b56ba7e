"""Pascal VOC for detector training: ``Annotations/*.xml``, ``JPEGImages/``, ``ImageSets/Main/default.txt``.

``labels/`` and ``data/`` hold the same XML files and frames as hard links (no extra disk space):
FiftyOne's ``VOCDetectionDataset`` looks there by default, Datumaro's ``voc`` in the VOC names.

One XML per exported frame, an ``<object>`` per box named after the part. VOC boxes are
integer pixels, 1-based and inclusive (``xmin = x + 1``, ``xmax = x + w``), inside the
image: boxes are clipped to the frame and ``truncated`` is 1 when clipping cut them.
``occluded`` is 1 when ``occluded > 0``; ``difficult`` is 0 (we do not guess what a
``failure`` flag means to a detector); the track id, source, failure flag and occlusion
fraction are kept as ``<attributes>`` (as Datumaro writes them). ``labelmap.txt`` lists
the parts so Datumaro reads our labels.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pandas as pd

from partlab.labelling.formats.base import ExportManifest, thinned_tracks
from partlab.labelling.formats.frames import frame_name, link_tree, write_frames
from partlab.labelling.formats.yolo import clipped_xyxy
from partlab.labelling.video import VideoInfo
from partlab.tracking.parts import PART_NAMES

NAME = "voc"
SUBSET = "default"


def _object(ann: ET.Element, r, box: np.ndarray, truncated: bool) -> None:
    obj = ET.SubElement(ann, "object")
    ET.SubElement(obj, "name").text = r.part
    ET.SubElement(obj, "pose").text = "Unspecified"
    ET.SubElement(obj, "truncated").text = "1" if truncated else "0"
    ET.SubElement(obj, "occluded").text = "1" if r.occluded > 0 else "0"
    ET.SubElement(obj, "difficult").text = "0"
    bnd = ET.SubElement(obj, "bndbox")
    x1, y1, x2, y2 = np.round(box).astype(int)
    for tag, v in (("xmin", x1 + 1), ("ymin", y1 + 1), ("xmax", x2), ("ymax", y2)):
        ET.SubElement(bnd, tag).text = str(int(v))
    attrs = ET.SubElement(obj, "attributes")
    for name, value in (("track_id", int(r.track_id)), ("failure", str(bool(r.failure)).lower()),
                        ("source", r.source), ("occlusion", f"{float(r.occluded):.6g}")):
        a = ET.SubElement(attrs, "attribute")
        ET.SubElement(a, "name").text = name
        ET.SubElement(a, "value").text = str(value)


def export(df: pd.DataFrame, out_dir: Path, info: VideoInfo, video_path=None, every: int = 1,
           frames: bool = True) -> Path:
    df, keep = thinned_tracks(df, info, video_path, every, out_dir)
    for sub in ("Annotations", "JPEGImages", "ImageSets/Main"):
        (out_dir / sub).mkdir(parents=True, exist_ok=True)
    xyxy = clipped_xyxy(df, info.width, info.height)
    raw = np.stack([df["x"], df["y"], df["x"] + df["w"], df["y"] + df["h"]], axis=1).reshape(-1, 4)
    cut = np.any(np.abs(xyxy - raw) > 1e-9, axis=1)
    by_frame = {int(f): [] for f in keep}
    for k, r in enumerate(df.itertuples(index=False)):
        by_frame[int(r.frame)].append(k)
    rows = list(df.itertuples(index=False))
    for f, ks in by_frame.items():
        ann = ET.Element("annotation")
        ET.SubElement(ann, "folder").text = "JPEGImages"
        ET.SubElement(ann, "filename").text = f"{frame_name(f)}.jpg"
        src = ET.SubElement(ann, "source")
        ET.SubElement(src, "database").text = "partlab"
        size = ET.SubElement(ann, "size")
        ET.SubElement(size, "width").text = str(info.width)
        ET.SubElement(size, "height").text = str(info.height)
        ET.SubElement(size, "depth").text = "3"
        ET.SubElement(ann, "segmented").text = "0"
        for k in ks:
            b = np.round(xyxy[k])
            if b[2] - b[0] >= 1 and b[3] - b[1] >= 1:  # nothing left of a box outside the frame
                _object(ann, rows[k], xyxy[k], bool(cut[k]))
        ET.indent(ann, space="  ")
        ET.ElementTree(ann).write(out_dir / "Annotations" / f"{frame_name(f)}.xml", encoding="utf-8")
    (out_dir / "ImageSets" / "Main" / f"{SUBSET}.txt").write_text(
        "".join(f"{frame_name(f)}\n" for f in keep), encoding="utf-8")
    (out_dir / "labelmap.txt").write_text(
        "# label:color_rgb:parts:actions\nbackground:0,0,0::\n" + "".join(
            f"{p}:{(37 * i) % 256},{(91 * i) % 256},{(53 * i) % 256}::\n" for i, p in enumerate(PART_NAMES, 1)),
        encoding="utf-8")
    link_tree(sorted((out_dir / "Annotations").glob("*.xml")), out_dir / "labels")
    if frames:
        written = write_frames(video_path, info, keep, out_dir / "JPEGImages", name=frame_name)
        link_tree(written.values(), out_dir / "data")
    ExportManifest.for_video(NAME, info, every, frames).write(out_dir)
    return out_dir
