"""A tiny synthetic clip (160x120, 20 frames) and its truth, shared by the format tests."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from partlab.labelling.video import probe, write_video
from partlab.tracking.tracks import normalise_tracks

W, H, N = 160, 120, 20


def make_truth() -> pd.DataFrame:
    """Two people walking; person 1 leaves for frames 8..11 and is half outside the frame at the
    end; flags vary so that lossless formats have something to keep."""
    rows = []
    for t in range(N):
        people = [(0, 10.0 + 2.5 * t, 20.0)]
        if not 8 <= t <= 11:
            people.append((3, 120.0 - 1.5 * t + (50.0 if t > 15 else 0.0), 25.5))
        for tid, x, y in people:
            parts = {"person": (x, y, 24.0, 80.0), "head": (x + 7.0, y, 10.0, 12.0),
                     "torso": (x + 2.0, y + 12.0, 20.0, 30.0), "hipleg": (x + 2.0, y + 42.0, 20.0, 38.0)}
            for part, (bx, by, bw, bh) in parts.items():
                rows.append({"frame": t, "track_id": tid, "part": part, "x": bx, "y": by, "w": bw, "h": bh,
                             "score": 0.5 + 0.01 * t if tid == 0 else float("nan"),
                             "failure": tid == 3 and part == "head" and t % 5 == 0,
                             "occluded": 0.25 if (tid == 0 and 5 <= t <= 7 and part == "torso") else 0.0,
                             "state": "normal" if tid == 0 else "", "source": "manual" if t == 0 else "tracker"})
    return normalise_tracks(pd.DataFrame(rows))


def render(truth: pd.DataFrame) -> list[np.ndarray]:
    frames = []
    for t in range(N):
        img = np.full((H, W, 3), 90, np.uint8)
        for r in truth[(truth.frame == t) & (truth.part != "person")].itertuples():
            x0, y0 = int(max(r.x, 0)), int(max(r.y, 0))
            img[y0:int(r.y + r.h), x0:int(r.x + r.w)] = (40 * (r.track_id + 1), 120, 200)
        frames.append(img)
    return frames


@pytest.fixture(scope="session")
def truth() -> pd.DataFrame:
    return make_truth()


@pytest.fixture(scope="session")
def clip(tmp_path_factory, truth):
    path = write_video(tmp_path_factory.mktemp("clip") / "clip.avi", render(truth), fps=10.0)
    return path, probe(path)
