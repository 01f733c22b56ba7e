"""The body tracker as a training and benchmark runner over in-memory or decoded frames.

Training (seed 002 sec. 4.2) runs the plain tracker (no failure detector) on each
corrected clip from the truth's first boxes and labels what it produced; the
benchmarks run it with and without a detector. One background model per run, as
the run loop (:func:`partlab.tracking.run.track`) does; the seed
goes straight to the body tracker (training's results predate the registry's seed streams).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pandas as pd

from partlab.tracking.body.tracker import BodyTracker
from partlab.tracking.core.background import BackgroundModel
from partlab.tracking.frame import FrameSet
from partlab.tracking.params import BodyParams
from partlab.tracking.protocol import SingleView
from partlab.tracking.run import run_frames


def run_body_tracker(frames: Callable[[], Iterator[tuple[int, np.ndarray]]], fps: float, init: pd.DataFrame,
                     seed: int = 0, params: BodyParams | None = None, occluders=(),
                     failure_detector=None) -> pd.DataFrame:
    """Track the people of ``init`` through ``frames()`` and return the tracks table."""
    params = params or BodyParams()
    tracker = BodyTracker(params, np.random.default_rng(seed), init=init, occluders=occluders,
                          failure_detector=failure_detector, fps=fps)
    sets = (FrameSet.single(index, frame) for index, frame in frames())
    return run_frames(SingleView(tracker, params), sets, lambda stream: BackgroundModel(params))


def body_tracker_runner(frames, fps: float, init: pd.DataFrame, seed: int, params: BodyParams | None = None,
                        failure_detector=None) -> pd.DataFrame:
    """:data:`partlab.models.training.TrackerRunner`: default parameters and no failure detector
    unless given (validation, :mod:`partlab.models.selection`, passes both)."""
    return run_body_tracker(frames, fps, init, seed, params=params, failure_detector=failure_detector)
