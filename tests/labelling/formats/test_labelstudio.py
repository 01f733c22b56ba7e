"""Label Studio video tracks (videorectangle keyframes): our writer and reader, the documented
keyframe examples, and Label Studio's own expansion of keyframes (label_studio_tools) in its venv."""

from __future__ import annotations

import json
import subprocess

import pandas as pd
import pytest
from defusedxml import ElementTree as SafeET

from partlab.labelling.formats import FormatError, export_dataset, import_dataset
from partlab.labelling.formats.labelstudio import expand
from tests.labelling.formats.test_peers_venv import _python

CORE = ["frame", "track_id", "part", "x", "y", "w", "h"]

#: label_studio_tools' documented examples (tests/test_video.py there): keyframes and what Label Studio shows
DISABLED_TILL_END = [{"frame": 1, "enabled": True, "x": 38, "y": 38, "width": 41, "height": 22, "rotation": 0},
                     {"frame": 5, "enabled": False, "x": 40, "y": 49, "width": 56, "height": 34, "rotation": 30}]
GAP = [{"frame": 1, "enabled": True, "x": 38, "y": 38, "width": 41, "height": 22, "rotation": 0},
       {"frame": 5, "enabled": False, "x": 40, "y": 49, "width": 41, "height": 22, "rotation": 0},
       {"frame": 11, "enabled": True, "x": 38, "y": 38, "width": 41, "height": 22, "rotation": 0},
       {"frame": 15, "enabled": False, "x": 40, "y": 49, "width": 41, "height": 22, "rotation": 0}]
ENABLED_TILL_END = [dict(DISABLED_TILL_END[0]), dict(DISABLED_TILL_END[1], enabled=True, width=41, height=22,
                                                     rotation=0)]


def test_keyframes_expand_as_the_documented_examples():
    got = expand(DISABLED_TILL_END, 10_000_000)
    assert [g[0] for g in got] == [1, 2, 3, 4, 5]  # disabled at 5: nothing after it
    assert got[2][1:5] == pytest.approx((39, 43.5, 48.5, 28)) and not got[2][5] and got[4][5]
    got = expand(GAP, 10_000_000)
    assert [g[0] for g in got] == [1, 2, 3, 4, 5, 11, 12, 13, 14, 15]
    assert got[7][1:3] == pytest.approx((39, 43.5))
    got = expand(ENABLED_TILL_END, 10)  # enabled last keyframe: held to the end of the video
    assert [g[0] for g in got] == list(range(1, 11)) and got[9][1:3] == pytest.approx((40, 49))


@pytest.fixture(scope="module")
def exported(tmp_path_factory, truth, clip):
    path, info = clip
    return export_dataset(truth, "labelstudio", tmp_path_factory.mktemp("ls"), info, video_path=path)


def test_round_trip_and_gaps(exported, truth):
    back = import_dataset(exported, "labelstudio")
    pd.testing.assert_frame_equal(back[CORE], truth[CORE], check_exact=False, atol=1e-6)
    task = json.loads((exported / "tasks.json").read_text())[0]
    regions = {r["id"]: r for r in task["annotations"][0]["result"]}
    assert len(regions) == 8 and task["data"]["video"] == "clip.avi"
    seq = regions["t3-head"]["value"]["sequence"]  # person 3 leaves at frame 8, back at 12 (1-based 9, 13)
    assert [k["frame"] for k in seq if not k["enabled"]] == [8, 20]
    assert regions["t3-head"]["value"]["labels"] == ["head"] and regions["t0-torso"]["value"]["framesCount"] == 20
    assert seq[0]["x"] == pytest.approx(100 * (120 + 7) / 160)
    config = SafeET.fromstring((exported / "labeling_config.xml").read_text())
    assert config.find("Video").get("framerate") == "10"
    assert [lab.get("value") for lab in config.iter("Label")][:4] == ["person", "head", "torso", "hipleg"]


def test_foreign_task_maps_labels_and_needs_a_size(tmp_path, clip):
    path, info = clip
    task = [{"id": 7, "data": {"video": "/data/upload/1/x.mp4"}, "annotations": [
        {"id": 1, "updated_at": "2024-01-01", "result": [
            {"id": "abc", "type": "videorectangle", "from_name": "box", "to_name": "video",
             "value": {"framesCount": 20, "labels": ["Face"], "sequence": GAP[:2]}}]},
        {"id": 2, "updated_at": "2024-02-01", "result": [
            {"id": "xyz", "type": "videorectangle", "from_name": "box", "to_name": "video",
             "value": {"framesCount": 20, "labels": ["Face"], "sequence": DISABLED_TILL_END}},
            {"id": "k", "type": "choices", "value": {"choices": ["ok"]}}]}]}]
    f = tmp_path / "export.json"
    f.write_text(json.dumps(task))
    with pytest.raises(FormatError, match="pass the clip with --video"):
        import_dataset(f, "labelstudio")
    df = import_dataset(f, "labelstudio", video=path)  # the latest annotation, 160x120 from the clip
    assert list(df["frame"]) == [0, 1, 2, 3, 4] and set(df["part"]) == {"head"}
    assert df.loc[4, ["x", "y", "w", "h"]].tolist() == pytest.approx([0.40 * 160, 0.49 * 120, 0.56 * 160, 0.34 * 120])
    assert df.attrs["skipped"] == {"choices regions (only videorectangle is read)": 1}
    f.write_text(json.dumps(task * 2))
    with pytest.raises(FormatError, match="2 Label Studio tasks with annotations; expected one video task"):
        import_dataset(f, "labelstudio")


LS_TOOLS = """
import json, sys
from label_studio_tools.postprocessing.video import extract_key_frames
regions = json.load(open(sys.argv[1]))[0]["annotations"][0]["result"]
out = {r["id"]: sorted({int(k["frame"]) for k in r["value"]["sequence"]}) for r in extract_key_frames(regions)}
print(json.dumps(out))
"""


def test_label_studio_expands_our_keyframes_to_our_boxes(exported, truth):
    exe = _python("labelstudio")
    run = subprocess.run([str(exe), "-c", LS_TOOLS, str(exported / "tasks.json")], check=True,
                         capture_output=True, text=True, timeout=300)
    frames = json.loads(run.stdout.strip().splitlines()[-1])
    for (tid, part), rows in truth.groupby(["track_id", "part"]):
        assert frames[f"t{tid}-{part}"] == sorted(int(f) + 1 for f in rows["frame"]), (tid, part)
