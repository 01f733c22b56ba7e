import json

import pandas as pd
import pytest
from pycocotools.coco import COCO

from partlab.labelling.formats import FormatError, export_dataset, import_dataset

CORE = ["frame", "track_id", "part", "x", "y", "w", "h", "score", "failure", "occluded", "state", "source"]


@pytest.fixture(scope="module")
def exported(tmp_path_factory, truth, clip):
    path, info = clip
    return export_dataset(truth, "coco", tmp_path_factory.mktemp("coco"), info, video_path=path)


def test_pycocotools_reads_images_categories_and_boxes(exported, truth):
    coco = COCO(str(exported / "annotations" / "instances_default.json"))
    assert len(coco.getImgIds()) == 20 and len(coco.getAnnIds()) == len(truth)
    head = coco.getCatIds(catNms=["head"])
    assert len(coco.getAnnIds(catIds=head)) == (truth.part == "head").sum() == 36
    img = coco.loadImgs(7 + 1)[0]
    assert (img["file_name"], img["frame_id"], img["width"], img["height"]) == ("frame_000007.jpg", 7, 160, 120)
    assert (exported / "images" / img["file_name"]).is_file()
    anns = coco.loadAnns(coco.getAnnIds(imgIds=[img["id"]], catIds=coco.getCatIds(catNms=["torso"])))
    t = truth[(truth.frame == 7) & (truth.part == "torso")].sort_values("track_id")
    assert [a["bbox"] for a in anns] == t[["x", "y", "w", "h"]].values.tolist()
    assert [a["track_id"] for a in anns] == [0, 3]
    assert anns[0]["attributes"]["occluded"] is True and anns[0]["attributes"]["occlusion"] == 0.25


def test_round_trip_with_our_importer(exported, truth):
    pd.testing.assert_frame_equal(import_dataset(exported, "coco")[CORE], truth[CORE])


def test_every_thins_the_images(tmp_path, truth, clip):
    path, info = clip
    out = export_dataset(truth, "coco", tmp_path / "c", info, video_path=path, every=5)
    doc = json.loads((out / "annotations" / "instances_default.json").read_text())
    assert [im["frame_id"] for im in doc["images"]] == [0, 5, 10, 15]
    assert sorted(p.name for p in (out / "images").iterdir()) == [
        "frame_000000.jpg", "frame_000005.jpg", "frame_000010.jpg", "frame_000015.jpg"]
    assert doc["info"]["frame_count"] == 20 and doc["info"]["fps"] == 10.0


def test_foreign_coco_frames_from_file_names(tmp_path):
    f = tmp_path / "instances.json"
    f.write_text(json.dumps({
        "images": [{"id": 1, "file_name": "img_0041.jpg"}, {"id": 2, "file_name": "other.png"}],
        "categories": [{"id": 1, "name": "Face"}, {"id": 2, "name": "dog"}],
        "annotations": [{"id": 5, "image_id": 1, "category_id": 1, "bbox": [1, 2, 3, 4]},
                        {"id": 6, "image_id": 2, "category_id": 1, "bbox": [1, 2, 3, 4], "track_id": 9},
                        {"id": 7, "image_id": 2, "category_id": 2, "bbox": [1, 2, 3, 4]}]}))
    df = import_dataset(f, "coco")
    assert df[["frame", "track_id", "part"]].values.tolist() == [[1, 9, "head"], [41, 5, "head"]]
    assert df.attrs["skipped"] == {"dog": 1}


def test_wrong_json_says_what_was_expected(tmp_path):
    f = tmp_path / "x.json"
    f.write_text('{"images": []}')
    with pytest.raises(FormatError, match="expected COCO detection JSON with lists 'images', 'annotations'"):
        import_dataset(f, "coco")
    f.write_text("not json")
    with pytest.raises(FormatError, match="not a JSON file"):
        import_dataset(f, "coco")
