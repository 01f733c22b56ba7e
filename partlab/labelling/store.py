"""The annotation store: projects, clips, tracker boxes, human edits as revisions,
occluder regions and model bundles, in SQL through SQLAlchemy.

SQLite in the data directory is the embedded default (WAL mode, so a killed
process loses nothing committed and readers do not block the writer); any database
URL works through ``PARTLAB_DATABASE_URL`` (PostgreSQL the same way).

Boxes come in two layers. Tracker boxes (``tracker_boxes``) are replaced by each
tracker run from its start frame on. Human edits (``edits``) are never replaced:
every edit of a (clip, frame, track, part) appends a revision, so an edit can be
undone and nothing is overwritten silently. The effective box of a key is its
newest edit if it has one, else the tracker's. A writer states the revision it
saw; if someone else has written since, :class:`StaleEditError` refuses the write
(optimistic concurrency: no blind merge, no lost work).
"""

from __future__ import annotations

import json
import os
import threading
from dataclasses import dataclass
from datetime import UTC, datetime
from os import PathLike
from pathlib import Path

import pandas as pd
from sqlalchemy import (
    JSON,
    Boolean,
    DateTime,
    Float,
    ForeignKey,
    Integer,
    String,
    Text,
    UniqueConstraint,
    create_engine,
    delete,
    event,
    func,
    insert,
    select,
    update,
)
from sqlalchemy.engine import make_url
from sqlalchemy.exc import IntegrityError, OperationalError
from sqlalchemy.orm import DeclarativeBase, Mapped, Session, mapped_column

from partlab.labelling import migrations
from partlab.labelling.config import data_dir, database_url
from partlab.labelling.video import probe, store_by_hash
from partlab.tracking.core.box import Box
from partlab.tracking.parts import check_part
from partlab.tracking.tracks import COLUMNS, TracksCSVError, check_table, check_value, normalise_tracks


class StoreError(ValueError):
    """A request the store refuses; the message says why."""


class StaleEditError(StoreError):
    """Someone else changed the box since the writer read it."""


def _now() -> datetime:
    return datetime.now(UTC)


class Base(DeclarativeBase):
    pass


class ProjectRow(Base):
    __tablename__ = "projects"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    name: Mapped[str] = mapped_column(String(200), unique=True)
    default_bundle_id: Mapped[int | None] = mapped_column(Integer, nullable=True)
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)


class ClipRow(Base):
    __tablename__ = "clips"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    project_id: Mapped[int] = mapped_column(ForeignKey("projects.id"), index=True)
    name: Mapped[str] = mapped_column(String(300))
    path: Mapped[str] = mapped_column(Text)
    sha256: Mapped[str] = mapped_column(String(64), index=True)
    fps: Mapped[float] = mapped_column(Float)
    width: Mapped[int] = mapped_column(Integer)
    height: Mapped[int] = mapped_column(Integer)
    frame_count: Mapped[int] = mapped_column(Integer)
    exported: Mapped[bool] = mapped_column(Boolean, default=False)
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)
    __table_args__ = (UniqueConstraint("project_id", "sha256"),)


class RunRow(Base):
    __tablename__ = "tracker_runs"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    clip_id: Mapped[int] = mapped_column(ForeignKey("clips.id"), index=True)
    tracker: Mapped[str] = mapped_column(String(20))
    bundle: Mapped[str] = mapped_column(Text, default="")
    seed: Mapped[int] = mapped_column(Integer, default=0)
    start_frame: Mapped[int] = mapped_column(Integer, default=0)
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)


class TrackerBoxRow(Base):
    __tablename__ = "tracker_boxes"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    clip_id: Mapped[int] = mapped_column(ForeignKey("clips.id"), index=True)
    run_id: Mapped[int] = mapped_column(ForeignKey("tracker_runs.id"))
    frame: Mapped[int] = mapped_column(Integer, index=True)
    track_id: Mapped[int] = mapped_column(Integer)
    part: Mapped[str] = mapped_column(String(20))
    x: Mapped[float] = mapped_column(Float)
    y: Mapped[float] = mapped_column(Float)
    w: Mapped[float] = mapped_column(Float)
    h: Mapped[float] = mapped_column(Float)
    score: Mapped[float | None] = mapped_column(Float, nullable=True)
    failure: Mapped[bool] = mapped_column(Boolean, default=False)
    occluded: Mapped[float] = mapped_column(Float, default=0.0)
    state: Mapped[str] = mapped_column(String(40), default="")
    camera: Mapped[str] = mapped_column(String(100), default="", server_default="")
    X: Mapped[float | None] = mapped_column("world_x", Float, nullable=True)
    Y: Mapped[float | None] = mapped_column("world_y", Float, nullable=True)
    Z: Mapped[float | None] = mapped_column("world_z", Float, nullable=True)
    # the run that replaced this box (None: in effect); kept so a re-track is undone as one step
    superseded_by: Mapped[int | None] = mapped_column(Integer, nullable=True, index=True)


#: what a revision of a human edit is: ``box`` a box the user drew, moved or flagged (a
#: keyframe, a corrected frame, training truth); ``restore`` hands the key back to the tracker
#: (an undone first edit); ``track`` an identity operation (merge, split, change id, delete from
#: a frame on) that moved or removed the tracker's box without checking its position; ``view`` a box
#: of one view of a take moved to the reprojection of a 3D point corrected in another view
#: (:mod:`partlab.labelling.multiview`; it follows a keyframe but is not one itself).
EDIT_KINDS: tuple[str, ...] = ("box", "restore", "track", "view")


class EditRow(Base):
    """One revision of one human-edited box; ``deleted`` marks a deletion."""

    __tablename__ = "edits"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    clip_id: Mapped[int] = mapped_column(ForeignKey("clips.id"), index=True)
    frame: Mapped[int] = mapped_column(Integer, index=True)
    track_id: Mapped[int] = mapped_column(Integer)
    part: Mapped[str] = mapped_column(String(20))
    revision: Mapped[int] = mapped_column(Integer)
    x: Mapped[float] = mapped_column(Float)
    y: Mapped[float] = mapped_column(Float)
    w: Mapped[float] = mapped_column(Float)
    h: Mapped[float] = mapped_column(Float)
    failure: Mapped[bool] = mapped_column(Boolean, default=False)
    occluded: Mapped[float] = mapped_column(Float, default=0.0)
    deleted: Mapped[bool] = mapped_column(Boolean, default=False)
    kind: Mapped[str] = mapped_column(String(12), default="box", server_default="box")
    author: Mapped[str] = mapped_column(String(100), default="")
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)
    camera: Mapped[str] = mapped_column(String(100), default="", server_default="")
    X: Mapped[float | None] = mapped_column("world_x", Float, nullable=True)
    Y: Mapped[float | None] = mapped_column("world_y", Float, nullable=True)
    Z: Mapped[float | None] = mapped_column("world_z", Float, nullable=True)
    # The unique key is what makes a concurrent stale write fail even between two
    # processes that both passed the revision check.
    __table_args__ = (UniqueConstraint("clip_id", "frame", "track_id", "part", "revision"),)


class OccluderRow(Base):
    __tablename__ = "occluders"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    clip_id: Mapped[int] = mapped_column(ForeignKey("clips.id"), index=True)
    x: Mapped[float] = mapped_column(Float)
    y: Mapped[float] = mapped_column(Float)
    w: Mapped[float] = mapped_column(Float)
    h: Mapped[float] = mapped_column(Float)


class ReviewRow(Base):
    """A reviewer's verdict on frames ``start..stop`` (inclusive) of one track; the newest
    verdict covering a frame is the one in effect."""

    __tablename__ = "reviews"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    clip_id: Mapped[int] = mapped_column(ForeignKey("clips.id"), index=True)
    track_id: Mapped[int] = mapped_column(Integer)
    start: Mapped[int] = mapped_column(Integer)
    stop: Mapped[int] = mapped_column(Integer)
    accepted: Mapped[bool] = mapped_column(Boolean)
    author: Mapped[str] = mapped_column(String(100), default="")
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)


class BundleRow(Base):
    __tablename__ = "bundles"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    project_id: Mapped[int] = mapped_column(ForeignKey("projects.id"), index=True)
    name: Mapped[str] = mapped_column(String(200))
    path: Mapped[str] = mapped_column(Text)
    summary: Mapped[str] = mapped_column(Text, default="{}")
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)
    __table_args__ = (UniqueConstraint("project_id", "name"),)


class TakeRow(Base):
    """A take: one or more synchronized streams (revision 2)."""

    __tablename__ = "takes"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    project_id: Mapped[int] = mapped_column(ForeignKey("projects.id"), index=True)
    name: Mapped[str] = mapped_column(String(300))
    path: Mapped[str] = mapped_column(Text, default="")
    fps: Mapped[float | None] = mapped_column(Float, nullable=True)
    #: what belongs to the world frame rather than one camera (units, origin, source file...)
    calibration: Mapped[dict] = mapped_column(JSON, default=dict)
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)
    __table_args__ = (UniqueConstraint("project_id", "name"),)


class StreamRow(Base):
    """One stream of a take, in the take's order; its video is a clip (at most one take's stream)."""

    __tablename__ = "streams"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    take_id: Mapped[int] = mapped_column(ForeignKey("takes.id"), index=True)
    name: Mapped[str] = mapped_column(String(100))
    position: Mapped[int] = mapped_column(Integer)
    clip_id: Mapped[int | None] = mapped_column(ForeignKey("clips.id"), nullable=True)
    depth_path: Mapped[str] = mapped_column(Text, default="")
    #: ``Camera.to_dict()`` of the stream, or None when uncalibrated
    calibration: Mapped[dict | None] = mapped_column(JSON, nullable=True)
    __table_args__ = (UniqueConstraint("take_id", "name"), UniqueConstraint("take_id", "position"),
                      UniqueConstraint("clip_id"))


class EventRow(Base):
    """One revision of one event (an activity between two frames); ``deleted`` marks a deletion."""

    __tablename__ = "events"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    clip_id: Mapped[int] = mapped_column(ForeignKey("clips.id"), index=True)
    take_id: Mapped[int | None] = mapped_column(ForeignKey("takes.id"), nullable=True)
    #: the event's identity across its revisions, unique within the clip
    event_id: Mapped[int] = mapped_column(Integer)
    revision: Mapped[int] = mapped_column(Integer)
    start_frame: Mapped[int] = mapped_column(Integer)
    end_frame: Mapped[int] = mapped_column(Integer)
    type: Mapped[str] = mapped_column(String(40))
    tracks: Mapped[list] = mapped_column(JSON, default=list)
    parts: Mapped[list] = mapped_column(JSON, default=list)
    confidence: Mapped[float | None] = mapped_column(Float, nullable=True)
    attributes: Mapped[dict] = mapped_column(JSON, default=dict)
    source: Mapped[str] = mapped_column(String(20), default="human")
    deleted: Mapped[bool] = mapped_column(Boolean, default=False)
    author: Mapped[str] = mapped_column(String(100), default="")
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)
    __table_args__ = (UniqueConstraint("clip_id", "event_id", "revision"),)


class JobRow(Base):
    """A job of the app run by a Dask worker (revision 3); see :mod:`partlab.engine.jobs`."""

    __tablename__ = "jobs"
    id: Mapped[str] = mapped_column(String(64), primary_key=True)
    kind: Mapped[str] = mapped_column(String(40))
    label: Mapped[str] = mapped_column(Text)
    meta: Mapped[dict] = mapped_column(JSON, default=dict)
    status: Mapped[str] = mapped_column(String(20), default="queued", index=True)
    done: Mapped[int] = mapped_column(Integer, default=0)
    total: Mapped[int] = mapped_column(Integer, default=0)
    error: Mapped[str] = mapped_column(Text, default="")
    result: Mapped[dict | None] = mapped_column(JSON, nullable=True)
    cancel: Mapped[bool] = mapped_column(Boolean, default=False)
    worker: Mapped[str] = mapped_column(String(200), default="")
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)
    updated: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)
    finished: Mapped[datetime | None] = mapped_column(DateTime(timezone=True), nullable=True)


class UserRow(Base):
    """A user who signs in to the app (revision 5); ``password`` is an Argon2id hash, never the password."""

    __tablename__ = "users"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    name: Mapped[str] = mapped_column(String(100), unique=True)
    password: Mapped[str] = mapped_column(Text)
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)


class RoleRow(Base):
    """One user's role in one project (revision 5)."""

    __tablename__ = "project_roles"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    user_id: Mapped[int] = mapped_column(ForeignKey("users.id"), index=True)
    project_id: Mapped[int] = mapped_column(ForeignKey("projects.id"), index=True)
    role: Mapped[str] = mapped_column(String(20))
    __table_args__ = (UniqueConstraint("user_id", "project_id"),)


@dataclass(frozen=True)
class Project:
    id: int
    name: str
    default_bundle_id: int | None
    created: datetime


@dataclass(frozen=True)
class Clip:
    id: int
    project_id: int
    name: str
    path: Path
    sha256: str
    fps: float
    width: int
    height: int
    frame_count: int
    created: datetime
    exported: bool


@dataclass(frozen=True)
class BundleRecord:
    id: int
    project_id: int
    name: str
    path: Path
    summary: dict
    created: datetime


@dataclass(frozen=True)
class StreamRecord:
    name: str
    position: int
    clip_id: int | None
    calibration: dict | None
    depth_path: str


@dataclass(frozen=True)
class TakeRecord:
    id: int
    project_id: int
    name: str
    path: str
    fps: float | None
    calibration: dict
    streams: tuple[StreamRecord, ...]
    created: datetime


#: columns of :meth:`Store.events`
EVENT_COLUMNS = ["event_id", "revision", "start_frame", "end_frame", "type", "tracks", "parts", "confidence",
                 "attributes", "source", "author", "take_id"]


def _nan(v: float | None) -> float:
    return float("nan") if v is None else float(v)


def _num_or_none(v) -> float | None:
    return None if v is None or pd.isna(v) else float(v)


def _project(r: ProjectRow) -> Project:
    return Project(r.id, r.name, r.default_bundle_id, r.created)


def _clip(r: ClipRow) -> Clip:
    return Clip(r.id, r.project_id, r.name, Path(r.path), r.sha256, r.fps, r.width, r.height, r.frame_count,
                r.created, bool(r.exported))


def _bundle(r: BundleRow) -> BundleRecord:
    return BundleRecord(r.id, r.project_id, r.name, Path(r.path), json.loads(r.summary or "{}"), r.created)


_ENGINES: dict[str, object] = {}
_ENGINES_LOCK = threading.Lock()


def connect_timeout() -> int:
    """Seconds to wait for a database server (``PARTLAB_DB_CONNECT_TIMEOUT``, default 5)."""
    raw = os.environ.get("PARTLAB_DB_CONNECT_TIMEOUT", "5")
    try:
        value = int(raw)
    except ValueError:
        raise StoreError(f"PARTLAB_DB_CONNECT_TIMEOUT must be a whole number of seconds, got {raw!r}") from None
    if value < 1:
        raise StoreError(f"PARTLAB_DB_CONNECT_TIMEOUT must be at least 1, got {value}")
    return value


#: what SQLite and PostgreSQL say when the database cannot be written, in words a user can act on
_STORAGE_FAILURES = (
    ("database or disk is full", "the disk holding the database is full"),
    ("could not extend file", "the disk holding the database is full"),
    ("no space left on device", "the disk holding the database is full"),
    ("attempt to write a readonly database", "the database is read-only (file or data directory)"),
    ("read-only transaction", "the database server only allows reading"),
    ("readonly database", "the database is read-only (file or data directory)"),
    ("unable to open database file", "the database file cannot be opened (a missing or read-only data directory?)"),
    ("disk i/o error", "the disk reported an I/O error"),
)


def storage_failure(exc: BaseException) -> str | None:
    """The reason, in words, when ``exc`` (a DBAPI error, or SQLAlchemy's wrapper of one) is a full
    disk or a read-only database; None for anything else."""
    text = " ".join(str(getattr(exc, "orig", None) or exc).split()).lower()
    code = getattr(getattr(exc, "orig", exc), "sqlstate", None)
    if code == "53100":  # PostgreSQL disk_full
        return "the disk holding the database is full"
    return next((said for found, said in _STORAGE_FAILURES if found in text), None)


def _storage_error(url: str, reason: str) -> StoreError:
    shown = make_url(url).render_as_string(hide_password=True)
    return StoreError(f"{shown}: {reason}; this change was not saved (what was saved before is intact)")


def dispose_engines() -> None:
    """Close every pooled connection of this process's engines and forget them (the next
    :class:`Store` opens a new one). For tests and workers that open many databases in turn: a
    PostgreSQL server refuses clients once its connection limit is reached."""
    with _ENGINES_LOCK:
        engines = list(_ENGINES.values())
        _ENGINES.clear()
    for eng in engines:
        eng.dispose()


def _engine(url: str):
    """One engine per URL per process (Streamlit reruns must not open new pools)."""
    with _ENGINES_LOCK:
        eng = _ENGINES.get(url)
        if eng is None:
            kwargs = {}
            if url.startswith("sqlite"):
                kwargs["connect_args"] = {"check_same_thread": False, "timeout": 30}
            elif url.startswith("postgresql"):  # a server that never answers fails in seconds, not minutes
                kwargs["connect_args"] = {"connect_timeout": connect_timeout()}
            eng = create_engine(url, **kwargs)

            @event.listens_for(eng, "handle_error")
            def _full_or_read_only(ctx):  # a full disk is a sentence, not a driver traceback
                reason = storage_failure(ctx.original_exception)
                if reason is not None:
                    raise _storage_error(url, reason) from ctx.original_exception

            if url.startswith("sqlite"):
                @event.listens_for(eng, "connect")
                def _pragmas(dbapi_conn, _record):
                    cur = dbapi_conn.cursor()
                    cur.execute("PRAGMA journal_mode=WAL")
                    cur.execute("PRAGMA synchronous=NORMAL")
                    cur.execute("PRAGMA foreign_keys=ON")
                    cur.execute("PRAGMA busy_timeout=30000")
                    cur.close()
            try:
                migrations.upgrade(eng)
            except migrations.SchemaError as exc:
                eng.dispose()
                raise StoreError(str(exc)) from None
            except StoreError:
                eng.dispose()
                raise
            except OperationalError as exc:
                eng.dispose()
                reason = storage_failure(exc)
                if reason is not None:
                    raise _storage_error(url, reason) from None
                shown = make_url(url).render_as_string(hide_password=True)
                reason = " ".join(str(getattr(exc, "orig", exc)).split())[:200]
                raise StoreError(f"cannot reach the database {shown} within {connect_timeout()} s ({reason}); "
                                 "check PARTLAB_DATABASE_URL and that the server is up") from None
            _ENGINES[url] = eng
        return eng


def _check_edit(frame, track_id, part, box, failure, occluded, xyz) -> None:
    """An edit by the tracks CSV's rules (finite, in range, int32, no negative sizes), refused with a
    StoreError naming the box and the value before any revision is compared (a NaN is not "stale")."""
    where = f"edit of {part} #{track_id} at frame {frame}"
    values = {"frame": frame, "track_id": track_id}
    if box is not None:
        values.update(x=box.x, y=box.y, w=box.w, h=box.h)
    if occluded is not None:
        values["occluded"] = occluded
    if failure is not None:
        values["failure"] = failure
    if xyz is not None and len(xyz) == 3:
        values.update(X=xyz[0], Y=xyz[1], Z=xyz[2])
    try:
        for col, v in values.items():
            check_value(col, v, f"{where}, {col}")
    except TracksCSVError as exc:
        raise StoreError(f"Not a usable box: {exc}") from None


def _point(before: dict | None, camera: str | None, xyz) -> dict:
    """camera and X, Y, Z of an edit: the given ones, else the box's current ones."""
    out = dict(camera=str(camera) if camera is not None else (before or {}).get("camera") or "")
    if xyz is not None:
        if len(xyz) != 3:
            raise StoreError(f"a 3D point needs X, Y, Z (mm), got {len(xyz)} numbers")
        out.update(X=_num_or_none(xyz[0]), Y=_num_or_none(xyz[1]), Z=_num_or_none(xyz[2]))
    else:
        out.update({k: (before or {}).get(k) for k in ("X", "Y", "Z")})
    return out


class Store:
    """The annotation store; cheap to construct (engines are shared per URL)."""

    def __init__(self, url: str | None = None, clips_dir: str | PathLike | None = None):
        self.url = url or database_url()
        self.engine = _engine(self.url)
        self.clips_dir = Path(clips_dir) if clips_dir else data_dir() / "clips"

    def _session(self) -> Session:
        return Session(self.engine, expire_on_commit=False)

    # ----------------------------------------------------------------- projects
    def create_project(self, name: str) -> Project:
        name = name.strip()
        if not name:
            raise StoreError("a project needs a name")
        with self._session() as s:
            if s.scalar(select(ProjectRow).where(ProjectRow.name == name)) is not None:
                raise StoreError(f"a project named {name!r} exists already")
            row = ProjectRow(name=name)
            s.add(row)
            s.commit()
            return _project(row)

    def projects(self) -> list[Project]:
        with self._session() as s:
            return [_project(r) for r in s.scalars(select(ProjectRow).order_by(ProjectRow.id))]

    def project(self, project_id: int) -> Project:
        with self._session() as s:
            row = s.get(ProjectRow, project_id)
            if row is None:
                raise StoreError(f"no project with id {project_id}")
            return _project(row)

    def project_by_name(self, name: str) -> Project | None:
        with self._session() as s:
            row = s.scalar(select(ProjectRow).where(ProjectRow.name == name))
            return _project(row) if row else None

    # -------------------------------------------------------------------- clips
    def add_clip(self, project_id: int, video_path: str | PathLike, name: str | None = None) -> Clip:
        """Copy a video into the data directory (by content hash) and register it.

        Raises :class:`partlab.labelling.video.VideoError` for unreadable files; adding the same
        content to the same project again returns the existing clip.
        """
        self.project(project_id)
        info = probe(video_path)
        path, digest = store_by_hash(video_path, self.clips_dir)
        with self._session() as s:
            existing = s.scalar(select(ClipRow).where(ClipRow.project_id == project_id, ClipRow.sha256 == digest))
            if existing is not None:
                return _clip(existing)
            row = ClipRow(project_id=project_id, name=name or Path(video_path).name, path=str(path), sha256=digest,
                          fps=info.fps, width=info.width, height=info.height, frame_count=info.frame_count)
            s.add(row)
            s.commit()
            return _clip(row)

    def clips(self, project_id: int) -> list[Clip]:
        with self._session() as s:
            rows = s.scalars(select(ClipRow).where(ClipRow.project_id == project_id).order_by(ClipRow.id))
            return [_clip(r) for r in rows]

    def clip(self, clip_id: int) -> Clip:
        with self._session() as s:
            row = s.get(ClipRow, clip_id)
            if row is None:
                raise StoreError(f"no clip with id {clip_id}")
            return _clip(row)

    def mark_exported(self, clip_id: int) -> None:
        with self._session() as s:
            row = s.get(ClipRow, clip_id)
            if row is None:
                raise StoreError(f"no clip with id {clip_id}")
            row.exported = True
            s.commit()

    # -------------------------------------------------------------- tracker runs
    def save_tracker_run(self, clip_id: int, tracks: pd.DataFrame, tracker: str = "body", bundle: str = "",
                         seed: int = 0, start_frame: int = 0, stop_frame: int | None = None,
                         track_ids: list[int] | None = None, parts: list[str] | None = None) -> int:
        """Store a tracker's boxes; they replace earlier tracker boxes of frames in
        ``[start_frame, stop_frame)`` (of the tracks in ``track_ids`` only, when given: a
        re-track keeps every track it was not asked to change), and of ``parts`` only when
        given. Replaced boxes are kept as
        superseded by this run, so :meth:`undo_run` brings them back; human edits are never touched."""
        self.clip(clip_id)
        df = normalise_tracks(tracks)
        try:  # the tracks CSV's rules: nothing is stored that partlab's own reader would refuse
            check_table(df, f"tracker run of clip {clip_id}")
        except TracksCSVError as exc:
            raise StoreError(str(exc)) from None
        with self._session() as s:
            run = RunRow(clip_id=clip_id, tracker=tracker, bundle=str(bundle), seed=seed, start_frame=start_frame)
            s.add(run)
            s.flush()
            cond = [TrackerBoxRow.clip_id == clip_id, TrackerBoxRow.frame >= start_frame,
                    TrackerBoxRow.superseded_by.is_(None)]
            if stop_frame is not None:
                cond.append(TrackerBoxRow.frame < stop_frame)
                df = df[df.frame < stop_frame]
            if track_ids is not None:
                ids = [int(t) for t in track_ids]
                cond.append(TrackerBoxRow.track_id.in_(ids))
                df = df[df.track_id.isin(ids)]
            if parts is not None:
                cond.append(TrackerBoxRow.part.in_(list(parts)))
                df = df[df.part.isin(list(parts))]
            s.execute(update(TrackerBoxRow).where(*cond).values(superseded_by=run.id))
            df = df[df.frame >= start_frame]
            records = [
                dict(clip_id=clip_id, run_id=run.id, frame=int(r.frame), track_id=int(r.track_id), part=r.part,
                     x=float(r.x), y=float(r.y), w=float(r.w), h=float(r.h),
                     score=None if pd.isna(r.score) else float(r.score), failure=bool(r.failure),
                     occluded=float(r.occluded), state=str(r.state), camera=str(r.camera),
                     X=_num_or_none(r.X), Y=_num_or_none(r.Y), Z=_num_or_none(r.Z))
                for r in df.itertuples(index=False)
            ]
            if records:
                s.execute(insert(TrackerBoxRow), records)  # ORM keys: X -> world_x
            s.commit()
            return run.id

    def undo_run(self, clip_id: int, run_id: int) -> None:
        """Take a tracker run back as one step: its boxes go, the boxes it replaced come back.
        Only the clip's newest run can be undone (an older one's boxes may be replaced again)."""
        with self._session() as s:
            newest = s.scalar(select(func.max(RunRow.id)).where(RunRow.clip_id == clip_id))
            if newest is None or int(newest) != int(run_id):
                raise StoreError(f"run {run_id} is not the newest tracker run of clip {clip_id}; "
                                 "only the newest run can be undone")
            s.execute(delete(TrackerBoxRow).where(TrackerBoxRow.clip_id == clip_id, TrackerBoxRow.run_id == run_id))
            s.execute(update(TrackerBoxRow).where(TrackerBoxRow.clip_id == clip_id,
                                                  TrackerBoxRow.superseded_by == run_id).values(superseded_by=None))
            s.execute(delete(RunRow).where(RunRow.id == run_id))
            s.commit()

    def data_version(self, clip_id: int) -> tuple[int, int, int, int]:
        """Changes whenever the clip's effective boxes or reviews may have changed (an edit, a
        run stored or undone, a verdict): a cheap cache key for readers of :meth:`tracks`."""
        with self._session() as s:
            e = s.scalar(select(func.max(EditRow.id)).where(EditRow.clip_id == clip_id)) or 0
            n, r = s.execute(select(func.count(RunRow.id), func.max(RunRow.id)).where(RunRow.clip_id == clip_id)).one()
            v = s.scalar(select(func.max(ReviewRow.id)).where(ReviewRow.clip_id == clip_id)) or 0
            nv = s.scalar(select(func.count(ReviewRow.id)).where(ReviewRow.clip_id == clip_id)) or 0
        return int(e), int(n or 0) * 1_000_000 + int(r or 0), int(v), int(nv)

    def runs(self, clip_id: int) -> pd.DataFrame:
        with self._session() as s:
            rows = s.scalars(select(RunRow).where(RunRow.clip_id == clip_id).order_by(RunRow.id)).all()
            return pd.DataFrame([dict(id=r.id, tracker=r.tracker, bundle=r.bundle, seed=r.seed,
                                      start_frame=r.start_frame, created=r.created) for r in rows])

    # ------------------------------------------------------------ effective boxes
    def _effective(self, clip_id: int, frame: int | None) -> pd.DataFrame:
        with self._session() as s:
            tq = select(TrackerBoxRow).where(TrackerBoxRow.clip_id == clip_id, TrackerBoxRow.superseded_by.is_(None))
            newest = (select(EditRow.frame, EditRow.track_id, EditRow.part,
                             func.max(EditRow.revision).label("rev"))
                      .where(EditRow.clip_id == clip_id).group_by(EditRow.frame, EditRow.track_id, EditRow.part))
            if frame is not None:
                tq = tq.where(TrackerBoxRow.frame == frame)
                newest = newest.where(EditRow.frame == frame)
            newest = newest.subquery()
            eq = select(EditRow).join(newest, (EditRow.clip_id == clip_id) & (EditRow.frame == newest.c.frame)
                                      & (EditRow.track_id == newest.c.track_id) & (EditRow.part == newest.c.part)
                                      & (EditRow.revision == newest.c.rev))
            tracker = [(r.frame, r.track_id, r.part, r.x, r.y, r.w, r.h, _nan(r.score), r.failure, r.occluded,
                        r.state, "tracker", r.camera, _nan(r.X), _nan(r.Y), _nan(r.Z), 0)
                       for r in s.scalars(tq)]
            # a "restore" revision leaves the tracker's box in effect (its revision still guards stale writes)
            edits, restored = [], []
            for r in s.scalars(eq):
                if r.kind == "restore":
                    restored.append((r.frame, r.track_id, r.part, r.revision))
                    continue
                edits.append((r.frame, r.track_id, r.part, r.x, r.y, r.w, r.h, float("nan"), r.failure, r.occluded,
                              "", "human" if r.kind == "box" else "tracker", r.camera, _nan(r.X), _nan(r.Y),
                              _nan(r.Z), r.revision, r.deleted))
        cols = list(COLUMNS) + ["revision"]
        tdf = pd.DataFrame(tracker, columns=cols)
        edf = pd.DataFrame(edits, columns=cols + ["deleted"])
        if restored:
            rdf = pd.DataFrame(restored, columns=["frame", "track_id", "part", "rev"])
            tdf = tdf.merge(rdf, on=["frame", "track_id", "part"], how="left")
            tdf["revision"] = tdf["rev"].fillna(tdf["revision"]).astype("int64")
            tdf = tdf.drop(columns="rev")
        if len(edf):
            keys = ["frame", "track_id", "part"]
            tdf = tdf.merge(edf[keys], on=keys, how="left", indicator=True)
            tdf = tdf[tdf["_merge"] == "left_only"].drop(columns="_merge")
            edf = edf[~edf["deleted"].astype(bool)].drop(columns="deleted")
            frames = [f for f in (tdf, edf) if len(f)]
            df = pd.concat(frames, ignore_index=True) if frames else tdf
        else:
            df = tdf
        out = normalise_tracks(df)
        out["revision"] = df["revision"].astype("int64").to_numpy() if len(df) else pd.Series([], dtype="int64")
        return out.sort_values(["frame", "track_id", "part"], kind="stable").reset_index(drop=True)

    def tracks(self, clip_id: int) -> pd.DataFrame:
        """Every effective box of a clip (tracks CSV columns plus ``revision``)."""
        return self._effective(clip_id, None)

    def frame_boxes(self, clip_id: int, frame: int) -> pd.DataFrame:
        return self._effective(clip_id, frame)

    # ------------------------------------------------------------- human edits
    def revision(self, clip_id: int, frame: int, track_id: int, part: str) -> int:
        with self._session() as s:
            return self._revision(s, clip_id, frame, track_id, part)

    @staticmethod
    def _revision(s: Session, clip_id: int, frame: int, track_id: int, part: str) -> int:
        rev = s.scalar(select(func.max(EditRow.revision)).where(
            EditRow.clip_id == clip_id, EditRow.frame == frame, EditRow.track_id == track_id, EditRow.part == part))
        return int(rev or 0)

    def edit_box(self, clip_id: int, frame: int, track_id: int, part: str, box: Box | None, *,
                 failure: bool | None = None, occluded: float | None = None, expected_revision: int,
                 author: str = "", camera: str | None = None,
                 xyz: tuple[float, float, float] | None = None, kind: str = "box") -> int:
        """Write a human edit of one box (``box=None`` deletes it); returns the new revision.

        ``failure``/``occluded``/``camera`` (stream name) and ``xyz`` (world mm; a tuple of NaN
        clears it) left as None keep their current values; ``kind`` as in :data:`EDIT_KINDS`.
        Refused with :class:`StaleEditError` when the newest revision is not ``expected_revision``.
        """
        [rev] = self.edit_boxes(clip_id, [dict(frame=frame, track_id=track_id, part=part, box=box, failure=failure,
                                               occluded=occluded, expected_revision=expected_revision, kind=kind,
                                               camera=camera, xyz=xyz)],
                                author=author)
        return rev

    def edit_boxes(self, clip_id: int, changes: list[dict], author: str = "") -> list[int]:
        """Write several edits in one transaction (all or none); each change is a dict of
        :meth:`edit_box`'s arguments (``frame, track_id, part, box, expected_revision`` and
        optional ``failure, occluded, kind``). Returns the new revisions in order."""
        clip = self.clip(clip_id)
        out = []
        with self._session() as s:
            for c in changes:
                _check_edit(c["frame"], c["track_id"], c["part"], c.get("box"), c.get("failure"), c.get("occluded"),
                            c.get("xyz"))
                frame, track_id, part = int(c["frame"]), int(c["track_id"]), check_part(str(c["part"]))
                kind = c.get("kind", "box")
                if kind not in EDIT_KINDS:
                    raise StoreError(f"edit kind must be one of {', '.join(EDIT_KINDS)}, got {kind!r}")
                if not 0 <= frame < clip.frame_count:
                    raise StoreError(f"frame {frame} is outside clip {clip.name!r} (0..{clip.frame_count - 1})")
                current = self._revision(s, clip_id, frame, track_id, part)
                if current != int(c["expected_revision"]):
                    s.rollback()
                    raise StaleEditError(self._stale_message(clip, frame, track_id, part, current,
                                                             int(c["expected_revision"])))
                before = self._current_content(s, clip_id, frame, track_id, part)
                box, failure, occluded = c.get("box"), c.get("failure"), c.get("occluded")
                if box is None:
                    x = y = w = h = 0.0
                    if before is not None:
                        x, y, w, h = before["x"], before["y"], before["w"], before["h"]
                else:
                    x, y, w, h = float(box.x), float(box.y), float(box.w), float(box.h)
                s.add(EditRow(clip_id=clip_id, frame=frame, track_id=track_id, part=part, revision=current + 1,
                              x=x, y=y, w=w, h=h,
                              failure=bool(failure) if failure is not None else bool(before and before["failure"]),
                              occluded=float(occluded) if occluded is not None else
                              float(before["occluded"]) if before else 0.0,
                              deleted=box is None and kind != "restore", author=author, kind=kind,
                              **_point(before, c.get("camera"), c.get("xyz"))))
                s.flush()
                out.append(current + 1)
            try:
                s.commit()
            except IntegrityError:
                s.rollback()
                raise StaleEditError(f"some boxes of {clip.name!r} were changed by someone else meanwhile; "
                                     "reload the frame and apply your change again") from None
        return out

    @staticmethod
    def _stale_message(clip: Clip, frame: int, track_id: int, part: str, current: int, expected: int) -> str:
        return (f"the {part} box of track {track_id} at frame {frame} of {clip.name!r} was changed by someone else "
                f"(revision {current}, you had {expected}); reload the frame and apply your change again")

    @staticmethod
    def _tracker_row(s: Session, clip_id: int, frame: int, track_id: int, part: str):
        return s.scalar(select(TrackerBoxRow).where(
            TrackerBoxRow.clip_id == clip_id, TrackerBoxRow.frame == frame, TrackerBoxRow.track_id == track_id,
            TrackerBoxRow.part == part, TrackerBoxRow.superseded_by.is_(None)).limit(1))

    @classmethod
    def _current_content(cls, s: Session, clip_id: int, frame: int, track_id: int, part: str) -> dict | None:
        e = s.scalar(select(EditRow).where(EditRow.clip_id == clip_id, EditRow.frame == frame,
                                           EditRow.track_id == track_id, EditRow.part == part)
                     .order_by(EditRow.revision.desc()).limit(1))
        if e is not None and e.kind != "restore":
            return dict(x=e.x, y=e.y, w=e.w, h=e.h, failure=e.failure, occluded=e.occluded, deleted=e.deleted,
                        camera=e.camera, X=e.X, Y=e.Y, Z=e.Z)
        t = cls._tracker_row(s, clip_id, frame, track_id, part)
        if t is not None:
            return dict(x=t.x, y=t.y, w=t.w, h=t.h, failure=t.failure, occluded=t.occluded, deleted=False,
                        camera=t.camera, X=t.X, Y=t.Y, Z=t.Z)
        return None

    def history(self, clip_id: int, frame: int, track_id: int, part: str) -> pd.DataFrame:
        with self._session() as s:
            rows = s.scalars(select(EditRow).where(EditRow.clip_id == clip_id, EditRow.frame == frame,
                                                   EditRow.track_id == track_id, EditRow.part == part)
                             .order_by(EditRow.revision)).all()
            cols = ["revision", "x", "y", "w", "h", "failure", "occluded", "deleted", "kind", "author", "created",
                    "camera", "X", "Y", "Z"]
            return pd.DataFrame([{c: _nan(getattr(r, c)) if c in "XYZ" else getattr(r, c) for c in cols}
                                 for r in rows], columns=cols)

    def undo(self, clip_id: int, frame: int, track_id: int, part: str, expected_revision: int,
             author: str = "") -> int:
        """Undo the newest edit by writing the previous revision's content as a new
        revision (so the undo itself can be undone); undoing the first edit hands the
        key back to the tracker (a ``restore`` revision: no longer a correction)."""
        [rev] = self.undo_many(clip_id, [(frame, track_id, part, expected_revision)], author=author)
        return rev

    def undo_many(self, clip_id: int, keys: list[tuple[int, int, str, int]], author: str = "") -> list[int]:
        """:meth:`undo` of several ``(frame, track_id, part, expected_revision)`` keys in one transaction."""
        clip = self.clip(clip_id)
        out = []
        with self._session() as s:
            for frame, track_id, part, expected in keys:
                current = self._revision(s, clip_id, frame, track_id, part)
                if current != expected:
                    s.rollback()
                    raise StaleEditError(self._stale_message(clip, frame, track_id, part, current, expected))
                if current == 0:
                    s.rollback()
                    raise StoreError(f"nothing to undo for the {part} box of track {track_id} at frame {frame}")
                prev = s.scalar(select(EditRow).where(EditRow.clip_id == clip_id, EditRow.frame == frame,
                                                      EditRow.track_id == track_id, EditRow.part == part,
                                                      EditRow.revision == current - 1))
                if prev is not None:
                    content = dict(x=prev.x, y=prev.y, w=prev.w, h=prev.h, failure=prev.failure,
                                   occluded=prev.occluded, deleted=prev.deleted, kind=prev.kind, camera=prev.camera,
                                   X=prev.X, Y=prev.Y, Z=prev.Z)
                else:
                    content = dict(x=0.0, y=0.0, w=0.0, h=0.0, failure=False, occluded=0.0, deleted=False,
                                   kind="restore")
                s.add(EditRow(clip_id=clip_id, frame=frame, track_id=track_id, part=part, revision=current + 1,
                              author=author, **content))
                s.flush()
                out.append(current + 1)
            try:
                s.commit()
            except IntegrityError:
                s.rollback()
                raise StaleEditError(f"some boxes of {clip.name!r} were changed by someone else meanwhile; "
                                     "reload the frame and undo again") from None
        return out

    def next_track_id(self, clip_id: int) -> int:
        with self._session() as s:
            a = s.scalar(select(func.max(TrackerBoxRow.track_id)).where(TrackerBoxRow.clip_id == clip_id)) or 0
            b = s.scalar(select(func.max(EditRow.track_id)).where(EditRow.clip_id == clip_id)) or 0
            return int(max(a, b)) + 1

    def edit_state(self, clip_id: int, keys: list[tuple[int, int, str]]) -> list[dict]:
        """For each key ``(frame, track_id, part)``, the change that would write its human
        layer back as it is now (what an undo of a later step writes): the newest edit's
        content and kind, or a ``restore`` when it has none; ``expected_revision`` is its
        newest revision now."""
        out = []
        with self._session() as s:
            for frame, track_id, part in keys:
                e = s.scalar(select(EditRow).where(EditRow.clip_id == clip_id, EditRow.frame == frame,
                                                   EditRow.track_id == track_id, EditRow.part == part)
                             .order_by(EditRow.revision.desc()).limit(1))
                c = dict(frame=int(frame), track_id=int(track_id), part=str(part), box=None, kind="restore",
                         expected_revision=int(e.revision) if e is not None else 0)
                if e is not None and e.kind != "restore":
                    c.update(kind=e.kind, failure=bool(e.failure), occluded=float(e.occluded), camera=e.camera,
                             xyz=(_nan(e.X), _nan(e.Y), _nan(e.Z)), box=None if e.deleted else Box(e.x, e.y, e.w, e.h))
                out.append(c)
        return out

    def revisions(self, clip_id: int) -> dict[tuple[int, int, str], int]:
        """The newest revision of every edited key ``(frame, track_id, part)`` of a clip."""
        with self._session() as s:
            rows = s.execute(select(EditRow.frame, EditRow.track_id, EditRow.part, func.max(EditRow.revision))
                             .where(EditRow.clip_id == clip_id)
                             .group_by(EditRow.frame, EditRow.track_id, EditRow.part)).all()
        return {(int(f), int(t), str(p)): int(r) for f, t, p, r in rows}

    def keyframes(self, clip_id: int) -> pd.DataFrame:
        """The human boxes in effect (``frame, track_id, part`` and the box; deletions
        included with ``deleted``): the corrected keys, which are the keyframes of track mode."""
        with self._session() as s:
            newest = (select(EditRow.frame, EditRow.track_id, EditRow.part, func.max(EditRow.revision).label("rev"))
                      .where(EditRow.clip_id == clip_id).group_by(EditRow.frame, EditRow.track_id, EditRow.part)
                      .subquery())
            rows = s.scalars(select(EditRow).join(
                newest, (EditRow.clip_id == clip_id) & (EditRow.frame == newest.c.frame)
                & (EditRow.track_id == newest.c.track_id) & (EditRow.part == newest.c.part)
                & (EditRow.revision == newest.c.rev)).where(EditRow.kind == "box")).all()
            cols = ["frame", "track_id", "part", "x", "y", "w", "h", "failure", "occluded", "deleted", "revision"]
            df = pd.DataFrame([{c: getattr(r, c) for c in cols} for r in rows], columns=cols)
        return df.sort_values(["track_id", "part", "frame"]).reset_index(drop=True)

    def human_frames(self, clip_id: int) -> list[int]:
        """Frames with at least one human correction in effect (an undone edit is none), ascending."""
        return sorted({int(f) for f in self.keyframes(clip_id).frame})

    def progress(self, clip_id: int) -> dict:
        clip = self.clip(clip_id)
        corrected = len(self.human_frames(clip_id))
        frames = clip.frame_count
        accepted = len(self.accepted_frames(clip_id))
        return dict(frames=frames, corrected_frames=corrected, fraction=corrected / frames if frames else 0.0,
                    accepted_frames=accepted, accepted_fraction=accepted / frames if frames else 0.0)

    # ------------------------------------------------------------------- review
    def review(self, clip_id: int, track_id: int, start: int, stop: int, accepted: bool, author: str = "") -> int:
        """Accept or reject frames ``start..stop`` (inclusive) of one track; returns the verdict's id."""
        clip = self.clip(clip_id)
        start, stop = int(start), int(stop)
        if not 0 <= start <= stop < clip.frame_count:
            raise StoreError(f"frames {start}..{stop} are not a range of clip {clip.name!r} "
                             f"(0..{clip.frame_count - 1})")
        with self._session() as s:
            row = ReviewRow(clip_id=clip_id, track_id=int(track_id), start=start, stop=stop, accepted=bool(accepted),
                            author=author)
            s.add(row)
            s.commit()
            return row.id

    def undo_review(self, clip_id: int, review_id: int) -> None:
        with self._session() as s:
            s.execute(delete(ReviewRow).where(ReviewRow.clip_id == clip_id, ReviewRow.id == review_id))
            s.commit()

    def reviews(self, clip_id: int) -> pd.DataFrame:
        with self._session() as s:
            rows = s.scalars(select(ReviewRow).where(ReviewRow.clip_id == clip_id).order_by(ReviewRow.id)).all()
            cols = ["id", "track_id", "start", "stop", "accepted", "author", "created"]
            return pd.DataFrame([{c: getattr(r, c) for c in cols} for r in rows], columns=cols)

    def _verdicts(self, clip_id: int) -> dict[tuple[int, int], bool]:
        """(frame, track_id) -> the newest verdict covering it."""
        verdict: dict[tuple[int, int], bool] = {}
        for r in self.reviews(clip_id).itertuples(index=False):  # oldest first: newer verdicts win
            for f in range(int(r.start), int(r.stop) + 1):
                verdict[(f, int(r.track_id))] = bool(r.accepted)
        return verdict

    def accepted(self, clip_id: int) -> pd.DataFrame:
        """``frame, track_id`` pairs whose newest covering verdict is an acceptance."""
        keys = sorted(k for k, ok in self._verdicts(clip_id).items() if ok)
        return pd.DataFrame(keys, columns=["frame", "track_id"], dtype="int64")

    def accepted_frames(self, clip_id: int) -> list[int]:
        """Frames where at least one track is accepted and none is rejected."""
        verdict = self._verdicts(clip_id)
        rejected = {f for (f, _), ok in verdict.items() if not ok}
        return sorted({f for (f, _), ok in verdict.items() if ok} - rejected)

    # ----------------------------------------------------------------- occluders
    def set_occluders(self, clip_id: int, boxes: list[Box]) -> None:
        self.clip(clip_id)
        with self._session() as s:
            s.execute(delete(OccluderRow).where(OccluderRow.clip_id == clip_id))
            s.add_all([OccluderRow(clip_id=clip_id, x=b.x, y=b.y, w=b.w, h=b.h) for b in boxes])
            s.commit()

    def occluders(self, clip_id: int) -> list[Box]:
        with self._session() as s:
            rows = s.scalars(select(OccluderRow).where(OccluderRow.clip_id == clip_id).order_by(OccluderRow.id))
            return [Box(r.x, r.y, r.w, r.h) for r in rows]

    # ------------------------------------------------------------------- bundles
    def add_bundle(self, project_id: int, name: str, path: str | PathLike, summary: dict | None = None
                   ) -> BundleRecord:
        self.project(project_id)
        with self._session() as s:
            if s.scalar(select(BundleRow).where(BundleRow.project_id == project_id, BundleRow.name == name)):
                raise StoreError(f"a bundle named {name!r} exists already in this project")
            row = BundleRow(project_id=project_id, name=name, path=str(path),
                            summary=json.dumps(summary or {}, default=str))
            s.add(row)
            s.commit()
            return _bundle(row)

    def bundles(self, project_id: int) -> list[BundleRecord]:
        with self._session() as s:
            rows = s.scalars(select(BundleRow).where(BundleRow.project_id == project_id).order_by(BundleRow.id))
            return [_bundle(r) for r in rows]

    def set_default_bundle(self, project_id: int, bundle_id: int | None) -> None:
        with self._session() as s:
            p = s.get(ProjectRow, project_id)
            if p is None:
                raise StoreError(f"no project with id {project_id}")
            if bundle_id is not None:
                b = s.get(BundleRow, bundle_id)
                if b is None or b.project_id != project_id:
                    raise StoreError(f"bundle {bundle_id} does not belong to project {p.name!r}")
            p.default_bundle_id = bundle_id
            s.commit()

    # --------------------------------------------------------------------- takes
    def add_take(self, project_id: int, name: str, streams: list[dict], *, path: str = "",
                 fps: float | None = None, calibration: dict | None = None) -> TakeRecord:
        """Register a take: ``streams`` in order, each ``dict(name=, clip_id=, calibration=None,
        depth_path="")`` where ``calibration`` is ``Camera.to_dict()`` (JSON); a clip is at most
        one stream of one take."""
        self.project(project_id)
        if not streams:
            raise StoreError(f"take {name!r} needs at least one stream")
        names = [str(st["name"]) for st in streams]
        if len(set(names)) != len(names):
            raise StoreError(f"take {name!r}: stream names repeat ({', '.join(names)})")
        with self._session() as s:
            if s.scalar(select(TakeRow).where(TakeRow.project_id == project_id, TakeRow.name == name)):
                raise StoreError(f"a take named {name!r} exists already in this project")
            row = TakeRow(project_id=project_id, name=name, path=str(path), fps=fps, calibration=calibration or {})
            s.add(row)
            s.flush()
            for position, st in enumerate(streams):
                clip_id = st.get("clip_id")
                if clip_id is not None and s.get(ClipRow, clip_id) is None:
                    raise StoreError(f"take {name!r}, stream {st['name']!r}: no clip with id {clip_id}")
                s.add(StreamRow(take_id=row.id, name=str(st["name"]), position=position, clip_id=clip_id,
                                calibration=st.get("calibration"), depth_path=str(st.get("depth_path") or "")))
            try:
                s.commit()
            except IntegrityError:
                s.rollback()
                raise StoreError(f"take {name!r}: a clip of it is already a stream of another take") from None
            return self.take(row.id)

    def import_take(self, project_id: int, path: str | PathLike, name: str | None = None) -> TakeRecord:
        """Add a take folder (or one video) from :func:`partlab.labelling.take.open_take`: each
        stream's video becomes a clip, each camera its stream's calibration."""
        from partlab.labelling.take import open_take

        with open_take(path) as take:
            streams = []
            for st in take.streams_:
                if st.color is None:
                    raise StoreError(f"{path}: stream {st.name!r} has no colour video; the store keeps videos")
                clip = self.add_clip(project_id, st.color.path, name=f"{Path(path).name}/{st.name}")
                streams.append(dict(name=st.name, clip_id=clip.id,
                                    calibration=st.camera.to_dict() if st.camera is not None else None,
                                    depth_path=str(st.depth.path) if st.depth is not None else ""))
            return self.add_take(project_id, name or Path(path).name, streams, path=str(Path(path).resolve()),
                                 fps=take.fps, calibration=dict(take.meta))

    def take(self, take_id: int) -> TakeRecord:
        with self._session() as s:
            row = s.get(TakeRow, take_id)
            if row is None:
                raise StoreError(f"no take with id {take_id}")
            streams = s.scalars(select(StreamRow).where(StreamRow.take_id == take_id).order_by(StreamRow.position))
            return TakeRecord(row.id, row.project_id, row.name, row.path, row.fps, dict(row.calibration or {}),
                              tuple(StreamRecord(st.name, st.position, st.clip_id, st.calibration, st.depth_path)
                                    for st in streams), row.created)

    def takes(self, project_id: int) -> list[TakeRecord]:
        with self._session() as s:
            ids = list(s.scalars(select(TakeRow.id).where(TakeRow.project_id == project_id).order_by(TakeRow.id)))
        return [self.take(i) for i in ids]

    def take_of_clip(self, clip_id: int) -> tuple[TakeRecord, str] | None:
        """The take a clip is a stream of and the stream's name, or None."""
        with self._session() as s:
            st = s.scalar(select(StreamRow).where(StreamRow.clip_id == clip_id))
            if st is None:
                return None
            take_id, name = st.take_id, st.name
        return self.take(take_id), name

    # -------------------------------------------------------------------- events
    def add_event(self, clip_id: int, start_frame: int, end_frame: int, type: str, *, tracks=(), parts=(),
                  confidence: float | None = None, attributes: dict | None = None, source: str = "human",
                  author: str = "", take_id: int | None = None) -> int:
        """Record an event over frames ``start_frame..end_frame`` (inclusive); returns its ``event_id``
        (its first revision is 1)."""
        self._check_event(clip_id, start_frame, end_frame, type, parts)
        with self._session() as s:
            for _ in range(3):  # two writers may pick the same new id: the unique key refuses one
                event_id = int(s.scalar(select(func.max(EventRow.event_id)).where(EventRow.clip_id == clip_id))
                               or 0) + 1
                s.add(EventRow(clip_id=clip_id, take_id=take_id, event_id=event_id, revision=1,
                               start_frame=int(start_frame), end_frame=int(end_frame), type=str(type),
                               tracks=[int(t) for t in tracks], parts=[str(p) for p in parts],
                               confidence=_num_or_none(confidence), attributes=dict(attributes or {}),
                               source=source, author=author))
                try:
                    s.commit()
                    return event_id
                except IntegrityError:
                    s.rollback()
        raise StoreError(f"could not add an event to clip {clip_id}: too many concurrent writers")

    def edit_event(self, clip_id: int, event_id: int, *, expected_revision: int, author: str = "",
                   delete: bool = False, **changes) -> int:
        """Append a revision of an event with ``changes`` (any of start_frame, end_frame, type, tracks,
        parts, confidence, attributes, source) or ``delete=True``; returns the new revision. Refused
        with :class:`StaleEditError` when the newest revision is not ``expected_revision``."""
        allowed = {"start_frame", "end_frame", "type", "tracks", "parts", "confidence", "attributes", "source"}
        unknown = sorted(set(changes) - allowed)
        if unknown:
            raise StoreError(f"events have no field(s) {', '.join(unknown)}; expected {', '.join(sorted(allowed))}")
        with self._session() as s:
            last = s.scalar(select(EventRow).where(EventRow.clip_id == clip_id, EventRow.event_id == event_id)
                            .order_by(EventRow.revision.desc()).limit(1))
            if last is None:
                raise StoreError(f"no event {event_id} in clip {clip_id}")
            if last.revision != expected_revision:
                raise StaleEditError(f"event {event_id} of clip {clip_id} was changed by someone else (revision "
                                     f"{last.revision}, you had {expected_revision}); reload and apply it again")
            fields = {k: getattr(last, k) for k in allowed} | {"take_id": last.take_id}
            fields.update(changes)
            self._check_event(clip_id, fields["start_frame"], fields["end_frame"], fields["type"], fields["parts"])
            s.add(EventRow(clip_id=clip_id, event_id=event_id, revision=last.revision + 1, deleted=delete,
                           author=author, **fields))
            try:
                s.commit()
            except IntegrityError:
                s.rollback()
                raise StaleEditError(f"event {event_id} of clip {clip_id} was changed by someone else; "
                                     "reload and apply it again") from None
            return last.revision + 1

    def events(self, clip_id: int, *, history: bool = False) -> pd.DataFrame:
        """The newest revision of every event of a clip that is not deleted (``history=True``: every
        revision, with ``deleted``), sorted by start frame."""
        with self._session() as s:
            q = select(EventRow).where(EventRow.clip_id == clip_id).order_by(EventRow.event_id, EventRow.revision)
            rows = [dict(event_id=r.event_id, revision=r.revision, start_frame=r.start_frame, end_frame=r.end_frame,
                         type=r.type, tracks=list(r.tracks or []), parts=list(r.parts or []),
                         confidence=_nan(r.confidence), attributes=dict(r.attributes or {}), source=r.source,
                         author=r.author, take_id=r.take_id, deleted=bool(r.deleted), created=r.created)
                    for r in s.scalars(q)]
        df = pd.DataFrame(rows, columns=EVENT_COLUMNS + ["deleted", "created"])
        if history:
            return df.reset_index(drop=True)
        df = df.drop_duplicates("event_id", keep="last")
        df = df[~df["deleted"].astype(bool)].drop(columns=["deleted", "created"])
        return df.sort_values(["start_frame", "event_id"], kind="stable").reset_index(drop=True)

    def _check_event(self, clip_id: int, start: int, end: int, type: str, parts) -> None:
        clip = self.clip(clip_id)
        if not 0 <= int(start) <= int(end) < clip.frame_count:
            raise StoreError(f"event frames {start}..{end} are not an interval inside clip {clip.name!r} "
                             f"(0..{clip.frame_count - 1})")
        if not str(type).strip():
            raise StoreError("an event needs a type (e.g. clap, handshake, exchange, pick, place)")
        for p in parts:
            check_part(p)
