import json

import motmetrics as mm
import numpy as np
import pandas as pd
import pytest

from partlab.labelling.evaluation import (
    EvaluationError,
    box_correct,
    evaluate,
    iou_distance,
    match_tracks,
    rate_curve_figure,
)
from partlab.tracking.tracks import normalise_tracks


def tracks(rows):
    return normalise_tracks(pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h"]))


def test_box_correct_on_hand_made_boxes():
    truth = [0, 0, 10, 10]
    cases = {
        (0, 0, 10, 10): True,  # the same box
        (5, 0, 10, 10): True,  # exactly half on the truth, centre on its edge
        (6, 0, 10, 10): False,  # 40 % on the truth
        (-5, -5, 20, 20): False,  # covers the truth but only a quarter of it lies on it
        (2, 2, 4, 4): True,  # small box inside
        (0, 0, 0, 0): False,  # empty box
        (np.nan, 0, 10, 10): False,  # no tracked box
    }
    got = box_correct(np.array(list(cases), float), np.array([truth] * len(cases), float))
    assert got.tolist() == list(cases.values())


def _two_people():
    """A is initialised at frame 0 (frames 0..3), B at frame 2 (frames 2..4), head only."""
    truth = [(f, 1, "head", 10 * f, 0, 10, 10) for f in range(4)] + \
            [(f, 2, "head", 100, 50, 10, 10) for f in range(2, 5)]
    tr = [(0, 1, "head", 0, 0, 10, 10), (1, 1, "head", 12, 0, 10, 10),  # right, right (80 %)
          (2, 1, "head", 27, 0, 10, 10), (3, 1, "head", 60, 0, 10, 10),  # wrong (30 %), wrong
          (2, 2, "head", 100, 50, 10, 10), (4, 2, "head", 101, 51, 10, 10)]  # right, missing, right
    return tracks(truth), tracks(tr)


def test_tracking_rate_by_frame_offset_known_by_hand():
    truth, tr = _two_people()
    r = evaluate(truth, tr, at=1, hota=False)
    assert r.matching == "track_id"
    assert r.rates["head"].tolist() == [1.0, 0.5, 0.5, 0.0]  # offsets 0..3
    assert r.counts["head"].tolist() == [2, 2, 2, 1]
    assert r.summary.loc["head", "rate_at"] == 0.5
    assert r.summary.loc["head", "rate_mean"] == pytest.approx(1 / 3)  # offsets 1..3: the initialisation is not scored
    # IoU: 1, 8/12, 3/17, 0 for A; 1, 0, 81/119 for B
    assert r.summary.loc["head", "mean_iou"] == pytest.approx((1 + 8 / 12 + 3 / 17 + 1 + 81 / 119) / 7)
    assert r.summary.loc["head", "rate_at"] == r.rate_at("head")
    assert list(r.rates.columns) == ["head"]  # no body parts, no person box: no person_mbr


def test_person_mbr_rate_uses_the_rectangle_around_the_three_parts():
    body = {"head": (4, 0, 4, 4), "torso": (2, 4, 8, 8), "hipleg": (2, 12, 8, 10)}  # MBR (2, 0, 8, 22)
    truth = tracks([(0, 0, p, *b) for p, b in body.items()] + [(1, 0, p, *b) for p, b in body.items()])
    shifted = {"head": (4, 0, 4, 4), "torso": (2, 4, 8, 8), "hipleg": (2, 12, 8, 40)}  # MBR (2, 0, 8, 52)
    tr = tracks([(0, 0, p, *b) for p, b in body.items()] + [(1, 0, p, *b) for p, b in shifted.items()])
    r = evaluate(truth, tr, at=1, hota=False)
    assert r.rates["person_mbr"].tolist() == [1.0, 0.0]  # 22/52 of the tracked MBR on the true one
    assert r.rates["hipleg"].tolist() == [1.0, 0.0]  # 10/40 of the tracked hip-leg on the truth
    # a tracked MBR 8 x 42 would still be right: 22/42 >= 1/2 and its centre (6, 21) is inside
    longer = tr.copy()
    longer.loc[(longer.frame == 1) & (longer.part == "hipleg"), "h"] = 30
    assert evaluate(truth, longer, hota=False).rates["person_mbr"].tolist() == [1.0, 1.0]
    assert r.rates["head"].tolist() == [1.0, 1.0]


def test_ids_that_differ_are_matched_by_mean_iou():
    truth, tr = _two_people()
    renamed = tr.assign(track_id=tr["track_id"].map({1: 2, 2: 1}))  # same boxes, swapped ids
    how, pairs = match_tracks(truth, renamed)
    assert how == "iou" and pairs[["truth_id", "track_id"]].values.tolist() == [[1, 2], [2, 1]]
    r = evaluate(truth, renamed, at=1, hota=False)
    assert "Hungarian" in r.note and r.rates["head"].tolist() == [1.0, 0.5, 0.5, 0.0]
    assert evaluate(truth, tr, hota=False).rates.equals(r.rates)
    with pytest.raises(EvaluationError, match="matching must be"):
        match_tracks(truth, tr, "name")


def test_mota_and_idf1_known_by_hand():
    # objects 1 and 2 over 4 frames (8 boxes). Tracker 10 follows 1 but misses frame 1 (1 miss),
    # 20 then 30 follow 2 (1 switch), 40 is a false positive at frame 3.
    truth = tracks([(f, 1, "torso", 0, 0, 10, 10) for f in range(4)]
                   + [(f, 2, "torso", 50, 0, 10, 10) for f in range(4)])
    tr = tracks([(f, 10, "torso", 1, 0, 10, 10) for f in (0, 2, 3)] + [(f, 20, "torso", 50, 0, 10, 10) for f in (0, 1)]
                + [(f, 30, "torso", 50, 0, 10, 10) for f in (2, 3)] + [(3, 40, "torso", 100, 0, 10, 10)])
    m = evaluate(truth, tr, hota=False).mot.loc["torso"]
    assert (m.num_misses, m.num_false_positives, m.num_switches, m.num_objects) == (1, 1, 1, 8)
    assert m.mota == pytest.approx(1 - 3 / 8)
    assert m.idf1 == pytest.approx(2 * 5 / (8 + 8))  # IDTP: 3 (1<->10) + 2 (2<->20)
    assert m.motp == pytest.approx(1 - 9 / 11 * 3 / 7 - 4 / 7)  # 3 boxes at IoU 9/11, 4 at 1


def test_eval_agrees_with_motmetrics_own_pipeline(tmp_path, monkeypatch):
    """Export truth and a noisy run as MOTChallenge files, let motmetrics load and match them."""
    from partlab.labelling.formats import export_dataset
    from partlab.labelling.formats.mot import part_file
    from partlab.labelling.video import VideoInfo

    rng = np.random.default_rng(4)
    rows = []
    for tid in range(3):
        for f in range(30):
            for k, part in enumerate(("head", "torso", "hipleg")):
                rows.append((f, tid, part, 20 + 40 * tid + f, 10 + 25 * k, 16, 22))
    truth = tracks(rows)
    noisy = truth.copy()
    noisy[["x", "y"]] += rng.normal(0, 1.5, (len(noisy), 2))
    noisy = noisy.drop(index=rng.choice(len(noisy), 20, replace=False))
    noisy.loc[(noisy.track_id == 1) & (noisy.frame >= 15), "track_id"] = 7  # an identity switch
    info = VideoInfo(tmp_path / "v.avi", 25.0, 200, 120, 30)
    ours = evaluate(truth, noisy, hota=False).mot
    monkeypatch.setattr(np, "asfarray", lambda a, dtype=float: np.asarray(a, dtype=dtype), raising=False)
    gt_dir = export_dataset(truth, "mot", tmp_path / "gt", info, frames=False)
    dt_dir = export_dataset(noisy, "mot", tmp_path / "dt", info, frames=False)
    for part in ("head", "torso", "hipleg"):  # each part is its own MOT file, gt/<part>.txt
        gt = mm.io.loadtxt(str(gt_dir / "gt" / part_file(part)), fmt="mot15-2D")
        dt = mm.io.loadtxt(str(dt_dir / "gt" / part_file(part)), fmt="mot15-2D")
        acc = mm.utils.compare_to_groundtruth(gt, dt, "iou", distth=0.5)
        theirs = mm.metrics.create().compute(acc, metrics=["mota", "idf1", "num_switches"], name=part)
        assert ours.loc[part, "mota"] == pytest.approx(theirs.loc[part, "mota"], abs=1e-12)
        assert ours.loc[part, "idf1"] == pytest.approx(theirs.loc[part, "idf1"], abs=1e-12)
        assert ours.loc[part, "num_switches"] == theirs.loc[part, "num_switches"]
    assert ours.loc["torso", "num_switches"] >= 1 and 0.5 < ours.loc["overall", "mota"] < 1.0
    assert part_file("head") == "head.txt" and part_file("person") == "gt.txt"


def test_iou_distance_is_nan_below_half():
    d = iou_distance(np.array([[0, 0, 10, 10]]), np.array([[0, 0, 10, 10], [5, 0, 10, 10], [2, 0, 10, 10]]))
    assert d[0, 0] == 0.0 and np.isnan(d[0, 1]) and d[0, 2] == pytest.approx(1 - 80 / 120)


def test_json_and_figure():
    truth, tr = _two_people()
    r = evaluate(truth, tr, at=1, hota=False)
    d = json.loads(r.to_json())
    assert d["matching"] == "track_id" and d["summary"]["head"]["rate_at"] == 0.5
    assert d["rates"]["head"] == {"0": 1.0, "1": 0.5, "2": 0.5, "3": 0.0}
    assert d["mot"]["head"]["num_objects"] == 7
    r_far = evaluate(truth, tr, at=50, hota=False)
    assert json.loads(r_far.to_json())["summary"]["head"]["rate_at"] is None  # no one tracked that long
    fig = rate_curve_figure(r)
    assert [t.name for t in fig.data] == ["head"] and list(fig.data[0].y) == [1.0, 0.5, 0.5, 0.0]


def test_bad_input():
    truth, tr = _two_people()
    with pytest.raises(EvaluationError, match="the truth has no boxes"):
        evaluate(truth.iloc[:0], tr)
    with pytest.raises(EvaluationError, match="tracks: 1 repeated"):
        evaluate(truth, pd.concat([tr, tr.iloc[[0]]]))


def test_eval_matches_motmetrics_published_numbers_on_tud():
    """motmetrics ships TUD-Campus/Stadtmitte truth and a tracker's output with the MOTChallenge
    devkit's numbers in its own tests; our MOT importer and evaluate must reproduce them."""
    from pathlib import Path

    from partlab.labelling.formats import import_dataset

    data = Path(mm.__file__).parent / "data"
    published = {"TUD-Campus": (0.526462, 0.557659, 0.277201, 7, 13, 150),
                 "TUD-Stadtmitte": (0.564014, 0.644619, 0.345904, 7, 45, 452)}
    for seq, (mota, idf1, motp, switches, fp, fn) in published.items():
        gt = import_dataset(data / seq / "gt.txt", "mot")
        test = import_dataset(data / seq / "test.txt", "mot")
        m = evaluate(gt, test, hota=False).mot.loc["person"]
        assert (m.mota, m.idf1, m.motp) == pytest.approx((mota, idf1, motp), abs=1e-6)
        assert (m.num_switches, m.num_false_positives, m.num_misses) == (switches, fp, fn)


def test_hota_known_by_hand():
    # one person tracked perfectly but under id 5 for frames 0-1 and id 6 for frames 2-3:
    # DetA = 1, AssA = 2 / (2 + 2 + 0) = 0.5, HOTA = sqrt(DetA * AssA)
    truth = tracks([(f, 1, "head", 0, 0, 10, 10) for f in range(4)])
    tr = tracks([(f, 5 if f < 2 else 6, "head", 0, 0, 10, 10) for f in range(4)])
    m = evaluate(truth, tr).mot
    assert m.loc["head", "deta"] == pytest.approx(1.0)
    assert m.loc["head", "assa"] == pytest.approx(0.5)
    assert m.loc["head", "hota"] == pytest.approx(np.sqrt(0.5))
    assert evaluate(truth, truth).mot.loc["overall", "hota"] == pytest.approx(1.0)


def _rows(rows):
    return pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h"])


def test_count_edits_moves_draws_and_deletes_once_each():
    from partlab.labelling.evaluation import count_edits

    truth = _rows([(0, 1, "person", 0, 0, 10, 20), (0, 2, "person", 50, 0, 10, 20),
                   (1, 1, "person", 1, 0, 10, 20), (1, 2, "person", 51, 0, 10, 20)])
    props = _rows([(0, 7, "person", 0, 0, 10, 20),      # right (ids play no part)
                   (0, 8, "person", 56, 0, 10, 20),     # IoU 4/16 = 0.25: moved
                   (1, 7, "person", 1, 0, 10, 20),      # right; track 2 missing at frame 1: drawn
                   (1, 9, "person", 200, 0, 10, 20),    # on nothing: pairs with the missing box, moved
                   (2, 9, "person", 200, 0, 10, 20)])   # a frame without truth: deleted
    e = count_edits(truth, props, keyframes=3)
    assert (e.moved, e.drawn, e.deleted, e.keyframes) == (2, 0, 1, 3)
    assert e.edits == 6 and e.truth_boxes == 4 and e.per_100 == 150.0


def test_soft_edits_blur_the_threshold_and_count_missing_and_spurious_boxes_whole():
    from partlab.labelling.evaluation import count_edits, soft_edits

    truth = _rows([(0, 1, "person", 0, 0, 10, 20), (0, 2, "person", 50, 0, 10, 20),
                   (1, 1, "person", 0, 0, 12, 20), (2, 1, "person", 0, 0, 10, 20), (3, 1, "person", 0, 0, 10, 20)])
    props = _rows([(0, 7, "person", 0, 0, 10, 20),       # right: 0
                   (0, 8, "person", 56, 0, 10, 20),      # IoU 0.25, below the ramp: 1
                   (1, 7, "person", 4, 0, 12, 20),       # IoU 0.5, the edits' threshold: 0.5
                   (2, 7, "person", 2.5, 0, 10, 20),     # IoU 0.6: 0.25
                   (3, 7, "person", 1.0, 0, 10, 20),     # IoU 9/11, above the ramp: 0
                   (3, 8, "person", 200, 0, 10, 20),     # spurious: 1
                   (4, 9, "person", 200, 0, 10, 20)])    # a frame without truth: 1
    e, n = soft_edits(truth, props)
    assert n == 5 and e == pytest.approx(1 + 0.5 + 0.25 + 1 + 1)
    assert count_edits(truth, props).edits == 3  # the IoU 0.5 and 0.6 boxes count as right
    assert soft_edits(truth, truth) == (0.0, 5)


def test_interpolation_between_keyframes_meets_them_and_is_linear():
    from partlab.labelling.evaluation import count_edits, interpolate_keyframes, keyframes_of

    frames = np.arange(0, 31)
    # walks right at 2 px/frame for 20 frames, then stops: keyframes every 25 miss the stop
    x = np.where(frames < 20, 2.0 * frames, 40.0)
    truth = _rows([(int(f), 1, "person", float(v), 0.0, 10.0, 20.0) for f, v in zip(frames, x)])
    keys = keyframes_of(truth, 25)
    assert keys["frame"].tolist() == [0, 25, 30]
    interp = interpolate_keyframes(keys)
    assert len(interp) == 31 and interp.set_index("frame").loc[12, "x"] == pytest.approx(40 * 12 / 25)
    e = count_edits(truth, interp, keyframes=len(keys))
    # interpolated x = 1.6 f against 2 f: IoU >= 0.5 needs |dx| <= 10/3, i.e. 0.4 f <= 3.33 up to f = 8;
    # after the stop (f >= 20) the truth stays at 40 against 1.6 f: right from f = 23 on
    wrong = [f for f in range(31) if abs(interp.set_index("frame").loc[f, "x"] - x[f]) > 10 / 3]
    assert e.moved == len(wrong) and e.edits == len(wrong) + 3
    assert 0 < len(wrong) < 20


def test_ids_agree_on_a_run_from_init_with_a_loose_start_and_a_track_gone():
    from partlab.labelling.evaluation import ids_agree

    truth = _rows([(f, k, "person", 100.0 * k + f, 0, 20, 40) for k in range(1, 6) for f in range(5)])
    run = truth[truth.track_id != 5].copy()  # track 5 ended early (withdrawn)
    run.loc[run.track_id == 2, "w"] = 50.0   # the tracker's own person box: IoU 0.4 with the drawn one
    assert ids_agree(truth, run)
    assert match_tracks(truth, run)[0] == "track_id"
    shuffled = run.assign(track_id=run["track_id"].map({1: 3, 2: 4, 3: 1, 4: 2}))
    assert not ids_agree(truth, shuffled)  # automatic numbering: same numbers, other people
    assert match_tracks(truth, shuffled)[0] == "iou"
    few = truth[truth.track_id <= 3]  # 3 of 5 truth tracks: not enough to call the ids the same
    assert not ids_agree(truth, few)
