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
import threading
from dataclasses import dataclass
from datetime import datetime, timezone
from os import PathLike
from pathlib import Path

import pandas as pd
from sqlalchemy import (Boolean, DateTime, Float, ForeignKey, Integer, String, Text, UniqueConstraint, create_engine,
                        delete, event, func, select, update)
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import DeclarativeBase, Mapped, Session, mapped_column

from partlab.labelling.config import data_dir, database_url
from partlab.labelling.video import VideoError, probe, store_by_hash
from partlab.tracking.core.box import Box
from partlab.tracking.parts import check_part
from partlab.tracking.tracks import COLUMNS, TAKE_COLUMNS, normalise_tracks


class StoreError(ValueError):
    """A request the store refuses; the message says why."""


class StaleEditError(StoreError):
    """Someone else changed the box since the writer read it."""


def _now() -> datetime:
    return datetime.now(timezone.utc)


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
    # the run that replaced this box (None: in effect); kept so a re-track is undone as one step
    superseded_by: Mapped[int | None] = mapped_column(Integer, nullable=True, index=True)


#: what a revision of a human edit is: ``box`` a box the user drew, moved or flagged (a
#: keyframe, a corrected frame, training truth); ``restore`` hands the key back to the tracker
#: (an undone first edit); ``track`` an identity operation (merge, split, change id, delete from
#: a frame on) that moved or removed the tracker's box without checking its position.
EDIT_KINDS: tuple[str, ...] = ("box", "restore", "track")


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
    kind: Mapped[str] = mapped_column(String(12), default="box")
    author: Mapped[str] = mapped_column(String(100), default="")
    created: Mapped[datetime] = mapped_column(DateTime(timezone=True), default=_now)
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


def _project(r: ProjectRow) -> Project:
    return Project(r.id, r.name, r.default_bundle_id, r.created)


def _clip(r: ClipRow) -> Clip:
    return Clip(r.id, r.project_id, r.name, Path(r.path), r.sha256, r.fps, r.width, r.height, r.frame_count,
                r.created, bool(r.exported))


def _bundle(r: BundleRow) -> BundleRecord:
    return BundleRecord(r.id, r.project_id, r.name, Path(r.path), json.loads(r.summary or "{}"), r.created)


_ENGINES: dict[str, object] = {}
_ENGINES_LOCK = threading.Lock()


def _engine(url: str):
    """One engine per URL per process (Streamlit reruns must not open new pools)."""
    with _ENGINES_LOCK:
        eng = _ENGINES.get(url)
        if eng is None:
            kwargs = {}
            if url.startswith("sqlite"):
                kwargs["connect_args"] = {"check_same_thread": False, "timeout": 30}
            eng = create_engine(url, **kwargs)
            if url.startswith("sqlite"):
                @event.listens_for(eng, "connect")
                def _pragmas(dbapi_conn, _record):
                    cur = dbapi_conn.cursor()
                    cur.execute("PRAGMA journal_mode=WAL")
                    cur.execute("PRAGMA synchronous=NORMAL")
                    cur.execute("PRAGMA foreign_keys=ON")
                    cur.execute("PRAGMA busy_timeout=30000")
                    cur.close()
            Base.metadata.create_all(eng)
            _add_missing_columns(eng)
            _ENGINES[url] = eng
        return eng


#: columns added after a data directory may have been made (table, column, SQL type and default);
#: to become an Alembic revision once the store has migrations
_ADDED_COLUMNS = (("edits", "kind", "VARCHAR(12) NOT NULL DEFAULT 'box'"),
                  ("tracker_boxes", "superseded_by", "INTEGER"))


def _add_missing_columns(eng) -> None:
    from sqlalchemy import inspect, text

    insp = inspect(eng)
    with eng.begin() as conn:
        for table, column, sql in _ADDED_COLUMNS:
            if column not in {c["name"] for c in insp.get_columns(table)}:
                conn.execute(text(f"ALTER TABLE {table} ADD COLUMN {column} {sql}"))


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
                     occluded=float(r.occluded), state=str(r.state))
                for r in df.itertuples(index=False)
            ]
            if records:
                s.execute(TrackerBoxRow.__table__.insert(), records)
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
            tracker = [(r.frame, r.track_id, r.part, r.x, r.y, r.w, r.h,
                        float("nan") if r.score is None else r.score, r.failure, r.occluded, r.state, "tracker", 0)
                       for r in s.scalars(tq)]
            # a "restore" revision leaves the tracker's box in effect (its revision still guards stale writes)
            edits, restored = [], []
            for r in s.scalars(eq):
                if r.kind == "restore":
                    restored.append((r.frame, r.track_id, r.part, r.revision))
                    continue
                edits.append((r.frame, r.track_id, r.part, r.x, r.y, r.w, r.h, float("nan"), r.failure, r.occluded,
                              "", "human" if r.kind == "box" else "tracker", r.revision, r.deleted))
        cols = [c for c in COLUMNS if c not in TAKE_COLUMNS] + ["revision"]
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
                 author: str = "", kind: str = "box") -> int:
        """Write a human edit of one box (``box=None`` deletes it); returns the new revision.

        ``failure``/``occluded`` left as None keep their current values; ``kind`` as in
        :data:`EDIT_KINDS`. Refused with :class:`StaleEditError` when the newest revision is
        not ``expected_revision``.
        """
        [rev] = self.edit_boxes(clip_id, [dict(frame=frame, track_id=track_id, part=part, box=box, failure=failure,
                                               occluded=occluded, expected_revision=expected_revision, kind=kind)],
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
                              deleted=box is None and kind != "restore", author=author, kind=kind))
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
            return dict(x=e.x, y=e.y, w=e.w, h=e.h, failure=e.failure, occluded=e.occluded, deleted=e.deleted)
        t = cls._tracker_row(s, clip_id, frame, track_id, part)
        if t is not None:
            return dict(x=t.x, y=t.y, w=t.w, h=t.h, failure=t.failure, occluded=t.occluded, deleted=False)
        return None

    def history(self, clip_id: int, frame: int, track_id: int, part: str) -> pd.DataFrame:
        with self._session() as s:
            rows = s.scalars(select(EditRow).where(EditRow.clip_id == clip_id, EditRow.frame == frame,
                                                   EditRow.track_id == track_id, EditRow.part == part)
                             .order_by(EditRow.revision)).all()
            cols = ["revision", "x", "y", "w", "h", "failure", "occluded", "deleted", "kind", "author", "created"]
            return pd.DataFrame([{c: getattr(r, c) for c in cols} for r in rows], columns=cols)

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
                                   occluded=prev.occluded, deleted=prev.deleted, kind=prev.kind)
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
                    c.update(kind=e.kind, failure=bool(e.failure), occluded=float(e.occluded),
                             box=None if e.deleted else Box(e.x, e.y, e.w, e.h))
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
            raise StoreError(f"frames {start}..{stop} are not a range of clip {clip.name!r} (0..{clip.frame_count - 1})")
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
