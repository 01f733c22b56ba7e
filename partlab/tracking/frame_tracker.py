"""The small interfaces the trackers, the failure detectors and the pipeline meet at.

A tracker is fed one decoded frame at a time with the shared foreground mask (one
decode and one background model serve every tracker, so ``--tracker all`` costs
one pass). A failure detector (seed 002 sec. 4.2) looks at a person's recent part
states and says which parts failed; the body tracker then adjusts (sec. 4.3).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from partlab.tracking.tracks import TrackRecord


class FrameTracker(Protocol):
    def step(self, index: int, frame: np.ndarray, foreground: np.ndarray) -> list[TrackRecord]:
        """Advance to frame ``index`` (BGR ``(H, W, 3) uint8``; ``foreground`` is the
        ``(H, W) uint8`` mask, 255 = moving) and return this frame's boxes."""
        ...


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
