"""The app's jobs as functions a Dask worker runs: ``task(progress, **plain_data)``.

They take ids, paths and numbers (never open objects), open the store themselves from its URL,
and report ``progress(done, total)``; :func:`partlab.engine.jobs.run_job` turns a cancellation
into :class:`partlab.engine.jobs.Cancelled` raised from that callback.
"""

from __future__ import annotations

import pandas as pd


def track_clip(progress, *, url: str, clip_id: int, tracker: str, bundle_path: str | None, seed: int,
               start: int = 0, stop: int | None = None, init: list[dict] | None = None) -> dict:
    """Track a stored clip and save the result as a tracker run (frames ``[start, stop)``)."""
    from partlab.app.pipeline import track_video
    from partlab.labelling.store import Store
    from partlab.models.bundle import load_bundle

    store = Store(url)
    clip = store.clip(clip_id)
    model = load_bundle(bundle_path) if bundle_path else None
    init_df = pd.DataFrame(init) if init else None
    df = track_video(str(clip.path), tracker=tracker, init=init_df, model=model,
                     occluders=tuple(store.occluders(clip_id)), seed=seed, progress=progress, start=start, stop=stop)
    run_id = store.save_tracker_run(clip_id, df, tracker=tracker, bundle=str(bundle_path or ""), seed=seed,
                                    start_frame=start, stop_frame=stop)
    return dict(run_id=run_id, boxes=int(len(df)), start=start, stop=stop)
