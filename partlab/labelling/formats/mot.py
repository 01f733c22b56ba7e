"""MOTChallenge ground truth: ``seqinfo.ini``, ``gt/gt.txt`` (people), ``gt/<part>.txt`` and ``img1/``.

``gt.txt`` rows are ``frame, id, x, y, w, h, conf, class, visibility`` (MOT16/17
layout): frames, ids and pixel coordinates count from 1 (the devkit's Matlab convention,
which motmetrics undoes by subtracting 1 from x and y), ``conf`` is 1 (consider the box) and
``visibility = 1 - occluded``.

Class map. ``gt/gt.txt`` holds the ``person`` boxes only, as class 1, MOT17's ``pedestrian``, so
TrackEval's MOTChallenge reader and the MOT devkits evaluate it as it is (MOT17's classes 2..13 are
other things: person on vehicle, car, ..., crowd, and TrackEval refuses a pedestrian evaluation with
any other class in it). Each other box part has its own file ``gt/<part>.txt`` (``head.txt``,
``torso.txt``, ``hipleg.txt``, ``left_hand.txt``, ``right_hand.txt``) in the same layout
with class 1 meaning "this part", so TrackEval evaluates a part with
``GT_LOC_FORMAT='{gt_folder}/{seq}/gt/head.txt'``. The id of a box is ``track_id + 1`` in every
file: one person has one MOT id across its parts. ``gt/labels.txt`` names class 1 (``person``) for
Datumaro's ``mot_seq``, which reads ``gt/gt.txt``.

Foreign files keep their ids as track ids; rows with ``conf == 0`` in a ``gt.txt`` are ignored
boxes in MOTChallenge and are skipped, and 10-column MOT15 files (no class) are read as
``pedestrian``. Frames are read from the file (1-based); ``seqinfo.ini``'s ``seqLength`` is the
frame count the sequence states. Datumaro copies MOT coordinates without the 1-pixel shift, so boxes
it converted from another format into MOT come in one pixel up and left.
"""

from __future__ import annotations

import configparser
import csv
import io
import math
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
from partlab.labelling.formats.frames import all_frames, write_frames
from partlab.labelling.video import VideoInfo
from partlab.limits import max_coord
from partlab.tracking.parts import BOX_PARTS
from partlab.tracking.tracks import TracksCSVError, check_value

NAME = "mot"
ID_RULE = "MOT id = track_id + 1; gt/gt.txt holds person boxes (class 1), gt/<part>.txt each other part"
PEDESTRIAN = 1  # MOT16/17 class 1


def part_file(part: str) -> str:
    """The file under ``gt/`` holding ``part``'s boxes."""
    return "gt.txt" if part == "person" else f"{part}.txt"


def _num(v: float) -> str:
    return f"{float(v):.10g}"


def export(df: pd.DataFrame, out_dir: Path, info: VideoInfo, video_path=None, every: int = 1,
           frames: bool = True) -> Path:
    df, keep = thinned_tracks(df, info, video_path, every, out_dir)
    df = df[df["part"].isin(BOX_PARTS)]  # MOT holds boxes; 3D joints (shoulders, elbows) are not boxes
    (out_dir / "gt").mkdir(exist_ok=True)
    vis = np.clip(1.0 - df["occluded"].to_numpy(dtype=float), 0.0, 1.0)
    lines: dict[str, list[str]] = {"person": []}
    for r, v in zip(df.itertuples(index=False), vis):
        lines.setdefault(r.part, []).append(
            f"{r.frame + 1},{int(r.track_id) + 1},{_num(r.x + 1)},{_num(r.y + 1)},{_num(r.w)},{_num(r.h)},1,"
            f"{PEDESTRIAN},{_num(v)}\n")
    for part, ls in lines.items():
        (out_dir / "gt" / part_file(part)).write_text("".join(ls), encoding="utf-8")
    (out_dir / "gt" / "labels.txt").write_text("person\n", encoding="utf-8")
    seq = configparser.ConfigParser()
    seq.optionxform = str  # MOT keys are camelCase
    seq["Sequence"] = {
        "name": Path(info.path).stem if info.path else out_dir.name,
        "imDir": "img1",
        "frameRate": _num(info.fps),
        "seqLength": str(info.frame_count),
        "imWidth": str(info.width),
        "imHeight": str(info.height),
        "imExt": ".jpg",
    }
    with open(out_dir / "seqinfo.ini", "w", encoding="utf-8") as f:
        seq.write(f, space_around_delimiters=False)
    if frames:  # img1/ is the whole sequence (seqLength frames), thinned by --every
        write_frames(video_path, info, all_frames(info, every), out_dir / "img1", name=lambda i: f"{i + 1:06d}")
    ExportManifest.for_video(NAME, info, every, frames, notes=ID_RULE).write(out_dir)
    return out_dir


def _find_gt(path: Path) -> Path:
    if path.is_file():
        return path
    for candidate in (path / "gt" / "gt.txt", path / "gt.txt", path / "det" / "det.txt"):
        if candidate.is_file():
            return candidate
    raise FormatError(f"{path}: not a MOTChallenge sequence; expected gt/gt.txt (and seqinfo.ini) in the "
                      "directory, or a MOT txt file")


def read_seqinfo(directory: Path) -> dict[str, str]:
    """The ``[Sequence]`` section of ``seqinfo.ini`` in ``directory`` ({} when absent)."""
    path = directory / "seqinfo.ini"
    if not path.is_file():
        return {}
    seq = configparser.ConfigParser()
    seq.optionxform = str
    try:
        seq.read(path, encoding="utf-8")
    except configparser.Error as exc:
        raise FormatError(f"{path}: not a MOTChallenge seqinfo.ini ({exc})") from None
    if "Sequence" not in seq:
        raise FormatError(f"{path}: no [Sequence] section; expected a MOTChallenge seqinfo.ini")
    return dict(seq["Sequence"])


def annotated_frame_count(path: Path) -> int | None:
    """The frame count a MOT sequence states (partlab.json or seqinfo.ini seqLength)."""
    root = path if path.is_dir() else (path.parent.parent if path.parent.name == "gt" else path.parent)
    manifest = ExportManifest.read(root)
    if manifest is not None:
        return manifest.frame_count
    seq = read_seqinfo(root)
    return int(seq["seqLength"]) if seq.get("seqLength", "").isdigit() else None


def import_(path: Path, mapping=None) -> pd.DataFrame:
    gt = _find_gt(path)
    root = path if path.is_dir() else (gt.parent.parent if gt.parent.name == "gt" else gt.parent)
    manifest = ExportManifest.read(root)
    ours = manifest is not None and manifest.format == NAME
    if ours and path.is_dir():
        frames = []
        for part in BOX_PARTS:
            f = gt.parent / part_file(part)
            if f.is_file() and f.stat().st_size:
                frames.append(_read(f, None, root, ours=True, part=part))
        df = pd.concat(frames, ignore_index=True) if frames else _read(gt, mapping, root, ours=True)
        return finish_import(df.to_dict("records"), {}, str(gt))
    df = _read(gt, mapping, root, ours=False)
    img_dir = root / read_seqinfo(root).get("imDir", "img1") if root.is_dir() else None
    if img_dir is not None and img_dir.is_dir():
        df.attrs["images"] = _images_by_frame(img_dir)
    df.attrs["frame_origin"] = "MOT frame numbers (1-based)"
    return df


def _images_by_frame(img_dir: Path) -> dict[int, Path]:
    """0-based frame -> image of a MOT ``img1/`` (named by their 1-based frame)."""
    out = {}
    for p in img_dir.iterdir():
        if p.stem.isdigit() and p.suffix.lower() in (".jpg", ".jpeg", ".png", ".bmp"):
            out[int(p.stem) - 1] = p
    return out


def _read(gt: Path, mapping, root: Path, ours: bool, part: str | None = None) -> pd.DataFrame:
    """Rows of one MOT file; ``part`` names the part of every row (our ``gt/<part>.txt``)."""
    labels_path = next((p for p in (gt.parent / "labels.txt", root / "labels.txt") if p.is_file()), None)
    try:
        labels = [ln.strip() for ln in labels_path.read_text(encoding="utf-8").splitlines()] if labels_path else []
        text = gt.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise FormatError(f"{labels_path if labels_path else gt}: not a text file (not UTF-8)") from None
    names = parse_mapping(mapping)
    names.setdefault("1", "person")  # MOT16/17 class 1 is 'pedestrian'
    is_gt = gt.name.startswith("gt")
    try:
        return _rows(gt, text, labels, names, is_gt, ours, part)
    except csv.Error as exc:
        raise FormatError(f"{gt}: not a MOTChallenge text file ({exc})") from None


def _rows(gt: Path, text: str, labels: list[str], names: dict, is_gt: bool, ours: bool, part) -> pd.DataFrame:
    rows: list[dict] = []
    skipped: dict[str, int] = {}
    limit = max_coord()
    for lineno, cells in enumerate(csv.reader(io.StringIO(text, newline="")), start=1):
        cells = [c.strip() for c in cells]
        while cells and cells[-1] == "":  # trailing commas
            cells.pop()
        if not cells:
            continue
        if len(cells) < 6:
            raise FormatError(f"{gt} line {lineno}: {len(cells)} values; expected MOTChallenge rows "
                              "frame,id,x,y,w,h,conf,class,visibility")
        try:
            v = [float(c) for c in cells]
        except ValueError:
            raise FormatError(f"{gt} line {lineno}: non-numeric value in {','.join(cells)[:80]}; expected "
                              "MOTChallenge rows frame,id,x,y,w,h,conf,class,visibility") from None
        try:  # the tracks CSV's rules (whole, int32; finite, in range)
            frame = check_value("frame", cells[0], f"{gt} line {lineno}, frame", limit)
            oid = check_value("track_id", cells[1], f"{gt} line {lineno}, id", limit)
            for k in range(6, min(len(v), 9)):
                check_value("score", cells[k], f"{gt} line {lineno}, column {k + 1}", limit)
        except TracksCSVError as exc:
            raise FormatError(str(exc)) from None
        if len(v) > 7 and not math.isfinite(v[7]):
            raise FormatError(f"{gt} line {lineno}, class: {cells[7]!r} is not a class number")
        if frame < 1:
            raise FormatError(f"{gt} line {lineno}: frame {frame}; MOTChallenge frames count from 1")
        conf = v[6] if len(v) > 6 else 1.0
        if len(v) == 9 or (len(v) == 8 and not ours):
            cls = int(v[7])
            label = labels[cls - 1] if labels and 1 <= cls <= len(labels) else str(cls)
        else:  # 6, 7 or 10 columns (MOT15: 3D position instead of class)
            label = "pedestrian"
        if is_gt and conf == 0:
            skipped["conf=0 (ignored)"] = skipped.get("conf=0 (ignored)", 0) + 1
            continue
        box_part = part or map_label(label, names)
        if box_part is None:
            skipped[label] = skipped.get(label, 0) + 1
            continue
        vis = v[8] if len(v) == 9 else 1.0
        rows.append({
            "_where": f"line {lineno}",
            "frame": frame - 1,
            "track_id": oid - 1 if ours else oid,
            "part": box_part, "x": v[2] - 1.0, "y": v[3] - 1.0, "w": v[4], "h": v[5],
            "score": float("nan") if is_gt else conf,
            "occluded": float(np.clip(1.0 - vis, 0.0, 1.0)) if 0.0 <= vis <= 1.0 else 0.0,
            "source": NAME,
        })
    return finish_import(rows, skipped, str(gt))
