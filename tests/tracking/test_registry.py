"""The registry: every entry builds, names are checked, and a new tracker plugs into the run loop."""

import numpy as np
import pandas as pd
import pytest

from partlab.errors import UserError
from partlab.tracking import registry
from partlab.tracking.core.box import Box
from partlab.tracking.frame import FrameSet
from partlab.tracking.protocol import TrackContext
from partlab.tracking.run import build_tracker, run_frames, seeded_streams
from partlab.tracking.tracks import TrackRecord, records_to_frame

SINGLE_COLOUR = [n for n in registry.names()
                 if registry.get(n).min_streams == 1 and not registry.get(n).needs - {"color"}]


def test_the_registry_holds_single_view_and_multi_stream_trackers():
    # the rest (cameras, depth) are stepped by their own tests with their takes
    assert {"body", "limbs"} <= set(SINGLE_COLOUR) and set(registry.names()) - set(SINGLE_COLOUR)


@pytest.mark.parametrize("name", SINGLE_COLOUR)
def test_every_single_view_entry_builds_and_steps(name):
    tracker = build_tracker(name, seed=3, context=TrackContext())
    frame = np.zeros((48, 64, 3), np.uint8)
    assert tracker.step(FrameSet.single(0, frame), {"cam0": np.zeros((48, 64), np.uint8)}) == []


def test_unknown_tracker_names_the_known_ones():
    with pytest.raises(UserError, match="unknown tracker 'bdoy'; expected one of body, limbs"):
        registry.get("bdoy")


def test_seed_streams_do_not_depend_on_other_trackers():
    a = seeded_streams(7, ["limbs"])["limbs"].random(3)
    b = seeded_streams(7, ["body", "limbs"])["limbs"].random(3)
    assert np.array_equal(a, b)


class _Centre:
    """A toy tracker: one box at the centre of the brightest pixels."""

    def __init__(self, params):
        self.params = params

    def step(self, frames, foreground):
        img = frames.first.color[..., 0]
        ys, xs = np.nonzero(img == img.max())
        return [TrackRecord(frames.index, 1, "head", Box(xs.mean() - 2, ys.mean() - 2, 4, 4))]

    def table(self, records):
        return records_to_frame(records)


def test_a_new_tracker_is_one_entry(monkeypatch):
    monkeypatch.setitem(registry.TRACKERS, "toy", registry.TrackerEntry(
        "toy", "test", "tests.tracking.test_registry:_build", ("body",), ("head",), foreground=False))
    frames = []
    for i in range(4):
        img = np.zeros((40, 60, 3), np.uint8)
        img[20, 10 + 5 * i] = 255
        frames.append(FrameSet.single(i, img))
    tracker = build_tracker("toy")
    got = run_frames(tracker, frames)
    assert isinstance(got, pd.DataFrame)
    assert (got["x"] + 2).tolist() == [10, 15, 20, 25]


def _build(params, rngs, context):
    return _Centre(params["body"])
