"""Tracking a stored clip or take by path: :func:`partlab.labelling.take.open_take` plus the one
run loop, :func:`partlab.tracking.run.track`. Kept as the app's and the command line's entry point."""

from __future__ import annotations

from collections.abc import Callable
from os import PathLike
from typing import TYPE_CHECKING

from partlab.labelling.take import open_take
from partlab.tracking.run import RunResult, track

if TYPE_CHECKING:
    import pandas as pd


def track_path(path: str | PathLike, tracker: str = "body", **options) -> RunResult:
    """Open ``path`` (a video or a take folder) and track it; ``options`` as for
    :func:`partlab.tracking.run.track`. Raises :class:`partlab.errors.UserError` with a clear message."""
    with open_take(path) as take:
        return track(take, tracker, **options)


def track_video(video_path: str | PathLike, tracker: str = "body", init: pd.DataFrame | None = None,
                model=None, occluders=(), seed: int = 0,
                progress: Callable[[int, int], None] | None = None, failure_detector=None,
                start: int = 0, stop: int | None = None, events_out: list | None = None) -> pd.DataFrame:
    """The tracks table of ``video_path``; ``events_out`` (a list) receives the events table."""
    result = track_path(video_path, tracker, init=init, model=model, occluders=occluders, seed=seed,
                        progress=progress, failure_detector=failure_detector, start=start, stop=stop)
    if events_out is not None and result.events is not None:
        events_out.append(result.events)
    return result.tracks
