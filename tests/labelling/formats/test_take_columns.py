"""camera, X, Y, Z (the tracks CSV columns of takes) through `partlab export` / `partlab import` and the store."""

import numpy as np
import pandas as pd
import pytest

from partlab.cli import main
from partlab.labelling.formats import export_dataset, import_dataset
from partlab.labelling.store import Store
from partlab.tracking.core.box import Box
from partlab.tracking.tracks import read_tracks_csv, write_tracks_csv


def _with_points(truth: pd.DataFrame) -> pd.DataFrame:
    """Track 0 seen by cam1 with a 3D point (none at frame 4), track 3 by cam2 without points."""
    df = truth.copy()
    df["camera"] = np.where(df["track_id"] == 0, "cam1", "cam2")
    t0 = (df["track_id"] == 0) & (df["frame"] != 4)
    df["X"] = np.where(t0, 1000.0 + 12.5 * df["frame"], np.nan)
    df["Y"] = np.where(t0, -250.75, np.nan)
    df["Z"] = np.where(t0, 1700.0 - 0.25 * df["frame"], np.nan)
    return df


@pytest.fixture
def files(tmp_path, truth, clip):
    path, _ = clip
    write_tracks_csv(_with_points(truth), tmp_path / "tracks.csv")
    return tmp_path, path


@pytest.mark.parametrize("fmt", ["parquet", "cvat"])
def test_export_import_keeps_camera_and_xyz(files, fmt, capsys):
    d, video = files
    assert main(["export", str(d / "tracks.csv"), "--video", str(video), "--format", fmt, "-o", str(d / fmt),
                 "--no-frames"]) == 0
    assert main(["import", str(d / fmt), "--format", fmt, "-o", str(d / "back.csv")]) == 0
    before, back = read_tracks_csv(d / "tracks.csv"), read_tracks_csv(d / "back.csv")
    pd.testing.assert_frame_equal(back, before)
    row = back[(back.frame == 6) & (back.track_id == 0) & (back.part == "head")].iloc[0]
    assert (row.camera, row.X, row.Y, row.Z) == ("cam1", 1075.0, -250.75, 1698.5)
    assert back.loc[back.frame == 4, "X"].isna().all() and (back.loc[back.track_id == 3, "camera"] == "cam2").all()
    assert (d / "back.csv").read_text().splitlines()[0].endswith(",camera,X,Y,Z")


def test_cvat_declares_take_attributes_only_when_boxes_have_them(tmp_path, truth, clip):
    _, info = clip
    plain = export_dataset(truth, "cvat", tmp_path / "plain", info, frames=False)
    assert "<name>camera</name>" not in (plain / "annotations.xml").read_text()
    take = export_dataset(_with_points(truth), "cvat", tmp_path / "take", info, frames=False)
    xml = (take / "annotations.xml").read_text()
    assert xml.count("<name>camera</name>") == 10  # one per label
    assert '<attribute name="X">1000</attribute>' in xml
    assert import_dataset(plain, "cvat")["camera"].eq("").all()


def test_csv_store_csv_keeps_camera_and_xyz(backend, tmp_path, truth, clip):
    path, _ = clip
    store = Store(clips_dir=tmp_path / "clips")
    c = store.add_clip(store.create_project("p").id, path)
    write_tracks_csv(_with_points(truth), tmp_path / "in.csv")
    store.save_tracker_run(c.id, read_tracks_csv(tmp_path / "in.csv"), tracker="limbs")
    store.edit_box(c.id, 13, 3, "head", Box(60, 30, 10, 12), expected_revision=0, camera="cam2",
                   xyz=(-420.5, 88.25, 2210.0))
    write_tracks_csv(store.tracks(c.id), tmp_path / "out.csv")
    out = read_tracks_csv(tmp_path / "out.csv")
    want = _with_points(truth)
    key = (want.frame == 13) & (want.track_id == 3) & (want.part == "head")
    want.loc[key, ["x", "y", "w", "h", "X", "Y", "Z"]] = [60.0, 30.0, 10.0, 12.0, -420.5, 88.25, 2210.0]
    want = read_tracks_csv(_csv(want, tmp_path))  # sorted as the writer sorts
    cols = ["frame", "track_id", "part", "x", "y", "w", "h", "score", "camera", "X", "Y", "Z"]
    want.loc[(want.frame == 13) & (want.track_id == 3) & (want.part == "head"), "score"] = np.nan
    pd.testing.assert_frame_equal(out[cols], want[cols])
    edited = out[(out.frame == 13) & (out.track_id == 3) & (out.part == "head")].iloc[0]
    assert (edited.source, edited.camera, edited.Z) == ("human", "cam2", 2210.0)


def _csv(df, tmp_path):
    write_tracks_csv(df, tmp_path / "want.csv")
    return tmp_path / "want.csv"
