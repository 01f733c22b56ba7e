import io

import pandas as pd
import pytest

from partlab.tracking.core.box import Box
from partlab.tracking.tracks import (
    COLUMNS,
    TAKE_COLUMNS,
    TrackRecord,
    TracksCSVError,
    frame_to_records,
    read_tracks_csv,
    records_to_frame,
    write_tracks_csv,
)

HEADER = "frame,track_id,part,x,y,w,h"


def _read(text):
    return read_tracks_csv(io.StringIO(text), name="t.csv")


def test_round_trip(tmp_path):
    recs = [TrackRecord(3, 1, "head", Box(10.5, 20, 8, 9), score=0.75, failure=True, occluded=0.25,
                        state="normal", source="human"),
            TrackRecord(0, 2, "torso", Box(1, 2, 3, 4))]
    path = tmp_path / "tracks.csv"
    write_tracks_csv(records_to_frame(recs), path)
    first = path.read_text().splitlines()[0]
    assert first == ",".join(c for c in COLUMNS if c not in TAKE_COLUMNS)  # 2D files stay as they were
    back = frame_to_records(read_tracks_csv(path))
    assert back[0].frame == 0
    assert pd.Series(back[1].as_row()).equals(pd.Series(recs[0].as_row()))  # NaN X,Y,Z equal NaN


def test_camera_and_3d_columns_round_trip(tmp_path):
    recs = [TrackRecord(5, 1, "left_hand", Box(10, 20, 8, 9), camera="cam1", X=-120.5, Y=300.25, Z=1510.0),
            TrackRecord(5, 1, "left_shoulder", Box(40, 20, 4, 4), camera="cam1", X=-200, Y=250, Z=1400),
            TrackRecord(5, 1, "head", Box(1, 2, 3, 4), camera="cam2")]
    path = tmp_path / "tracks3d.csv"
    write_tracks_csv(records_to_frame(recs), path)
    assert path.read_text().splitlines()[0].endswith(",camera,X,Y,Z")
    back = read_tracks_csv(path)
    hand = back[back.part == "left_hand"].iloc[0]
    assert (hand.camera, hand.X, hand.Y, hand.Z) == ("cam1", -120.5, 300.25, 1510.0)
    assert back[back.part == "head"].iloc[0][["X", "Y", "Z"]].isna().all()
    with pytest.raises(TracksCSVError, match="column 'Z'"):
        _read(HEADER + ",camera,X,Y,Z\n0,1,head,1,2,3,4,cam0,1,2,inf\n")


def test_optional_columns_and_unknown_columns():
    df = _read(HEADER + ",colour,failure\n0,1,head,1,2,3,4,red,1\n")
    assert list(df.columns) == list(COLUMNS)
    assert bool(df.failure[0]) is True
    assert df.source[0] == "tracker"


@pytest.mark.parametrize("text,message", [
    ("frame,track_id,part,x,y,w\n", "missing column(s) 'h'"),
    ("track_id,frame,part,x,y,w,h\n", "in that order"),
    (HEADER + "\n0,1,elbow,1,2,3,4\n", "line 2, column 'part': unknown part 'elbow'"),
    (HEADER + "\n0,1,head,1,2,3,4\n1,1,head,1,2,-3,4\n", "line 3, column 'w': negative size -3"),
    (HEADER + "\n0,1,head,1,abc,3,4\n", "line 2, column 'y': 'abc' is not a number"),
    (HEADER + "\nx,1,head,1,2,3,4\n", "line 2, column 'frame': 'x' is not an integer"),
    (HEADER + "\n0,1,head\n", "line 2: 3 cells"),
    ("", "empty"),
])
def test_malformed_csv_names_line_and_column(text, message):
    with pytest.raises(TracksCSVError) as err:
        _read(text)
    assert message in str(err.value)
    assert str(err.value).startswith("t.csv")


def test_write_sorts_by_frame_track_part():
    df = pd.DataFrame({"frame": [1, 0, 0], "track_id": [1, 2, 1], "part": ["head", "head", "torso"],
                       "x": [0, 0, 0], "y": [0, 0, 0], "w": [1, 1, 1], "h": [1, 1, 1]})
    buf = io.StringIO()
    write_tracks_csv(df, buf)
    rows = buf.getvalue().splitlines()[1:]
    assert [r.split(",")[:3] for r in rows] == [["0", "1", "torso"], ["0", "2", "head"], ["1", "1", "head"]]


def _mixed_records(take: bool) -> list[TrackRecord]:
    import math

    recs = [TrackRecord(5, 2, "hipleg", Box(-0.0, 1.005, 2.675, 300.125), score=float("nan")),
            TrackRecord(5, 2, "head", Box(10.5, 20, 8, 9), score=0.755, failure=True, occluded=0.25,
                        state="lost, coasting", source="human"),
            TrackRecord(0, 10, "person", Box(1e5, 2, 3, 4), score=-1.5),
            TrackRecord(5, 1, "right_hand", Box(7, 8, 9, 10), state='say "hi"'),
            TrackRecord(0, 3, "torso", Box(1, 2, 3, 4))]
    if take:
        recs.append(TrackRecord(2, 4, "head", Box(1, 1, 5, 5), camera="cam1", X=12.345, Y=math.nan, Z=-0.004))
    return recs


@pytest.mark.parametrize("take", [False, True])
def test_the_pandas_free_writer_and_reader_give_the_tables_bytes_and_rows(tmp_path, take):
    from partlab.tracking.tracks import read_track_records, write_track_records

    recs = _mixed_records(take)
    write_tracks_csv(records_to_frame(recs), tmp_path / "pandas.csv")
    write_track_records(recs, tmp_path / "plain.csv")
    text = (tmp_path / "pandas.csv").read_bytes()
    assert (tmp_path / "plain.csv").read_bytes() == text
    assert (b"cam1" in text) is take and b'"lost, coasting"' in text
    back = read_track_records(tmp_path / "plain.csv")
    # the same rows, in the file's order (compared as text: NaN is not equal to itself)
    assert [repr(r) for r in frame_to_records(read_tracks_csv(tmp_path / "plain.csv"))] == [repr(r) for r in back]
    assert [(r.frame, r.track_id, r.part) for r in back][:3] == [(0, 3, "torso"), (0, 10, "person"), (2, 4, "head")
                                                                 if take else (5, 1, "right_hand")]
    with pytest.raises(TracksCSVError, match="line 2, column 'w'"):
        read_track_records(io.StringIO(HEADER + "\n0,1,head,1,2,-3,4\n"), name="t.csv")
