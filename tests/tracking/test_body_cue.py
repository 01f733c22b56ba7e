"""Detection as a cue for the body tracker: HOG on regions, Hungarian association, tracks started
by confirmed detections and ended when their person leaves."""

import numpy as np
import pytest

from partlab.labelling.synth import make_scene
from partlab.labelling.synth import scenarios as S
from partlab.labelling.synth.motion import walk
from partlab.tracking.body.tracker import BodyTracker
from partlab.tracking.core.background import BackgroundModel
from partlab.tracking.core.box import iou_xywh
from partlab.tracking.core.people import associate, associate_near
from partlab.tracking.params import BodyParams
from partlab.tracking.tracks import records_to_frame
from tests.tracking.test_body import _init, _rate, _run, _scene


def _crossing(rng, camera, n_frames, fps):
    """One walker entering on the left at 9 m, crossing the room and leaving on the right."""
    (app,) = S.sample_appearances(rng, 1)
    return S.Script([S.Actor(app, walk(camera, n_frames, [(0.0, -1.3, 9.0), (1.0, 1.3, 9.0)], app.height_m))])


def test_hungarian_association_prefers_the_total_overlap_and_gates_by_iou():
    tracks = np.array([[0, 0, 10, 20], [2.5, 0, 10, 20], [100, 100, 10, 20]], float)
    dets = np.array([[1, 0, 10, 20], [-2, 0, 10, 20], [300, 0, 10, 20]], float)
    # greedily, track 0 would take detection 0 (IoU 0.82) and leave track 1 detection 1 (0.38);
    # the assignment maximises the total: track 0 -> detection 1 (0.67), track 1 -> detection 0 (0.74)
    assert sorted(associate(tracks, dets, 0.3)) == [(0, 1), (1, 0)]
    assert associate(tracks, dets, 0.7) == [(1, 0)]
    assert associate(tracks, dets, 0.9) == []
    # centres 0.25 heights apart pair up; a box twice the height does not
    near = associate_near(np.array([[0, 0, 10, 40], [50, 0, 10, 20]], float),
                          np.array([[10, 0, 10, 40], [50, 0, 10, 40]], float), 0.5)
    assert near == [(0, 0)]


def test_colour_affinity_gates_and_weighs_the_assignment():
    # two walkers side by side: both detections overlap both tracks; by IoU alone track 0 takes
    # detection 0, but detection 0 looks like track 1 (affinity 0.9) and detection 1 like track 0
    tracks = np.array([[0, 0, 10, 20], [4, 0, 10, 20]], float)
    dets = np.array([[1, 0, 10, 20], [3, 0, 10, 20]], float)
    assert sorted(associate(tracks, dets, 0.3)) == [(0, 0), (1, 1)]
    aff = np.array([[0.2, 0.9], [0.9, 0.2]])
    assert sorted(associate(tracks, dets, 0.3, aff, 0.0, 1.0)) == [(0, 1), (1, 0)]
    # gated: pairs below the minimum similarity are never made, even if nothing else is left
    assert associate(tracks, dets[:1], 0.3, aff[:, :1], 0.5, 0.0) == [(1, 0)]
    assert associate(tracks[:1], dets[:1], 0.3, aff[:1, :1], 0.5, 0.0) == []
    # NaN affinity (not computed) never pairs when gating
    assert associate(tracks[:1], dets[:1], 0.3, np.array([[np.nan]]), 0.1, 0.0) == []


def test_the_detection_cue_starts_a_track_on_a_person_entering_and_ends_it_on_leaving(monkeypatch):
    monkeypatch.setitem(S.BUILDERS, "single", _crossing)
    params = BodyParams().updated({"detector.blob_starts": False})  # only detections start tracks
    starts, ends, ious = [], [], []
    for seed in (0, 1):
        sc = make_scene("single", seed=seed, n_frames=90, width=640, height=480)
        truth = sc.truth[sc.truth["part"] == "person"]
        inside = truth[(truth.x > 2) & (truth.x + truth.w < 638)]
        tracks = _run(BodyTracker(params, np.random.default_rng(0)), list(sc.frames))
        person = tracks[tracks["part"] == "person"]
        assert person["track_id"].nunique() == 1  # one person, one track, no duplicate
        starts.append(person.frame.min() - inside.frame.min())
        ends.append(person.frame.max() - inside.frame.max())
        both = person.merge(truth, on="frame", suffixes=("", "_t"))
        ious.append(np.mean([iou_xywh(np.array([[r.x, r.y, r.w, r.h]]), np.array([[r.x_t, r.y_t, r.w_t, r.h_t]]))[0, 0]
                             for r in both.itertuples()]))
    # wholly in view at frame ~15, seen by the detector in about half the scans: started within
    # 10 frames (seed 0: 6, seed 1: 3), and ended within 4 frames of leaving the view
    assert max(starts) <= 10 and min(starts) >= 0
    assert all(0 <= e <= 4 for e in ends)
    assert np.mean(ious) >= 0.55


def test_without_the_detector_or_blobs_nobody_starts(monkeypatch):
    """The track above comes from the detector: with neither cue no track starts at all."""
    monkeypatch.setitem(S.BUILDERS, "single", _crossing)
    sc = make_scene("single", seed=0, n_frames=45, width=640, height=480)
    p = BodyParams().updated({"detector.blob_starts": False, "detector.min_score": 50.0})
    assert _run(BodyTracker(p, np.random.default_rng(0)), list(sc.frames)).empty


def test_detector_parameters_are_checked():
    with pytest.raises(ValueError, match="detector.confirm_hits"):
        BodyParams().updated({"detector.confirm_hits": 4, "detector.confirm_window": 3})
    with pytest.raises(ValueError, match="detector.scale_step"):
        BodyParams().updated({"detector.scale_step": 1.0})


class _OnePersonHOG:
    """Stands in for OpenCV's HOG on a frame holding one person ``height`` px tall centred at
    ``centre``: like ``detectMultiScale`` it only tries windows of 128 px and up in the image it
    gets (a pyramid from scale 1), and answers with the smallest window that holds the person's
    body (three quarters of the window's height), scored higher the better it fits. ``crops``:
    (x0, y0, f) of each call, recorded by the test."""

    def __init__(self, centre, height, crops):
        self.centre, self.height, self.crops = np.asarray(centre, float), height, crops

    def detectMultiScale(self, img, winStride, padding, scale):
        x0, y0, f = self.crops[-1]
        body = self.height * f  # the person's height in the resized crop
        win_h = max(128.0, body / 0.75)
        cx, cy = (self.centre - (x0, y0)) * f
        return np.array([[cx - win_h / 4, cy - win_h / 2, win_h / 2, win_h]]), np.array([[2 * body / 0.75 / win_h]])


def test_a_person_smaller_than_the_track_region_is_found_at_their_size(monkeypatch):
    """A walker going away inside a track's box grown with them: the region scan's smallest window
    is larger than the person; the finer scan around it finds the window that fits."""
    from partlab.tracking.core.box import Box
    from partlab.tracking.core.people import PeopleDetector

    frame = np.zeros((240, 360, 3), np.uint8)
    region = Box(100, 80, 30, 64)  # the track's box; the person is 40 px tall inside it
    found = {}
    for finer in (1.0, 0.7):
        det = PeopleDetector(BodyParams().updated({"detector.finer": finer}).detector.scan())
        crops = []
        real_scan = det._scan

        def scan(frame, crop, f, real_scan=real_scan, crops=crops):
            crops.append((int(crop.x), int(crop.y), f))
            return real_scan(frame, crop, f)

        monkeypatch.setattr(det, "_scan", scan)
        det.hog = _OnePersonHOG((115, 112), 40.0, crops)
        found[finer] = det.detect(frame, [region])
        assert len(found[finer]) == 1
        assert len(crops) == (1 if finer == 1 else 2)
    # region 64 px tall: at fill 1.2 the smallest window holds a body of 64 / 1.2 = 53 px
    assert found[1.0][0, 3] == pytest.approx(64 / 1.2, rel=0.02)
    x, y, w, h, _ = found[0.7][0]
    assert h == pytest.approx(40, rel=0.02)
    assert (x + w / 2, y + h / 2) == pytest.approx((115, 112), abs=1.5)


def test_steering_keeps_the_parts_near_their_proportions_at_the_first_detection():
    """A hip-leg box grown below the feet (over a dark road) is brought back within
    ``layout_tolerance`` of its share of the person at the track's first detection when a later
    detection steers the track; without the tolerance it keeps most of its grown height."""
    import cv2

    from partlab.tracking.core.box import Box

    frame = np.full((240, 320, 3), 90, np.uint8)
    frame[60:160, 140:170] = (40, 60, 200)
    frame = cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb)
    start = {"head": Box(148, 60, 14, 14), "torso": Box(142, 75, 26, 35), "hipleg": Box(143, 110, 24, 50)}
    grown = {}
    for tolerance in (0.0, 1.25):
        params = BodyParams().updated({"detector.layout_tolerance": tolerance})
        t = BodyTracker(params, np.random.default_rng(0))
        person = t.start_track(1, dict(start), frame, None, 0)
        hip = person.filters["hipleg"]
        first, det = hip.box, t._reported_person_box(person)  # the detector sees the person as at the start
        t.cue._steer(person, det, det, 1.0)  # the first detection: nothing moves
        assert hip.box.as_tuple() == pytest.approx(first.as_tuple())
        hip.steer(Box(first.x, first.y, first.w, first.h * 2.0), 1.0)  # drifted below the feet
        t.cue._steer(person, t._reported_person_box(person), det, 1.0)
        grown[tolerance] = (hip.box.w / first.w, hip.box.h / first.h)
    assert grown[0.0][1] > 1.4  # shrunk only by the person's height ratio
    assert grown[1.25][1] == pytest.approx(1.25, abs=0.01)
    assert grown[1.25][0] == pytest.approx(grown[0.0][0])  # the width had not drifted


def test_layout_tolerance_is_checked():
    with pytest.raises(ValueError, match="detector.layout_tolerance"):
        BodyParams().updated({"detector.layout_tolerance": 0.8})


def test_the_swap_guard_does_not_steer_a_track_onto_a_detection_its_neighbour_overlaps_as_much():
    """Two walkers side by side (crossing): the one detection lies between them, overlapping both
    tracks about equally; the assignment gives it to one of them. Steered, that track jumps onto the
    other walker (where two people cross, the window may be the other's); with ``swap_guard`` the
    contested detection steers nobody, while one that only its own track overlaps still steers."""
    import cv2

    from partlab.tracking.core.box import Box

    frame = np.full((240, 320, 3), 90, np.uint8)
    frame[60:160, 100:130] = (40, 60, 200)
    frame[60:160, 124:154] = (200, 60, 40)
    ycc = cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb)
    between = np.array([[110.0, 60.0, 30.0, 100.0, 1.0]])  # overlaps both person boxes about equally
    own = np.array([[90.0, 60.0, 30.0, 100.0, 1.0]])  # overlaps track 1 only
    moved = {}
    for guard in (0.0, 0.7):
        for name, dets in (("between", between), ("own", own)):
            t = BodyTracker(BodyParams().updated({"detector.swap_guard": guard}), np.random.default_rng(0))
            t.frame_size = (320, 240)
            for tid, x in ((1, 100), (2, 124)):
                t.start_track(tid, {"person": Box(x, 60, 30, 100)}, ycc, None, 0)
            before = {k: t._reported_person_box(q).centre[0] for k, q in t.people.items()}
            t.cue.detector.detect = lambda frame, regions, dets=dets: dets
            t.cue.step(0, frame, ycc, None)
            moved[guard, name] = {k: t._reported_person_box(q).centre[0] - before[k] for k, q in t.people.items()}
    # without the guard the contested detection pulls one track 8 px or more towards the other walker
    assert max(abs(v) for v in moved[0.0, "between"].values()) > 4
    assert moved[0.7, "between"] == pytest.approx({1: 0.0, 2: 0.0}, abs=1e-6)
    # a detection only its own track overlaps steers with the guard on as without it
    assert moved[0.7, "own"][1] == pytest.approx(moved[0.0, "own"][1])
    assert moved[0.7, "own"][1] < -1


def test_steer_velocity_brings_the_parts_velocity_towards_the_motion_of_the_detections():
    """A walker moving 4 px a frame whose track's filters think it stands still: two detections
    three frames apart show the motion; with a gain of 0.5 every part's velocity goes half of the
    way there, with 0 the detections move the boxes but not the velocity. The gain is
    ``steer_velocity_auto`` in an automatic run and ``steer_velocity`` in a run from given boxes."""
    import cv2

    from partlab.tracking.core.box import Box

    frame = np.full((240, 320, 3), 90, np.uint8)
    frame[60:160, 100:130] = (40, 60, 200)
    ycc = cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb)
    velocity = {}
    runs = {("auto", 0.0): ({"detector.steer_velocity_auto": 0.0}, None),
            ("auto", 0.5): ({"detector.steer_velocity_auto": 0.5}, None),
            ("init", 0.0): ({"detector.steer_velocity": 0.0, "detector.steer_velocity_auto": 0.5}, []),
            ("init", 0.5): ({"detector.steer_velocity": 0.5, "detector.steer_velocity_auto": 0.0}, [])}
    for key, (changes, init) in runs.items():
        t = BodyTracker(BodyParams().updated(changes), np.random.default_rng(0), init=init)
        assert t.auto == (init is None)
        t.frame_size = (320, 240)
        person = t.start_track(1, {"person": Box(100, 60, 30, 100)}, ycc, None, 0)
        det = t._reported_person_box(person)
        for index in (0, 3):  # the cue scans every third frame
            box = np.array([[det.x + 4.0 * index, det.y, det.w, det.h, 1.0]])
            t.cue.detector.detect = lambda frame, regions, box=box: box
            t.cue.step(index, frame, ycc, None)
        velocity[key] = {n: tuple(f.state[4:6]) for n, f in person.filters.items()}
    for mode in ("auto", "init"):
        for name in ("head", "torso", "hipleg"):
            assert velocity[mode, 0.0][name] == pytest.approx((0.0, 0.0), abs=1e-6)
            assert velocity[mode, 0.5][name] == pytest.approx((2.0, 0.0), abs=1e-4)



def test_a_track_re_acquired_standing_learns_its_walkers_speed_again():
    """A track no detection has matched for ``reacquire_after`` frames is re-acquired by a detection
    0.8 of its width ahead (too far to be matched) and put there standing. The walker goes on at
    -4 px a frame: with ``dynamics.relearn_velocity`` the track learns that speed again as a new
    track does (within 6 frames); without, it learns it only through its velocity noise, as on
    PETS09's person 17 (re-acquired at the end of his start, his track stopped
    there and lost him for 130 frames)."""
    import cv2

    from partlab.tracking.core.box import Box

    velocity, behind = {}, {}
    for relearn in (True, False):
        params = BodyParams().updated({"dynamics.relearn_velocity": relearn, "detector.every": 1,
                                       "detection.end_init_tracks": False})
        t = BodyTracker(params, np.random.default_rng(0), init=[])
        t.frame_size = (320, 240)
        x0 = 100.0

        def frame_at(x):
            f = np.full((240, 320, 3), 90, np.uint8)
            f[60:160, int(round(x)):int(round(x)) + 30] = (40, 60, 200)
            f[60:80, int(round(x)) + 8:int(round(x)) + 22] = (90, 140, 200)  # a head
            return f

        first = frame_at(x0)
        person = t.start_track(1, {"person": Box(x0, 60, 30, 100)}, cv2.cvtColor(first, cv2.COLOR_BGR2YCrCb), None, 0)
        det = t._reported_person_box(person)
        jump = 0.8 * det.w
        ahead = Box(det.x + jump, det.y, det.w, det.h)
        t.cue.last_match[1] = 0
        index = params.detector.reacquire_after
        x = x0 + jump
        t.cue.detector.detect = lambda frame, regions, b=ahead: np.array([[b.x, b.y, b.w, b.h, 1.0]])
        t.cue.step(index, frame_at(x), cv2.cvtColor(frame_at(x), cv2.COLOR_BGR2YCrCb), None)
        assert person.filters["torso"].state[0] == pytest.approx(x0 + jump + 15, abs=3)  # re-acquired there
        assert person.filters["torso"].state[4] == pytest.approx(0.0, abs=1e-6)  # standing
        t.cue.detector.detect = lambda frame, regions: np.zeros((0, 5))
        for k in range(1, 7):
            x -= 4.0
            t.step(index + k, frame_at(x), None)
        velocity[relearn] = float(person.filters["torso"].state[4])
        behind[relearn] = float(person.filters["torso"].state[0] - (x + 15))
    # measured: -4.4 with, -1.5 without (its velocity noise alone); on the walker 0.3 px against 2.5 px
    assert velocity[True] <= -3.5
    assert velocity[False] >= -2.5
    assert abs(behind[True]) <= 1.5


def _two_in_dark_jackets(xa: float, xb: float) -> np.ndarray:
    """Two people in the same dark jackets, A in blue jeans and B in grey trousers (BGR)."""
    f = np.full((240, 360, 3), 150, np.uint8)
    for x, legs in ((xa, (170, 100, 40)), (xb, (70, 70, 70))):
        x = int(round(x))
        f[60:78, x + 8:x + 22] = (90, 140, 200)  # head
        f[78:112, x:x + 30] = (35, 35, 40)  # jacket
        f[112:160, x + 2:x + 28] = legs
    return f


def test_of_two_tracks_on_one_person_the_one_given_on_another_person_goes_and_yields():
    """Two walkers in the same dark jackets, one in blue jeans (A), one in grey trousers (B), both
    given by their first boxes. Then both tracks sit on A (where PETS09's persons 9 and 15 met, the
    track of the one was carried onto the other). With ``duplicate_margin`` the track whose first
    models match A worse (B's, by its legs) is the one that goes lost, whoever a detection matched
    last; with 0 the one matched less recently goes (here A's own track). With ``lost_yields`` the
    lost one does not take A's next detection from A's track, even when it overlaps it more."""
    import cv2

    from partlab.tracking.core.box import Box

    first = _two_in_dark_jackets(100, 220)
    later = _two_in_dark_jackets(100, 220)
    ycc0, ycc = cv2.cvtColor(first, cv2.COLOR_BGR2YCrCb), cv2.cvtColor(later, cv2.COLOR_BGR2YCrCb)
    lost, taken, sims = {}, {}, {}
    for margin, yields in ((0.1, True), (0.0, True), (0.1, False)):
        params = BodyParams().updated({"detector.duplicate_margin": margin, "detector.lost_yields": yields})
        t = BodyTracker(params, np.random.default_rng(0), init=[])
        t.frame_size = (360, 240)
        a = t.start_track(1, {"person": Box(100, 60, 30, 100)}, ycc0, None, 0)
        b = t.start_track(2, {"person": Box(220, 60, 30, 100)}, ycc0, None, 0)
        for f in b.filters.values():  # B's track carried onto A, 2 px to the right of A's own
            f.shift(np.array([-118.0, 0.0]))
        for f in a.filters.values():
            f.shift(np.array([-2.0, 0.0]))
        shared = t._reported_person_box(a)
        sims[margin, yields] = (t.cue._first_similarity(a, shared, ycc), t.cue._first_similarity(b, shared, ycc))
        t.cue.last_match.update({1: 0, 2: 3})  # B's track took A's last detection
        t.cue.detector.detect = lambda frame, regions: np.zeros((0, 5))
        t.cue.step(6, later, ycc, None)
        lost[margin, yields] = sorted(k for k, q in t.people.items() if q.lost_since is not None)
        # A's next detection, where B's lost track sits (it overlaps it more than A's own track)
        on_b = t._reported_person_box(b)
        det = np.array([[on_b.x, on_b.y, on_b.w, on_b.h, 1.0]])
        t.cue.detector.detect = lambda frame, regions, det=det: det
        t.cue.step(9, later, ycc, None)
        taken[margin, yields] = (t.cue.last_match[1], t.cue.last_match[2], b.lost_since is not None)
    rho_a, rho_b = sims[0.1, True]
    assert rho_a >= 0.9 and rho_b <= rho_a - 0.2  # measured: 1.00 against 0.50
    assert lost[0.1, True] == [2]
    assert lost[0.0, True] == [1]  # recency: A's own track goes
    # yielding: A's track takes the detection and B's stays lost; without, B's takes it (A's is
    # left unmatched, and after ``reacquire_after`` frames jumps to a free detection elsewhere)
    assert taken[0.1, True] == (9, 3, True)
    assert taken[0.1, False][:2] == (0, 9)


def test_a_track_due_for_re_acquisition_claims_its_persons_detection_from_a_track_given_on_another():
    """The same two people; B's track is carried onto A and holds A's detection, while A's own
    track coasted 35 px to the left and no detection has matched it for ``reacquire_after`` frames.
    With ``reacquire_claims`` A's track, whose first models match the detection at 1.00 against
    B's 0.50, takes it (jumps there) and B's track goes lost; without, there is no free detection
    to re-acquire and B's track keeps A's person."""
    import cv2

    from partlab.tracking.core.box import Box

    first = _two_in_dark_jackets(100, 220)
    ycc0 = cv2.cvtColor(first, cv2.COLOR_BGR2YCrCb)
    out = {}
    for claims in (True, False):
        params = BodyParams().updated({"detector.reacquire_claims": claims})
        t = BodyTracker(params, np.random.default_rng(0), init=[])
        t.frame_size = (360, 240)
        a = t.start_track(1, {"person": Box(100, 60, 30, 100)}, ycc0, None, 0)
        b = t.start_track(2, {"person": Box(220, 60, 30, 100)}, ycc0, None, 0)
        for f in b.filters.values():
            f.shift(np.array([-120.0, 0.0]))
        for f in a.filters.values():
            f.shift(np.array([-35.0, 0.0]))
        on_a = t._reported_person_box(b)
        det = np.array([[on_a.x, on_a.y, on_a.w, on_a.h, 1.0]])
        t.cue.detector.detect = lambda frame, regions, det=det: det
        index = params.detector.reacquire_after
        index += -index % params.detector.every  # a frame the cue scans
        t.cue.last_match.update({1: 0, 2: index - 3})
        t.cue.step(index, first, ycc0, None)
        out[claims] = (t._reported_person_box(a).centre[0] - on_a.centre[0], a.lost_since, b.lost_since)
    dx, a_lost, b_lost = out[True]
    assert abs(dx) < 3 and a_lost is None and b_lost is not None  # A's track on A, B's lost
    dx, a_lost, b_lost = out[False]
    assert dx < -30 and b_lost is None  # A's track left where it coasted, B's on A


def test_a_track_measured_on_its_walker_is_not_re_acquired_by_the_one_following_on_its_path():
    """``reacquire_against``: two walkers in one coat walk left at 5 px a frame, one 42 px behind
    the other (PETS09 persons 3 and 4 from frame 528); only the front one is given. The detector
    never sees the front walker and, from frame 12 on, sees the one behind. The front track,
    measured on its walker but unmatched for ``reacquire_after`` frames, is due for re-acquisition:
    without the option it jumps back onto the walker following it (the detection is free, near and
    of the same colours) and follows him; with it, the detection lies on the path its walker took
    in the last ``reacquire_after`` frames, against its motion, and the track stays."""
    coat = dict(shirt=(40, 40, 150), trousers=(60, 60, 60))
    frames, truths = _scene(n=36, walkers=(dict(x0=220, vx=-5.0, **coat), dict(x0=262, vx=-5.0, **coat)))
    out = {}
    for against in (0.0, 0.5):
        params = BodyParams().updated({"detector.reacquire_against": against})
        for seed in (0, 1):
            tracker = BodyTracker(params, np.random.default_rng(seed), init=_init(truths[0], ids=(1,)))
            now = [0]

            def detect(frame, regions, now=now, after=params.detector.reacquire_after):
                if now[0] < after:
                    return np.zeros((0, 5))
                b = truths[now[0]][2]["person"]
                return np.array([[b.x, b.y, b.w, b.h, 1.0]])

            tracker.cue.detector.detect = detect
            bgm = BackgroundModel(params)
            rows = []
            for i, f in enumerate(frames):
                now[0] = i
                rows.extend(tracker.step(i, f, bgm.apply(f)))
            tracks = records_to_frame(rows)
            out[against, seed] = (_rate(tracks, truths, 1, "person", 1)[0], _rate(tracks, truths, 1, "person", 2)[0])
    for seed in (0, 1):
        own, other = out[0.0, seed]
        # measured 0.33 and 0.67: it jumped onto the walker behind at frame 12 and followed him
        assert own < 0.4 and other > 0.6, (seed, own, other)
        own, other = out[0.5, seed]
        assert own >= 0.95 and other < 0.1, (seed, own, other)  # measured 1.0 and 0.0


def test_of_two_tracks_on_one_walker_the_one_placed_there_later_leaves_the_detection_to_the_other():
    """``reacquire_owner``: two walkers in the same coats, A and B 60 px to its right. Track 2 was
    given on B and ran ahead onto A (last measured clear of everyone at frame 6); track 1 is given
    on A at frame 6 (PETS09 seed 2, frame 528: track 3 given on person 3 where track 4 sat). Both
    sit on A, touching, and no detection has matched either for ``reacquire_after`` frames when the
    detector sees B alone. Without the option the first in id order (track 1) jumps onto B and the
    two swap walkers; with it track 1, placed on A later (a given box ranks before a measurement of
    the same frame), stays and track 2 takes B's detection."""
    import cv2

    from partlab.tracking.core.box import Box

    def two_in_one_coat(xa: float, xb: float) -> np.ndarray:
        f = np.full((240, 360, 3), 150, np.uint8)
        for x in (int(xa), int(xb)):
            f[60:78, x + 8:x + 22] = (90, 140, 200)  # head
            f[78:112, x:x + 30] = (35, 35, 40)  # coat
            f[112:160, x + 2:x + 28] = (170, 100, 40)  # jeans
        return f

    frame = two_in_one_coat(100, 160)
    ycc = cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb)
    on_a, on_b = Box(100, 60, 30, 100), Box(160, 60, 30, 100)
    out = {}
    for owner in (False, True):
        params = BodyParams().updated({"detector.reacquire_owner": owner})
        t = BodyTracker(params, np.random.default_rng(0), init=[])
        t.frame_size = (360, 240)
        b = t.start_track(2, {"person": on_b}, ycc, None, 0)
        b.given = {"person": on_b}
        for f in b.filters.values():  # ran ahead onto A, 2 px to the right of A's own track
            f.shift(np.array([-58.0, 0.0]))
        b.seen = (6, *t._reported_person_box(b).centre)
        a = t.start_track(1, {"person": on_a}, ycc, None, 6)
        a.given = {"person": on_a}
        assert t._touching(a.part_boxes(), b.part_boxes())[0]
        det = np.array([[on_b.x, on_b.y, on_b.w, on_b.h, 1.0]])
        t.cue.detector.detect = lambda frame, regions, det=det: det
        index = 6 + params.detector.reacquire_after
        index += -index % params.detector.every  # a frame the cue scans
        t.cue.step(index, frame, ycc, None)
        out[owner] = (t._reported_person_box(a).centre[0] - on_a.centre[0],
                      t._reported_person_box(b).centre[0] - on_b.centre[0])
    a_off, b_off = out[False]
    assert abs(a_off - 60) < 3 and b_off < -50  # track 1 on B, track 2 left on A: swapped
    a_off, b_off = out[True]
    assert abs(a_off) < 3 and abs(b_off) < 3  # each on its own walker


def test_a_track_re_acquired_onto_another_place_forgets_the_motion_it_had_before_the_jump():
    """``reacquire_forgets``: a track whose clean centres say it walked right at 4 px a frame, due for
    re-acquisition, jumps 60 px left onto a detection. Kept, those centres and the first ones
    after the jump make the jump read as motion (PETS09 seed 8: a track re-acquired, then put
    behind someone, coasted at -13.6 px a frame while its walker walked at -4); with the option its
    person-box velocity starts again from the frames after the jump."""
    import cv2

    from partlab.tracking.core.box import Box

    frame = np.full((240, 360, 3), 150, np.uint8)
    frame[60:78, 108:122] = (90, 140, 200)
    frame[78:112, 100:130] = (35, 35, 40)
    frame[112:160, 102:128] = (170, 100, 40)
    ycc = cv2.cvtColor(frame, cv2.COLOR_BGR2YCrCb)
    out = {}
    for forgets in (False, True):
        params = BodyParams().updated({"detector.reacquire_forgets": forgets})
        t = BodyTracker(params, np.random.default_rng(0), init=[])
        t.frame_size = (360, 240)
        a = t.start_track(1, {"person": Box(100, 60, 30, 100)}, ycc, None, 0)
        for f in a.filters.values():  # it walked right to 160 (its walker is back at 100)
            f.shift(np.array([60.0, 0.0]))
        a.centres.extend((k, 135.0 + 4 * k, 110.0) for k in range(6))
        det = np.array([[100.0, 60.0, 30.0, 100.0, 1.0]])
        t.cue.detector.detect = lambda frame, regions, det=det: det
        index = params.detector.reacquire_after
        index += -index % params.detector.every
        t.cue.step(index, frame, ycc, None)
        assert abs(t._reported_person_box(a).centre[0] - 115) < 3  # jumped onto the detection
        a.centres.append((index + 1, 115.0, 110.0))  # the first clean frame after the jump
        out[forgets] = (len(a.centres), a.velocity())
    n, v = out[False]
    assert n == 7 and v[0] > 3.5  # the walk before the jump, 4 px a frame
    n, v = out[True]
    assert n == 1 and v is None  # starts again: no velocity until three clean frames after the jump
