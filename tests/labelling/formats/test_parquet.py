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

    _, info = clip
    out = export_dataset(truth, "parquet", tmp_path / "p", info)
    (out / "stale.txt").write_text("old")
    export_dataset(truth.iloc[:10], "parquet", out, info)
    assert not (out / "stale.txt").exists() and len(import_dataset(out, "parquet")) == 10
    other = tmp_path / "mine"
    other.mkdir()
    (other / "thesis.tex").write_text("keep me")
    with pytest.raises(FormatError, match="not empty and holds no partlab export"):
        export_dataset(truth, "parquet", other, info)
    assert (other / "thesis.tex").read_text() == "keep me"
