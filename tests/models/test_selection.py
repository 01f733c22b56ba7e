from dataclasses import replace

import numpy as np
import pytest
from walkers import walking_truth

from partlab.models.selection import mean_rates, part_rates, select_components, selection_table
from partlab.tracking.params import BodyParams

DEFAULT = BodyParams()


def _fake_runner(truths, shift: float = 0.0):
    """A deterministic 'tracker': reports the truth boxes moved right by ``shift`` box widths,
    then moved and scaled by how ``params.output.extent`` differs from the built-in one (as the
    real tracker's output would be); a detector moves nothing."""
    calls = []

    def run(i, params, detector):
        calls.append((i, params, detector))
        t = truths[i].copy()
        if detector == "harmful":  # its adjustments knock every head off
            t.loc[t.part == "head", "x"] += t.loc[t.part == "head", "w"]
        for part, (sw, sh, dx, dy) in params.output.extent.items():
            bw, bh, bdx, bdy = DEFAULT.output.extent[part]
            m = t.part == part
            w, h = t.loc[m, "w"], t.loc[m, "h"]
            cx = t.loc[m, "x"] + w / 2 + shift * w + (dx - bdx) * w
            cy = t.loc[m, "y"] + h / 2 + (dy - bdy) * h
            nw, nh = w * sw / bw, h * sh / bh
            t.loc[m, "x"], t.loc[m, "y"], t.loc[m, "w"], t.loc[m, "h"] = cx - nw / 2, cy - nh / 2, nw, nh
        return t
    return run, calls


def test_part_rates_counts_half_on_and_centre_inside():
    truth = walking_truth(1, 5, seed=0)
    assert part_rates(truth, truth) == {"head": 1.0, "torso": 1.0, "hipleg": 1.0}
    moved = truth.copy()
    head = moved.part == "head"
    moved.loc[head & (moved.frame >= 3), "x"] += moved.loc[head, "w"].max() * 0.6  # centre leaves the box
    r = part_rates(moved, truth)
    assert r["head"] == pytest.approx(2 / 4) and r["torso"] == 1.0  # frames 1..4 scored, 3 and 4 wrong
    assert mean_rates([r, {"head": 1.0, "torso": 0.0, "hipleg": 1.0}])["mean"] == pytest.approx((0.75 + 0.5 + 1) / 3)


def test_selection_drops_a_bad_extent_and_keeps_a_good_one():
    truths = [walking_truth(2, 20, seed=s) for s in (1, 2)]
    hip = DEFAULT.output.extent["hipleg"]
    # (1) fitted extent that triples the hip-leg box: at most a third of it lies on the part
    bad = DEFAULT.updated({"output.extent": {**DEFAULT.output.extent, "hipleg": (hip[0] * 3, hip[1] * 3, 0.0, 0.25)}})
    run, calls = _fake_runner(truths)
    sel = select_components(run, truths, DEFAULT, bad, detector="svm")
    assert sel.kept == {"noise": False, "extent": False, "detector": True}
    assert sel.body_params.output.extent == DEFAULT.output.extent and sel.failure_detector == "svm"
    assert sel.scores["builtin"]["mean"] == 1.0 and sel.scores["+extent"]["hipleg"] == 0.0
    assert sel.scores["+detector"]["mean"] == 1.0  # a tie: the detector did no harm, so it stays
    assert len(calls) == 3 * 2  # built-in, +extent, +detector (noise not fitted: no run)
    # (2) the tracker reports every box 0.6 widths to the right: all centres off the part;
    # a fitted extent that shifts them back is kept, a detector that moves nothing stays (no harm)
    good = DEFAULT.updated({"output.extent": {p: (sw, sh, dx - 0.6, dy) for p, (sw, sh, dx, dy)
                                              in DEFAULT.output.extent.items()}})
    run, calls = _fake_runner(truths, shift=0.6)
    base_tracks = [run(i, DEFAULT, None) for i in range(2)]
    sel = select_components(run, truths, DEFAULT, good, detector="svm", base_tracks=base_tracks)
    assert sel.scores["builtin"]["mean"] == 0.0 and sel.scores["+extent"]["mean"] == 1.0
    assert sel.kept == {"noise": False, "extent": True, "detector": True}
    assert sel.body_params.output.extent["head"][2] == pytest.approx(-0.6)
    assert len(calls) == 2 + 2 * 2  # the base tracks were given: built-in not re-run
    text = selection_table(sel.to_dict())
    assert "kept" in text and "not fitted" in text and "dropped" not in text


def test_a_detector_that_lowers_the_rate_is_dropped():
    truths = [walking_truth(1, 10, seed=2)]
    run, _ = _fake_runner(truths)
    sel = select_components(run, truths, DEFAULT, DEFAULT, detector="harmful")
    assert sel.kept["detector"] is False and sel.failure_detector is None
    assert sel.scores["+detector"]["head"] == 0.0 and sel.scores["builtin"]["mean"] == 1.0


def test_training_from_a_bundle_keeps_its_detector_unless_the_new_one_does_no_harm():
    truths = [walking_truth(1, 10, seed=2)]
    run, calls = _fake_runner(truths)
    # the new detector knocks heads off: the start bundle's detector stays
    sel = select_components(run, truths, DEFAULT, DEFAULT, detector="harmful", base_detector="shipped")
    assert sel.failure_detector == "shipped" and sel.kept["detector"] is False
    assert calls[0][2] == "shipped"  # the baseline was tracked with the start's detector
    # a harmless new detector replaces it (it was trained on the user's own corrections)
    sel = select_components(run, truths, DEFAULT, DEFAULT, detector="svm", base_detector="shipped")
    assert sel.failure_detector == "svm" and sel.kept["detector"] is True
    # and a detector the baseline would have ruined its baseline score with is measured as such
    sel = select_components(run, truths, DEFAULT, DEFAULT, detector="svm", base_detector="harmful")
    assert sel.scores["builtin"]["head"] == 0.0 and sel.failure_detector == "svm"
    assert "start (with its detector)" in selection_table({**sel.to_dict(), "start_detector": True})


def test_noise_is_tried_first_and_kept_params_carry_on():
    truths = [walking_truth(1, 10, seed=3)]
    noisy = DEFAULT.updated({"dynamics.noise": {**DEFAULT.dynamics.noise,
                                                "head": replace(DEFAULT.dynamics.noise["head"], lam=35.0)}})
    run, calls = _fake_runner(truths)
    sel = select_components(run, truths, DEFAULT, noisy)
    # the fake tracker ignores the noise: a tie, so the built-in noise stays
    assert sel.kept["noise"] is False
    assert sel.body_params.dynamics.noise["head"].lam == DEFAULT.dynamics.noise["head"].lam
    assert np.isclose(sel.scores["+noise"]["mean"], 1.0) and "+extent" not in sel.scores


def test_noise_that_helps_one_part_and_hurts_another_is_kept_for_the_part_it_helps():
    truths = [walking_truth(1, 10, seed=4)]
    fitted = DEFAULT.updated({"dynamics.noise": {**DEFAULT.dynamics.noise,
                                                 "head": replace(DEFAULT.dynamics.noise["head"], lam=35.0),
                                                 "hipleg": replace(DEFAULT.dynamics.noise["hipleg"], lam=36.0)}})

    def run(i, params, detector):  # fitted head noise knocks heads off, built-in hip-leg noise hip-legs
        t = truths[i].copy()
        if params.dynamics.noise["head"].lam == 35.0:
            t.loc[t.part == "head", "x"] += t.loc[t.part == "head", "w"]
        if params.dynamics.noise["hipleg"].lam != 36.0:
            t.loc[t.part == "hipleg", "x"] += t.loc[t.part == "hipleg", "w"]
        return t

    sel = select_components(run, truths, DEFAULT, fitted)
    assert sel.kept["noise"] is True and sel.scores["+noise(hipleg)"]["mean"] == 1.0
    assert sel.body_params.dynamics.noise["hipleg"].lam == 36.0
    assert sel.body_params.dynamics.noise["head"].lam == DEFAULT.dynamics.noise["head"].lam
    text = selection_table(sel.to_dict())
    assert [line.split()[-1] for line in text.splitlines()[1:3]] == ["baseline", "dropped"]
    assert "+noise(hipleg)" in text.splitlines()[3] and text.splitlines()[3].split()[-1] == "kept"


def _inner_rect_runner(truths):
    """A deterministic 'tracker' for :func:`partlab.models.training.train_bundle`: its inner rectangle is the
    true box moved right by 0.3 of its width, reported through ``params.output.extent``; with the
    built-in extent the boxes are too large and off-centre (under half of them on the part)."""
    def rows(df):
        return set(zip(df["frame"], df["track_id"], df["part"], df["x"].round(3)))

    def run(frames, fps, init, seed, params=None, failure_detector=None):
        # which clip: the one whose truth holds the boxes it starts from (training hands the runner its
        # own frames), tracked from the first of them (validation runs start at the holdout's cut)
        params = params or BodyParams()
        g = next(g for _f, g in truths if rows(init) <= rows(g))
        t = g[g["frame"] >= init["frame"].min()].copy()
        for part, (sw, sh, dx, dy) in params.output.extent.items():
            m = t.part == part
            w, h = t.loc[m, "w"], t.loc[m, "h"]
            cx, cy = t.loc[m, "x"] + w / 2 + 0.3 * w + dx * w, t.loc[m, "y"] + h / 2 + dy * h
            t.loc[m, "x"], t.loc[m, "y"] = cx - sw * w / 2, cy - sh * h / 2
            t.loc[m, "w"], t.loc[m, "h"] = sw * w, sh * h
        t["source"] = "tracker"
        return t
    return run


def test_train_bundle_validates_on_the_training_clips_and_records_it():
    from partlab.models.training import iterate_frames, train_bundle

    truths = [walking_truth(2, 30, seed=s) for s in (4, 5)]
    clips = [(iterate_frames(np.zeros((30, 8, 8, 3), np.uint8)), 25.0, t) for t in truths]
    runner = _inner_rect_runner([(c[0], t) for c, t in zip(clips, truths)])
    b = train_bundle(clips, seed=0, tracker_runner=runner, perturbed_per_person=100, fit_sharpness=False)
    sel = b.summary["selection"]
    assert sel["kept"] == {"noise": False, "extent": True, "detector": False}  # no SVM could be fitted
    assert sel["scores"]["builtin"]["mean"] == 0.0 and sel["scores"]["+extent"]["mean"] == 1.0
    for part in ("head", "torso", "hipleg"):
        assert b.body_params.output.extent[part] == pytest.approx((1.0, 1.0, -0.3, 0.0), abs=1e-3)
    assert b.body_params.dynamics.noise == DEFAULT.dynamics.noise and b.failure_detector is None
    assert "svms" in b.summary
