"""Events (activities over a range of frames) next to a dataset export, in the form each tool reads.

Every export with events writes ``events.csv`` (the events CSV, :data:`partlab.labelling.events.CSV_COLUMNS`
plus ``event_id``). Besides:

- **cvat**: ``events.xml``, *CVAT for images 1.1* with one ``<tag>`` per frame of each event's range
  (``<image id="42" name="frame_000042.png">``, the frames of ``images/``; CVAT matches a video task's
  frames by that name), labelled with
  the event's kind and carrying ``event`` (its id), ``start_frame``, ``end_frame``, ``tracks``,
  ``parts`` and ``confidence`` attributes, so the ranges come back whole. CVAT for *video* 1.1 has no
  tags (CVAT's maintainers: cvat-ai/cvat#2923 and #7198; CVAT neither writes nor reads ``<tag>``
  there, and Datumaro fails on a ``<tag>`` outside an ``<image>``), so ``annotations.xml`` stays
  tag-free and the tags are their own file: Datumaro's ``cvat`` importer reads it as Label
  annotations per frame, and CVAT takes it as a *CVAT for images 1.1* upload into the video task
  (an upload replaces the task's annotations: upload ``annotations.xml`` to a copy of the task, or
  import the tags with the CVAT SDK into a task of their own).
- **coco**: an ``events`` list and ``event_categories`` at the top level of the COCO JSON (readers
  ignore keys they do not know: ``pycocotools.coco.COCO`` and Datumaro's ``coco`` importer read the
  boxes as before): ``{id, category_id, kind, start_frame, end_frame, image_ids: [first, last],
  track_ids, parts, confidence, attributes}``, frames 0-based like ``frame_id``, image ids
  ``frame + 1`` like the images'.
- **parquet**: ``events.parquet`` (the same table as ``events.csv``).
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import pandas as pd
from defusedxml import ElementTree as SafeET
from defusedxml.common import DefusedXmlException

from partlab.labelling.events import CSV_COLUMNS, KINDS
from partlab.labelling.formats.base import FormatError
from partlab.labelling.formats.frames import frame_name
from partlab.labelling.video import VideoInfo

CSV_NAME = "events.csv"
CVAT_NAME = "events.xml"
PARQUET_NAME = "events.parquet"
COCO_JSON = ("annotations/instances_default.json", "labels.json")
#: colours of the kinds (the editor's timeline uses the same)
KIND_COLOURS = {"clap": "#f28e2b", "handshake": "#4e79a7", "exchange": "#e15759", "pick": "#59a14f",
                "place": "#b07aa1", "hand_head": "#bab0ac"}
TAG_ATTRIBUTES = ("event", "start_frame", "end_frame", "tracks", "parts", "confidence")


def _table(events: pd.DataFrame) -> pd.DataFrame:
    df = events.copy()
    if "event_id" not in df:
        df["event_id"] = range(1, len(df) + 1)
    for c in CSV_COLUMNS:
        if c not in df:
            df[c] = 0 if c.startswith("track_id") else (float("nan") if c == "confidence" else "")
    return df[list(CSV_COLUMNS) + ["event_id"]].sort_values(["start_frame", "event_id"]).reset_index(drop=True)


def _sides(r) -> tuple[list[int], list[str]]:
    """The tracks and parts involved (side b only when it names a part: ``track_id_b = 0`` with no
    ``part_b`` is a one-hand activity, while 0 is a valid track id)."""
    sides = [(int(r.track_id_a), str(r.part_a or ""))]
    if str(r.part_b or ""):
        sides.append((int(r.track_id_b), str(r.part_b)))
    return list(dict.fromkeys(t for t, _ in sides)), [p for _, p in sides if p]


def _num(v) -> str:
    return "" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{float(v):.6g}"


def write_cvat_tags(events: pd.DataFrame, path: Path, info: VideoInfo, every: int = 1) -> Path:
    """``events`` as CVAT for images 1.1 per-frame tags (see the module)."""
    root = ET.Element("annotations")
    ET.SubElement(root, "version").text = "1.1"
    task = ET.SubElement(ET.SubElement(root, "meta"), "task")
    for tag, text in (("name", Path(info.path).stem if info.path else "partlab"), ("size", str(info.frame_count)),
                      ("mode", "annotation"), ("start_frame", "0"), ("stop_frame", str(max(info.frame_count - 1, 0)))):
        ET.SubElement(task, tag).text = text
    labels = ET.SubElement(task, "labels")
    for kind in sorted(set(KINDS) | set(events["kind"])):
        label = ET.SubElement(labels, "label")
        ET.SubElement(label, "name").text = kind
        ET.SubElement(label, "color").text = KIND_COLOURS.get(kind, "#bab0ac")
        ET.SubElement(label, "type").text = "tag"
        attrs = ET.SubElement(label, "attributes")
        for name in TAG_ATTRIBUTES:
            a = ET.SubElement(attrs, "attribute")
            for k, v in (("name", name), ("mutable", "False"), ("input_type", "text"), ("default_value", ""),
                         ("values", "")):
                ET.SubElement(a, k).text = v
    per_frame: dict[int, list] = {}
    for r in events.itertuples(index=False):
        for f in range(int(r.start_frame), int(r.end_frame) + 1):
            if f % every == 0:
                per_frame.setdefault(f, []).append(r)
    for f in sorted(per_frame):
        image = ET.SubElement(root, "image", {"id": str(f), "name": f"{frame_name(f)}.png", "width": str(info.width),
                                              "height": str(info.height)})
        for r in per_frame[f]:
            tag = ET.SubElement(image, "tag", {"label": str(r.kind), "source": "manual"})
            tracks, parts = _sides(r)
            values = dict(event=str(int(r.event_id)), start_frame=str(int(r.start_frame)),
                          end_frame=str(int(r.end_frame)), tracks=",".join(map(str, tracks)), parts=",".join(parts),
                          confidence=_num(r.confidence))
            for name in TAG_ATTRIBUTES:
                ET.SubElement(tag, "attribute", {"name": name}).text = values[name]
    ET.indent(root, space="  ")
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
    return path


def read_cvat_tags(path: Path) -> pd.DataFrame:
    """The events of a CVAT for images 1.1 file's tags: one event per ``event`` attribute (ours), else
    one per run of consecutive frames tagged with the same label (a file made in CVAT)."""
    try:
        root = SafeET.parse(str(path)).getroot()
    except (ET.ParseError, DefusedXmlException, UnicodeDecodeError) as exc:
        raise FormatError(f"{path}: not a readable XML file ({exc}); expected CVAT for images 1.1 tags") from None
    seen: dict[tuple, dict] = {}
    for image in root.iter("image"):
        try:
            frame = int(image.get("id", ""))
        except ValueError:
            raise FormatError(f"{path}: an <image> without a numeric id") from None
        for tag in image.findall("tag"):
            attrs = {a.get("name"): (a.text or "") for a in tag.findall("attribute")}
            label = tag.get("label", "")
            key = (label, attrs["event"]) if attrs.get("event") else (label, None, frame)
            if key[1] is None:  # a foreign tag: joins the run of its label ending at the frame before
                prev = next((k for k, e in seen.items()
                             if k[0] == label and k[1] is None and e["end_frame"] == frame - 1), None)
                if prev is not None:
                    seen[prev]["end_frame"] = frame
                    continue
            e = seen.setdefault(key, dict(start_frame=frame, end_frame=frame, kind=label, attrs=attrs))
            e["start_frame"], e["end_frame"] = min(e["start_frame"], frame), max(e["end_frame"], frame)
    rows = []
    for e in seen.values():
        a = e["attrs"]
        tracks = [int(t) for t in a.get("tracks", "").split(",") if t.strip().isdigit()]
        parts = [p for p in a.get("parts", "").split(",") if p]
        if len(tracks) == 1 and len(parts) == 2:
            tracks = tracks * 2
        rows.append(dict(start_frame=int(a.get("start_frame") or e["start_frame"]),
                         end_frame=int(a.get("end_frame") or e["end_frame"]), kind=e["kind"],
                         track_id_a=tracks[0] if tracks else 0, part_a=parts[0] if parts else "",
                         track_id_b=tracks[1] if len(tracks) > 1 else 0, part_b=parts[1] if len(parts) > 1 else "",
                         ended_by="", object_colour="", confidence=float(a["confidence"]) if a.get("confidence")
                         else float("nan")))
    return pd.DataFrame(rows, columns=list(CSV_COLUMNS)).sort_values("start_frame").reset_index(drop=True)


def add_coco_events(events: pd.DataFrame, out_dir: Path) -> None:
    """The ``events`` extension in the COCO JSON (and FiftyOne's ``labels.json``, a hard link or copy)."""
    kinds = sorted(set(KINDS) | set(events["kind"]))
    cat = {k: i + 1 for i, k in enumerate(kinds)}
    items = []
    for r in events.itertuples(index=False):
        tracks, parts = _sides(r)
        attrs = {k: str(getattr(r, k)) for k in ("ended_by", "object_colour") if str(getattr(r, k) or "")}
        items.append(dict(id=int(r.event_id), category_id=cat[str(r.kind)], kind=str(r.kind),
                          start_frame=int(r.start_frame), end_frame=int(r.end_frame),
                          image_ids=[int(r.start_frame) + 1, int(r.end_frame) + 1], track_ids=tracks, parts=parts,
                          confidence=None if r.confidence != r.confidence else float(r.confidence), attributes=attrs))
    for name in COCO_JSON:
        path = out_dir / name
        if not path.is_file():
            continue
        doc = json.loads(path.read_text(encoding="utf-8"))
        doc["event_categories"] = [dict(id=cat[k], name=k) for k in kinds]
        doc["events"] = items
        with path.open("r+", encoding="utf-8") as fh:  # in place: a hard link to it sees the change
            fh.truncate(0)
            fh.write(json.dumps(doc, indent=1))


def read_coco_events(path: Path) -> pd.DataFrame:
    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    rows = []
    for e in doc.get("events", []):
        tracks, parts = list(e.get("track_ids", [])), list(e.get("parts", []))
        if len(tracks) == 1 and len(parts) == 2:
            tracks = tracks * 2
        attrs = e.get("attributes", {})
        rows.append(dict(start_frame=int(e["start_frame"]), end_frame=int(e["end_frame"]), kind=str(e["kind"]),
                         track_id_a=tracks[0] if tracks else 0, part_a=parts[0] if parts else "",
                         track_id_b=tracks[1] if len(tracks) > 1 else 0, part_b=parts[1] if len(parts) > 1 else "",
                         ended_by=attrs.get("ended_by", ""), object_colour=attrs.get("object_colour", ""),
                         confidence=float("nan") if e.get("confidence") is None else float(e["confidence"])))
    return pd.DataFrame(rows, columns=list(CSV_COLUMNS))


def export_events(events: pd.DataFrame | None, out_dir: Path, fmt: str, info: VideoInfo, every: int = 1) -> None:
    """Write ``events`` next to the ``fmt`` export in ``out_dir`` (see the module); nothing when there are none."""
    if events is None or not len(events):
        return
    df = _table(events)
    late = df[df.end_frame >= info.frame_count]
    if len(late):
        r = late.iloc[0]
        raise FormatError(f"the {r.kind} event {r.start_frame}-{r.end_frame} ends after the clip's last frame "
                          f"({info.frame_count - 1}); the events are of another clip")
    df.to_csv(out_dir / CSV_NAME, index=False)
    if fmt == "cvat":
        write_cvat_tags(df, out_dir / CVAT_NAME, info, every)
    elif fmt == "coco":
        add_coco_events(df, out_dir)
    elif fmt == "parquet":
        df.to_parquet(out_dir / PARQUET_NAME, index=False)
