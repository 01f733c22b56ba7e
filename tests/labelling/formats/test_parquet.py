import pandas as pd

from labelling.formats import export_dataset, import_dataset
from tracking.tracks import read_tracks_csv


def test_parquet_and_csv_round_trip_exactly(tmp_path, truth, clip):
    _, info = clip
    out = export_dataset(truth, "parquet", tmp_path / "p", info)
    assert sorted(p.name for p in out.iterdir()) == ["partlab.json", "tracks.csv", "tracks.parquet"]
    back = import_dataset(out, "parquet")
    pd.testing.assert_frame_equal(back, truth)
    raw = pd.read_parquet(out / "tracks.parquet")
    assert raw["failure"].dtype == bool and raw["occluded"].max() == 0.25
    pd.testing.assert_frame_equal(read_tracks_csv(out / "tracks.csv"), truth, check_exact=False, atol=0.005)
