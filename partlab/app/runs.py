"""Start the app's long work as background jobs: tracking, re-tracking, training.

This is glue only: the algorithms are ``partlab.app.pipeline.track_video`` (trackers),
``partlab.models.training.train_bundle`` (SVMs and variances) and the store. They are imported
when a job starts (the pages stay quick to load); an import that breaks fails the job or the page,
it is never hidden. Jobs run on the engine (:mod:`partlab.engine`, a local Dask cluster outside the
server) unless the app was started with ``--jobs threads``.
"""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd

from partlab.app import jobs
from partlab.labelling.config import data_dir
from partlab.labelling.store import Clip, Store
from partlab.labelling.video import VideoClip

TRACKERS: tuple[str, ...] = ("body", "limbs", "all")


def _load_model(bundle_path: str | Path | None):
    if not bundle_path:
        return None
    from partlab.models.bundle import load_bundle

    return load_bundle(bundle_path)


BUILTIN = "built-in parameters"
SHIPPED = "partlab's shipped bundle"


def bundle_choices(store: Store, project) -> dict[str, str | None]:
    """Model bundles to track with, label -> directory (None: the trackers' built-in
    parameters); the project's default first, then built-in, the shipped bundle
    (what ``partlab track --model default`` uses) and the project's other bundles."""
    bundles = store.bundles(project.id)
    default = next((b for b in bundles if b.id == project.default_bundle_id), None)
    out: dict[str, str | None] = {}
    if default is not None:
        out[f"{default.name} (project default)"] = str(default.path)
    out[BUILTIN] = None
    from partlab.models.bundle import MANIFEST, default_bundle_path

    if (default_bundle_path() / MANIFEST).is_file():
        out[SHIPPED] = str(default_bundle_path())
    for b in bundles:
        if b is not default:
            out[b.name] = str(b.path)
    return out


def next_human_frame(store: Store, clip_id: int, after: int) -> int | None:
    """The first human-corrected frame after ``after`` (re-tracking stops there)."""
    later = [f for f in store.human_frames(clip_id) if f > after]
    return later[0] if later else None


def start_tracking(store: Store, clip: Clip, tracker: str = "body", bundle_path: str | Path | None = None,
                   seed: int = 0, start: int = 0, retrack: bool = False, init_from_boxes: bool = False,
                   init: pd.DataFrame | None = None, track_id: int | None = None) -> jobs.Job:
    """Track a clip in the background and store the result as a tracker run.

    With ``retrack``, the tracker runs between the keyframes around frame ``start``
    (:func:`partlab.labelling.trackops.retrack_window`; only ``track_id`` when given) from
    the effective boxes at the first of them, and replaces the boxes of those tracks in
    that range only; every other track, every human edit and every other frame stay as
    they are, and ``Store.undo_run`` takes the run back as one step. With
    ``init_from_boxes``, a whole-clip run starts from the stored boxes of frame
    ``start`` instead of detecting people; ``init`` gives such boxes directly (e.g. a
    synthetic scene's init.csv).
    """
    from partlab.app import pipeline
    from partlab.labelling import access

    access.require(store, clip.project_id)  # the job stores its run through a store of its own
    if tracker not in TRACKERS:
        raise ValueError(f"tracker must be one of {', '.join(TRACKERS)}, got {tracker!r}")
    stop, track_ids = None, None
    if retrack:
        from partlab.labelling.trackops import retrack_window

        start, stop, track_ids = retrack_window(store, clip.id, start, track_id)
        if not track_ids:
            raise ValueError(f"frame {start} has no boxes to re-track from; draw them first")
    if retrack or init_from_boxes:
        init = store.frame_boxes(clip.id, start)
        if not len(init):
            raise ValueError(f"frame {start} has no boxes to re-track from; draw them first")
        init = init.drop(columns=["revision"], errors="ignore")
        if track_ids is not None:
            init = init[init.track_id.isin(track_ids)]
    occluders = tuple(store.occluders(clip.id))
    what = f"re-track {clip.name} from frame {start}" + (f" to {stop}" if stop is not None else "") if retrack \
        else f"track {clip.name} ({tracker})"
    if jobs.engine_enabled():  # on a Dask worker: survives a server restart, can be cancelled
        from partlab.engine import tasks

        return jobs.submit_engine("track", what, tasks.track_clip, dict(clip_id=clip.id, project_id=clip.project_id),
                                  url=store.url, clip_id=clip.id, tracker=tracker,
                                  bundle_path=str(bundle_path) if bundle_path else None, seed=seed, start=start,
                                  stop=stop, init=None if init is None else init.to_dict("records"),
                                  track_ids=track_ids)

    def work(progress):
        from partlab.labelling.events import store_run_events

        model = _load_model(bundle_path)
        found: list = []
        df = pipeline.track_video(str(clip.path), tracker=tracker, init=init, model=model, occluders=occluders,
                                  seed=seed, progress=progress, start=start, stop=stop, events_out=found)
        run_id = store.save_tracker_run(clip.id, df, tracker=tracker, bundle=str(bundle_path or ""), seed=seed,
                                        start_frame=start, stop_frame=stop, track_ids=track_ids)
        event_ids = store_run_events(store, clip.id, found[0] if found else None, start=start, stop=stop,
                                     track_ids=track_ids)
        return dict(run_id=run_id, boxes=int(len(df)), events=len(event_ids), start=start, stop=stop,
                    track_ids=track_ids)

    what = f"re-track {clip.name} from frame {start}" + (f" to {stop}" if stop is not None else "") \
        + (f" (tracks {', '.join(map(str, track_ids))})" if track_ids else "") if retrack \
        else f"track {clip.name} ({tracker})"
    return jobs.submit("track", what, work, clip_id=clip.id, project_id=clip.project_id)


def clip_state(store: Store, clip: Clip, runs: pd.DataFrame | None = None) -> str:
    """untracked, tracked, corrected n%, exported (the clip list's state column)."""
    progress = store.progress(clip.id)
    if progress["corrected_frames"]:
        state = f"corrected {100 * progress['fraction']:.0f}%"
    else:
        runs = store.runs(clip.id) if runs is None else runs
        state = "tracked" if len(runs) else "untracked"
    return f"exported ({state})" if clip.exported else state


def safe_name(name: str) -> str:
    """A file-system-safe version of a user-given name."""
    cleaned = re.sub(r"[^A-Za-z0-9._-]+", "-", name.strip()).strip("-.")
    if not cleaned:
        raise ValueError("the name needs at least one letter or digit")
    return cleaned[:80]


def frames_factory(path: Path):
    """A callable giving a fresh iterator of ``(index, BGR frame)`` over a clip (decode order)."""
    def frames():
        return VideoClip(path).frames()
    return frames


def training_truth(store: Store, clip_id: int) -> pd.DataFrame:
    """The boxes a clip teaches from: every effective box of its corrected frames."""
    tracks = store.tracks(clip_id)
    human = set(store.human_frames(clip_id))
    return tracks[tracks.frame.isin(human)].drop(columns=["revision"]).reset_index(drop=True)


def _training_inputs(store: Store, project_id: int, clip_ids: list[int], name: str) -> tuple[list, Path]:
    """The clips to train from ``(frames, fps, truth)`` and the bundle's new folder, or ValueError."""
    if not clip_ids:
        raise ValueError("pick at least one corrected clip")
    folder = safe_name(name)
    if any(b.name == name for b in store.bundles(project_id)):
        raise ValueError(f"a bundle named {name!r} exists already in this project")
    clips = []
    for cid in clip_ids:
        clip = store.clip(cid)
        truth = training_truth(store, cid)
        if not len(truth):
            raise ValueError(f"clip {clip.name!r} has no corrected frames yet")
        clips.append((frames_factory(clip.path), clip.fps, truth))
    from partlab.models import training

    training.check_span(clips, [store.clip(cid).name for cid in clip_ids], training.TrainingOptions().dt)
    out = data_dir() / "bundles" / str(project_id) / folder
    if out.exists():
        raise ValueError(f"{out} exists already; choose another bundle name")
    return clips, out


def start_training(store: Store, project_id: int, clip_ids: list[int], name: str, seed: int = 0,
                   make_default: bool = False, start_path: str | Path | None = None) -> jobs.Job:
    """Train a bundle from corrected clips in the background, save it and register it.
    ``start_path``: the bundle to improve on (its detector stays unless the new one does no
    worse, :func:`partlab.models.training.train_bundle`); None: the built-in parameters."""
    from partlab.labelling import access
    from partlab.models import bundle as bundle_mod

    access.require(store, project_id)  # the job registers its bundle through a store of its own
    from partlab.models import training
    from partlab.models.runner import body_tracker_runner as runner  # the tracker's own failures: the paper's samples

    clips, out = _training_inputs(store, project_id, clip_ids, name)
    names = [store.clip(cid).name for cid in clip_ids]
    if jobs.engine_enabled():  # on a Dask worker, like tracking
        from partlab.engine import tasks

        return jobs.submit_engine("train", f"train bundle {name}", tasks.train_bundle, dict(project_id=project_id),
                                  url=store.url, project_id=project_id, clip_ids=list(clip_ids), name=name,
                                  out=str(out), seed=seed, make_default=make_default,
                                  start_path=str(start_path) if start_path else None)
    start = _load_model(start_path)

    def work(progress):
        total = training.training_steps(len(clips), with_tracker=True)
        steps = iter(range(1, 10**6))

        def step(_message: str) -> None:  # train_bundle reports named steps; the bar counts them
            progress(next(steps), total)

        progress(0, total)
        bundle = training.train_bundle(clips=clips, seed=seed, progress=step, tracker_runner=runner, names=names,
                                       start=start)
        if bundle.summary["nothing_learnt"]:  # never saved, never a project's default
            raise training.NothingLearnt(f"learnt nothing: {bundle.summary['nothing_learnt']}")
        bundle_mod.save_bundle(bundle, out)
        record = store.add_bundle(project_id, name, out, summary=bundle.summary)
        if make_default:
            store.set_default_bundle(project_id, record.id)
        return dict(bundle_id=record.id, path=str(out))

    return jobs.submit("train", f"train bundle {name}", work, project_id=project_id)


def first_boxes(truth: pd.DataFrame) -> pd.DataFrame:
    """Every truth track's boxes at its first frame: where a fair comparison starts
    (seed 002 sec. 5.3 counts frames after each person's initialisation)."""
    first = truth.groupby("track_id")["frame"].transform("min")
    return truth[truth["frame"] == first].reset_index(drop=True)


def start_comparison_run(clip: Clip, tracker: str, bundle_name: str, bundle_path: str | Path | None,
                         seed: int = 0, init: pd.DataFrame | None = None) -> jobs.Job:
    """Track a clip with one bundle without storing the result (Evaluate page), from
    ``init`` boxes when given; the job's result is the tracks DataFrame."""
    from partlab.app import pipeline

    def work(progress):
        start = int(init.frame.min()) if init is not None and len(init) else 0
        return pipeline.track_video(str(clip.path), tracker=tracker, model=_load_model(bundle_path), init=init,
                                    seed=seed, progress=progress, start=start)

    return jobs.submit("compare", f"{clip.name} with {bundle_name}", work, clip_id=clip.id, bundle=bundle_name,
                       tracker=tracker, seed=seed)
