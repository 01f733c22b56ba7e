import configparser

import motmetrics as mm
import numpy as np
import pandas as pd
import pytest

from partlab.labelling.evaluation import iou_distance
from partlab.labelling.formats import FormatError, export_dataset, import_dataset

CORE = ["frame", "track_id", "part", "x", "y", "w", "h", "occluded"]


@pytest.fixture(scope="module")
def exported(tmp_path_factory, truth, clip):
    path, info = clip
    return export_dataset(truth, "mot", tmp_path_factory.mktemp("mot"), info, video_path=path)


def test_layout_states_the_clip(exported, clip):
    _, info = clip
    seq = configparser.ConfigParser()
    seq.read(exported / "seqinfo.ini")
    assert dict(seq["Sequence"]) == {"name": "clip", "imdir": "img1", "framerate": "10", "seqlength": "20",
                                     "imwidth": "160", "imheight": "120", "imext": ".jpg"}
    assert (exported / "gt" / "labels.txt").read_text().split() == ["person"]
    assert sorted(p.name for p in (exported / "gt").iterdir()) == ["gt.txt", "head.txt", "hipleg.txt", "labels.txt",
                                                                  "torso.txt"]
    images = sorted(p.name for p in (exported / "img1").iterdir())
    assert images[0] == "000001.jpg" and images[-1] == "000020.jpg" and len(images) == 20


def test_motmetrics_reads_the_boxes_flags_and_classes(exported, truth):
    gt = mm.io.loadtxt(str(exported / "gt" / "gt.txt"), fmt="mot15-2D")
    assert len(gt) == (truth.part == "person").sum() == 36 and set(gt["ClassId"]) == {1}  # MOT17 pedestrian
    torso = mm.io.loadtxt(str(exported / "gt" / "torso.txt"), fmt="mot15-2D")
    # motmetrics undoes MOT's 1-based pixels and frames: our decoder frame 7, track 0 (MOT id 1), torso
    row = torso.loc[(8, 1)]
    t = truth[(truth.frame == 7) & (truth.track_id == 0) & (truth.part == "torso")].iloc[0]
    assert (row.X, row.Y, row.Width, row.Height) == pytest.approx((t.x, t.y, t.w, t.h))
    assert row.Visibility == pytest.approx(0.75)  # occluded 0.25
    assert sorted(torso.index.get_level_values(1).unique()) == [1, 4]  # track_id + 1, as in gt.txt
    assert gt.index.is_unique and torso.index.is_unique


def test_truth_against_itself_with_motmetrics_gives_mota_one(exported, monkeypatch):
    gt = mm.io.loadtxt(str(exported / "gt" / "gt.txt"), fmt="mot15-2D")
    acc = mm.MOTAccumulator(auto_id=False)
    for frame, g in gt.groupby(level=0):
        ids = g.index.get_level_values(1).to_numpy()
        boxes = g[["X", "Y", "Width", "Height"]].to_numpy()
        acc.update(ids, ids, iou_distance(boxes, boxes), frameid=frame)
    summary = mm.metrics.create().compute(acc, metrics=["mota", "idf1", "num_objects"])
    assert summary.loc[0, "mota"] == 1.0 and summary.loc[0, "idf1"] == 1.0
    assert summary.loc[0, "num_objects"] == len(gt)
    # and motmetrics' own pipeline, once numpy's removed asfarray is put back for it
    monkeypatch.setattr(np, "asfarray", lambda a, dtype=float: np.asarray(a, dtype=dtype), raising=False)
    acc2 = mm.utils.compare_to_groundtruth(gt, gt, "iou", distth=0.5)
    assert mm.metrics.create().compute(acc2, metrics=["mota"]).loc[0, "mota"] == 1.0


def test_round_trip_with_our_importer(exported, truth):
    back = import_dataset(exported, "mot")
    pd.testing.assert_frame_equal(back[CORE], truth[CORE])
    assert set(back["source"]) == {"mot"}


def test_every_thins_frames_and_names_them_by_decoder_index(tmp_path, truth, clip):
    path, info = clip
    out = export_dataset(truth, "mot", tmp_path / "m", info, video_path=path, every=5)
    assert sorted(p.name for p in (out / "img1").iterdir()) == ["000001.jpg", "000006.jpg", "000011.jpg", "000016.jpg"]
    back = import_dataset(out, "mot")
    assert sorted(back["frame"].unique()) == [0, 5, 10, 15]
    assert len(back) == 4 + 4 + 4 + 4 + 4 * 3  # person 3 is away at frame 10


def test_foreign_mot17_gt_and_mapping(tmp_path):
    gt = tmp_path / "seq" / "gt" / "gt.txt"
    gt.parent.mkdir(parents=True)
    gt.write_text("1,1,11,21,30,60,1,1,0.8\n"  # pedestrian
                  "1,2,50,20,30,60,0,1,1\n"  # conf 0: ignored in MOTChallenge ground truth
                  "2,1,12,21,30,60,1,1,1\n"
                  "2,5,80,10,10,10,1,7,1\n")  # class 7 (static person): not mapped by default
    (tmp_path / "seq" / "seqinfo.ini").write_text("[Sequence]\nseqLength=2\nframeRate=25\n")
    df = import_dataset(tmp_path / "seq", "mot")
    assert list(df["frame"]) == [0, 1] and list(df["track_id"]) == [1, 1] and set(df["part"]) == {"person"}
    assert df.loc[0, ["x", "y", "occluded"]].tolist() == pytest.approx([10, 20, 0.2])
    assert df.attrs["skipped"] == {"conf=0 (ignored)": 1, "7": 1}
    df = import_dataset(gt, "mot", mapping="7=head")
    assert sorted(df["part"]) == ["head", "person", "person"]


def test_mot15_ten_columns_read_as_pedestrians(tmp_path):
    f = tmp_path / "det.txt"
    f.write_text("3,4,10,20,5,6,-1,-1,-1,-1\n")
    df = import_dataset(f, "mot")
    assert df[["frame", "track_id", "part", "x", "y", "w", "h"]].iloc[0].tolist() == [2, 4, "person", 9, 19, 5, 6]


def test_bad_files_say_what_was_expected(tmp_path):
    with pytest.raises(FormatError, match="expected gt/gt.txt"):
        import_dataset(tmp_path, "mot")
    f = tmp_path / "gt.txt"
    f.write_text("1,2,3\n")
    with pytest.raises(FormatError, match="line 1: 3 values; expected MOTChallenge rows"):
        import_dataset(f, "mot")
    f.write_text("1,2,a,4,5,6,1,1,1\n")
    with pytest.raises(FormatError, match="line 1: non-numeric"):
        import_dataset(f, "mot")
    f.write_text("0,2,3,4,5,6,1,1,1\n")
    with pytest.raises(FormatError, match="frames count from 1"):
        import_dataset(f, "mot")


def test_export_refuses_duplicates_and_frames_outside_the_clip(tmp_path, truth, clip):
    path, info = clip
    repeated = r"2 rows repeat a \(frame, track_id, part\), e.g. frame 0, track 0, part head"
    with pytest.raises(FormatError, match=repeated):
        export_dataset(pd.concat([truth, truth.iloc[[1]]]), "mot", tmp_path / "a", info, frames=False)
    late = truth.assign(frame=truth["frame"] + 5)
    with pytest.raises(FormatError, match="outside the clip's 20 frames"):
        export_dataset(late, "mot", tmp_path / "b", info, frames=False)
    with pytest.raises(FormatError, match="needs the video"):
        export_dataset(truth, "mot", tmp_path / "c", info)


def test_trailing_commas_and_no_frames(tmp_path, truth, clip):
    f = tmp_path / "gt.txt"
    f.write_text("2,3,11,21,5,6,1,1,1,,\n")
    assert import_dataset(f, "mot")[["frame", "track_id", "x"]].values.tolist() == [[1, 3, 10]]
    path, info = clip
    out = export_dataset(truth.iloc[:4], "mot", tmp_path / "m", info, video_path=path, every=3)
    # img1/ holds the whole sequence (thinned), not only the annotated frame 0
    assert len(list((out / "img1").iterdir())) == 7  # frames 0, 3, ..., 18


def test_datumaro_reads_our_mot_and_we_read_datumaros(exported, truth, tmp_path):
    from datumaro.components.dataset import Dataset

    ds = Dataset.import_from(str(exported), "mot_seq")
    names = [c.name for c in ds.categories()[list(ds.categories())[0]]]
    anns = [a for item in ds for a in item.annotations]
    people = truth[truth.part == "person"]
    assert len(anns) == len(people) == 36 and {names[a.label] for a in anns} == {"person"}
    ds.export(str(tmp_path / "dm"), "mot_seq_gt")  # a MOT sequence written by another tool
    back = import_dataset(tmp_path / "dm", "mot")
    assert len(back) == 36 and set(back["part"]) == {"person"}
    # Datumaro keeps MOT's 1-based pixels as they are on both sides, so the boxes come back exactly
    assert np.allclose(np.sort(back["x"]), np.sort(people["x"]))
    assert sorted(back["frame"].unique()) == list(range(20))
