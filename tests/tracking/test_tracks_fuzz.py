"""Any input to the tracks CSV reader gives either a table its own writer and reader give back
unchanged, or a TracksCSVError naming the line (never another exception)."""

import io

import pandas as pd
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from partlab.tracking.tracks import TracksCSVError, read_tracks_csv, write_tracks_csv

CELLS = st.sampled_from(["0", "1", "-1", "2.5", "1e308", "1e20", "nan", "NaN", "inf", "-inf", "", " ", "head",
                         "person", "left_elbow", "elbow", "true", "false", "yes", "9223372036854775808",
                         "2147483648", "0.5", "1.5", "cam1", '"', "\x00", "é", "1,2"])
HEADERS = st.sampled_from(["frame,track_id,part,x,y,w,h", "frame,track_id,part,x,y,w,h,score,failure,occluded",
                           "frame,track_id,part,x,y,w,h,camera,X,Y,Z", "frame,track_id,part,x,y,w",
                           "track_id,frame,part,x,y,w,h", ""])


def _check(text: str) -> None:
    try:
        df = read_tracks_csv(io.StringIO(text), name="f.csv")
    except TracksCSVError as exc:
        assert str(exc).startswith("f.csv")
        return
    out = io.StringIO()
    write_tracks_csv(df, out)
    back = read_tracks_csv(io.StringIO(out.getvalue()), name="back.csv")
    pd.testing.assert_frame_equal(back[["frame", "track_id", "part"]], df[["frame", "track_id", "part"]])
    assert ((back[["x", "y", "w", "h"]] - df[["x", "y", "w", "h"]]).abs() <= 0.005 + 1e-9).all(axis=None)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(HEADERS, st.lists(st.lists(CELLS, min_size=0, max_size=12), max_size=6))
def test_structured_rows(header, rows):
    _check(header + "\n" + "\n".join(",".join(r) for r in rows) + "\n")


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=300))
def test_any_text(text):
    _check(text)
