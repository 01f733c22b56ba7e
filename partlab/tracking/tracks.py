"""The tracks CSV: what ``partlab track`` writes and ``train``/``eval``/``export`` read.

Header row, then ``frame,track_id,part,x,y,w,h`` first and in that order, then any of
the optional columns ``score, failure, occluded, state, source`` and, for takes,
``camera, X, Y, Z``. ``frame`` is the 0-based decode index, ``x, y`` the top-left corner,
``w, h`` the size in pixels; ``camera`` names the take's stream the box is in (empty for a
one-stream take) and ``X, Y, Z`` are the part's 3D position in millimetres in the take's world
frame (empty when unknown). Readers ignore columns they do not know. In memory a tracks table is
a pandas DataFrame with exactly these columns (optional ones filled with their defaults); the
writer leaves out ``camera`` and ``X, Y, Z`` when no row has them, so 2D files stay as they were.
:func:`read_track_records` and :func:`write_track_records` read and write the same files as lists
of :class:`TrackRecord` without pandas (``partlab track``'s start-up: importing pandas costs more
than tracking a short clip).
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

from partlab.limits import MAX_ID, max_coord, max_csv_rows
from partlab.tracking.core.box import Box
from partlab.tracking.parts import PART_NAMES

if TYPE_CHECKING:
    import pandas as pd

REQUIRED_COLUMNS: tuple[str, ...] = ("frame", "track_id", "part", "x", "y", "w", "h")
OPTIONAL_COLUMNS: tuple[str, ...] = ("score", "failure", "occluded", "state", "source", "camera", "X", "Y", "Z")
#: the optional columns of takes, written only when some row has them
TAKE_COLUMNS: tuple[str, ...] = ("camera", "X", "Y", "Z")
COLUMNS: tuple[str, ...] = REQUIRED_COLUMNS + OPTIONAL_COLUMNS

#: Value an optional column takes when a file does not have it.
DEFAULTS: dict[str, object] = {
    "score": float("nan"),
    "failure": False,
    "occluded": 0.0,
    "state": "",
    "source": "tracker",
    "camera": "",
    "X": float("nan"),
    "Y": float("nan"),
    "Z": float("nan"),
}


class TracksCSVError(ValueError):
    """A tracks CSV that cannot be read; the message names the file, line and column."""


@dataclass(frozen=True, slots=True)
class TrackRecord:
    """One box of one part of one track at one frame (a row of the tracks CSV)."""

    frame: int
    track_id: int
    part: str
    box: Box
    score: float = float("nan")
    failure: bool = False
    occluded: float = 0.0
    state: str = ""
    source: str = "tracker"
    camera: str = ""
    X: float = float("nan")
    Y: float = float("nan")
    Z: float = float("nan")

    def as_row(self) -> dict[str, object]:
        return {
            "frame": self.frame,
            "track_id": self.track_id,
            "part": self.part,
            "x": self.box.x,
            "y": self.box.y,
            "w": self.box.w,
            "h": self.box.h,
            "score": self.score,
            "failure": self.failure,
            "occluded": self.occluded,
            "state": self.state,
            "source": self.source,
            "camera": self.camera,
            "X": self.X,
            "Y": self.Y,
            "Z": self.Z,
        }


def empty_tracks() -> pd.DataFrame:
    """A tracks table with no rows and the canonical columns and dtypes."""
    import pandas as pd

    return normalise_tracks(pd.DataFrame({c: [] for c in REQUIRED_COLUMNS}))


def records_to_frame(records) -> pd.DataFrame:
    """Tracks table from an iterable of :class:`TrackRecord`."""
    import pandas as pd

    rows = [r.as_row() for r in records]
    if not rows:
        return empty_tracks()
    return normalise_tracks(pd.DataFrame(rows))


def frame_to_records(df: pd.DataFrame) -> list[TrackRecord]:
    """The rows of a tracks table as :class:`TrackRecord` objects."""
    df = normalise_tracks(df)
    columns = [df[c].tolist() for c in COLUMNS]  # plain Python values, column by column (fast)
    return [
        TrackRecord(int(f), int(t), str(p), Box(float(x), float(y), float(w), float(h)), float(s), bool(fa),
                    float(o), str(st), str(so), str(c), float(X), float(Y), float(Z))
        for f, t, p, x, y, w, h, s, fa, o, st, so, c, X, Y, Z in zip(*columns, strict=True)
    ]


def _parse_bool(text: str) -> bool | None:
    t = text.strip().lower()
    if t in ("1", "true", "yes", "y", "t"):
        return True
    if t in ("0", "false", "no", "n", "f", ""):
        return False
    return None


def _rows(reader, label: str):
    """The CSV module's rows, its own errors (NUL bytes, stray quotes) said with the line."""
    while True:
        try:
            yield next(reader)
        except StopIteration:
            return
        except csv.Error as exc:
            raise TracksCSVError(f"{label} line {reader.line_num}: not a CSV row ({exc})") from None


INT_COLUMNS = ("frame", "track_id")
FLOAT_COLUMNS = ("x", "y", "w", "h", "score", "occluded", "X", "Y", "Z")
#: columns whose values must be finite and within ``PARTLAB_MAX_COORD``
COORD_COLUMNS = ("x", "y", "w", "h", "X", "Y", "Z")


def check_value(col: str, value, where: str, coord_limit: float | None = None, text_numbers: bool = True):
    """The one rule set for a cell of a tracks table, shared by the CSV reader, every importer
    and the store: ``value`` (text as in the CSV, or a number/bool from a JSON or XML file) as the
    column's type, or a :class:`TracksCSVError` naming ``where`` and the value.

    Numbers are checked as the CSV reader checks their text (:func:`_parse_cell`: frames and ids
    whole in 0..2**31-1; ``x, y, w, h, X, Y, Z`` finite within ``PARTLAB_MAX_COORD``, sizes not
    negative; ``score`` not infinite; ``occluded`` in [0, 1]; ``failure`` a boolean, ``"false"``
    being False). Booleans, lists and objects are not numbers; a NaN ``X, Y, Z`` is "unknown".
    With ``text_numbers=False`` (JSON files, whose numbers are numbers) text is refused for the
    frame and the box.
    """
    if coord_limit is None:
        coord_limit = max_coord()
    numeric = col in INT_COLUMNS or col in FLOAT_COLUMNS
    if isinstance(value, str):
        if not text_numbers and col in ("frame", "x", "y", "w", "h"):
            raise TracksCSVError(f"{where}: {_short(value)} is text, not a number")
        cell = value.strip()
    elif value is None:
        cell = ""
    elif isinstance(value, bool):
        if numeric:
            raise TracksCSVError(f"{where}: {value!r} is a boolean, not a number")
        cell = str(value).lower()
    elif isinstance(value, int) or (hasattr(value, "dtype") and getattr(value, "ndim", 1) == 0
                                    and value.dtype.kind in "iub"):
        cell = str(int(value))
    elif isinstance(value, float) or (hasattr(value, "dtype") and getattr(value, "ndim", 1) == 0
                                      and value.dtype.kind == "f"):
        if math.isnan(value) and col in ("X", "Y", "Z"):
            return float("nan")  # an unknown 3D position
        cell = repr(float(value))
    else:
        raise TracksCSVError(f"{where}: {_short(value)} is not a single value")
    return _parse_cell(col, cell, where, coord_limit)


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def check_rows(rows: list[dict], label: str, text_numbers: bool = True) -> list[dict]:
    """``rows`` (dicts of tracks columns, an optional ``_where`` naming each one's place in its
    file) checked and converted by :func:`check_value`; errors read ``LABEL WHERE, column 'C': ...``."""
    coord_limit = max_coord()
    out = []
    for i, row in enumerate(rows):
        place = row.get("_where", f"box {i + 1}")
        out.append({col: check_value(col, v, f"{label} {place}, column '{col}'", coord_limit, text_numbers)
                    for col, v in row.items() if col in COLUMNS})
    return out


def check_table(df: pd.DataFrame, label: str) -> None:
    """:func:`check_value`'s rules over a normalised tracks table at once (what the store and the
    writers take); raises :class:`TracksCSVError` naming the first bad row (counted from 1) and value."""
    import numpy as np

    limit = max_coord()
    tests = {
        "frame": lambda v: (v >= 0) & (v <= MAX_ID), "track_id": lambda v: (v >= 0) & (v <= MAX_ID),
        "x": lambda v: np.isfinite(v) & (np.abs(v) <= limit), "y": lambda v: np.isfinite(v) & (np.abs(v) <= limit),
        "w": lambda v: np.isfinite(v) & (v >= 0) & (v <= limit),
        "h": lambda v: np.isfinite(v) & (v >= 0) & (v <= limit),
        "score": lambda v: ~np.isinf(v), "occluded": lambda v: (v >= 0) & (v <= 1),
        **{c: (lambda v: np.isnan(v) | (np.abs(v) <= limit)) for c in ("X", "Y", "Z")},
    }
    for col, test in tests.items():
        if col not in df.columns:
            continue
        values = df[col].to_numpy(dtype=float)
        bad = ~test(values)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            check_value(col, values[i].item(), f"{label} row {i + 1}, column '{col}'", limit)
            raise TracksCSVError(f"{label} row {i + 1}, column '{col}': {values[i]!r} is out of range")


def read_tracks_csv(source: str | PathLike | io.TextIOBase, *, name: str | None = None) -> pd.DataFrame:
    """Read and validate a tracks CSV.

    Every malformed cell is reported as ``FILE line L, column 'C': problem`` (lines
    counted from 1, the header being line 1), so a user can open the file there.
    """
    import pandas as pd

    return normalise_tracks(pd.DataFrame(_read_columns(source, name)))


def read_track_records(source: str | PathLike | io.TextIOBase, *, name: str | None = None) -> list[TrackRecord]:
    """:func:`read_tracks_csv`'s rows, in the file's order, as :class:`TrackRecord` (no pandas)."""
    cols = _read_columns(source, name)
    n = len(cols["frame"])
    get = {c: cols.get(c) or [DEFAULTS[c]] * n for c in OPTIONAL_COLUMNS}
    return [TrackRecord(cols["frame"][i], cols["track_id"][i], cols["part"][i],
                        Box(cols["x"][i], cols["y"][i], cols["w"][i], cols["h"][i]),
                        *(get[c][i] for c in OPTIONAL_COLUMNS))
            for i in range(n)]


def _read_columns(source: str | PathLike | io.TextIOBase, name: str | None) -> dict[str, list]:
    """The checked cells of a tracks CSV by column (the columns the file has)."""
    label, text = _read_text(source, name)
    reader = _rows(csv.reader(io.StringIO(text, newline="")), label)
    try:
        header = next(reader)
    except StopIteration:
        raise TracksCSVError(f"{label}: the file is empty; expected a header row "
                             f"starting with {','.join(REQUIRED_COLUMNS)}") from None
    header = [h.strip() for h in header]
    _check_header(header, label)
    index = {c: i for i, c in enumerate(header) if c in COLUMNS}
    cols: dict[str, list] = {c: [] for c in index}
    coord_limit, row_limit = max_coord(), max_csv_rows()
    for lineno, row in enumerate(reader, start=2):
        if not row or all(not cell.strip() for cell in row):
            continue
        if lineno - 1 > row_limit:
            raise TracksCSVError(f"{label}: more than the limit of {row_limit} rows "
                                 "(set PARTLAB_MAX_CSV_ROWS to change it)")
        if len(row) < len(REQUIRED_COLUMNS):
            raise TracksCSVError(f"{label} line {lineno}: {len(row)} cells, expected at least "
                                 f"{len(REQUIRED_COLUMNS)} ({','.join(REQUIRED_COLUMNS)})")
        for col, i in index.items():
            cell = row[i].strip() if i < len(row) else ""
            cols[col].append(_parse_cell(col, cell, f"{label} line {lineno}, column '{col}'", coord_limit))
    return cols


def _read_text(source: str | PathLike | io.TextIOBase, name: str | None) -> tuple[str, str]:
    """``(label for messages, the CSV's text)`` of a path or an open text stream."""
    if not isinstance(source, (str, PathLike)):
        return name or "tracks CSV", source.read()
    path = Path(source)
    label = name or str(path)
    try:
        return label, path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise TracksCSVError(f"{label}: no such file") from None
    except UnicodeDecodeError:
        raise TracksCSVError(f"{label}: not a text CSV file (not UTF-8)") from None


def _check_header(header: list[str], label: str) -> None:
    if tuple(header[: len(REQUIRED_COLUMNS)]) == REQUIRED_COLUMNS:
        return
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise TracksCSVError(f"{label} line 1: missing column(s) {', '.join(repr(m) for m in missing)}; "
                             f"the header must start with {','.join(REQUIRED_COLUMNS)}")
    raise TracksCSVError(f"{label} line 1: the header must start with {','.join(REQUIRED_COLUMNS)} "
                         f"in that order, got {','.join(header[:len(REQUIRED_COLUMNS)])}")


def _parse_int(cell: str, where: str) -> int:
    """A non-negative id or frame (``3`` or ``3.0``) within :data:`MAX_ID`."""
    try:
        value = int(cell)
    except ValueError:
        try:
            f = float(cell)
        except ValueError:
            raise TracksCSVError(f"{where}: {cell!r} is not an integer") from None
        if not f.is_integer():
            raise TracksCSVError(f"{where}: {cell!r} is not an integer") from None
        if f > MAX_ID:
            raise TracksCSVError(f"{where}: {cell!r} is larger than the limit of {MAX_ID}") from None
        value = int(f)
    if value < 0:
        raise TracksCSVError(f"{where}: {value} is negative")
    if value > MAX_ID:
        raise TracksCSVError(f"{where}: {value} is larger than the limit of {MAX_ID}")
    return value


def _parse_number(col: str, cell: str, where: str, coord_limit: float) -> float:
    if cell == "" and col in ("score", "occluded", "X", "Y", "Z"):
        return DEFAULTS[col]
    try:
        value = float(cell)
    except ValueError:
        raise TracksCSVError(f"{where}: {cell!r} is not a number") from None
    if col in ("x", "y", "w", "h", "X", "Y", "Z"):
        if not math.isfinite(value):
            raise TracksCSVError(f"{where}: {cell!r} is not a finite number")
        if abs(value) > coord_limit:
            raise TracksCSVError(f"{where}: {cell!r} is beyond the limit of {coord_limit:g} "
                                 "(set PARTLAB_MAX_COORD to change it)")
    if col == "score" and math.isinf(value):
        raise TracksCSVError(f"{where}: {cell!r} is not a finite number")
    if col == "occluded" and not 0.0 <= value <= 1.0:
        raise TracksCSVError(f"{where}: {cell!r} is not a fraction between 0 and 1")
    if col in ("w", "h") and value < 0:
        raise TracksCSVError(f"{where}: negative size {value:g}")
    return value


def _parse_cell(col: str, cell: str, where: str, coord_limit: float):
    """One cell of column ``col``, checked; ``where`` names it in the error."""
    if col in ("frame", "track_id"):
        return _parse_int(cell, where)
    if col == "part":
        if cell not in PART_NAMES:
            raise TracksCSVError(f"{where}: unknown part {cell!r}; expected one of {', '.join(PART_NAMES)}")
        return cell
    if col in ("x", "y", "w", "h", "score", "occluded", "X", "Y", "Z"):
        return _parse_number(col, cell, where, coord_limit)
    if col == "failure":
        value = _parse_bool(cell)
        if value is None:
            raise TracksCSVError(f"{where}: {cell!r} is not a boolean (0/1/true/false)")
        return value
    return cell if cell else DEFAULTS[col]  # state, source, camera


def normalise_tracks(df: pd.DataFrame) -> pd.DataFrame:
    """Canonical column order, dtypes and defaults; extra columns are dropped."""
    import pandas as pd

    missing = [c for c in REQUIRED_COLUMNS if c not in df.columns]
    if missing:
        raise TracksCSVError(f"tracks table lacks column(s) {', '.join(missing)}")
    out = pd.DataFrame(index=df.index)
    out["frame"] = df["frame"].astype("int64")
    out["track_id"] = df["track_id"].astype("int64")
    out["part"] = df["part"].astype(str)
    for c in ("x", "y", "w", "h"):
        out[c] = df[c].astype("float64")
    for c in OPTIONAL_COLUMNS:
        if c in df.columns:
            out[c] = df[c]
        else:
            out[c] = DEFAULTS[c]
    out["score"] = out["score"].astype("float64")
    out["failure"] = out["failure"].fillna(False).astype(bool)
    out["occluded"] = out["occluded"].fillna(0.0).astype("float64")
    out["state"] = out["state"].fillna("").astype(str)
    out["source"] = out["source"].fillna("tracker").astype(str)
    out["camera"] = out["camera"].fillna("").astype(str)
    for c in ("X", "Y", "Z"):
        out[c] = pd.to_numeric(out[c], errors="coerce").astype("float64")
    return out.reset_index(drop=True)


def has_take_columns(df: pd.DataFrame) -> bool:
    """Whether some row names a camera or a 3D position."""
    return bool(len(df)) and bool((df["camera"] != "").any() or df[["X", "Y", "Z"]].notna().any(axis=None))


def write_tracks_csv(df: pd.DataFrame, dest: str | PathLike | io.TextIOBase) -> None:
    """Write a tracks table to a file or an open text stream, as :func:`write_track_records` does."""
    df = normalise_tracks(df)
    _write_rows(list(zip(*(df[c].tolist() for c in COLUMNS), strict=True)), dest)


def write_track_records(records: list[TrackRecord], dest: str | PathLike | io.TextIOBase) -> None:
    """Write tracks rows to a file (replaced whole, so a full disk leaves an earlier file as it was)
    or an open text stream: sorted by frame, track and part (parts in :data:`PART_NAMES` order,
    others after), ``%.2f`` floats, empty cells for NaN, ``failure`` as 0/1, and the take columns
    (``camera,X,Y,Z``) only when a row has them. No pandas: a body run writes its rows directly."""
    _write_rows([(r.frame, r.track_id, r.part, r.box.x, r.box.y, r.box.w, r.box.h, r.score, r.failure, r.occluded,
                  r.state, r.source, r.camera, r.X, r.Y, r.Z) for r in records], dest)


def _write_rows(rows: list[tuple], dest: str | PathLike | io.TextIOBase) -> None:
    """The one tracks CSV writer: ``rows`` are tuples of plain values in :data:`COLUMNS` order."""
    order = {p: i for i, p in enumerate(PART_NAMES)}
    rows.sort(key=lambda r: (r[0], r[1], order.get(r[2], len(order))))
    take = any(r[12] != "" or not (math.isnan(r[13]) and math.isnan(r[14]) and math.isnan(r[15])) for r in rows)
    header = [c for c in COLUMNS if take or c not in TAKE_COLUMNS]

    def num(v: float) -> str:
        return "" if math.isnan(v) else "%.2f" % v  # noqa: UP031 (pandas' float_format, the same text)

    def write(fh) -> None:
        out = csv.writer(fh, lineterminator="\n")
        out.writerow(header)
        for frame, track_id, part, x, y, w, h, score, failure, occluded, state, source, camera, X, Y, Z in rows:
            row = [frame, track_id, part, num(x), num(y), num(w), num(h), num(score), int(failure), num(occluded),
                   state, source]
            if take:
                row += [camera, num(X), num(Y), num(Z)]
            out.writerow(row)

    if not isinstance(dest, (str, PathLike)):
        write(dest)
        return
    from partlab.files import replacing

    with replacing(dest) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        write(fh)
