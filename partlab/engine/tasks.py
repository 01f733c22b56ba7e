"""The app's jobs as functions a Dask worker runs: ``task(progress, **plain_data)``.

They take ids, paths and numbers (never open objects), open the store themselves from its URL,
and report ``progress(done, total)``; :func:`partlab.engine.jobs.run_job` turns a cancellation
into :class:`partlab.engine.jobs.Cancelled` raised from that callback.
"""

from __future__ import annotations

import pandas as pd


def track_clip(progress, *, url: str, clip_id: int, tracker: str, bundle_path: str | None, seed: int,
               start: int = 0, stop: int | None = None, init: list[dict] | None = None,
               track_ids: list[int] | None = None) -> dict:
    """Track a stored clip and save the result as a tracker run (frames ``[start, stop)``; of the
    tracks ``track_ids`` only when given, as a re-track), with the
    events it recognised (activities, joins: :func:`partlab.labelling.events.store_run_events`), so
    the Correct page's timeline shows them."""
    from partlab.app.pipeline import track_video
    from partlab.labelling.events import store_run_events
    from partlab.labelling.store import Store
    from partlab.models.bundle import load_bundle

    store = Store(url)
    clip = store.clip(clip_id)
    model = load_bundle(bundle_path) if bundle_path else None
    init_df = pd.DataFrame(init) if init else None
    found: list = []
    df = track_video(str(clip.path), tracker=tracker, init=init_df, model=model,
                     occluders=tuple(store.occluders(clip_id)), seed=seed, progress=progress, start=start, stop=stop,
                     events_out=found)
    run_id = store.save_tracker_run(clip_id, df, tracker=tracker, bundle=str(bundle_path or ""), seed=seed,
                                    start_frame=start, stop_frame=stop, track_ids=track_ids)
    event_ids = store_run_events(store, clip_id, found[0] if found else None, start=start, stop=stop,
                                 track_ids=track_ids)
    return dict(run_id=run_id, boxes=int(len(df)), events=len(event_ids), start=start, stop=stop,
                track_ids=track_ids)


def train_bundle(progress, *, url: str, project_id: int, clip_ids: list[int], name: str, out: str, seed: int = 0,
                 make_default: bool = False, start_path: str | None = None, with_tracker: bool = True) -> dict:
    """Train a bundle from a project's corrected clips, save it to ``out`` and register it
    (``with_tracker``: also learn from the body tracker's own failures, as the app does)."""
    from partlab.app.runs import frames_factory, training_truth
    from partlab.labelling.store import Store
    from partlab.models import bundle as bundle_mod
    from partlab.models import training
    from partlab.models.runner import body_tracker_runner

    store = Store(url)
    clips = [(frames_factory(store.clip(cid).path), store.clip(cid).fps, training_truth(store, cid))
             for cid in clip_ids]
    names = [store.clip(cid).name for cid in clip_ids]
    start = bundle_mod.load_bundle(start_path) if start_path else None
    runner = body_tracker_runner if with_tracker else None
    total = training.training_steps(len(clips), with_tracker=runner is not None)
    steps = iter(range(1, 10**6))

    def step(_message: str) -> None:  # train_bundle reports named steps; the bar counts them
        progress(next(steps), total)

    progress(0, total)
    bundle = training.train_bundle(clips=clips, seed=seed, progress=step, tracker_runner=runner,
                                   names=names, start=start)
    if bundle.summary["nothing_learnt"]:  # never saved, never a project's default
        raise training.NothingLearnt(f"learnt nothing: {bundle.summary['nothing_learnt']}")
    bundle_mod.save_bundle(bundle, out)
    record = store.add_bundle(project_id, name, out, summary=bundle.summary)
    if make_default:
        store.set_default_bundle(project_id, record.id)
    return dict(bundle_id=record.id, path=str(out))
