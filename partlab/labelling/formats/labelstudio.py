"""Label Studio video object tracking: ``tasks.json`` of ``videorectangle`` regions, ``labeling_config.xml``.

A Label Studio video track is one region of type ``videorectangle`` whose ``value.sequence`` lists
keyframes ``{frame, enabled, x, y, width, height, rotation, time}``: ``frame`` counts from 1, the box is
in percent of the frame size, and Label Studio interpolates linearly between a keyframe and the next
one. ``enabled: false`` on a keyframe ends the track's lifespan there (the box is shown on that frame,
none after it until the next keyframe), so a gap is a disabled keyframe followed by the keyframe where
the track comes back; an enabled last keyframe holds its box to the end of the video
(``value.framesCount``).

Export: one task for the clip (``data.video`` is the clip's file name, to be served by Label Studio's
local storage or replaced by its URL), one ``annotations`` entry, one region per (person, part), with
every box a keyframe, labelled with the part name (``value.labels``), region id ``t<track_id>-<part>``
so the person comes back on import, and the last box before a gap or the end disabled.
``labeling_config.xml`` is the project's labelling interface: a ``<Video>`` with the clip's frame
rate, a ``<VideoRectangle>`` and ``<Labels>`` naming our parts.

Import: a tasks JSON export (a list of tasks, a single task, or our directory), of exactly one video
task; its most recent annotation (or, with none, its most recent prediction), every region of type
``videorectangle`` expanded to one box per frame as Label Studio shows it; labels are mapped to parts
(``--mapping``), the track id is taken from our region ids, else one track per region.
"""

from __future__ import annotations

import json
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pandas as pd

from partlab.labelling.formats.base import (
    ExportManifest,
    FormatError,
    finish_import,
    map_label,
    parse_mapping,
    thinned_tracks,
)
from partlab.labelling.video import VideoInfo
from partlab.limits import max_frames
from partlab.tracking.parts import BOX_PARTS

NAME = "labelstudio"
FILE_NAME = "tasks.json"
CONFIG_NAME = "labeling_config.xml"
FROM_NAME, TO_NAME = "box", "video"  # the control and object tag names of labeling_config.xml
_OUR_ID = re.compile(r"^t(\d+)-([a-z_]+)$")


def labeling_config(fps: float, parts=BOX_PARTS) -> str:
    """The Label Studio labelling interface for our video tracks."""
    view = ET.Element("View")
    ET.SubElement(view, "Header", {"value": "Track each person's parts"})
    ET.SubElement(view, "Video", {"name": TO_NAME, "value": "$video", "framerate": f"{float(fps):g}"})
    ET.SubElement(view, "VideoRectangle", {"name": FROM_NAME, "toName": TO_NAME})
    labels = ET.SubElement(view, "Labels", {"name": "videoLabels", "toName": TO_NAME, "allowEmpty": "false"})
    for p in parts:
        ET.SubElement(labels, "Label", {"value": p})
    ET.indent(view, space="  ")
    return ET.tostring(view, encoding="unicode") + "\n"


def regions(df: pd.DataFrame, info: VideoInfo, every: int = 1) -> list[dict]:
    """``videorectangle`` regions of a tracks table (one per (track_id, part)), as Label Studio stores them."""
    out = []
    W, H = float(info.width), float(info.height)
    for (track_id, part), rows in df.groupby(["track_id", "part"], sort=False):
        rows = rows.sort_values("frame")
        frames = rows["frame"].to_numpy()
        seq = []
        for k, r in enumerate(rows.itertuples(index=False)):
            nxt = frames[k + 1] if k + 1 < len(frames) else None
            seq.append({"frame": int(r.frame) + 1, "enabled": bool(nxt is not None and nxt == r.frame + every),
                        "rotation": 0, "x": 100.0 * r.x / W, "y": 100.0 * r.y / H,
                        "width": 100.0 * r.w / W, "height": 100.0 * r.h / H,
                        "time": round(float(r.frame) / info.fps, 6)})
        scores = rows["score"].dropna()
        region = {"id": f"t{int(track_id)}-{part}", "type": "videorectangle", "from_name": FROM_NAME,
                  "to_name": TO_NAME, "original_width": int(info.width), "original_height": int(info.height),
                  "origin": "prediction" if set(rows["source"]) == {"tracker"} else "manual",
                  "value": {"framesCount": int(info.frame_count), "duration": info.frame_count / info.fps,
                            "sequence": seq, "labels": [part]}}
        if len(scores):
            region["score"] = float(scores.mean())
        out.append(region)
    return out


def export(df: pd.DataFrame, out_dir: Path, info: VideoInfo, video_path=None, every: int = 1,
           frames: bool = False) -> Path:
    """Write ``tasks.json`` and ``labeling_config.xml`` (the clip itself is uploaded to Label Studio)."""
    df, _ = thinned_tracks(df, info, video_path, every, out_dir)
    df = df[df["part"].isin(BOX_PARTS)]
    task = {"data": {"video": Path(info.path).name if info.path else "clip.mp4"},
            "annotations": [{"result": regions(df, info, every), "ground_truth": False}],
            "meta": {"partlab": {"fps": info.fps, "frame_count": info.frame_count, "width": info.width,
                                 "height": info.height}}}
    (out_dir / FILE_NAME).write_text(json.dumps([task], indent=1), encoding="utf-8")
    (out_dir / CONFIG_NAME).write_text(labeling_config(info.fps), encoding="utf-8")
    ExportManifest.for_video(NAME, info, every, False,
                             notes="Label Studio frames count from 1; region id t<track_id>-<part>").write(out_dir)
    return out_dir


def _find_json(path: Path) -> Path:
    if path.is_file():
        return path
    if (path / FILE_NAME).is_file():
        return path / FILE_NAME
    found = [p for p in sorted(path.glob("*.json")) if p.name != "partlab.json"]
    if len(found) == 1:
        return found[0]
    raise FormatError(f"{path}: expected a Label Studio JSON export ({FILE_NAME}, or one .json file)")


def _task(path: Path) -> tuple[Path, dict]:
    js = _find_json(path)
    try:
        doc = json.loads(js.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        raise FormatError(f"{js}: not a JSON file ({exc}); expected a Label Studio JSON export") from None
    except RecursionError:
        raise FormatError(f"{js}: JSON nested too deeply; expected a Label Studio JSON export") from None
    tasks = doc if isinstance(doc, list) else [doc]
    tasks = [t for t in tasks if isinstance(t, dict) and ("annotations" in t or "predictions" in t)]
    if len(tasks) != 1:
        raise FormatError(f"{js}: {len(tasks)} Label Studio tasks with annotations; expected one video task "
                          "(export one task, or split the file)")
    return js, tasks[0]


def results_of(task: dict) -> list:
    """The regions of a task's most recent annotation, or of its most recent prediction when it has none."""
    for key in ("annotations", "predictions"):
        entries = [a for a in task.get(key) or [] if isinstance(a, dict) and not a.get("was_cancelled")]
        if entries:
            latest = max(entries, key=lambda a: (str(a.get("updated_at", "")), a.get("id") or 0))
            return latest.get("result") or []
    return []


def annotated_frame_count(path: Path) -> int | None:
    _, task = _task(path)
    counts = {r.get("value", {}).get("framesCount") for r in results_of(task) if isinstance(r, dict)}
    counts = {c for c in counts if isinstance(c, int)}
    return counts.pop() if len(counts) == 1 else None


def expand(sequence: list[dict], frames_count: int | None) -> list[tuple[int, float, float, float, float, bool]]:
    """Frames ``(frame 1-based, x, y, w, h, keyframe)`` a keyframe sequence shows (see the module docstring)."""
    limit = max_frames()
    keys = [k for k in sequence if isinstance(k, dict)]
    for k in keys:  # whole frame numbers inside the clip limit, before any frame is expanded
        f = k["frame"]
        if isinstance(f, bool) or not isinstance(f, (int, float)) or not math.isfinite(f) or f != int(f) \
                or not 1 <= f <= limit:
            raise TypeError(f"a whole frame number in 1..{limit} (PARTLAB_MAX_FRAMES), got {f!r}")
    keys.sort(key=lambda k: k["frame"])
    out: dict[int, tuple] = {}
    for i, a in enumerate(keys):
        box = np.array([a["x"], a["y"], a["width"], a["height"]], float)
        out[int(a["frame"])] = (int(a["frame"]), *box, True)
        if not a.get("enabled", True):
            continue
        b = keys[i + 1] if i + 1 < len(keys) else None
        if b is None and frames_count is not None and (isinstance(frames_count, bool) or not isinstance(
                frames_count, int) or not 0 <= frames_count <= limit):  # held to the end: the end must be sane
            raise TypeError(f"a framesCount in 0..{limit} (PARTLAB_MAX_FRAMES), got {frames_count!r}")
        end = int(b["frame"]) if b is not None else int(frames_count or a["frame"]) + 1
        nb = np.array([b["x"], b["y"], b["width"], b["height"]], float) if b is not None else box
        for f in range(int(a["frame"]) + 1, end):
            t = (f - a["frame"]) / (b["frame"] - a["frame"]) if b is not None else 0.0
            out.setdefault(f, (f, *(box + (nb - box) * t), False))
    return [out[f] for f in sorted(out)]


def import_(path: Path, mapping=None, size: tuple[int, int] | None = None) -> pd.DataFrame:
    """Boxes of the task's latest annotation; ``size`` (width, height: the clip's, given with --video)
    turns percentages into pixels when the regions do not state ``original_width/height``."""
    js, task = _task(path)
    if size is None:
        meta = (task.get("meta") or {}).get("partlab") or {}
        size = (meta["width"], meta["height"]) if "width" in meta and "height" in meta else None
    return tracks_from_results(results_of(task), size, str(js), mapping)


def tracks_from_results(regions_: list, size: tuple[int, int] | None, source: str, mapping=None) -> pd.DataFrame:
    """A tracks table of Label Studio result regions (one box per frame each ``videorectangle`` shows)."""
    names = parse_mapping(mapping)
    rows: list[dict] = []
    skipped: dict[str, int] = {}
    regions_ = [r for r in regions_ if isinstance(r, dict)]
    video = [r for r in regions_ if str(r.get("type", "")).lower() == "videorectangle"]
    for r in regions_:
        if r not in video:
            key = f"{r.get('type')} regions (only videorectangle is read)"
            skipped[key] = skipped.get(key, 0) + 1
    next_id = max([int(m.group(1)) for r in video if (m := _OUR_ID.match(str(r.get("id", ""))))], default=-1) + 1
    for r in video:
        value = r.get("value") or {}
        labels = value.get("labels") or []
        label = labels[0] if labels else ""
        part = map_label(label, names)
        seq = value.get("sequence") or []
        if part is None:
            skipped[label or "(no label)"] = skipped.get(label or "(no label)", 0) + len(seq)
            continue
        m = _OUR_ID.match(str(r.get("id", "")))
        if m:
            track_id = int(m.group(1))
        else:
            track_id, next_id = next_id, next_id + 1
        W = float(r.get("original_width") or (size[0] if size else 0))
        H = float(r.get("original_height") or (size[1] if size else 0))
        if not (W > 0 and H > 0):
            raise FormatError(f"{source}: region {r.get('id')} gives no frame size (original_width/height) to turn "
                              "its percentages into pixels; pass the clip with --video")
        try:
            with np.errstate(over="ignore", invalid="ignore"):  # huge numbers become inf, refused below
                boxes = expand(seq, value.get("framesCount"))
        except (KeyError, TypeError) as exc:
            raise FormatError(f"{source}: region {r.get('id')} has a keyframe without {exc}; expected "
                              "frame, x, y, width, height") from None
        except (ValueError, OverflowError) as exc:
            raise FormatError(f"{source}: region {r.get('id')}: a keyframe's x, y, width, height are not numbers "
                              f"({exc})") from None
        for frame, x, y, w, h, key in boxes:
            x, y, w, h = (float(v) for v in (x, y, w, h))
            if frame < 1:
                raise FormatError(f"{source}: region {r.get('id')} has frame {frame}; Label Studio frames count "
                                  "from 1")
            rows.append({"_where": f"region {r.get('id')!r} frame {frame}",
                         "frame": frame - 1, "track_id": track_id, "part": part,
                         "x": x * W / 100.0, "y": y * H / 100.0, "w": w * W / 100.0, "h": h * H / 100.0,
                         "score": float(r["score"]) if isinstance(r.get("score"), (int, float)) else float("nan"),
                         "source": NAME if key else "interpolated"})
    df = finish_import(rows, skipped, source)
    df.attrs["frame_origin"] = "Label Studio frame numbers (1-based)"
    return df
