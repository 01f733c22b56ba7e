import numpy as np
import pytest
import yaml
from datumaro.components.dataset import Dataset

from partlab.labelling.formats import FormatError, export_dataset, import_dataset
from partlab.tracking.parts import BOX_PARTS


def _clipped(t, w=160, h=120):
    x1, y1 = max(t.x, 0), max(t.y, 0)
    return [x1, y1, min(t.x + t.w, w) - x1, min(t.y + t.h, h) - y1]


def test_yolo_read_by_datumaro(tmp_path, truth, clip):
    path, info = clip
    out = export_dataset(truth, "yolo", tmp_path / "y", info, video_path=path)
    data = yaml.safe_load((out / "data.yaml").read_text())
    assert data["names"] == dict(enumerate(BOX_PARTS)) and data["nc"] == 6
    assert (out / "train" / "classes.txt").read_text().split() == list(BOX_PARTS)
    ds = Dataset.import_from(str(out))  # detected by itself (as roboflow_yolo, the layout it reads)
    names = [c.name for c in ds.categories()[list(ds.categories())[0]]]
    assert len(ds) == 20 and sum(len(i.annotations) for i in ds) == len(truth)
    item = next(i for i in ds if i.id == "frame_000018")
    got = sorted((names[a.label], *np.round(a.get_bbox(), 2)) for a in item.annotations)
    want = sorted((t.part, *np.round(_clipped(t), 2)) for t in truth[truth.frame == 18].itertuples())
    assert [g[0] for g in got] == [w[0] for w in want]
    assert np.allclose([g[1:] for g in got], [w[1:] for w in want], atol=0.02)
    # person 3 runs off the right edge at frame 18: its box ends at the frame border
    assert max(g[1] + g[3] for g in got) == pytest.approx(160.0)


def test_voc_read_by_datumaro_with_flags(tmp_path, truth, clip):
    path, info = clip
    out = export_dataset(truth, "voc", tmp_path / "v", info, video_path=path)
    ds = Dataset.import_from(str(out), "voc", coordinate_mode="voc-one-based")
    names = [c.name for c in ds.categories()[list(ds.categories())[0]]]
    assert len(ds) == 20 and sum(len(i.annotations) for i in ds) == len(truth)
    anns = {(item.id, names[a.label], int(a.attributes["track_id"])): a for item in ds for a in item.annotations}
    a = anns[("frame_000006", "torso", 0)]
    assert a.attributes["occluded"] is True and a.attributes["truncated"] is False
    assert a.get_bbox() == pytest.approx([27.0, 32.0, 20.0, 30.0])  # x = 10 + 2.5*6 + 2
    assert anns[("frame_000017", "person", 3)].attributes["truncated"] is True
    failure = anns[("frame_000015", "head", 3)].attributes
    assert failure["failure"] == "true" and failure["difficult"] is False  # a marked tracker failure
    # person 3, frames 16..19: all four parts cross x = 160 at 16 and 17, the head ends inside from 18 on
    assert sum(a.attributes["truncated"] for a in anns.values()) == 4 + 4 + 3 + 3


def test_yolo_and_voc_are_export_only(tmp_path):
    with pytest.raises(FormatError, match="yolo is export-only"):
        import_dataset(tmp_path, "yolo")
    with pytest.raises(FormatError, match="unknown format 'labelme'"):
        import_dataset(tmp_path, "labelme")
