"""Each transition of seed 000 sec. 5.2, driven by synthetic observations."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from partlab.tracking.limbs.state_machine import LimbState, LimbStateMachine, Observation, assign_by_direction
from partlab.tracking.params import LimbParams

P = LimbParams().updated({"states.combine_distance": 20.0, "states.split_distance": 30.0,
                         "states.lost_likelihood": 0.15, "states.recover_likelihood": 0.3, "states.lost_frames": 3,
                         "states.start_frames": 3, "states.start_prior": 0.5, "states.history_frames": 10})
S = LimbState


def ok(x, y, lik=0.8, labelled=True, modes=()):
    return Observation(position=(x, y), likelihood=lik, labelled=labelled, modes=modes)


def test_uninitialized_starts_after_start_frames_strong_priors_and_a_weak_one_resets():
    m = LimbStateMachine(P)
    m.add(0)
    for f, prior in enumerate([0.9, 0.9, 0.2, 0.9, 0.9]):
        assert m.update(f, {0: Observation(position=(5, 5), prior=prior)}) == []
        assert m.state(0) == S.UNINITIALIZED
    tr = m.update(5, {0: Observation(position=(5, 5), prior=0.6)})
    assert [(t.old, t.new) for t in tr] == [(S.UNINITIALIZED, S.UNLABELLED)]
    assert m.state(0) == S.UNLABELLED


def test_unlabelled_becomes_normal_when_a_label_cue_arrives():
    m = LimbStateMachine(P)
    m.add(0, S.UNLABELLED)
    m.update(0, {0: ok(0, 0, labelled=False)})
    assert m.state(0) == S.UNLABELLED
    m.update(1, {0: ok(0, 0, labelled=True)})
    assert m.state(0) == S.NORMAL


def _pair_joined():
    """Left tracker 0 at x=100 moving left to meet tracker 1 coming from x=40."""
    m = LimbStateMachine(P)
    m.add(0, S.NORMAL)
    m.add(1, S.NORMAL)
    for f, gap in enumerate([60, 50, 40, 30, 24]):
        m.update(f, {0: ok(70 + gap / 2, 80), 1: ok(70 - gap / 2, 80)})
        assert m.state(0) == S.NORMAL and m.state(1) == S.NORMAL
    tr = m.update(5, {0: ok(78, 80), 1: ok(62, 80)})  # 16 px apart < 20
    assert {(t.tracker, t.new, t.partner) for t in tr} == {(0, S.COMBINED, 1), (1, S.COMBINED, 0)}
    return m


def test_normal_pair_closer_than_combine_distance_is_combined_and_remembers_direction():
    m = _pair_joined()
    assert m.partner(0) == 1 and m.partner(1) == 0
    assert m.is_leader(0) and not m.is_leader(1)
    # 24 px apart (>= 20) at frame 4 is the last frame they were apart: 0 minus 1 = +24 in x
    np.testing.assert_allclose(m.direction_before(0), [24.0, 0.0])
    np.testing.assert_allclose(m.direction_before(1), [-24.0, 0.0])


def test_combined_stays_while_modes_are_closer_than_split_distance():
    m = _pair_joined()
    for f in range(6, 10):
        tr = m.update(f, {0: ok(70, 80, modes=((60, 80), (85, 80)))})  # 25 px < 30
        assert tr == []
    assert m.state(0) == S.COMBINED and m.state(1) == S.COMBINED


@pytest.mark.parametrize("modes", [((105, 82), (35, 79)), ((35, 79), (105, 82))])
def test_split_gives_each_tracker_the_mode_on_its_side_whatever_the_mode_order(modes):
    m = _pair_joined()
    tr = m.update(6, {0: ok(70, 80, modes=modes)})
    got = {t.tracker: (t.new, t.position) for t in tr}
    assert got[0] == (S.UNLABELLED, (105.0, 82.0))  # tracker 0 was on the right before joining
    assert got[1] == (S.UNLABELLED, (35.0, 79.0))
    assert m.partner(0) is None and m.partner(1) is None
    assert [(e.start_frame, e.end_frame, e.tracker_a, e.tracker_b, e.ended_by) for e in m.events] == \
        [(5, 6, 0, 1, "split")]
    # labelled again on the next frame -> normal
    m.update(7, {0: ok(106, 82), 1: ok(34, 79)})
    assert m.state(0) == S.NORMAL and m.state(1) == S.NORMAL


def test_normal_is_lost_after_lost_frames_low_likelihood_only():
    m = LimbStateMachine(P)
    m.add(0, S.NORMAL)
    for f, lik in enumerate([0.1, 0.1, 0.5, 0.1, 0.1]):  # the good frame resets the count
        m.update(f, {0: ok(0, 0, lik=lik)})
        assert m.state(0) == S.NORMAL
    tr = m.update(5, {0: ok(0, 0, lik=0.05)})
    assert [(t.old, t.new, t.reason) for t in tr] == [(S.NORMAL, S.LOST, "low likelihood")]


def test_lost_recovers_above_recover_likelihood_with_hysteresis():
    m = LimbStateMachine(P)
    m.add(0, S.LOST)
    m.add(1, S.LOST)
    m.update(0, {0: ok(0, 0, lik=0.2), 1: ok(50, 0, lik=0.2)})  # above lost, below recover
    assert m.state(0) == S.LOST and m.state(1) == S.LOST
    m.update(1, {0: ok(0, 0, lik=0.35, labelled=True), 1: ok(50, 0, lik=0.35, labelled=False)})
    assert m.state(0) == S.NORMAL  # a labelled target goes straight back to normal
    assert m.state(1) == S.UNLABELLED  # one that never had a type must be labelled first


def test_combined_pair_is_lost_together():
    m = _pair_joined()
    for f in range(6, 8):
        m.update(f, {0: ok(70, 80, lik=0.05)})
        assert m.state(0) == S.COMBINED
    tr = m.update(8, {0: ok(70, 80, lik=0.05)})
    assert {(t.tracker, t.new) for t in tr} == {(0, S.LOST), (1, S.LOST)}
    assert m.events[-1].ended_by == "lost" and m.events[-1].end_frame == 8


def test_only_one_pair_per_tracker_and_the_closest_pair_wins():
    m = LimbStateMachine(P)
    for t in range(3):
        m.add(t, S.NORMAL)
    m.update(0, {0: ok(0, 0), 1: ok(15, 0), 2: ok(25, 0)})  # 0-1: 15, 1-2: 10, 0-2: 25
    assert m.state(1) == S.COMBINED and m.partner(1) == 2
    assert m.state(0) == S.NORMAL


def test_assign_by_direction_keeps_the_angle_below_90_degrees():
    a, b = assign_by_direction(np.array([0.0, -10.0]), np.array([[3.0, 40.0], [5.0, 0.0]]))
    np.testing.assert_allclose(a, [5.0, 0.0])  # a was above b (smaller y) before joining
    np.testing.assert_allclose(b, [3.0, 40.0])


def test_remove_refuses_a_started_tracker():
    m = LimbStateMachine(P)
    m.add(0, S.NORMAL)
    with pytest.raises(ValueError, match="only uninitialized"):
        m.remove(0)
    with pytest.raises(ValueError, match="already exists"):
        m.add(0)


def test_a_drifting_tracker_below_the_lost_threshold_is_not_combined():
    m = LimbStateMachine(P)
    m.add(0, S.NORMAL)
    m.add(1, S.NORMAL)
    m.update(0, {0: ok(0, 0, lik=0.05), 1: ok(10, 0)})
    assert m.state(0) == S.NORMAL and m.state(1) == S.NORMAL


def test_with_sizes_the_distances_scale_with_the_targets():
    p = LimbParams().updated({"states.combine_distance": 20.0, "states.split_distance": 30.0,
                              "states.combine_size": 1.3, "states.split_size": 1.8,
                              "states.lost_likelihood": 0.15, "states.history_frames": 10})
    m = LimbStateMachine(p)
    m.add(0, S.NORMAL)
    m.add(1, S.NORMAL)
    big = dict(likelihood=0.8, labelled=True, size=40.0)  # 40 px targets: combine < 52 px, split > 72 px
    m.update(0, {0: Observation(position=(100, 0), **big), 1: Observation(position=(40, 0), **big)})
    assert m.state(0) == S.NORMAL  # 60 px apart
    m.update(1, {0: Observation(position=(90, 0), **big), 1: Observation(position=(45, 0), **big)})
    assert m.state(0) == S.COMBINED  # 45 px < 52, although more than combine_distance
    m.update(2, {0: Observation(position=(70, 0), modes=((100, 0), (40, 0)), **big)})
    assert m.state(0) == S.COMBINED  # modes 60 px apart < 72
    m.update(3, {0: Observation(position=(70, 0), modes=((110, 0), (30, 0)), **big)})
    assert m.state(0) == S.UNLABELLED and m.state(1) == S.UNLABELLED


@pytest.mark.parametrize("x, seen, unseen, guess", [(104.0, 0, 1, 36.0), (36.0, 1, 0, 104.0)])
def test_a_pair_whose_one_mode_leaves_the_meeting_point_splits_with_the_other_hand_lost(x, seen, unseen, guess):
    # met at x=70 (tracker 0 came from the right); one mode only, 34 px to one side (> 30): the
    # hands parted and one of them is not seen (one camera: taken back behind its body). The mode
    # is the hand of that side; the other is lost, looked for as far back on its own side.
    m = _pair_joined()
    for f, step in enumerate([10.0, 20.0, 30.0], start=6):  # within the split distance: still together
        at = 70 + step * np.sign(x - 70)
        assert m.update(f, {0: replace(ok(at, 80, modes=((at, 80),)), two_people=True)}) == []
    # one person's two hands (a walker's, crossing as they swing): not split so
    assert m.update(9, {0: ok(x, 80, modes=((x, 80),))}) == []
    tr = m.update(10, {0: replace(ok(x, 80, modes=((x, 80),)), two_people=True)})
    got = {t.tracker: (t.new, t.reason, t.position) for t in tr}
    assert got[seen] == (S.UNLABELLED, "split", (x, 80.0))
    assert got[unseen] == (S.LOST, "split unseen", (guess, 80.0))
    assert [(e.start_frame, e.end_frame, e.ended_by) for e in m.events] == [(5, 10, "split")]
    assert m.partner(0) is None and m.partner(1) is None


def test_a_pair_moving_together_across_the_join_direction_or_with_the_rule_off_stays_combined():
    m = _pair_joined()
    for f, y in enumerate([90.0, 100.0, 115.0, 130.0], start=6):  # 50 px down, across the direction
        assert m.update(f, {0: replace(ok(72, y, modes=((72, y),)), two_people=True)}) == []
    assert m.state(0) == S.COMBINED and m.state(1) == S.COMBINED
    off = LimbStateMachine(P.updated({"states.split_unseen": False}))
    for t in (0, 1):
        off.add(t, S.NORMAL)
    for f, gap in enumerate([60, 50, 40, 30, 24]):
        off.update(f, {0: ok(70 + gap / 2, 80), 1: ok(70 - gap / 2, 80)})
    off.update(5, {0: ok(78, 80), 1: ok(62, 80)})
    assert off.update(6, {0: replace(ok(110, 80, modes=((110, 80),)), two_people=True)}) == []
    assert off.state(0) == S.COMBINED and off.state(1) == S.COMBINED
