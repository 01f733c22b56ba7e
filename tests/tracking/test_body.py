"""The three-part body tracker on small drawn scenes (seed 002 sec. 4)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from partlab.tracking.body.decomposition import decompose
from partlab.tracking.body.tracker import BodyTracker, _overlap_fraction, init_starts
from partlab.tracking.core.background import BackgroundModel
from partlab.tracking.core.box import Box
from partlab.tracking.core.histogram import to_ycc
from partlab.tracking.params import BodyParams
from partlab.tracking.tracks import records_to_frame
from tests.tracking.walkers import background, correct, draw_walker

W, H = 320, 200


def _scene(n=60, walkers=(dict(x0=40, vx=2.0, shirt=(40, 40, 160), trousers=(120, 60, 30)),), seed=0):
    """Frames and truth of walkers drawn in list order (later ones in front)."""
    rng = np.random.default_rng(seed)
    bg = background(rng, W, H)
    frames, truths = [], []
    for t in range(n):
        f = bg.copy()
        tr = {}
        for k, w in enumerate(walkers, start=1):
            tr[k] = draw_walker(f, w["x0"] + w["vx"] * t, 50, 110, w["shirt"], w["trousers"], phase=t / 3)
        f = np.clip(f.astype(np.int16) + rng.integers(-6, 7, f.shape), 0, 255).astype(np.uint8)
        frames.append(f)
        truths.append(tr)
    return frames, truths


def _init(truth, ids=(1,)):
    return pd.DataFrame([dict(frame=0, track_id=i, part="person", x=b.x, y=b.y, w=b.w, h=b.h)
                         for i in ids for b in [truth[i]["person"]]])


def _run(tracker, frames):
    bgm = BackgroundModel(tracker.params)
    out = []
    for i, f in enumerate(frames):
        out.extend(tracker.step(i, f, bgm.apply(f)))
    return records_to_frame(out)


def _rate(tracks, truths, track_id, part, tid_truth=None):
    tid_truth = tid_truth or track_id
    rows = tracks[(tracks.track_id == track_id) & (tracks.part == part)]
    hits = [correct(Box(r.x, r.y, r.w, r.h), truths[r.frame][tid_truth][part]) for r in rows.itertuples()]
    return np.mean(hits), len(hits)


def test_decomposition_finds_the_three_parts_of_a_drawn_person():
    frames, truths = _scene(n=1)
    ycc = to_ycc(frames[0])
    t = truths[0][1]
    mask = np.zeros((H, W), np.uint8)
    p = t["person"]
    # the foreground of the drawn walker: every pixel that differs from the background
    bg = background(np.random.default_rng(0), W, H)
    mask[np.abs(frames[0].astype(int) - bg).sum(axis=2) > 40] = 255
    parts = decompose(ycc, mask, p, BodyParams())
    for name in ("head", "torso", "hipleg"):
        assert correct(parts[name], t[name]), (name, parts[name], t[name])
    assert parts["head"].y2 <= parts["torso"].y + 1 <= parts["hipleg"].y + 1
    # the hip-leg rectangle is the upper half of its section only
    assert parts["hipleg"].y2 < p.y2 - 0.2 * p.h


def test_decomposition_without_a_mask_uses_colour_contrast():
    """First frames: no background model yet; the person is told from its surroundings."""
    frames, truths = _scene(n=1, walkers=(dict(x0=150, vx=0.0, shirt=(40, 40, 160), trousers=(120, 60, 30)),))
    t = truths[0][1]
    loose = Box(t["person"].x - 20, t["person"].y - 6, t["person"].w + 24, t["person"].h + 12)  # more room left
    parts = decompose(to_ycc(frames[0]), None, loose, BodyParams())
    for name in ("head", "torso", "hipleg"):
        assert correct(parts[name], t[name]), (name, parts[name], t[name])
    # (with the whole loose box as foreground the head box takes in the background on the left)
    assert abs(parts["torso"].centre[0] - t["torso"].centre[0]) < 5


def test_boxes_stay_on_a_walker_and_person_row_is_the_mbr():
    frames, truths = _scene(n=60)
    tracks = _run(BodyTracker(BodyParams(), np.random.default_rng(1), init=_init(truths[0])), frames)
    for part in ("head", "torso", "hipleg", "person"):
        rate, n = _rate(tracks, truths, 1, part)
        assert n == 60
        assert rate >= 0.9, part
    f30 = tracks[tracks.frame == 30].set_index("part")
    assert f30.loc["person", "x"] == pytest.approx(f30.loc[["head", "torso", "hipleg"], "x"].min())
    bottom = (f30.loc[["head", "torso", "hipleg"], "y"] + f30.loc[["head", "torso", "hipleg"], "h"]).max()
    assert f30.loc["person", "y"] + f30.loc["person", "h"] == pytest.approx(bottom)
    assert set(tracks["state"]) <= {"init", "tracked"}


def test_same_seed_same_output_and_whole_mode():
    frames, truths = _scene(n=15)
    a = _run(BodyTracker(BodyParams(), np.random.default_rng(5), init=_init(truths[0])), frames)
    b = _run(BodyTracker(BodyParams(), np.random.default_rng(5), init=_init(truths[0])), frames)
    pd.testing.assert_frame_equal(a, b)
    whole = _run(BodyTracker(BodyParams(), np.random.default_rng(5), init=_init(truths[0]), whole=True), frames)
    assert set(whole["part"]) == {"person"} and len(whole) == 15
    assert _rate(whole, truths, 1, "person")[0] >= 0.9


def test_people_are_found_without_init_and_tracks_end_when_they_leave():
    frames, truths = _scene(n=90, walkers=(dict(x0=-10, vx=4.5, shirt=(40, 40, 160), trousers=(120, 60, 30)),))
    tracks = _run(BodyTracker(BodyParams(), np.random.default_rng(2)), frames)
    assert tracks["track_id"].nunique() == 1
    first = int(tracks["frame"].min())
    assert first <= 12                       # background learnt, blob stable for start_frames
    rate, n = _rate(tracks, truths, int(tracks["track_id"].iloc[0]), "torso", 1)
    assert rate >= 0.85
    # the walker leaves (centre beyond 320 + 10) around t = 76: the track ends before the last frame
    assert tracks["frame"].max() < 89


def test_a_walker_in_the_first_frame_leaves_a_ghost_that_starts_no_track():
    # the walker stands in frame 0, so the background model learns it there and, once it walks
    # off, keeps reporting foreground where it stood; only the walker itself gets a track
    frames, truths = _scene(n=70, walkers=(dict(x0=70, vx=3.0, shirt=(40, 40, 160), trousers=(120, 60, 30)),))
    tracks = _run(BodyTracker(BodyParams(), np.random.default_rng(2)), frames)
    assert tracks["track_id"].nunique() == 1
    tid = int(tracks["track_id"].iloc[0])
    rate, n = _rate(tracks, truths, tid, "torso", 1)
    assert n >= 40 and rate >= 0.85
    # with the old start rule (seen 3 frames running, no motion needed) the ghost starts a track
    old = BodyParams().updated({"detection.start_min_motion": 0.0, "detection.margin": -1.0,
                               "detection.ghost_edge_contrast": 0.0})
    assert _run(BodyTracker(old, np.random.default_rng(2)), frames)["track_id"].nunique() > 1


def test_occluded_person_is_predicted_through_the_occlusion():
    """Sec. 4.3.1: B walks behind A; B's parts follow its dynamics while hidden and B is
    tracked again after they separate (without it B's filters would lock onto A)."""
    walkers = (dict(x0=90, vx=1.0, shirt=(40, 140, 40), trousers=(60, 60, 60)),      # B, behind
               dict(x0=170, vx=-1.0, shirt=(40, 40, 160), trousers=(120, 60, 30)))  # A, in front
    frames, truths = _scene(n=80, walkers=walkers)
    tracker = BodyTracker(BodyParams(), np.random.default_rng(3), init=_init(truths[0], ids=(1, 2)))
    tracks = _run(tracker, frames)
    b = tracks[(tracks.track_id == 1) & (tracks.part == "torso")].set_index("frame")
    states = tracks[(tracks.track_id == 1) & (tracks.part == "person")].set_index("frame")["state"]
    assert (states == "occluded").sum() >= 5
    # while occluded, B's predicted torso keeps moving right at about its speed (1 px/frame)
    occ = states[states == "occluded"].index
    xs = b.loc[occ, "x"].to_numpy()
    assert np.all(np.diff(xs) > 0.3)
    assert np.mean(np.diff(xs)) == pytest.approx(1.0, abs=0.4)
    # after the crossing both are on their own torsos again
    for tid in (1, 2):
        late = tracks[(tracks.track_id == tid) & (tracks.part == "torso") & (tracks.frame >= 65)]
        hits = [correct(Box(r.x, r.y, r.w, r.h), truths[r.frame][tid]["torso"]) for r in late.itertuples()]
        assert np.mean(hits) >= 0.8, tid


def test_parts_behind_an_occluder_follow_the_visible_parts():
    """Sec. 4.3.2: a pillar hides the walker's hip-leg; it is carried along by the head and
    torso and the walker is still tracked when the hip-leg reappears."""
    frames, truths = _scene(n=70)
    pillar = Box(120, 100, 40, 100)  # low wall: covers legs only
    for f in frames:
        f[100:200, 120:160] = (30, 200, 200)
    tracker = BodyTracker(BodyParams(), np.random.default_rng(4), init=_init(truths[0]), occluders=[pillar])
    tracks = _run(tracker, frames)
    hip = tracks[(tracks.track_id == 1) & (tracks.part == "hipleg")]
    assert (hip["occluded"] > 0).sum() >= 5
    late = hip[hip.frame >= 60]
    hits = [correct(Box(r.x, r.y, r.w, r.h), truths[r.frame][1]["hipleg"]) for r in late.itertuples()]
    assert np.mean(hits) >= 0.8


def test_init_rows_of_other_parts_are_ignored_and_bad_boxes_refused():
    init = pd.DataFrame([
        dict(frame=3, track_id=7, part="torso", x=10, y=10, w=20, h=30),
        dict(frame=3, track_id=7, part="left_hand", x=0, y=0, w=5, h=5),
        dict(frame=5, track_id=7, part="torso", x=12, y=10, w=20, h=30),
    ])
    starts = init_starts(init)
    assert list(starts) == [7] and starts[7].frame == 3 and set(starts[7].boxes) == {"torso"}
    bad = pd.DataFrame([dict(frame=0, track_id=1, part="person", x=0, y=0, w=1, h=30)])
    with pytest.raises(ValueError, match="too small"):
        init_starts(bad)


def _mean_iou(tracks, truths, part):
    rows = tracks[(tracks.track_id == 1) & (tracks.part == part) & (tracks.frame > 0)]
    return float(np.mean([Box(r.x, r.y, r.w, r.h).iou(truths[r.frame][1][part]) for r in rows.itertuples()]))


def test_reported_boxes_cover_the_parts_not_just_their_inner_rectangles():
    """The filters track inner rectangles; the written boxes are widened to the part's extent
    (``BodyParams.output.extent``), so a user corrects far less. (1, 1, 0, 0) gives the paper's
    inner rectangles back, which overlap the drawn parts much less."""

    frames, truths = _scene(n=30)
    wide = _run(BodyTracker(BodyParams(), np.random.default_rng(1), init=_init(truths[0])), frames)
    inner_params = BodyParams().updated({"output.extent": {}})
    inner = _run(BodyTracker(inner_params, np.random.default_rng(1), init=_init(truths[0])), frames)
    for part in ("head", "torso", "person"):
        assert _mean_iou(wide, truths, part) > _mean_iou(inner, truths, part) + 0.15, part
    assert _mean_iou(wide, truths, "torso") > 0.6
    assert _rate(wide, truths, 1, "torso")[0] >= 0.9
    # the same filters underneath: the centres of the two outputs differ only by the shift
    w = wide[(wide.part == "torso") & (wide.frame == 20)].iloc[0]
    i = inner[(inner.part == "torso") & (inner.frame == 20)].iloc[0]
    assert w.w == pytest.approx(i.w * BodyParams().output.extent["torso"][0], rel=1e-3)


def test_automatic_start_decomposes_the_blob_that_found_the_person():
    # the synthetic walker is found around frame 8, while the background model is young; its
    # parts must come from that foreground blob (colour contrast puts the head across the wall's
    # dark stripe: head rate 0.0-0.3 on these seeds)
    from partlab.labelling.evaluation import evaluate
    from partlab.labelling.synth import make_scene

    rates = []
    for seed in (0, 1, 2):
        sc = make_scene("single", seed=seed, n_frames=60, width=360, height=240)
        tracks = _run(BodyTracker(BodyParams(), np.random.default_rng(0)), list(sc.frames))
        assert tracks.track_id.nunique() == 1 and tracks.frame.min() < 20
        rates.append(evaluate(sc.truth, tracks, hota=False).summary.loc["head", "rate_mean"])
    assert np.mean(rates) >= 0.5


def test_a_person_found_again_has_its_coasted_rows_bridged_by_a_straight_line():
    """``occlusion.bridge``: B walks behind A and coasts; once measured again, the rows written while
    it coasted lie on the straight line from the row before to the row it was found at, for every
    part and the person box. Off, the coasted rows are the dynamics' (a line of another slope)."""
    walkers = (dict(x0=90, vx=1.0, shirt=(40, 140, 40), trousers=(60, 60, 60)),      # B, behind
               dict(x0=170, vx=-1.0, shirt=(40, 40, 160), trousers=(120, 60, 30)))  # A, in front
    frames, truths = _scene(n=80, walkers=walkers)
    runs = {}
    for bridge in (False, True):
        p = BodyParams().updated({"occlusion.bridge": bridge})
        tracker = BodyTracker(p, np.random.default_rng(3), init=_init(truths[0], ids=(1, 2)))
        bgm = BackgroundModel(p)
        records = []
        for i, f in enumerate(frames):
            records.extend(tracker.step(i, f, bgm.apply(f)))
        runs[bridge] = (records_to_frame(tracker.finish(records)), tracker.bridges)
    (plain, none), (bridged, spans) = runs[False], runs[True]
    assert none == [] and spans
    tid, first, found = max(spans, key=lambda s: s[2] - s[1])
    assert tid == 1 and found - first >= 5  # B, behind A for a while
    for part in ("torso", "person"):
        rows = bridged[(bridged.track_id == 1) & (bridged.part == part)].set_index("frame")
        xs = rows.loc[first - 1:found, "x"].to_numpy()
        np.testing.assert_allclose(np.diff(xs, 2), 0.0, atol=1e-6)  # a straight line ...
        old = plain[(plain.track_id == 1) & (plain.part == part)].set_index("frame")
        assert xs[0] == pytest.approx(old.loc[first - 1, "x"])    # ... from the row before
        assert xs[-1] == pytest.approx(old.loc[found, "x"])       # ... to the row it was found at
        assert np.abs(xs - old.loc[first - 1:found, "x"].to_numpy()).max() > 0.5  # not the rows coasted
    # nothing else changes
    inside = np.zeros(len(bridged), bool)
    for t, a, b in spans:
        inside |= ((bridged.track_id == t) & bridged.frame.between(a, b - 1)).to_numpy()
    pd.testing.assert_frame_equal(bridged[~inside], plain[~inside])


def _at_the_edge(exit_margin: float, vx: float, vy: float = 0.0):
    """A tracker whose --init walker stands at the right border with velocity ``(vx, vy)`` and has just
    had no foreground support for ``lost_frames`` frames, after the background warm-up."""
    frames, truths = _scene(n=1, walkers=(dict(x0=300, vx=0.0, shirt=(40, 40, 160), trousers=(120, 60, 30)),))
    p = BodyParams().updated({"detection.exit_margin": exit_margin})
    tracker = BodyTracker(p, np.random.default_rng(0), init=_init(truths[0]))
    tracker.step(0, frames[0], None)
    person = tracker.people[1]
    for f in person.filters.values():
        f.set_velocity(np.array([vx, vy]))
    tracker.frames_seen = p.background.warmup + 1
    person.unsupported = p.detection.lost_frames - 1
    tracker._end_tracks([person], np.zeros((H, W), np.uint8), W, H, index=100)
    return tracker


def test_a_track_lost_at_the_frame_edge_moving_out_has_walked_out():
    """``detection.exit_margin``: lost at the border while moving towards it, the track ends and its
    rows since its support went are withdrawn; moving inwards (or with the margin 0) it goes lost
    and coasts as before."""
    lost_frames = BodyParams().detection.lost_frames
    out = _at_the_edge(0.25, vx=2.0)
    assert 1 not in out.people and out.withdrawn == [(1, 100 - lost_frames + 1)]
    for tracker in (_at_the_edge(0.25, vx=-2.0), _at_the_edge(0.0, vx=2.0)):
        assert tracker.people[1].lost_since == 100 - lost_frames + 1 and tracker.withdrawn == []


def test_a_track_lost_while_walking_along_the_frame_edge_has_not_walked_out():
    """Walking along the border (here down the right edge, a little outwards) is not walking out of
    the frame: the track goes lost and coasts; standing still there, it has walked out as before."""
    lost_frames = BodyParams().detection.lost_frames
    along = _at_the_edge(0.25, vx=0.5, vy=4.0)
    assert along.people[1].lost_since == 100 - lost_frames + 1 and along.withdrawn == []
    still = _at_the_edge(0.25, vx=0.0, vy=0.0)
    assert 1 not in still.people and still.withdrawn == [(1, 100 - lost_frames + 1)]


def test_a_track_that_was_at_the_edge_moving_out_before_its_support_went_has_walked_out():
    """``detection.exit_window``: the box was at the right border moving out on a supported frame,
    then bounced back inwards (its velocity points away from the border) as its support went: it
    has walked out all the same. With the window 0 only the last frame counts, and it goes lost."""
    lost_frames = BodyParams().detection.lost_frames
    frames, truths = _scene(n=1, walkers=(dict(x0=300, vx=0.0, shirt=(40, 40, 160), trousers=(120, 60, 30)),))
    for window in (10, 0):
        p = BodyParams().updated({"detection.exit_window": window})
        tracker = BodyTracker(p, np.random.default_rng(0), init=_init(truths[0]))
        tracker.step(0, frames[0], None)
        person = tracker.people[1]
        tracker.frames_seen = p.background.warmup + 1
        for f in person.filters.values():
            f.set_velocity(np.array([2.0, 0.0]))  # at the border, walking out, still supported
        tracker._end_tracks([person], np.full((H, W), 255, np.uint8), W, H, index=90)
        assert 1 in tracker.people and person.unsupported == 0
        for f in person.filters.values():
            f.set_velocity(np.array([-2.0, 0.0]))  # the box bounces back inwards
        person.unsupported = lost_frames - 1
        tracker._end_tracks([person], np.zeros((H, W), np.uint8), W, H, index=100)
        if window:
            assert 1 not in tracker.people and tracker.withdrawn == [(1, 100 - lost_frames + 1)]
        else:
            assert tracker.people[1].lost_since == 100 - lost_frames + 1 and tracker.withdrawn == []


def test_the_person_box_sides_without_the_head():
    """``output.head_sets_sides`` False: a head box sticking out sideways beyond the body does not
    widen the person row (its left and right come from torso and hip-leg); its top still comes from
    the head. True: the paper's MBR of the three parts."""
    frames, truths = _scene(n=1)
    rows = {}
    for sides in (True, False):
        p = BodyParams().updated({"output.head_sets_sides": sides})
        tracker = BodyTracker(p, np.random.default_rng(1), init=_init(truths[0]))
        tracker.step(0, frames[0], None)
        tracker.people[1].filters["head"].shift(np.array([-25.0, 0.0]))  # 25 px left of the body
        rows[sides] = records_to_frame(tracker._records(1, set())).set_index("part")
    for sides, at in rows.items():
        body = at.loc[["torso", "hipleg"]]
        left = at.loc["head", "x"] if sides else body["x"].min()
        assert at.loc["head", "x"] < body["x"].min() - 10
        assert at.loc["person", "x"] == pytest.approx(left)
        assert at.loc["person", "x"] + at.loc["person", "w"] == pytest.approx((body["x"] + body["w"]).max())
        assert at.loc["person", "y"] == pytest.approx(at.loc["head", "y"])


def test_a_track_started_from_a_drawn_box_writes_that_box_on_its_first_frame():
    """The box a person drew (--init) is the proposal on its own frame, to the pixel; later frames
    are the tracker's (the decomposed parts' box). Automatic starts write the tracker's box."""
    frames, truths = _scene(n=6)
    drawn = truths[0][1]["person"]
    given = Box(drawn.x - 3, drawn.y - 2, drawn.w + 9, drawn.h + 4)  # a loose box, as people draw
    init = pd.DataFrame([dict(frame=0, track_id=1, part="person", x=given.x, y=given.y, w=given.w, h=given.h)])
    tracks = _run(BodyTracker(BodyParams(), np.random.default_rng(0), init=init), frames)
    person = tracks[(tracks.track_id == 1) & (tracks.part == "person")].set_index("frame")
    assert tuple(person.loc[0, ["x", "y", "w", "h"]]) == pytest.approx(given.as_tuple())
    assert person.loc[0, "state"] == "init"
    later = Box(*person.loc[1, ["x", "y", "w", "h"]])
    assert later.w < given.w - 4  # the tracker's own box from the next frame on


def test_a_person_is_put_behind_another_only_when_their_similarities_differ_beyond_their_jitter():
    """Sec. 4.3.1: of two touching persons the one whose touching parts match their models worse
    is behind and coasts. A part's similarity to its own model moves by itself from frame to frame
    (PETS09 from the first boxes, seeds 1-8: by 0.01 at the median, 0.022 at the 75th percentile,
    0.073 at the 95th), so a difference of 0.04 says nothing about who is in front: with
    ``occlusion.margin`` 0.08 both stay measured, with 0.02 (before) the lower one coasts. A
    difference of 0.16 puts it behind either way."""
    from partlab.tracking.core.histogram import to_ycc as ycc_of

    frame = np.full((H, W, 3), 90, np.uint8)
    frame[50:160, 100:130] = (40, 40, 160)
    frame[50:160, 112:142] = (40, 140, 40)
    ycc = ycc_of(frame)
    behind = {}
    for margin in (0.02, "default"):
        params = BodyParams() if margin == "default" else BodyParams().updated({"occlusion.margin": margin})
        for low in (0.92, 0.80):
            t = BodyTracker(params, np.random.default_rng(0), init=[])
            a = t.start_track(1, {"person": Box(100, 50, 30, 110)}, ycc, None, 0)
            b = t.start_track(2, {"person": Box(112, 50, 30, 110)}, ycc, None, 0)
            for person, score in ((a, 0.96), (b, low)):
                person.scores = {n: score for n in person.filters}
                person.prev = {n: f.state.copy() for n, f in person.filters.items()}
            t._resolve_inter_person_occlusion([a, b])
            assert a.touching and b.touching
            behind[margin, low] = (a.occluded_by, b.occluded_by)
    assert behind[0.02, 0.92] == (None, 1)  # 0.04 apart: the old margin hides track 2
    assert behind["default", 0.92] == (None, None)  # within the jitter: nobody is hidden yet
    assert behind[0.02, 0.80] == behind["default", 0.80] == (None, 1)


def test_a_track_just_released_from_yielding_is_behind_the_measured_track_it_touches():
    """``detector.released_behind``: track 2 went lost on track 1's person (the first models said
    so, ``lost_yields``) and its torso probe has just ended that loss; its scores (0.99) are those
    of its last measured frame, track 1's (0.86) of this frame, just after it claimed its person
    back. Without the option the stale scores put track 1 behind track 2 (PETS09 seed 1, frame 43:
    track 1 then coasts off its person and track 2 keeps it); with it track 2 is the one behind.
    A track still lost (yielding or not) is judged by its scores either way."""
    from partlab.tracking.core.histogram import to_ycc as ycc_of

    frame = np.full((H, W, 3), 90, np.uint8)
    frame[50:160, 100:130] = (40, 40, 160)
    frame[50:160, 112:142] = (40, 140, 40)
    ycc = ycc_of(frame)
    behind = {}
    for on in (True, False):
        params = BodyParams().updated({"detector.released_behind": on})
        for state in ("released", "yielding", "lost"):
            t = BodyTracker(params, np.random.default_rng(0), init=[])
            a = t.start_track(1, {"person": Box(100, 50, 30, 110)}, ycc, None, 0)
            b = t.start_track(2, {"person": Box(112, 50, 30, 110)}, ycc, None, 0)
            for person, score in ((a, 0.86), (b, 0.99)):
                person.scores = {n: score for n in person.filters}
                person.prev = {n: f.state.copy() for n, f in person.filters.items()}
            a.observed = {n: None for n in a.filters}  # track 1 measured this frame, track 2 not
            if state == "released":
                b.yields_from, b.released = 40, True
            elif state == "yielding":
                b.lost_since = b.yields_from = 40
            else:
                b.lost_since = 40
            t._resolve_inter_person_occlusion([a, b])
            behind[on, state] = (a.occluded_by, b.occluded_by)
    assert behind[True, "released"] == (None, 1)
    assert behind[False, "released"] == (2, None)
    for state in ("yielding", "lost"):
        assert behind[True, state] == behind[False, state] == (2, None)


def test_a_track_started_standing_takes_its_walkers_speed_and_does_not_lag_onto_the_one_behind():
    """``dynamics.start_velocity_frames``: two walkers in the same coat start overlapping, the front
    one (track 2) walking left at 5 px a frame, the one behind at 2 (PETS09 persons 3 and 4 at frame
    528). Both tracks start standing. Without the option the front track's velocity is still about
    -1 px a frame after 8 frames: it lags onto the slower walker (rate on its own walker 0.38-0.88
    on these seeds, on the other one 0.4-0.95); with it the velocity is about -4 by frame 4 and the
    track stays on its walker."""
    walkers = (dict(x0=250, vx=-2.0, shirt=(40, 40, 150), trousers=(60, 60, 60)),   # behind, slow
               dict(x0=262, vx=-5.0, shirt=(40, 40, 150), trousers=(60, 60, 60)))   # in front, fast
    frames, truths = _scene(n=40, walkers=walkers)
    for frames_on, seeds in ((0, (1,)), (12, (0, 1, 3))):
        params = BodyParams().updated({"dynamics.start_velocity_frames": frames_on})
        for seed in seeds:
            tracker = BodyTracker(params, np.random.default_rng(seed), init=_init(truths[0], ids=(1, 2)))
            bgm = BackgroundModel(params)
            out, vx = [], []
            for i, f in enumerate(frames):
                out.extend(tracker.step(i, f, bgm.apply(f)))
                if i in (4, 8):
                    vx.append(float(tracker.people[2].filters["torso"].state[4]))
            tracks = records_to_frame(out)
            own, other = (_rate(tracks, truths, 2, "person", k)[0] for k in (2, 1))
            if frames_on == 0:  # standing start: the particles learn the speed through their noise only
                assert all(-2.0 < v < 0.0 for v in vx), vx
                assert own < 0.5 and other > 0.9, (own, other)
            else:
                assert all(-5.5 < v < -3.0 for v in vx), (seed, vx)
                assert own >= 0.95 and other < 0.5, (seed, own, other)


def _cut_by_the_edge(vx: float, vy: float, along: bool = True):
    """The --init walker moved 16 px right, so that its person box is cut by the right border,
    moving at ``(vx, vy)`` and judged once with ``leave_fraction`` 0.1 above the share of its box
    in view: ``(that share, the tracker)``."""
    frames, truths = _scene(n=1, walkers=(dict(x0=300, vx=0.0, shirt=(40, 40, 160), trousers=(120, 60, 30)),))
    out = []
    for fraction in (0.5, None):
        p = BodyParams().updated({"detection.leave_fraction": fraction or out[0] + 0.1,
                                  "detection.leave_along": along})
        tracker = BodyTracker(p, np.random.default_rng(0), init=_init(truths[0]))
        tracker.step(0, frames[0], None)
        for f in tracker.people[1].filters.values():
            f.state[0] += 16.0
            f.set_velocity(np.array([vx, vy]))
        out.append(_overlap_fraction(tracker.people[1].box(), Box(0, 0, W, H)))
    tracker._end_tracks([tracker.people[1]], np.full((H, W), 255, np.uint8), W, H, index=10)
    return out[0], tracker


def test_a_track_cut_by_the_edge_it_walks_along_does_not_end():
    """``detection.leave_along``: a box with less than ``leave_fraction`` in view ends, unless its
    person walks along the border that cuts it (here down the right edge) or back in; moving out,
    standing, or with the rule off, it ends as before."""
    inside, _ = _cut_by_the_edge(0.0, 0.0)
    assert 0.6 < inside < 0.9  # the walker's box is cut by the right border
    for vx, vy in ((0.5, 4.0), (-2.0, 0.0)):  # down the edge; back into the frame
        assert 1 in _cut_by_the_edge(vx, vy)[1].people
    for vx, vy, along in ((2.0, 0.0, True), (0.0, 0.0, True), (0.5, 4.0, False)):
        assert 1 not in _cut_by_the_edge(vx, vy, along)[1].people
