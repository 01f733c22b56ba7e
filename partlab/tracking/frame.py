"""What a tracker is fed: the frames of one instant of a take.

A :class:`Frame` is one stream's image at one frame index: a colour image and, when the stream
has one, a depth image in millimetres. A :class:`FrameSet` holds every stream of a take at the
same index (one stream for a plain video). A :class:`TakeSource` is anything that yields
frame sets: :class:`partlab.labelling.take.Take` opens folders and videos, tests and benchmarks
can pass a list. Trackers never read files themselves.

Depth convention: ``float32`` millimetres along the camera's optical axis (z, not the ray
length), ``NaN`` where the sensor measured nothing (a 16-bit PNG's 0 is *missing*, not near).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from partlab.tracking.camera import Camera

#: stream name of a take made from a single video
DEFAULT_STREAM = "cam0"


@dataclass(frozen=True, slots=True)
class Frame:
    """One stream at one frame index.

    ``color``: ``(H, W, 3) uint8`` BGR (OpenCV's order), or None for a depth-only stream;
    ``depth``: ``(H, W) float32`` millimetres, NaN = unmeasured, or None;
    ``camera``: the stream's calibration, or None when the take has none.
    """

    index: int
    color: np.ndarray | None
    depth: np.ndarray | None = None
    stream: str = DEFAULT_STREAM
    camera: Camera | None = None

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)`` in pixels."""
        image = self.color if self.color is not None else self.depth
        return int(image.shape[1]), int(image.shape[0])


@dataclass(frozen=True)
class FrameSet:
    """Every stream of a take at frame ``index`` (streams in the take's order)."""

    index: int
    views: Mapping[str, Frame] = field(default_factory=dict)

    @property
    def first(self) -> Frame:
        """The first stream's frame: what a single-camera tracker works on."""
        return next(iter(self.views.values()))

    def __len__(self) -> int:
        return len(self.views)

    @classmethod
    def single(cls, index: int, color: np.ndarray | None, depth: np.ndarray | None = None,
               stream: str = DEFAULT_STREAM, camera: Camera | None = None) -> FrameSet:
        return cls(index, {stream: Frame(index, color, depth, stream, camera)})


class TakeSource(Protocol):
    """What the run loop needs of a take (see :class:`partlab.labelling.take.Take`)."""

    @property
    def fps(self) -> float: ...

    @property
    def frame_count(self) -> int: ...

    @property
    def streams(self) -> tuple[str, ...]: ...

    @property
    def cameras(self) -> Mapping[str, Camera | None]: ...

    def frames(self, start: int = 0, stop: int | None = None) -> Iterator[FrameSet]: ...

    def close(self) -> None: ...


class MemoryTake:
    """A one-stream :class:`TakeSource` over frames already in memory (a list or a ``(T, H, W, 3)``
    array), e.g. decoded image folders in benchmarks or frames a test draws."""

    def __init__(self, frames, fps: float = 25.0, stream: str = DEFAULT_STREAM):
        self._frames = frames
        self._fps = float(fps)
        self._stream = stream

    @property
    def fps(self) -> float:
        return self._fps

    @property
    def frame_count(self) -> int:
        return len(self._frames)

    @property
    def streams(self) -> tuple[str, ...]:
        return (self._stream,)

    @property
    def cameras(self) -> Mapping[str, Camera | None]:
        return {self._stream: None}

    def frames(self, start: int = 0, stop: int | None = None) -> Iterator[FrameSet]:
        stop = len(self._frames) if stop is None else min(stop, len(self._frames))
        for i in range(start, stop):
            yield FrameSet.single(i, self._frames[i], stream=self._stream)

    def close(self) -> None:
        pass
