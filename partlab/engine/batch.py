"""``partlab batch``: pre-annotate many clips on Dask, one task per clip (or per chunk of a long one).

What a batch is made of, top to bottom:

1. **The clips** (:func:`discover`): the videos and take folders of a directory, the rows of a
   manifest CSV (``path`` and optionally ``name``, ``init``), or the clips of a project in the store.
2. **The plan** (:func:`plan_chunks`): a clip of at most ``chunk + overlap`` frames is one task,
   which gives exactly the rows ``partlab track`` gives with the same tracker, bundle and seed. A
   longer clip is cut into chunks of ``chunk`` frames; each chunk's task starts ``overlap`` frames
   early, so that its background model and detection have warmed up by the time its own frames
   begin (the overlap's rows are used for joining only).
3. **The join** (:func:`join_chunks`): the tracks of consecutive chunks are matched on the overlap
   by the evaluation's IoU matching (:func:`partlab.labelling.evaluation.match_tracks`, Hungarian
   on mean IoU); a matched track keeps the earlier chunk's id, an unmatched one gets a new id.
4. **The results** (:class:`FolderSink`, :class:`StoreSink`): ``OUT/<name>.csv`` and a marker
   ``OUT/<name>.done.json`` written after it, or a tracker run in the store. A rerun skips a clip
   whose marker (or stored run) has the same tracker, bundle, seed and chunking, so a killed batch
   finishes only the rest; a clip that fails is reported with its message and the others go on.
"""

from __future__ import annotations

import json
import math
import os
import time
import traceback
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from os import PathLike
from pathlib import Path

import pandas as pd

from partlab.engine import DEFAULT_CHUNK, DEFAULT_OVERLAP
from partlab.errors import UserError

#: chunk tracks whose boxes overlap an earlier chunk's track by less than this mean IoU over the
#: overlap are new people, not continuations (the evaluation's "right box" needs 0.5 on one box;
#: a mean over frames where either may have drifted is held to less)
JOIN_MIN_IOU = 0.3


@dataclass(frozen=True)
class ClipJob:
    """One clip of a batch: its output ``name`` (unique in the batch), the video or take folder
    ``path``, optional ``init`` boxes (a tracks CSV) and its ``clip_id`` when it is in the store."""

    name: str
    path: str
    init: str | None = None
    clip_id: int | None = None


@dataclass(frozen=True)
class Settings:
    """What a result depends on; a rerun skips clips done with equal settings."""

    tracker: str = "body"
    model: str | None = None  # bundle directory, "default" (the shipped one) or None (built-in)
    seed: int = 0
    chunk: int = DEFAULT_CHUNK
    overlap: int = DEFAULT_OVERLAP

    def check(self) -> None:
        from partlab.tracking import registry

        registry.get(self.tracker)
        if self.chunk < 0:
            raise UserError(f"--chunk-frames must be 0 (no chunks) or positive, got {self.chunk}")
        if self.overlap < 0 or (self.chunk and self.overlap >= self.chunk):
            raise UserError(f"--overlap must be at least 0 and below --chunk-frames ({self.chunk}), "
                            f"got {self.overlap}")


# ---------------------------------------------------------------------------------------- 1. clips
def discover(source: str | PathLike) -> list[ClipJob]:
    """The clips of a directory (its videos, and its sub-folders that are takes, in name order) or
    of a manifest CSV (``path`` relative to the manifest, optional ``name`` and ``init``)."""
    from partlab.labelling.video import VIDEO_EXTENSIONS

    src = Path(source)
    if not src.exists():
        raise UserError(f"{src}: no such folder or manifest")
    if src.is_file():
        return _manifest(src)
    jobs = []
    for entry in sorted(src.iterdir()):
        if entry.is_file() and entry.suffix.lower() in VIDEO_EXTENSIONS:
            jobs.append(ClipJob(entry.stem, str(entry)))
        elif entry.is_dir() and any(f.suffix.lower() in VIDEO_EXTENSIONS for f in entry.iterdir()):
            jobs.append(ClipJob(entry.name, str(entry)))
    if not jobs:
        raise UserError(f"{src}: no videos or take folders in it")
    return _unique(jobs, str(src))


def _manifest(path: Path) -> list[ClipJob]:
    try:
        df = pd.read_csv(path, dtype=str, keep_default_na=False)
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise UserError(f"{path}: not a readable manifest CSV ({exc})") from None
    if "path" not in df.columns:
        raise UserError(f"{path} line 1: a manifest needs a 'path' column (optional: name, init)")
    jobs = []
    for line, row in enumerate(df.itertuples(index=False), start=2):
        clip = (path.parent / row.path).resolve() if row.path else None
        if clip is None or not clip.exists():
            raise UserError(f"{path} line {line}: no such clip {row.path!r}")
        init = getattr(row, "init", "") or None
        if init:
            init = str((path.parent / init).resolve())
            if not Path(init).is_file():
                raise UserError(f"{path} line {line}: no such init file {row.init!r}")
        name = getattr(row, "name", "") or (clip.stem if clip.is_file() else clip.name)
        jobs.append(ClipJob(name, str(clip), init))
    if not jobs:
        raise UserError(f"{path}: the manifest lists no clips")
    return _unique(jobs, str(path))


def _unique(jobs: list[ClipJob], where: str) -> list[ClipJob]:
    seen: dict[str, str] = {}
    for j in jobs:
        if j.name in seen:
            raise UserError(f"{where}: two clips would both write {j.name!r} ({seen[j.name]} and {j.path}); "
                            "give them distinct names (a manifest's name column)")
        seen[j.name] = j.path
    return jobs


def project_clips(store, project_name: str) -> list[ClipJob]:
    """The clips of a project in the store, named by clip id and name."""
    project = store.project_by_name(project_name)
    if project is None:
        raise UserError(f"--project {project_name!r}: no such project in {store.url}")
    return [ClipJob(f"{c.id}-{Path(c.name).stem}", str(c.path), None, c.id) for c in store.clips(project.id)]


# ----------------------------------------------------------------------------------------- 2. plan
def plan_chunks(frame_count: int, chunk: int, overlap: int) -> list[tuple[int, int, int]]:
    """``(run_from, keep_from, stop)`` per task: a task tracks ``[run_from, stop)`` and its rows of
    ``[keep_from, stop)`` are kept. One task when ``chunk`` is 0 or the clip fits in ``chunk + overlap``."""
    if chunk <= 0 or frame_count <= chunk + overlap:
        return [(0, 0, frame_count)]
    n = math.ceil(frame_count / chunk)
    out = []
    for k in range(n):
        keep, stop = k * chunk, min(frame_count, (k + 1) * chunk)
        out.append((max(0, keep - overlap), keep, stop))
    return out


# ----------------------------------------------------------------------------------------- 3. join
def join_chunks(pieces: list[tuple[int, pd.DataFrame]], overlap: int, min_iou: float = JOIN_MIN_IOU
                ) -> pd.DataFrame:
    """Join the tracks of consecutive chunks ``[(keep_from, tracks), ...]`` into one table.

    Chunk k's rows before its ``keep_from`` (the overlap) are matched against what is already
    joined there; its tracks take the matched ids, the others fresh ids above every id so far.
    """
    from partlab.labelling.evaluation import match_tracks
    from partlab.tracking.tracks import empty_tracks, normalise_tracks

    joined = empty_tracks()
    for k, (keep_from, df) in enumerate(pieces):
        df = normalise_tracks(df)
        if k == 0 or df.empty:
            joined = pd.concat([joined, df[df.frame >= keep_from]], ignore_index=True)
            continue
        lo = keep_from - overlap
        before = joined[(joined.frame >= lo) & (joined.frame < keep_from)]
        mine = df[(df.frame >= lo) & (df.frame < keep_from)]
        mapping: dict[int, int] = {}
        if len(before) and len(mine):
            _, pairs = match_tracks(before, mine, how="iou")
            pairs = pairs[pairs["mean_iou"] >= min_iou]
            mapping = {int(b): int(a) for a, b in zip(pairs["truth_id"], pairs["track_id"])}
        next_id = int(joined["track_id"].max()) + 1 if len(joined) else 0
        for tid in sorted(set(df["track_id"]) - set(mapping)):
            mapping[int(tid)] = next_id
            next_id += 1
        kept = df[df.frame >= keep_from].copy()
        kept["track_id"] = kept["track_id"].map(mapping).astype("int64")
        joined = pd.concat([joined, kept], ignore_index=True)
    return normalise_tracks(joined)


# ------------------------------------------------------------------------------- tasks on workers
def track_piece(job: ClipJob, settings: Settings, run_from: int, stop: int) -> dict:
    """A worker's task: track ``[run_from, stop)`` of a clip. Never raises: a failure is returned
    as ``{"error": message}`` so the batch goes on."""
    t0 = time.perf_counter()
    try:
        from partlab.app.pipeline import track_path
        from partlab.commands.track import load_model
        from partlab.tracking.tracks import read_tracks_csv

        model = load_model(settings.model) if settings.model else None
        init = read_tracks_csv(job.init) if job.init else None
        result = track_path(job.path, settings.tracker, init=init, model=model, seed=settings.seed,
                            start=run_from, stop=stop)
        return {"tracks": result.tracks, "seconds": time.perf_counter() - t0, "pid": os.getpid()}
    except Exception as exc:  # reported per clip; the trace goes to the worker's log
        traceback.print_exc()
        return {"error": f"{type(exc).__name__}: {exc}" if not isinstance(exc, UserError) else str(exc),
                "seconds": time.perf_counter() - t0}


def finish_clip(job: ClipJob, settings: Settings, keeps: list[int], pieces: list[dict], sink) -> dict:
    """A worker's task: join a clip's pieces and hand the tracks to ``sink``; returns the clip's summary."""
    seconds = sum(p.get("seconds", 0.0) for p in pieces)
    errors = [p["error"] for p in pieces if "error" in p]
    if errors:
        return dict(name=job.name, status="failed", error=errors[0], seconds=seconds, boxes=0, tracks=0)
    try:
        tracks = pieces[0]["tracks"] if len(pieces) == 1 else \
            join_chunks([(k, p["tracks"]) for k, p in zip(keeps, pieces)], settings.overlap)
        sink.save(job, settings, tracks)
    except Exception as exc:
        traceback.print_exc()
        return dict(name=job.name, status="failed", error=f"{type(exc).__name__}: {exc}", seconds=seconds,
                    boxes=0, tracks=0)
    return dict(name=job.name, status="done", error="", seconds=seconds, boxes=int(len(tracks)),
                tracks=int(tracks["track_id"].nunique()) if len(tracks) else 0, chunks=len(pieces))


# -------------------------------------------------------------------------------------- 4. results
class FolderSink:
    """``OUT/<name>.csv`` per clip and, after it, the marker ``OUT/<name>.done.json``."""

    def __init__(self, out_dir: str | PathLike):
        self.out = Path(out_dir)

    def _marker(self, name: str) -> Path:
        return self.out / f"{name}.done.json"

    def done(self, job: ClipJob, settings: Settings) -> bool:
        try:
            marker = json.loads(self._marker(job.name).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return False
        return marker.get("settings") == asdict(settings) and (self.out / f"{job.name}.csv").is_file()

    def save(self, job: ClipJob, settings: Settings, tracks: pd.DataFrame) -> None:
        from partlab.tracking.tracks import write_tracks_csv

        self.out.mkdir(parents=True, exist_ok=True)
        tmp = self.out / f".{job.name}.csv.part"
        write_tracks_csv(tracks, tmp)
        os.replace(tmp, self.out / f"{job.name}.csv")
        marker = dict(clip=job.path, settings=asdict(settings), boxes=int(len(tracks)), finished=time.time())
        tmp = self.out / f".{job.name}.done.part"
        tmp.write_text(json.dumps(marker, indent=1), encoding="utf-8")
        os.replace(tmp, self._marker(job.name))


class StoreSink:
    """A tracker run per clip in the store at ``url`` (SQLite file or PostgreSQL)."""

    def __init__(self, url: str):
        self.url = url

    def _store(self):
        from partlab.labelling.store import Store

        return Store(self.url)

    def done(self, job: ClipJob, settings: Settings) -> bool:
        runs = self._store().runs(job.clip_id)
        if runs.empty:
            return False
        same = (runs.tracker == settings.tracker) & (runs.bundle == (settings.model or "")) & \
               (runs.seed == settings.seed) & (runs.start_frame == 0)
        return bool(same.any())

    def save(self, job: ClipJob, settings: Settings, tracks: pd.DataFrame) -> None:
        self._store().save_tracker_run(job.clip_id, tracks, tracker=settings.tracker, bundle=settings.model or "",
                                       seed=settings.seed)


# ------------------------------------------------------------------------------------- the batch
@dataclass
class BatchReport:
    done: list[dict]
    failed: list[dict]
    skipped: list[str]
    seconds: float

    def table(self) -> pd.DataFrame:
        rows = self.done + self.failed + [dict(name=n, status="skipped") for n in self.skipped]
        return pd.DataFrame(rows, columns=["name", "status", "boxes", "tracks", "seconds", "error"])


def frame_count(path: str) -> int:
    from partlab.labelling.take import open_take

    with open_take(path) as take:
        return take.frame_count


def run_batch(client, jobs: Iterable[ClipJob], settings: Settings, sink, *,
              on_result: Callable[[dict], None] | None = None) -> BatchReport:
    """Submit every clip not done yet to ``client`` (a :class:`distributed.Client`) and wait.

    ``on_result(summary)`` is called as each clip ends (the command line's progress bar)."""
    from distributed import as_completed

    settings.check()
    t0 = time.perf_counter()
    jobs = list(jobs)
    skipped = [j.name for j in jobs if sink.done(j, settings)]
    todo = [j for j in jobs if j.name not in set(skipped)]
    finals, submitted, done, failed = [], [], [], []
    for job in todo:
        try:
            chunks = [(0, 0, None)] if job.init else plan_chunks(frame_count(job.path), settings.chunk,
                                                                 settings.overlap)
        except Exception as exc:  # an unreadable clip fails alone
            failed.append(dict(name=job.name, status="failed", error=str(exc), seconds=0.0, boxes=0, tracks=0))
            if on_result is not None:
                on_result(failed[-1])
            continue
        submitted.append(job)
        pieces = [client.submit(track_piece, job, settings, run_from, stop, pure=False,
                                key=f"track-{job.name}-{k}-{time.monotonic_ns()}")
                  for k, (run_from, _, stop) in enumerate(chunks)]
        finals.append(client.submit(finish_clip, job, settings, [keep for _, keep, _ in chunks], pieces, sink,
                                    pure=False, key=f"finish-{job.name}-{time.monotonic_ns()}"))
    by_key = {f.key: j for f, j in zip(finals, submitted)}
    for future in as_completed(finals):
        try:
            summary = future.result()
        except Exception as exc:  # the worker died under it (KilledWorker) or the task could not be sent
            summary = dict(name=by_key[future.key].name, status="failed", error=f"{type(exc).__name__}: {exc}",
                           seconds=0.0, boxes=0, tracks=0)
        (done if summary["status"] == "done" else failed).append(summary)
        if on_result is not None:
            on_result(summary)
    return BatchReport(done, failed, skipped, time.perf_counter() - t0)
