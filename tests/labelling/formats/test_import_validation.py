"""The importers' edges: wrong types, numbers a later step cannot use, deep JSON and non-UTF-8 files are
refused with a FormatError naming the file, the place and the value, never imported as something else."""

import json

import pytest

from partlab.labelling.events import EventsError, read_events
from partlab.labelling.formats import FormatError, import_dataset

BASE = {"id": 7, "image_id": 1, "category_id": 1, "bbox": [1, 2, 3, 4]}


def _coco(tmp_path, ann, images=None):
    p = tmp_path / "a.json"
    p.write_text(json.dumps({"images": images or [{"id": 1, "file_name": "f_000003.jpg"}], "annotations": [ann],
                             "categories": [{"id": 1, "name": "head"}]}))
    return p


def test_coco_boolean_strings_are_booleans(tmp_path):
    df = import_dataset(_coco(tmp_path, {**BASE, "attributes": {"failure": "false", "occluded": "false"}}), "coco")
    assert not df["failure"].iloc[0] and df["occluded"].iloc[0] == 0.0
    df = import_dataset(_coco(tmp_path, {**BASE, "attributes": {"failure": "true"}}), "coco")
    assert df["failure"].iloc[0] and df["frame"].iloc[0] == 3


@pytest.mark.parametrize("ann, says", [
    ({**BASE, "bbox": ["1", 2, 3, 4]}, "annotation 7, column 'x': '1' is text"),
    ({**BASE, "bbox": [1, 2, -3, 4]}, "column 'w': negative size -3"),
    ({**BASE, "bbox": [1, 2, 1e308, 4]}, "column 'w': '1e+308' is beyond the limit"),
    ({**BASE, "bbox": [1, 2, True, 4]}, "column 'w': True is a boolean"),
    ({**BASE, "track_id": [1]}, "column 'track_id': [1] is not a single value"),
    ({**BASE, "track_id": 2**40}, "column 'track_id': 1099511627776 is larger than the limit of 2147483647"),
    ({**BASE, "track_id": 2**70}, "larger than the limit"),
    ({**BASE, "attributes": {"failure": "maybe"}}, "column 'failure': 'maybe' is not a boolean"),
    ({**BASE, "attributes": {"occlusion": 7}}, "column 'occluded': '7' is not a fraction"),
    ({**BASE, "image_id": [1]}, "annotation 7 refers to no image"),
])
def test_coco_refusals_name_the_annotation_and_value(tmp_path, ann, says):
    with pytest.raises(FormatError, match="a.json") as exc:
        import_dataset(_coco(tmp_path, ann), "coco")
    assert says in str(exc.value)


def test_coco_frames_and_ids_of_images(tmp_path):
    with pytest.raises(FormatError, match="column 'frame': -5 is negative"):
        import_dataset(_coco(tmp_path, BASE, images=[{"id": 1, "frame_id": -5}]), "coco")
    with pytest.raises(FormatError, match="image 'x': the id is not an integer"):
        import_dataset(_coco(tmp_path, BASE, images=[{"id": "x"}]), "coco")


def test_deep_json_and_non_utf8(tmp_path):
    p = tmp_path / "a.json"
    p.write_text("[" * 100_000 + "]" * 100_000)
    for fmt in ("coco", "labelstudio"):
        with pytest.raises(FormatError, match="a.json"):
            import_dataset(p, fmt)
    p.write_bytes(b'{"images": "\xff\xfe"}')
    with pytest.raises(FormatError, match="a.json: not a JSON file"):
        import_dataset(p, "coco")
    gt = tmp_path / "gt.txt"
    gt.write_bytes(b"1,1,1,1,5,5,1,1,1\n\xff\n")
    with pytest.raises(FormatError, match="not UTF-8"):
        import_dataset(gt, "mot")


@pytest.mark.parametrize("line, says", [
    ("1,1,1,1,nan,5,1,1,1", "line 1, column 'w': 'nan' is not a finite number"),
    ("1,1,1,1,inf,5,1,1,1", "line 1, column 'w': 'inf' is not a finite number"),
    ("1,1,1,1,-5,5,1,1,1", "line 1, column 'w': negative size -5"),
    ("-3,1,1,1,5,5,1,1,1", "line 1, frame: -3 is negative"),
    ("1,1e308,1,1,5,5,1,1,1", "line 1, id: '1e308' is larger than the limit"),
    ("1,2147483648,1,1,5,5,1,1,1", "line 1, id: 2147483648 is larger than the limit"),
    ("1,1.5,1,1,5,5,1,1,1", "line 1, id: '1.5' is not an integer"),
    ("1,1,1,1,5,5,1,nan,1", "line 1, class: 'nan' is not a class number"),
])
def test_mot_rows(tmp_path, line, says):
    gt = tmp_path / "gt.txt"
    gt.write_text(line + "\n")
    with pytest.raises(FormatError, match="gt.txt") as exc:
        import_dataset(gt, "mot")
    assert says in str(exc.value)


def _cvat(tmp_path, box):
    p = tmp_path / "annotations.xml"
    p.write_text(f'<annotations><track id="0" label="head">{box}</track></annotations>')
    return p


@pytest.mark.parametrize("box, says", [
    ('<box frame="0" xtl="nan" ytl="1" xbr="5" ybr="5"/>', "xtl: 'nan' is not a finite number"),
    ('<box frame="-1" xtl="1" ytl="1" xbr="5" ybr="5"/>', "column 'frame': -1 is negative"),
    ('<box frame="1" xtl="5" ytl="1" xbr="1" ybr="5"/>', "column 'w': negative size -4"),
    ('<box frame="x" xtl="1" ytl="1" xbr="5" ybr="5"/>', "column 'frame': 'x' is not an integer"),
    ('<box frame="1" xtl="1" ytl="1" xbr="5" ybr="5"><attribute name="person">[1]</attribute></box>',
     "column 'track_id': '[1]' is not an integer"),
    ('<box frame="1" xtl="1" ytl="1" xbr="5" ybr="5"><attribute name="failure">maybe</attribute></box>',
     "column 'failure': 'maybe' is not a boolean"),
])
def test_cvat_boxes(tmp_path, box, says):
    with pytest.raises(FormatError, match="annotations.xml") as exc:
        import_dataset(_cvat(tmp_path, box), "cvat")
    assert says in str(exc.value)


def test_labelstudio_frames_are_bounded(tmp_path):
    region = {"id": "r", "type": "videorectangle", "original_width": 100, "original_height": 100,
              "value": {"labels": ["head"], "framesCount": 10**12,
                        "sequence": [{"frame": 1, "x": 1, "y": 1, "width": 5, "height": 5, "enabled": True}]}}
    p = tmp_path / "tasks.json"
    p.write_text(json.dumps([{"annotations": [{"result": [region]}]}]))
    with pytest.raises(FormatError, match="framesCount in 0..360000"):
        import_dataset(p, "labelstudio")
    region["value"]["sequence"][0]["frame"] = 1e300
    p.write_text(json.dumps([{"annotations": [{"result": [region]}]}]))
    with pytest.raises(FormatError, match="whole frame number"):
        import_dataset(p, "labelstudio")


def test_events_frames_fit_int32(tmp_path):
    p = tmp_path / "events.csv"
    p.write_text("start_frame,end_frame,kind\n0,1e20,clap\n")
    with pytest.raises(EventsError, match="line 2, column 'end_frame': .* larger than the limit"):
        read_events(p)
