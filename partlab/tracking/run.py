"""The one run loop: a take decoded once, one background model per stream, every tracker fed.

:func:`track` is what ``partlab track``, the app's Track and Re-track buttons, training's
validation and the benchmarks call. Frames come from a
:class:`~partlab.tracking.frame.TakeSource` (a video or take folder opened by
:func:`partlab.labelling.take.open_take`, or frames in memory), so this module reads no files.
``start``/``stop`` re-track a stretch of the take, e.g. from a frame a user corrected (``init``
then holds the boxes at ``start``). The same ``seed`` gives the same output: each kind of
parameters draws from its own fixed stream of the seed (:mod:`partlab.tracking.registry`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from partlab.errors import UserError
from partlab.tracking import registry
from partlab.tracking.core.background import BackgroundModel
from partlab.tracking.frame import FrameSet, TakeSource
from partlab.tracking.protocol import SingleView, TrackContext, Tracker
from partlab.tracking.tracks import TrackRecord, TracksCSVError, empty_tracks, normalise_tracks, records_to_frame

if TYPE_CHECKING:
    import pandas as pd

Progress = Callable[[int, int], None]


@dataclass
class RunResult:
    """``tracks``: the tracks table (frame indexes of the whole take); ``events``: what the
    tracker recognised (joins, activities), or None when it recognises nothing. A single-view
    run keeps its rows as ``records`` (:class:`TrackRecord`) and makes the table when it is
    first asked for, so ``partlab track`` writes them without importing pandas."""

    _tracks: pd.DataFrame | None = None
    events: pd.DataFrame | None = None
    records: list[TrackRecord] | None = field(default=None, repr=False)

    @property
    def tracks(self) -> pd.DataFrame:
        if self._tracks is None:
            self._tracks = records_to_frame(self.records or [])
        return self._tracks


def model_params(model: Any, key: str) -> Any:
    """The parameters of kind ``key`` in ``model``: None (defaults), a parameters object, or a
    bundle (``params[key]``, or its ``<key>_params`` / ``limb_params`` attribute)."""
    cls = registry.params_class(key)
    if model is None:
        return cls()
    if isinstance(model, cls):
        return model
    by_key = getattr(model, "params", None)
    if isinstance(by_key, Mapping) and by_key.get(key) is not None:
        return by_key[key]
    legacy = {"body": "body_params", "limbs": "limb_params"}.get(key, f"{key}_params")
    found = getattr(model, legacy, None)
    return found if found is not None else cls()


def seeded_streams(seed: int, keys: Iterable[str]) -> dict[str, np.random.Generator]:
    """One independent generator per parameter key, from the key's fixed slot of ``seed``."""
    slots = {k: registry.PARAMETERS[k].rng_slot for k in keys}
    if not slots:
        return {}
    children = np.random.default_rng(seed).bit_generator.seed_seq.spawn(max(2, max(slots.values()) + 1))
    return {k: np.random.default_rng(children[s]) for k, s in slots.items()}


def build_tracker(name: str, *, model: Any = None, seed: int = 0, context: TrackContext | None = None,
                  rngs: Mapping[str, np.random.Generator] | None = None) -> Tracker:
    """Tracker ``name`` of the registry with ``model``'s parameters (``rngs``: generators per
    parameter key, by default :func:`seeded_streams` of ``seed``)."""
    from partlab.tracking.core import kernels

    entry = registry.get(name)
    kernels.prepare()  # numba's compiler set up without what the kernels never use (start-up time)
    params = {k: model_params(model, k) for k in entry.param_keys}
    rngs = dict(rngs) if rngs is not None else seeded_streams(seed, entry.param_keys)
    return registry.load(entry.factory)(params, rngs, context or TrackContext())


def frame_sets(frames: Iterable) -> Iterable[FrameSet]:
    """One-stream frame sets from in-memory BGR frames (``(H, W, 3) uint8`` arrays, indexed from
    0, or ``(index, array)`` pairs), for synthetic scenes and benchmarks."""
    for i, item in enumerate(frames):
        index, color = item if isinstance(item, tuple) else (i, item)
        yield FrameSet.single(int(index), color)


def run_single_view(tracker: Any, frames: Iterable, background: Any = None,
                    progress: Progress | None = None) -> pd.DataFrame:
    """:func:`run_frames` for a single-view tracker (``BodyTracker``, ``LimbTracker``) over
    in-memory frames (:func:`frame_sets`); ``background``: the model whose ``apply(frame)`` gives
    the foreground mask (one per run), or None for no mask."""
    factory = (lambda _stream: background) if background is not None else None
    return run_frames(SingleView(tracker, tracker.params), frame_sets(frames), factory, progress)


def run_frames(tracker: Tracker, frames: Iterable[FrameSet], background: Callable[[str], Any] | None = None,
               progress: Progress | None = None, total: int | None = None) -> pd.DataFrame:
    """Feed ``tracker`` every frame set of ``frames`` and return its tracks table.

    ``background(stream)`` makes the background model of a stream (called once per stream; None:
    no foreground masks). ``progress(done, total)`` is called after every frame.
    """
    return tracker.table(_step_all(tracker, frames, background, progress, total))


def run_records(tracker: SingleView, frames: Iterable[FrameSet], background: Callable[[str], Any] | None = None,
                progress: Progress | None = None, total: int | None = None) -> list[TrackRecord]:
    """:func:`run_frames` of a single-view tracker, its rows as :class:`TrackRecord`."""
    return tracker.rows(_step_all(tracker, frames, background, progress, total))


def _step_all(tracker: Tracker, frames: Iterable[FrameSet], background: Callable[[str], Any] | None,
              progress: Progress | None, total: int | None) -> list[TrackRecord]:
    """Every row ``tracker.step`` returns over ``frames`` (one background model per stream)."""
    models: dict[str, Any] = {}
    records: list[TrackRecord] = []
    done = 0
    for frames_now in frames:
        masks: dict[str, np.ndarray | None] = {}
        for stream, view in frames_now.views.items():
            if background is None or view.color is None:
                masks[stream] = None
                continue
            if stream not in models:
                models[stream] = background(stream)
            masks[stream] = models[stream].apply(view.color)
        records.extend(tracker.step(frames_now, masks))
        done += 1
        if progress is not None:
            progress(done, total if total is not None else done)
    return records


def check_take(entry: registry.TrackerEntry, take: TakeSource) -> None:
    """Refuse a take the tracker cannot work on, naming what it lacks."""
    streams = tuple(take.streams)
    if len(streams) < entry.min_streams:
        raise UserError(f"tracker {entry.name!r} needs a take of at least {entry.min_streams} streams; "
                        f"this one has {len(streams)}")
    if "calibration" in entry.needs:
        missing = [s for s in streams if take.cameras.get(s) is None]
        if missing:
            raise UserError(f"tracker {entry.name!r} needs every stream calibrated; "
                            f"no calibration for {', '.join(missing)}")
    if "depth" in entry.needs and not getattr(take, "has_depth", False):
        raise UserError(f"tracker {entry.name!r} needs depth; the take has no depth stream")


def track(take: TakeSource, tracker: str = "body", *, init: pd.DataFrame | None = None, model: Any = None,
          occluders=(), seed: int = 0, progress: Progress | None = None, failure_detector: Any = None,
          start: int = 0, stop: int | None = None) -> RunResult:
    """Track ``take`` with registry tracker ``tracker`` and return its rows and events.

    ``model``: None (built-in parameters), a parameters object, or a model bundle (its failure
    detector is used unless ``failure_detector`` is given). Raises :class:`UserError` with a clear
    message for a take the tracker cannot use, a bad ``init`` table or a bad frame range.
    """
    entry = registry.get(tracker)
    check_take(entry, take)
    n = take.frame_count
    if start < 0 or start >= n:
        raise UserError(f"start frame {start} is outside the clip (0..{n - 1})")
    stop = n if stop is None else min(int(stop), n)
    if stop <= start:
        raise UserError(f"stop frame {stop} is not after start frame {start}")
    if isinstance(init, list):  # rows read without pandas (the command line)
        init = [r for r in init if r.frame >= start]
    elif init is not None:
        try:
            init = normalise_tracks(init)
        except (TracksCSVError, ValueError, KeyError) as exc:
            raise UserError(f"bad init table: {exc}") from None
        init = init[init["frame"] >= start]
    detector = failure_detector if failure_detector is not None else getattr(model, "failure_detector", None)
    context = TrackContext(init=init, occluders=tuple(occluders), fps=take.fps, cameras=dict(take.cameras),
                           failure_detector=detector, backgrounds=dict(getattr(take, "backgrounds", None) or {}))
    built = build_tracker(tracker, model=model, seed=seed, context=context)
    body_params = model_params(model, "body")  # the background model's settings
    background = (lambda stream: BackgroundModel(body_params)) if entry.foreground else None
    frames = take.frames(start, stop)
    if isinstance(built, SingleView):  # its rows are the output: no table until one is asked for
        records = run_records(built, frames, background, progress, total=stop - start)
        return RunResult(events=built.events, records=records)
    tracks = run_frames(built, frames, background, progress, total=stop - start)
    events = getattr(built, "events", None)
    return RunResult(tracks if len(tracks) else empty_tracks(), events)
