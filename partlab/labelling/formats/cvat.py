"""CVAT for video 1.1 XML (``annotations.xml``): the lossless format.

One ``<track>`` per (person, part), labelled with the part name, the person (our ``track_id``) in
an immutable ``person`` attribute on every box (not ``track_id``: Datumaro sets that one to the CVAT
track). The tracks are not grouped: Datumaro (and CVAT's own
COCO export) merge the shapes of a group into one instance, which would turn a person's four parts
into one box. The frames are ``images/frame_000042.png`` (PNG, where Datumaro looks for a video task's
frames). Every box we have is a keyframe; a box with ``outside="1"`` closes a track where
its next exported frame has no box (CVAT would otherwise interpolate over the gap).
``occluded="1"`` when ``occluded > 0``; the exact fraction (``occlusion``), ``failure``, ``source``,
``confidence`` (the score) and ``state`` are per-frame attributes (and ``camera``, ``X``, ``Y``, ``Z``
when some box has them), so importing our own export gives back every box and flag. Foreign files:
boxes with ``outside="1"`` are dropped, the
track's ``group_id - 1`` is the track id when it has one, else ids continue after the
largest, and missing attributes take their defaults (``source`` is ``cvat`` for
keyframes and ``interpolated`` otherwise). The track id of a box is its ``person`` attribute, else
its track's ``group_id - 1`` (partlab 0.2 exports and grouped CVAT tasks), else a new id per track.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd
from defusedxml import ElementTree as SafeET
from defusedxml.common import DefusedXmlException

from partlab.labelling.formats.base import (
    ExportManifest,
    FormatError,
    finish_import,
    map_label,
    parse_mapping,
    thinned_tracks,
)
from partlab.labelling.formats.frames import all_frames, frame_name, write_frames
from partlab.labelling.video import VideoInfo
from partlab.tracking.parts import PART_NAMES
from partlab.tracking.tracks import TracksCSVError, check_value, has_take_columns

NAME = "cvat"
FILE_NAME = "annotations.xml"
COLOURS = {"person": "#33ddff", "head": "#fa3253", "torso": "#34d1b7", "hipleg": "#ff6037",
           "left_hand": "#ddff33", "right_hand": "#b83df5", "left_shoulder": "#3d3df5",
           "right_shoulder": "#f59331", "left_elbow": "#2a7dd1", "right_elbow": "#d12a7d"}
#: per-frame attributes: name -> (CVAT input type, default value, values line)
ATTRIBUTES: dict[str, tuple[str, str, str]] = {
    "person": ("number", "0", "0;1000000;1"),  # track_id; Datumaro keeps its own "track_id"
    "failure": ("checkbox", "false", "false\ntrue"),
    "source": ("text", "tracker", "tracker"),
    "occlusion": ("text", "0", "0"),
    "confidence": ("text", "", ""),  # the tracker's score; not "score", which Datumaro parses as a number
    "state": ("text", "", ""),
}
#: attributes of takes (the tracks CSV's camera, X, Y, Z), declared and written only when some box has them
TAKE_ATTRIBUTES: dict[str, tuple[str, str, str]] = {
    "camera": ("text", "", ""),
    "X": ("text", "", ""),
    "Y": ("text", "", ""),
    "Z": ("text", "", ""),
}


def _num(v: float) -> str:
    return f"{float(v):.10g}"


def _meta(root: ET.Element, info: VideoInfo, every: int, attributes: dict) -> None:
    meta = ET.SubElement(root, "meta")
    task = ET.SubElement(meta, "task")
    name = Path(info.path).stem if info.path else "partlab"
    for tag, text in (("id", "1"), ("name", name), ("size", str(info.frame_count)), ("mode", "interpolation"),
                      ("overlap", "0"), ("bugtracker", ""), ("flipped", "False"),
                      ("start_frame", "0"), ("stop_frame", str(max(info.frame_count - 1, 0))),
                      ("frame_filter", f"step={every}" if every > 1 else "")):
        ET.SubElement(task, tag).text = text
    labels = ET.SubElement(task, "labels")
    for part in PART_NAMES:
        label = ET.SubElement(labels, "label")
        ET.SubElement(label, "name").text = part
        ET.SubElement(label, "color").text = COLOURS[part]
        ET.SubElement(label, "type").text = "rectangle"
        attrs = ET.SubElement(label, "attributes")
        for attr_name, (input_type, default, values) in attributes.items():
            a = ET.SubElement(attrs, "attribute")
            ET.SubElement(a, "name").text = attr_name
            ET.SubElement(a, "mutable").text = "False" if attr_name == "person" else "True"
            ET.SubElement(a, "input_type").text = input_type
            ET.SubElement(a, "default_value").text = default
            ET.SubElement(a, "values").text = values
    size = ET.SubElement(task, "original_size")
    ET.SubElement(size, "width").text = str(info.width)
    ET.SubElement(size, "height").text = str(info.height)
    ET.SubElement(meta, "dumped").text = datetime.now(UTC).isoformat(timespec="seconds")
    ET.SubElement(meta, "source").text = f"partlab, fps={_num(info.fps)}"


def _box(track: ET.Element, r, *, outside: bool, take: bool) -> None:
    occluded = float(r.occluded)
    b = ET.SubElement(track, "box", {
        "frame": str(int(r.frame)), "keyframe": "1", "outside": "1" if outside else "0",
        "occluded": "1" if occluded > 0 else "0",
        "xtl": _num(r.x), "ytl": _num(r.y), "xbr": _num(r.x + r.w), "ybr": _num(r.y + r.h), "z_order": "0",
    })
    values = {"person": str(int(r.track_id)), "failure": "true" if bool(r.failure) else "false",
              "source": str(r.source),
              "occlusion": _num(occluded), "confidence": "" if math.isnan(r.score) else _num(r.score),
              "state": str(r.state)}
    if take:
        values.update(camera=str(r.camera), **{a: "" if math.isnan(getattr(r, a)) else _num(getattr(r, a))
                                                for a in ("X", "Y", "Z")})
    for name, value in values.items():
        ET.SubElement(b, "attribute", {"name": name}).text = value


def export(df: pd.DataFrame, out_dir: Path, info: VideoInfo, video_path=None, every: int = 1,
           frames: bool = True) -> Path:
    df, keep = thinned_tracks(df, info, video_path, every, out_dir)
    root = ET.Element("annotations")
    ET.SubElement(root, "version").text = "1.1"
    take = has_take_columns(df)
    _meta(root, info, every, ATTRIBUTES | TAKE_ATTRIBUTES if take else ATTRIBUTES)
    for cvat_id, ((_track_id, part), rows) in enumerate(
            df.groupby(["track_id", "part"], sort=False)):
        track = ET.SubElement(root, "track", {"id": str(cvat_id), "label": part, "source": "manual"})
        rows = rows.sort_values("frame")
        frame_list = rows["frame"].to_numpy()
        for k, r in enumerate(rows.itertuples(index=False)):
            _box(track, r, outside=False, take=take)
            nxt = frame_list[k + 1] if k + 1 < len(frame_list) else None
            gap = int(r.frame) + every
            if (nxt is None or nxt != gap) and gap < info.frame_count:
                _box(track, r._replace(frame=gap), outside=True, take=take)
    ET.indent(root, space="  ")
    ET.ElementTree(root).write(out_dir / FILE_NAME, encoding="utf-8", xml_declaration=True)
    if frames:  # a CVAT task holds every frame (meta size), thinned by --every
        write_frames(video_path, info, all_frames(info, every), out_dir / "images", name=frame_name, ext=".png")
    ExportManifest.for_video(NAME, info, every, frames,
                             notes="the person of a box is its track_id attribute").write(out_dir)
    return out_dir


def _find_xml(path: Path) -> Path:
    if path.is_file():
        return path
    if (path / FILE_NAME).is_file():
        return path / FILE_NAME
    xmls = sorted(path.glob("*.xml"))
    if len(xmls) == 1:
        return xmls[0]
    raise FormatError(f"{path}: expected a CVAT for video 1.1 XML file ({FILE_NAME}) in the directory")


def _parse(xml: Path) -> ET.Element:
    try:
        root = SafeET.parse(str(xml)).getroot()
    except (ET.ParseError, DefusedXmlException, UnicodeDecodeError) as exc:
        raise FormatError(f"{xml}: not a readable XML file ({exc}); expected CVAT for video 1.1 XML") from None
    if root.tag != "annotations":
        raise FormatError(f"{xml}: root element <{root.tag}>, expected <annotations> of CVAT for video 1.1 XML")
    return root


def annotated_frame_count(path: Path) -> int | None:
    """The frame count the XML states (``meta/task/size`` or ``meta/job/size``)."""
    root = _parse(_find_xml(path))
    size = root.find("meta/task/size")
    if size is None:
        size = root.find("meta/job/size")
    return int(size.text) if size is not None and (size.text or "").strip().isdigit() else None


def _attr_float(text: str | None, default: float) -> float:
    try:
        return float(text) if text not in (None, "") else default
    except ValueError:
        return default


def import_(path: Path, mapping=None) -> pd.DataFrame:
    xml = _find_xml(path)
    root = _parse(xml)
    tracks = root.findall("track")
    if not tracks:
        hint = " (it is CVAT for images: <image> elements; export the task as 'CVAT for video 1.1')" \
            if root.find("image") is not None else ""
        raise FormatError(f"{xml}: no <track> elements; expected CVAT for video 1.1 XML{hint}")
    names = parse_mapping(mapping)
    groups = []
    for t in tracks:
        try:
            groups.append(int(t.get("group_id", "0") or 0))
        except ValueError:
            raise FormatError(f"{xml}: track {t.get('id')}, group_id {t.get('group_id')!r} is not an integer") from None
    stated = [int(float(a.text)) for a in root.iter("attribute")
              if a.get("name") == "person" and (a.text or "").strip().lstrip("-").replace(".", "", 1).isdigit()]
    next_id = max([g - 1 for g in groups if g > 0] + stated, default=-1) + 1
    rows: list[dict] = []
    skipped: dict[str, int] = {}
    for t, group in zip(tracks, groups):
        label = t.get("label", "")
        part = map_label(label, names)
        boxes = t.findall("box")
        others = [c.tag for c in t if c.tag != "box"]
        if others:
            key = f"<{others[0]}> shapes (only boxes are read)"
            skipped[key] = skipped.get(key, 0) + len(others)
        if part is None:
            skipped[label] = skipped.get(label, 0) + len(boxes)
            continue
        if group > 0:
            track_id = group - 1
        else:
            track_id, next_id = next_id, next_id + 1
        for b in boxes:
            if b.get("outside") == "1":
                continue
            if any(b.get(k) is None for k in ("frame", "xtl", "ytl", "xbr", "ybr")):
                raise FormatError(f"{xml}: track {t.get('id')} has a <box> without frame/xtl/ytl/xbr/ybr; "
                                  "expected CVAT for video 1.1 XML")
            where = f"track {t.get('id')} box frame {b.get('frame')!r}"
            try:
                xtl, ytl, xbr, ybr = (check_value("x", b.get(k), f"{xml} {where}, {k}") for k in
                                      ("xtl", "ytl", "xbr", "ybr"))
            except TracksCSVError as exc:
                raise FormatError(str(exc)) from None
            frame = b.get("frame")
            attrs = {a.get("name"): (a.text or "") for a in b.findall("attribute")}
            keyframe = b.get("keyframe", "1") == "1"
            occluded_flag = 1.0 if b.get("occluded") == "1" else 0.0
            box_track = attrs["person"] if attrs.get("person", "").strip() else track_id
            rows.append({
                "_where": where,
                "frame": frame, "track_id": box_track, "part": part,
                "x": xtl, "y": ytl, "w": xbr - xtl, "h": ybr - ytl,
                "score": attrs.get("confidence", attrs.get("score")),
                "failure": attrs.get("failure", "false"),
                "occluded": attrs.get("occlusion") or occluded_flag,
                "state": attrs.get("state", ""),
                "source": attrs.get("source") or ("cvat" if keyframe else "interpolated"),
                "camera": attrs.get("camera", ""),
                **{a: attrs.get(a) for a in ("X", "Y", "Z")},
            })
    df = finish_import(rows, skipped, str(xml))
    images = xml.parent / "images"
    if images.is_dir():  # a CVAT task's frames: images/frame_000042.png (or .jpg)
        df.attrs["images"] = {int(p.stem[6:]): p for p in images.iterdir()
                              if p.stem.startswith("frame_") and p.stem[6:].isdigit()}
    df.attrs["frame_origin"] = "CVAT frame numbers"
    dup = df.duplicated(["frame", "track_id", "part"])
    if dup.any():
        raise FormatError(f"{xml}: {int(dup.sum())} boxes repeat a (frame, group, label); two CVAT tracks of "
                          "one group share a label. Ungroup them in CVAT or export without groups")
    return df
