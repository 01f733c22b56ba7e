import pandas as pd

from partlab.labelling.formats import export_dataset, import_dataset
from partlab.tracking.tracks import read_tracks_csv


def test_parquet_and_csv_round_trip_exactly(tmp_path, truth, clip):
    _, info = clip
    out = export_dataset(truth, "parquet", tmp_path / "p", info)
    assert sorted(p.name for p in out.iterdir()) == ["partlab.json", "tracks.csv", "tracks.parquet"]
    back = import_dataset(out, "parquet")
    pd.testing.assert_frame_equal(back, truth)
    raw = pd.read_parquet(out / "tracks.parquet")
    assert raw["failure"].dtype == bool and raw["occluded"].max() == 0.25
    pd.testing.assert_frame_equal(read_tracks_csv(out / "tracks.csv"), truth, check_exact=False, atol=0.005)


def test_export_replaces_a_previous_export_but_not_other_files(tmp_path, truth, clip):
    import pytest

    from partlab.labelling.formats import FormatError

    path, info = clip
    out = export_dataset(truth, "mot", tmp_path / "p", info, video_path=path)
    assert (out / "img1").is_dir()
    (out / "notes.txt").write_text("the user's own file")  # not written by the export: must survive
    export_dataset(truth.iloc[:10], "parquet", out, info)
    assert not (out / "img1").exists() and not (out / "gt").exists()  # the earlier export's files went
    assert (out / "notes.txt").read_text() == "the user's own file" and len(import_dataset(out, "parquet")) == 10
    export_dataset(truth, "parquet", out, info)  # and again: the notes are still not the export's
    assert (out / "notes.txt").exists()
    other = tmp_path / "mine"
    other.mkdir()
    (other / "thesis.tex").write_text("keep me")
    with pytest.raises(FormatError, match="not empty and holds no partlab export"):
        export_dataset(truth, "parquet", other, info)
    assert (other / "thesis.tex").read_text() == "keep me"
    (other / "partlab.json").write_text('{"format": "mot", "fps": 25, "width": 8, "height": 8, "frame_count": 1}')
    with pytest.raises(FormatError, match="did not list its files"):  # 0.1's manifest: nothing is guessed
        export_dataset(truth, "parquet", other, info)
    assert (other / "thesis.tex").read_text() == "keep me"
