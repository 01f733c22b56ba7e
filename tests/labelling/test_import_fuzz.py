"""Any input to an importer gives either a table partlab's own tracks CSV reader accepts back after
``write_tracks_csv``, or a refusal (FormatError / UserError) naming the file; never another exception."""

import io
import json
import shutil
import tempfile
from pathlib import Path

import pandas as pd
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from partlab.errors import UserError
from partlab.labelling.events import EventsError, read_events
from partlab.labelling.formats import FormatError, import_dataset
from partlab.tracking.tracks import read_tracks_csv, write_tracks_csv

FAST = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])

#: the numbers and look-alikes that broke the readers before: huge, NaN/inf, negative, text, bools, lists
NUMBERS = st.one_of(
    st.integers(min_value=-3, max_value=40), st.sampled_from([2**31, 2**63, 2**70, -1e308, 1e308, 1e20, 0.5, -2.5]),
    st.floats(allow_nan=True, allow_infinity=True), st.booleans(), st.none(),
    st.sampled_from(["1", "false", "true", "nan", "", "x", "1e308"]), st.lists(st.integers(0, 3), max_size=2),
    st.just({}),
)
#: mostly plausible numbers, sometimes hostile ones (so both branches of the property are exercised)
VALUE = st.one_of(st.integers(0, 30), st.integers(0, 30), st.floats(0, 50), NUMBERS)
JSON = st.recursive(st.one_of(NUMBERS, st.text(max_size=5)),
                    lambda children: st.lists(children, max_size=3) | st.dictionaries(st.text(max_size=4), children,
                                                                                       max_size=3), max_leaves=8)


ACCEPTED: list[str] = []


def _check(path: Path, fmt: str) -> None:
    try:
        df = import_dataset(path, fmt)
    except (FormatError, UserError) as exc:
        assert "\n" not in str(exc) or fmt == "cvat"  # one line (an XML parser's message may quote a line)
        return
    finally:
        shutil.rmtree(path.parent, ignore_errors=True)
    ACCEPTED.append(fmt)
    out = io.StringIO()
    write_tracks_csv(df, out)
    back = read_tracks_csv(io.StringIO(out.getvalue()), name="back.csv")
    assert len(back) == len(df)
    pd.testing.assert_series_equal(back["frame"], df["frame"])
    pd.testing.assert_series_equal(back["failure"], df["failure"])


def _write(name: str, data) -> Path:
    d = Path(tempfile.mkdtemp(prefix="partlab-fuzz-"))
    p = d / name
    if isinstance(data, bytes):
        p.write_bytes(data)
    else:
        p.write_text(data, encoding="utf-8")
    return p


ANNOTATION = st.fixed_dictionaries(
    {"id": VALUE, "image_id": st.sampled_from([1, 1, 2, "1", [1]]),
     "category_id": st.sampled_from([1, 2, 1, "1", None]),
     "bbox": st.one_of(st.lists(VALUE, min_size=4, max_size=4), st.lists(VALUE, min_size=4, max_size=4), JSON)},
    optional={"track_id": VALUE, "score": VALUE,
              "attributes": st.fixed_dictionaries({}, optional={
                  "failure": st.one_of(st.sampled_from(["false", "true", False, True, 0, 1]), NUMBERS),
                  "occluded": st.one_of(st.booleans(), NUMBERS), "occlusion": st.one_of(st.floats(0, 1), NUMBERS),
                  "track_id": VALUE, "outside": NUMBERS})})
IMAGE = st.fixed_dictionaries({"id": st.sampled_from([1, 2, 1, 2, "1", None, 1.5])},
                              optional={"frame_id": VALUE, "file_name": st.sampled_from(["f_000003.jpg", "", "x"])})


@FAST
@given(st.lists(IMAGE, max_size=3), st.lists(ANNOTATION, max_size=4), st.booleans())
@example([{"id": 1, "frame_id": 4}], [{"id": 1, "image_id": 1, "category_id": 1, "bbox": [1, 2, 3, 4],
                                      "attributes": {"failure": "false"}}], False)
def test_coco(images, annotations, wrap):
    doc = {"images": images, "annotations": annotations,
           "categories": [{"id": 1, "name": "head"}, {"id": 2, "name": "person"}]}
    _check(_write("a.json", json.dumps(doc if not wrap else {"images": doc, "annotations": [],
                                                             "categories": []})), "coco")


@FAST
@given(JSON)
def test_coco_any_json(doc):
    _check(_write("a.json", json.dumps(doc)), "coco")


CELL = st.sampled_from(["0", "1", "2", "3", "1", "2", "3", "7.5", "-1", "1.5", "nan", "inf", "1e308", "2147483648", "",
                        "x", "9" * 30])
ATTR = st.sampled_from(["xtl", "ytl", "xbr", "ybr", "frame", "outside", "keyframe", "occluded"])


@FAST
@given(st.lists(st.tuples(st.one_of(st.fixed_dictionaries({k: CELL for k in ("frame", "xtl", "ytl", "xbr", "ybr")}),
                                    st.dictionaries(ATTR, CELL, max_size=8)),
                          st.dictionaries(st.sampled_from(["person", "failure", "occlusion", "confidence", "X"]),
                                          CELL, max_size=3)), max_size=4),
       st.sampled_from(["head", "person", "car"]), CELL)
def test_cvat(boxes, label, group):
    xml = "".join("<box " + " ".join(f'{k}="{v}"' for k, v in attrs.items()) + ">"
                  + "".join(f'<attribute name="{n}">{v}</attribute>' for n, v in inner.items()) + "</box>"
                  for attrs, inner in boxes)
    _check(_write("annotations.xml", f'<annotations><track id="0" label="{label}" group_id="{group}">{xml}'
                                     "</track></annotations>"), "cvat")


@FAST
@given(st.lists(st.one_of(st.lists(CELL, min_size=9, max_size=9), st.lists(CELL, min_size=0, max_size=10)), max_size=5))
@example([["1", "2", "1", "1", "2", "2", "1", "1", "1"]])
def test_mot(rows):
    _check(_write("gt.txt", "\n".join(",".join(r) for r in rows) + "\n"), "mot")


@FAST
@given(st.lists(st.fixed_dictionaries({"frame": st.one_of(st.integers(1, 20), NUMBERS), "x": VALUE, "y": VALUE,
                                       "width": VALUE, "height": VALUE}, optional={"enabled": st.booleans()}),
                max_size=3),
       st.one_of(st.integers(1, 30), NUMBERS), st.one_of(st.just(100), NUMBERS), st.sampled_from(["t0-head", "r1", 5]))
def test_labelstudio(sequence, frames_count, width, rid):
    region = {"id": rid, "type": "videorectangle", "original_width": width, "original_height": 100,
              "value": {"labels": ["head"], "framesCount": frames_count, "sequence": sequence}}
    _check(_write("tasks.json", json.dumps([{"annotations": [{"result": [region]}]}])), "labelstudio")


@FAST
@given(st.binary(max_size=200), st.sampled_from(["coco", "labelstudio", "mot", "cvat", "parquet"]))
def test_any_bytes(data, fmt):
    name = {"coco": "a.json", "labelstudio": "tasks.json", "mot": "gt.txt", "cvat": "annotations.xml",
            "parquet": "tracks.csv"}[fmt]
    _check(_write(name, data), fmt)


@FAST
@given(st.lists(st.tuples(CELL, CELL, st.sampled_from(["clap", "pick", "x", ""])), max_size=4))
def test_events(rows):
    p = _write("events.csv", "start_frame,end_frame,kind\n" + "".join(f"{a},{b},{k}\n" for a, b, k in rows))
    try:
        df = read_events(p)
    except EventsError:
        return
    finally:
        shutil.rmtree(p.parent, ignore_errors=True)
    assert (df["start_frame"] <= df["end_frame"]).all() and (df["end_frame"] < 2**31).all()


def test_the_fuzzed_importers_also_accept():
    """Guard against a suite whose inputs are all refused: the examples above import (runs last)."""
    assert {"coco", "mot"} <= set(ACCEPTED)
