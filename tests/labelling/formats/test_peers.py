"""Each export opened by the peer tools' own packages in their default layouts (issue: "work with the
tools annotation teams already use"). Every test here uses the peer's package, not our reader."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from datumaro.components.dataset import Dataset
from datumaro.components.environment import Environment
from pycocotools.coco import COCO
from pycocotools.cocoeval import COCOeval

from partlab.labelling.formats import export_dataset, import_dataset


@pytest.fixture(scope="module")
def exports(tmp_path_factory, truth, clip):
    path, info = clip
    root = tmp_path_factory.mktemp("peers")
    return {fmt: export_dataset(truth, fmt, root / fmt, info, video_path=path)
            for fmt in ("mot", "cvat", "coco", "yolo", "voc")}


@pytest.mark.parametrize("fmt, detected", [("mot", ["mot_seq"]), ("cvat", ["cvat"]), ("coco", ["coco_instances"]),
                                           ("yolo", ["roboflow_yolo"])])
def test_datumaro_detects_each_format_by_itself(exports, truth, fmt, detected):
    assert Environment().detect_dataset(str(exports[fmt])) == detected
    ds = Dataset.import_from(str(exports[fmt]))  # no format named: Datumaro's own detection
    n = sum(len(item.annotations) for item in ds)
    assert len(ds) == 20
    assert n == {"mot": 36, "cvat": len(truth) + 4}.get(fmt, len(truth))  # MOT: people; CVAT: + 4 "outside"
    assert all(item.media is not None and item.media.has_data for item in ds)  # frames linked


def test_datumaro_voc_reads_ours_as_voc(exports, truth):
    # any detection-only VOC matches voc, voc_classification and voc_detection in Datumaro; "voc" reads all
    assert "voc" in Environment().detect_dataset(str(exports["voc"]))
    ds = Dataset.import_from(str(exports["voc"]), "voc")
    assert sum(len(i.annotations) for i in ds) == len(truth)


def test_datumaro_cvat_to_coco_keeps_every_box_and_to_yolo_runs(exports, truth, tmp_path):
    ds = Dataset.import_from(str(exports["cvat"]))
    ds.export(str(tmp_path / "coco"), "coco_instances", save_media=True)
    (js,) = (tmp_path / "coco" / "annotations").glob("*.json")
    doc = json.loads(js.read_text())
    inside = [a for a in doc["annotations"] if not a["attributes"]["outside"]]
    assert len(inside) == len(truth) == 144  # not merged by group into one box per person
    back = import_dataset(js, "coco")  # and the person of each part survives the trip
    assert len(back) == len(truth)
    cols = ["frame", "track_id", "part", "x", "y", "w", "h"]
    assert sorted(map(tuple, back[cols].values.tolist())) == sorted(map(tuple, truth[cols].values.tolist()))
    ds.export(str(tmp_path / "yolo"), "yolo", save_media=True)
    assert len(list((tmp_path / "yolo").rglob("*.png"))) == 20


def test_cocoeval_runs_on_our_coco_as_truth_and_as_detections(exports):
    gt = COCO(str(exports["coco"] / "annotations" / "instances_default.json"))
    anns = gt.loadAnns(gt.getAnnIds())
    assert all("score" in a for a in anns)
    perfect = COCOeval(gt, gt.loadRes(anns), "bbox")
    perfect.evaluate(), perfect.accumulate(), perfect.summarize()
    assert perfect.stats[0] == pytest.approx(1.0)  # AP@[.5:.95] of the truth against itself
    shifted = [dict(a, bbox=[a["bbox"][0] + 0.5 * a["bbox"][2], *a["bbox"][1:]]) for a in anns]
    worse = COCOeval(gt, gt.loadRes(shifted), "bbox")
    worse.evaluate(), worse.accumulate(), worse.summarize()
    assert worse.stats[1] < 0.05  # half a box to the side: IoU 1/3 < 0.5 everywhere


def _trackeval(gt_root, seq, tracker_txt, tmp_path, gt_file="gt.txt"):
    import trackeval

    trackers = tmp_path / "trackers" / "partlab" / "data"
    trackers.mkdir(parents=True, exist_ok=True)
    shutil.copy(tracker_txt, trackers / f"{seq}.txt")
    (tmp_path / "seqmap.txt").write_text(f"name\n{seq}\n")
    cfg = {"GT_FOLDER": str(gt_root), "TRACKERS_FOLDER": str(tmp_path / "trackers"), "SKIP_SPLIT_FOL": True,
           "SEQMAP_FILE": str(tmp_path / "seqmap.txt"), "TRACKERS_TO_EVAL": ["partlab"], "PRINT_CONFIG": False,
           "GT_LOC_FORMAT": "{gt_folder}/{seq}/gt/" + gt_file}
    ev = trackeval.Evaluator({"PRINT_RESULTS": False, "PRINT_CONFIG": False, "OUTPUT_SUMMARY": False,
                              "OUTPUT_DETAILED": False, "PLOT_CURVES": False, "TIME_PROGRESS": False,
                              "DISPLAY_LESS_PROGRESS": True})
    res, _ = ev.evaluate([trackeval.datasets.MotChallenge2DBox(cfg)],
                         [trackeval.metrics.HOTA(), trackeval.metrics.CLEAR({"PRINT_CONFIG": False})])
    return res["MotChallenge2DBox"]["partlab"][seq]["pedestrian"]


def test_trackeval_reads_our_mot_for_the_person_class_and_each_part(exports, tmp_path):
    seq_dir = exports["mot"]
    seq = seq_dir.name
    gt = seq_dir / "gt" / "gt.txt"
    r = _trackeval(seq_dir.parent, seq, gt, tmp_path / "person")
    assert r["CLEAR"]["MOTA"] == pytest.approx(1.0) and np.mean(r["HOTA"]["HOTA"]) == pytest.approx(1.0)
    assert r["CLEAR"]["CLR_TP"] == 36
    # a tracker that swaps nothing but misses person 3 entirely
    lines = [ln for ln in gt.read_text().splitlines() if ln.split(",")[1] != "4"]
    (tmp_path / "half.txt").write_text("\n".join(lines) + "\n")
    r = _trackeval(seq_dir.parent, seq, tmp_path / "half.txt", tmp_path / "half")
    assert r["CLEAR"]["CLR_TP"] == 20 and r["CLEAR"]["CLR_FN"] == 16
    # each part is its own class-1 file: the heads evaluated with TrackEval's GT_LOC_FORMAT
    r = _trackeval(seq_dir.parent, seq, seq_dir / "gt" / "head.txt", tmp_path / "head", gt_file="head.txt")
    assert r["CLEAR"]["CLR_TP"] == 36 and r["CLEAR"]["MOTA"] == pytest.approx(1.0)
