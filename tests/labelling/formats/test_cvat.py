import numpy as np
import pandas as pd
import pytest
from datumaro.components.dataset import Dataset

from partlab.labelling.formats import FormatError, export_dataset, import_dataset
from partlab.tracking.parts import PART_NAMES


@pytest.fixture(scope="module")
def exported(tmp_path_factory, truth, clip):
    path, info = clip
    return export_dataset(truth, "cvat", tmp_path_factory.mktemp("cvat"), info, video_path=path)


def test_round_trip_keeps_every_box_and_flag(exported, truth):
    back = import_dataset(exported, "cvat")
    pd.testing.assert_frame_equal(back, truth)
    assert back["failure"].sum() == truth["failure"].sum() == 3
    assert back["score"].isna().sum() == 64  # person 3 has no scores: still none after the trip


def test_datumaro_reads_tracks_with_outside_and_occluded(exported, truth):
    ds = Dataset.import_from(str(exported), "cvat")
    labels = [c.name for c in ds.categories()[list(ds.categories())[0]]]
    assert labels == list(PART_NAMES)
    boxes = [(int(item.id.split("_")[-1]), a) for item in ds for a in item.annotations]
    inside = [(f, a) for f, a in boxes if not a.attributes["outside"]]
    outside = [(f, a) for f, a in boxes if a.attributes["outside"]]
    assert len(inside) == len(truth)
    # person 3 leaves at frame 8 (a box per part marks it outside) and comes back at 12
    assert sorted({f for f, _ in outside}) == [8] and len(outside) == 4
    assert {int(a.attributes["person"]) for _, a in outside} == {3} and {a.group for _, a in outside} == {0}
    occluded = sorted(f for f, a in inside if a.attributes["occluded"])
    assert occluded == [5, 6, 7]
    f, head = next((f, a) for f, a in inside if f == 10 and labels[a.label] == "head" and a.attributes["person"] == 0)
    t = truth[(truth.frame == 10) & (truth.track_id == 0) & (truth.part == "head")].iloc[0]
    assert head.get_bbox() == pytest.approx([t.x, t.y, t.w, t.h])


def test_every_thins_and_closes_gaps_at_the_next_exported_frame(tmp_path, truth, clip):
    _, info = clip
    out = export_dataset(truth, "cvat", tmp_path / "c", info, every=4, frames=False)
    xml = (out / "annotations.xml").read_text()
    assert "<frame_filter>step=4</frame_filter>" in xml
    back = import_dataset(out, "cvat")
    assert sorted(back["frame"].unique()) == [0, 4, 8, 12, 16]
    assert sorted(back.loc[back.track_id == 3, "frame"].unique()) == [0, 4, 12, 16]
    # person 3's boxes at frame 4 are followed by outside boxes at frame 8
    assert xml.count('outside="1"') == 4
    assert 'frame="8" keyframe="1" outside="1"' in xml


def test_foreign_cvat_without_groups_or_attributes(tmp_path):
    f = tmp_path / "task.xml"
    f.write_text("""<?xml version="1.0"?><annotations><version>1.1</version><meta><task><size>10</size>
      <labels><label><name>face</name></label><label><name>car</name></label></labels></task></meta>
      <track id="0" label="face"><box frame="2" outside="0" occluded="1" keyframe="1" xtl="1" ytl="2" xbr="11" ybr="22"/>
        <box frame="3" outside="0" occluded="0" keyframe="0" xtl="2" ytl="2" xbr="12" ybr="22"/>
        <box frame="4" outside="1" occluded="0" keyframe="1" xtl="2" ytl="2" xbr="12" ybr="22"/></track>
      <track id="1" label="face"><box frame="2" outside="0" occluded="0" keyframe="1" xtl="50" ytl="2" xbr="60" ybr="22"/></track>
      <track id="2" label="car"><box frame="2" outside="0" occluded="0" keyframe="1" xtl="0" ytl="0" xbr="5" ybr="5"/></track>
      </annotations>""")
    df = import_dataset(f, "cvat")
    assert df[["frame", "track_id", "part", "x", "w", "occluded", "source"]].values.tolist() == [
        [2, 0, "head", 1.0, 10.0, 1.0, "cvat"], [2, 1, "head", 50.0, 10.0, 0.0, "cvat"],
        [3, 0, "head", 2.0, 10.0, 0.0, "interpolated"]]
    assert df.attrs["skipped"] == {"car": 1}
    df = import_dataset(f, "cvat", mapping={"car": "person"})
    assert (df["part"] == "person").sum() == 1


def test_wrong_files_say_what_was_expected(tmp_path):
    f = tmp_path / "a.xml"
    f.write_text('<annotations><version>1.1</version><image id="0" name="x.jpg"/></annotations>')
    with pytest.raises(FormatError, match="no <track> elements; expected CVAT for video 1.1 XML .*CVAT for images"):
        import_dataset(f, "cvat")
    f.write_text("<root/>")
    with pytest.raises(FormatError, match="root element <root>, expected <annotations>"):
        import_dataset(f, "cvat")
    f.write_text('<!DOCTYPE a [<!ENTITY x "xx">]><annotations>&x;</annotations>')
    with pytest.raises(FormatError, match="not a readable XML file"):
        import_dataset(f, "cvat")


def test_import_refuses_a_clip_with_another_frame_count(tmp_path, exported, truth, clip):
    from partlab.labelling.video import write_video

    short = write_video(tmp_path / "short.avi", [np.zeros((120, 160, 3), np.uint8)] * 12, fps=10.0)
    with pytest.raises(FormatError, match="the clip has 12 frames but the annotations were made on a clip of 20"):
        import_dataset(exported, "cvat", video=short)
    assert len(import_dataset(exported, "cvat", video=clip[1])) == len(truth)


def test_import_from_a_zip_of_the_export(tmp_path, exported, truth):
    import shutil
    import zipfile

    archive = shutil.make_archive(str(tmp_path / "export"), "zip", exported.parent, exported.name)
    pd.testing.assert_frame_equal(import_dataset(archive, "cvat"), truth)
    evil = tmp_path / "evil.zip"
    with zipfile.ZipFile(evil, "w") as z:
        z.writestr("../annotations.xml", "<annotations/>")
    with pytest.raises(FormatError, match="climbs out of the target"):
        import_dataset(evil, "cvat")
