"""Fixtures of the app tests: a tiny synthetic clip and a store holding it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from partlab.labelling.video import write_video

N_FRAMES, WIDTH, HEIGHT = 12, 96, 72


def walker_frames(n: int = N_FRAMES, width: int = WIDTH, height: int = HEIGHT) -> list[np.ndarray]:
    """A light 'person' (head + body) walking right over a dark green floor."""
    frames = []
    for i in range(n):
        f = np.full((height, width, 3), (60, 90, 60), np.uint8)
        x = 10 + 3 * i
        f[20:64, x:x + 14] = (200, 180, 160)
        f[20:30, x + 3:x + 11] = (120, 150, 220)
        frames.append(f)
    return frames


def walker_boxes(n: int = N_FRAMES) -> pd.DataFrame:
    rows = []
    for i in range(n):
        x = 10 + 3 * i
        rows.append(dict(frame=i, track_id=1, part="person", x=x, y=20, w=14, h=44))
        rows.append(dict(frame=i, track_id=1, part="head", x=x + 3, y=20, w=8, h=10))
    return pd.DataFrame(rows)


@pytest.fixture(autouse=True)
def _no_old_jobs():
    """Each test sees only its own background jobs (the registry is process-wide)."""
    from partlab.app import jobs

    yield
    for job in jobs.active():
        jobs.wait(job.id, 120)
    jobs.clear_finished()


@pytest.fixture
def boxes():
    """The walker's true boxes (tracks CSV columns)."""
    return walker_boxes()


@pytest.fixture
def clip_file(tmp_path):
    return write_video(tmp_path / "walker.mp4", walker_frames(), fps=10.0)


@pytest.fixture
def store():
    from partlab.labelling.store import Store

    return Store()


@pytest.fixture
def tracked_clip(store, clip_file):
    """(project, clip) with one tracker run of the walker's true boxes."""
    project = store.create_project("test")
    clip = store.add_clip(project.id, clip_file)
    store.save_tracker_run(clip.id, walker_boxes(), tracker="body")
    return project, clip
