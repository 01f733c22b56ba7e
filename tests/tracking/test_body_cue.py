"""Detection as a cue for the body tracker: HOG on regions, Hungarian association, tracks started
by confirmed detections and ended when their person leaves."""

import numpy as np
import pytest

from partlab.labelling.synth import make_scene
from partlab.labelling.synth import scenarios as S
from partlab.labelling.synth.motion import walk
from partlab.tracking.body.tracker import BodyTracker
from partlab.tracking.core.box import iou_xywh
from partlab.tracking.core.people import associate, associate_near
from partlab.tracking.params import BodyParams
from tests.tracking.test_body import _run


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
