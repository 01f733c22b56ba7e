"""COCO detection JSON with its frames, in the layouts COCO readers look for by default.

Layout (one export opens in each reader without options)::

    annotations/instances_default.json   the JSON (Datumaro's and the COCO API's layout: subset "default")
    images/frame_000042.jpg ...          the annotated frames (Datumaro: ``images/``)
    labels.json, data/                   the same JSON and frames as hard links (FiftyOne's
                                         ``COCODetectionDataset`` defaults), no extra disk space

One image entry per exported frame (``id = frame + 1``, our decoder index in
``frame_id``), one annotation per box with ``track_id``, the part as its category
(``id = part_index + 1``), a top-level ``score`` (the tracker's, 1.0 for boxes without one, so
``COCO.loadRes`` and ``COCOeval`` take the file as detections) and our flags in ``attributes``
(``occluded`` as a boolean
the way CVAT and Datumaro write it, the exact fraction in ``occlusion``). ``info``
states the fps and frame count of the clip. Importing a foreign file takes the frame
from ``frame_id``, else from the digits ending the file name, else from the image's
position; the track from ``track_id`` (top level or in ``attributes``), else each box
is its own track.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pandas as pd

from partlab.labelling.formats.base import (
    ExportManifest,
    FormatError,
    finish_import,
    map_label,
    parse_mapping,
    thinned_tracks,
)
from partlab.labelling.formats.frames import frame_name, link_or_copy, link_tree, write_frames
from partlab.labelling.video import VideoInfo
from partlab.tracking.parts import PART_NAMES

NAME = "coco"
FILE_NAME = "annotations/instances_default.json"
FIFTYONE_LABELS = "labels.json"
FIFTYONE_DATA = "data"
OLD_FILE_NAME = "annotations.json"  # partlab 0.2 exports


def export(df: pd.DataFrame, out_dir: Path, info: VideoInfo, video_path=None, every: int = 1,
           frames: bool = True) -> Path:
    df, keep = thinned_tracks(df, info, video_path, every, out_dir)
    images = [{"id": int(f) + 1, "file_name": f"{frame_name(f)}.jpg", "width": info.width,
               "height": info.height, "frame_id": int(f)} for f in keep]
    categories = [{"id": i + 1, "name": p, "supercategory": "person"} for i, p in enumerate(PART_NAMES)]
    cat = {p: i + 1 for i, p in enumerate(PART_NAMES)}
    annotations = []
    for k, r in enumerate(df.itertuples(index=False), start=1):
        annotations.append({
            "id": k, "image_id": int(r.frame) + 1, "category_id": cat[r.part],
            "bbox": [float(r.x), float(r.y), float(r.w), float(r.h)], "area": float(r.w * r.h),
            "iscrowd": 0, "segmentation": [], "track_id": int(r.track_id),
            "score": 1.0 if math.isnan(r.score) else float(r.score),
            "attributes": {"occluded": bool(r.occluded > 0), "occlusion": float(r.occluded),
                           "failure": bool(r.failure), "source": str(r.source),
                           "score": None if math.isnan(r.score) else float(r.score), "state": str(r.state),
                           "track_id": int(r.track_id)},
        })
    doc = {
        "info": {"description": "partlab export", "fps": info.fps, "frame_count": info.frame_count,
                 "frame_numbering": "frame_id is the 0-based decoder index; image id = frame_id + 1",
                 "every": every},
        "licenses": [],
        "images": images,
        "annotations": annotations,
        "categories": categories,
    }
    (out_dir / FILE_NAME).parent.mkdir(parents=True, exist_ok=True)
    (out_dir / FILE_NAME).write_text(json.dumps(doc, indent=1), encoding="utf-8")
    link_or_copy(out_dir / FILE_NAME, out_dir / FIFTYONE_LABELS)
    if frames:
        written = write_frames(video_path, info, keep, out_dir / "images", name=frame_name)
        link_tree(written.values(), out_dir / FIFTYONE_DATA)
    ExportManifest.for_video(NAME, info, every, frames).write(out_dir)
    return out_dir


def _find_json(path: Path) -> Path:
    if path.is_file():
        return path
    for name in (FILE_NAME, OLD_FILE_NAME, FIFTYONE_LABELS):
        if (path / name).is_file():
            return path / name
    found = sorted(path.glob("*.json")) + sorted((path / "annotations").glob("*.json"))
    found = [p for p in found if p.name != "partlab.json"]
    if len(found) == 1:
        return found[0]
    raise FormatError(f"{path}: expected a COCO JSON file ({FILE_NAME}, {FIFTYONE_LABELS}, or one .json in "
                      "annotations/)")


def annotated_frame_count(path: Path) -> int | None:
    info = _load(_find_json(path)).get("info") or {}
    n = info.get("frame_count") if isinstance(info, dict) else None
    return int(n) if isinstance(n, int) else None


def _load(js: Path) -> dict:
    try:
        doc = json.loads(js.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        raise FormatError(f"{js}: not a JSON file ({exc}); expected COCO detection JSON") from None
    except RecursionError:
        raise FormatError(f"{js}: JSON nested too deeply; expected COCO detection JSON") from None
    if not isinstance(doc, dict) or not all(isinstance(doc.get(k), list)
                                            for k in ("images", "annotations", "categories")):
        raise FormatError(f"{js}: expected COCO detection JSON with lists 'images', 'annotations' and "
                          "'categories'")
    return doc


def _hashable(v) -> bool:
    return not isinstance(v, (list, dict))


def _short(v) -> str:
    text = repr(v)
    return text if len(text) <= 40 else text[:37] + "..."


def import_(path: Path, mapping=None) -> pd.DataFrame:
    js = _find_json(path)
    doc = _load(js)
    names = parse_mapping(mapping)
    cats = {c.get("id"): str(c.get("name", c.get("id"))) for c in doc["categories"] if isinstance(c, dict)}
    images = [im for im in doc["images"] if isinstance(im, dict)]
    for im in images:
        if not isinstance(im.get("id", 0), int) or isinstance(im.get("id"), bool):
            raise FormatError(f"{js}: image {_short(im.get('id'))}: the id is not an integer")
    images.sort(key=lambda im: im.get("id", 0))
    frame_of: dict = {}
    origin = set()
    for position, im in enumerate(images):
        if isinstance(im.get("frame_id"), int) and not isinstance(im.get("frame_id"), bool):
            frame_of[im.get("id")] = im["frame_id"]  # checked with the boxes (finish_import)
            origin.add("frame_id")
        else:
            m = re.search(r"(\d+)$", Path(str(im.get("file_name", ""))).stem)
            frame_of[im.get("id")] = int(m.group(1)) if m else position
            origin.add("file names" if m else "image order")
    image_of = {}
    subset = js.stem.split("_", 1)[1] if js.stem.startswith("instances_") else "default"
    roots = [js.parent, js.parent / "images", js.parent / FIFTYONE_DATA, js.parent.parent / "images",
             js.parent.parent / "images" / subset, js.parent.parent / FIFTYONE_DATA]
    for im in images:
        name = str(im.get("file_name", ""))
        found = next((r / name for r in roots if name and (r / name).is_file()), None)
        if found is not None:
            image_of[frame_of[im.get("id")]] = found
    rows: list[dict] = []
    skipped: dict[str, int] = {}
    for a in doc["annotations"]:
        if not isinstance(a, dict) or not _hashable(a.get("image_id")) or a.get("image_id") not in frame_of:
            raise FormatError(f"{js}: annotation {a.get('id') if isinstance(a, dict) else a!r} refers to no image")
        cat_id = a.get("category_id")
        label = cats.get(cat_id, str(cat_id)) if _hashable(cat_id) else str(cat_id)
        part = map_label(label, names)
        if part is None:
            skipped[label] = skipped.get(label, 0) + 1
            continue
        bbox = a.get("bbox")
        if not (isinstance(bbox, list) and len(bbox) == 4):
            raise FormatError(f"{js}: annotation {a.get('id')} has no [x, y, w, h] bbox")
        attrs = a.get("attributes") if isinstance(a.get("attributes"), dict) else {}
        if attrs.get("outside") is True:  # a CVAT track's end, kept by Datumaro: no box there
            skipped["outside (track ended)"] = skipped.get("outside (track ended)", 0) + 1
            continue
        track_id = a.get("track_id", attrs.get("person", attrs.get("track_id")))
        if track_id is None:
            track_id = a.get("id", len(rows))
        score = attrs.get("score", attrs.get("confidence", a.get("score")))
        occluded = attrs.get("occluded")
        if isinstance(occluded, str):  # "false" is not occluded
            occluded = occluded.strip().lower() in ("1", "true", "yes", "y", "t")
        occlusion = attrs.get("occlusion", 1.0 if occluded is True or occluded == 1 else 0.0)
        rows.append({  # raw values: finish_import checks them by the tracks CSV's rules ("false" is False)
            "_where": f"annotation {_short(a.get('id'))}",
            "frame": frame_of[a["image_id"]], "track_id": track_id, "part": part,
            "x": bbox[0], "y": bbox[1], "w": bbox[2], "h": bbox[3],
            "score": score, "failure": attrs.get("failure", False), "occluded": occlusion,
            "state": str(attrs.get("state", "")), "source": str(attrs.get("source", NAME)),
        })
    df = finish_import(rows, skipped, str(js), text_numbers=False)
    df.attrs["images"] = image_of
    df.attrs["frame_origin"] = "frame_id" if origin == {"frame_id"} else " and ".join(sorted(origin))
    return df
