"""The small interfaces the trackers, the failure detectors and the run loop meet at.

A :class:`Tracker` is started from boxes (the ``init`` of its :class:`TrackContext`, or none to
find people itself), then fed one :class:`~partlab.tracking.frame.FrameSet` at a time with the
shared foreground masks (one decode and one background model serve every tracker, so
``--tracker all`` costs one pass), and returns that frame's rows. Its tunable numbers are one
parameters object (``params``). :class:`SingleView` adapts a tracker that works on one colour
image (:class:`FrameTracker`) to this interface. A failure detector (Zhao & Lee sec. 4.2) looks at
a person's recent part states and says which parts failed; the body tracker then adjusts (sec. 4.3).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from partlab.tracking.camera import Camera
from partlab.tracking.core.box import Box
from partlab.tracking.frame import FrameSet
from partlab.tracking.tracks import TrackRecord, empty_tracks, records_to_frame

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True)
class TrackContext:
    """Everything a tracker is started with besides its parameters and random generator.

    ``init``: the boxes to start from, a tracks table or a list of :class:`TrackRecord` (the
    command line's, read without pandas; :meth:`init_table` gives the table), or None: find
    people automatically;
    ``occluders``: fixed regions that can hide people; ``fps``: frames per second of the take;
    ``cameras``: the take's calibration per stream (None where a stream has none);
    ``failure_detector``: a :class:`FailureDetector` or None; ``backgrounds``: per stream an
    empty-scene image ``(H, W, 3) uint8`` when the take has one (a take's
    ``<stream>_background.png``), for trackers that subtract a fixed background.
    """

    init: pd.DataFrame | list[TrackRecord] | None = None
    occluders: Sequence[Box] = ()
    fps: float = 25.0
    cameras: Mapping[str, Camera | None] = field(default_factory=dict)
    failure_detector: Any = None
    backgrounds: Mapping[str, np.ndarray] = field(default_factory=dict)

    def init_table(self) -> pd.DataFrame | None:
        """``init`` as a tracks table (None when there is none)."""
        if isinstance(self.init, list):
            return records_to_frame(self.init)
        return self.init


class Tracker(Protocol):
    """One tracker of a run. ``params``: its parameters object; ``events``: a table of what it
    recognised (joins, activities) or None."""

    params: Any

    def step(self, frames: FrameSet, foreground: Mapping[str, np.ndarray | None]) -> list[TrackRecord]:
        """Advance to ``frames.index`` and return this frame's rows (``foreground``: per stream,
        the ``(H, W) uint8`` moving-pixel mask, 255 = moving, or None when nobody asked for it)."""
        ...

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        """The run's tracks table from every row ``step`` returned (trackers that post-process
        whole tracks, e.g. joining identities, do it here)."""
        ...


class FrameTracker(Protocol):
    """A single-camera colour tracker (the body and limb trackers)."""

    def step(self, index: int, frame: np.ndarray, foreground: np.ndarray) -> list[TrackRecord]:
        """Advance to frame ``index`` (BGR ``(H, W, 3) uint8``; ``foreground`` is the
        ``(H, W) uint8`` mask, 255 = moving) and return this frame's boxes."""
        ...


class SingleView:
    """A :class:`FrameTracker` seen as a :class:`Tracker`: it works on the take's first stream."""

    def __init__(self, tracker: FrameTracker, params: Any):
        self.tracker = tracker
        self.params = params

    @property
    def events(self) -> pd.DataFrame | None:
        return getattr(self.tracker, "events", None)

    def step(self, frames: FrameSet, foreground: Mapping[str, np.ndarray | None]) -> list[TrackRecord]:
        view = frames.first
        return self.tracker.step(frames.index, view.color, foreground.get(view.stream))

    def rows(self, records: list[TrackRecord]) -> list[TrackRecord]:
        """The run's rows from every row ``step`` returned (e.g. rows of lost tracks withdrawn)."""
        finish = getattr(self.tracker, "finish", None)
        return finish(records) if finish is not None else records

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        records = self.rows(records)
        return records_to_frame(records) if records else empty_tracks()


@dataclass(frozen=True)
class FailureVerdict:
    """Which body parts a failure detector judges lost at this frame.

    ``failed`` lists part names among ``head, torso, hipleg``; ``multi`` is the fourth
    SVM's answer (two or three parts failed: re-initialise the person rather than
    rebuild one part from the other two). ``scores`` are the detectors' decision
    values per part (higher = more likely tracked), for the ``score`` column and the app.
    """

    failed: tuple[str, ...] = ()
    multi: bool = False
    scores: dict[str, float] | None = None


class FailureDetector(Protocol):
    def detect(self, history: np.ndarray, fps: float) -> FailureVerdict:
        """``history``: ``(T, 3, 4) float`` ``[cx, cy, w, h]`` of head, torso, hip-leg over the
        person's recent frames, newest last (T >= 1; at most 0.5 s + 1 frames are needed)."""
        ...
