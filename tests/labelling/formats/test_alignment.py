"""Imports cannot go one frame wrong silently: the shift of Datumaro-made files is corrected by the
images' content, or refused by range when the files have no images."""

import numpy as np
import pytest
from datumaro.components.dataset import Dataset

from partlab.labelling.formats import FormatError, export_dataset, import_dataset
from partlab.labelling.video import probe, write_video

COLS = ["frame", "track_id", "x", "y", "w", "h"]


@pytest.fixture(scope="module")
def datumaro_coco(tmp_path_factory, truth, clip):
    """Our MOT sequence through Datumaro into COCO: its images are named 1.jpg .. 20.jpg."""
    path, info = clip
    root = tmp_path_factory.mktemp("align")
    ds = Dataset.import_from(str(export_dataset(truth, "mot", root / "mot", info, video_path=path)))
    ds.export(str(root / "media"), "coco_instances", save_media=True)
    ds.export(str(root / "bare"), "coco_instances", save_media=False)
    return root


def _people(truth):
    """The person boxes as Datumaro's COCO has them: MOT ids, MOT's 1-based pixels kept as they are."""
    people = truth[truth.part == "person"]
    return people.assign(track_id=people["track_id"] + 1, x=people["x"] + 1, y=people["y"] + 1)[COLS].values.tolist()


def test_one_based_names_are_one_frame_late_without_the_clip(datumaro_coco):
    df = import_dataset(datumaro_coco / "media", "coco")
    assert (df["frame"].min(), df["frame"].max()) == (1, 20)


def test_the_clip_corrects_the_shift_by_content(datumaro_coco, truth, clip):
    path, _ = clip
    df = import_dataset(datumaro_coco / "media", "coco", video=path)
    assert df.attrs["frame_shift"] == -1 and "4 images compared" in df.attrs["frame_check"]
    assert sorted(df[COLS].values.tolist()) == sorted(_people(truth))


def test_without_images_a_box_past_the_last_frame_is_refused(datumaro_coco, truth, clip):
    path, _ = clip
    with pytest.raises(FormatError, match=r"boxes on frames 1\.\.20 but the clip clip.avi has frames 0\.\.19 "
                                          r"\(frames read from file names\).*--frame-offset -1"):
        import_dataset(datumaro_coco / "bare", "coco", video=path)
    df = import_dataset(datumaro_coco / "bare", "coco", video=path, frame_offset=-1)
    assert sorted(df[COLS].values.tolist()) == sorted(_people(truth))


def test_our_own_export_is_not_shifted(tmp_path, truth, clip):
    path, info = clip
    out = export_dataset(truth, "cvat", tmp_path / "c", info, video_path=path)
    df = import_dataset(out, "cvat", video=path)
    assert df.attrs["frame_shift"] == 0 and df.attrs["frame_check"].startswith("4 images compared")
    assert len(df) == len(truth)


def test_a_static_shot_cannot_decide_and_keeps_the_file_numbers(tmp_path, truth):
    still = np.full((120, 160, 3), 90, np.uint8)
    still[40:80, 60:100] = (10, 200, 30)
    path = write_video(tmp_path / "still.avi", [still] * 20, fps=10.0)
    info = probe(path)
    out = export_dataset(truth, "coco", tmp_path / "c", info, video_path=path)
    df = import_dataset(out, "coco", video=path)
    assert df.attrs["frame_shift"] == 0 and "undecided" in df.attrs["frame_check"]
    assert sorted(df["frame"].unique()) == list(range(20))
