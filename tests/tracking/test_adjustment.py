"""Failure adjustment (seed 002 sec. 4.3) driven by a stub failure detector."""

from __future__ import annotations

import numpy as np
import pytest

from partlab.tracking.body.adjustment import head_from_torso, hipleg_from_torso, torso_from_head_and_hipleg
from partlab.tracking.body.tracker import BodyTracker
from partlab.tracking.core.box import Box
from partlab.tracking.params import BodyParams
from partlab.tracking.protocol import FailureVerdict
from tests.tracking.test_body import _init, _run, _scene
from tests.tracking.walkers import correct


class DisplacingDetector:
    """Knocks one part's filter off the walker at frame ``at`` (as a distractor would), and
    flags a part as failed when its centre is more than a torso width from the torso's."""

    def __init__(self, tracker_ref, part, at, shift=(100.0, 0.0)):
        self.ref, self.part, self.at, self.shift = tracker_ref, part, at, shift
        self.calls = 0
        self.flagged_at = []

    def detect(self, history, fps):
        self.calls += 1
        assert history.ndim == 3 and history.shape[1:] == (3, 4)
        tracker = self.ref[0]
        frame = self.calls  # one call per frame for the single walker (frame 0 is the start)
        if frame == self.at:
            f = next(iter(tracker.people.values())).filters[self.part]
            f.state[0:2] += self.shift
            f.particles[:, 0:2] += np.asarray(self.shift, dtype=np.float32)
            return FailureVerdict()
        h = history[-1]
        torso = h[1]
        failed = tuple(n for k, n in ((0, "head"), (2, "hipleg"))
                       if abs(h[k, 0] - torso[0]) > torso[2])
        if failed:
            self.flagged_at.append(frame)
        return FailureVerdict(failed=failed, scores={n: -1.0 for n in failed})


@pytest.mark.parametrize("part", ["head", "hipleg"])
def test_displaced_part_is_rebuilt_from_the_torso(part):
    frames, truths = _scene(n=40)
    ref = []
    det = DisplacingDetector(ref, part, at=20)
    tracker = BodyTracker(BodyParams(), np.random.default_rng(8), init=_init(truths[0]), failure_detector=det)
    ref.append(tracker)
    tracks = _run(tracker, frames)
    assert det.calls == 39
    rows = tracks[(tracks.part == part)].set_index("frame")
    # without adjustment the filter stays on the background 100 px away (rate 0.0 measured with a
    # detector that never flags); with it the
    # part is flagged (failure column) and back on the walker within a frame or two
    assert det.flagged_at and det.flagged_at[0] <= 22
    flagged = det.flagged_at[0]
    assert bool(rows.loc[flagged, "failure"]) and rows.loc[flagged, "state"] == "adjusted"
    assert not rows.loc[flagged + 3:, "failure"].any()
    hits = [correct(Box(r.x, r.y, r.w, r.h), truths[f][1][part]) for f, r in rows.loc[flagged + 1:].iterrows()]
    assert np.mean(hits) >= 0.85


def test_torso_is_the_mean_of_head_and_hipleg_eq4():
    t = torso_from_head_and_hipleg(Box(10, 0, 10, 10), Box(0, 40, 30, 20))
    # centres (15, 5) and (15, 50) -> (15, 27.5); sizes (10, 10) and (30, 20) -> (20, 15)
    assert t.as_tuple() == pytest.approx((5.0, 20.0, 20.0, 15.0))


def test_head_and_hipleg_regions_use_the_foreground_or_geometry():
    mask = np.zeros((200, 100), np.uint8)
    mask[20:34, 44:56] = 255          # a head blob above the torso
    mask[34:60, 32:68] = 255          # shoulders and torso below it
    torso, hip = Box(35, 45, 30, 40), Box(38, 85, 24, 30)
    head = head_from_torso(torso, hip, Box(0, 0, 12, 12), mask, 100, 200)
    # the top 1.2 x 12 = 14 rows of the foreground: the head, not the shoulders
    assert head.centre == pytest.approx((50.0, 27.0), abs=0.6)
    assert head.w < 14
    # no foreground: the previous size straight above the torso
    head2 = head_from_torso(torso, hip, Box(0, 0, 12, 12), None, 100, 200)
    assert head2.as_tuple() == pytest.approx((44.0, 33.0, 12.0, 12.0))
    mask[85:145, 42:58] = 255         # legs below the torso
    hl = hipleg_from_torso(torso, hip, Box(0, 0, 20, 30), mask, 100, 200)
    assert hl.y == pytest.approx(85.0) and hl.h == pytest.approx(30.0)
    assert hl.centre[0] == pytest.approx(50.0, abs=0.6)


def _bent_person():
    """A person bending forward, drawn flat: legs standing at x 40..60, the torso lying
    horizontally from the hips to the right at shoulder height, the head hanging beside it."""
    import cv2

    frame = np.full((200, 200, 3), (120, 124, 120), np.uint8)   # grey floor/wall (BGR)
    frame[100:180, 40:60] = (60, 50, 40)                         # trousers
    frame[80:104, 40:120] = (200, 120, 60)                       # blue shirt, lying horizontal
    cv2.circle(frame, (132, 92), 11, (120, 160, 220), -1)        # skin-coloured head beside it
    frame[81:88, 124:141] = (30, 30, 30)                         # hair on top
    mask = np.zeros((200, 200), np.uint8)
    mask[np.any(frame != (120, 124, 120), axis=2)] = 255
    ycc = cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb)
    return ycc, mask


def test_a_bending_persons_lost_head_is_found_by_its_model_not_put_above_the_torso():
    from partlab.tracking.body.adjustment import adjust_person

    ycc, mask = _bent_person()
    head_true = Box(121, 81, 22, 22)
    results = {}
    for search in (0.0, 0.6):
        params = BodyParams().updated({"decomposition.shrink_given_parts": False, "adjustment.search": search})
        tracker = BodyTracker(params, np.random.default_rng(3))
        person = tracker.start_track(1, {"head": head_true, "torso": Box(90, 82, 24, 20),
                                         "hipleg": Box(41, 104, 18, 40)}, ycc, mask, 0)
        head = person.filters["head"]
        head.shift(np.array([-60.0, 40.0]))                          # lost on the floor by the legs
        adjust_person(tracker, person, FailureVerdict(failed=("head",)), ycc, mask)
        results[search] = head.box
    # the paper's rebuild puts it straight above the torso, where there is nothing
    assert not correct(results[0.0], head_true) and results[0.0].y2 <= 83
    # the search with the head's own model finds the hanging head, and keeps that model
    assert correct(results[0.6], head_true)
    assert results[0.6].centre == pytest.approx(head_true.centre, abs=8.0)  # within the head's radius (11 px)
