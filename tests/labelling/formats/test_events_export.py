"""Events next to an export: CVAT for images tags, the COCO ``events`` extension, parquet and CSV,
read back by us and by the peers' own readers (Datumaro, pycocotools)."""

import json

import datumaro as dm
import pandas as pd
import pytest
from pycocotools.coco import COCO

from partlab.labelling.events import from_store, read_events
from partlab.labelling.formats import export_clip, import_dataset
from partlab.labelling.formats.events import read_coco_events, read_cvat_tags
from partlab.labelling.store import Store


@pytest.fixture
def stored(tmp_path, truth, clip):
    path, _ = clip
    store = Store(f"sqlite:///{tmp_path / 'db.sqlite'}", clips_dir=tmp_path / "clips")
    c = store.add_clip(store.create_project("p").id, path)
    store.save_tracker_run(c.id, truth)
    store.add_event(c.id, 2, 5, "clap", tracks=[0], parts=["left_hand", "right_hand"], confidence=0.75)
    store.add_event(c.id, 4, 13, "handshake", tracks=[0, 3], parts=["right_hand", "right_hand"],
                    attributes=dict(ended_by="split"))
    e = store.add_event(c.id, 15, 17, "pick", tracks=[3], parts=["right_hand"])
    store.edit_event(c.id, e, expected_revision=1, end_frame=19, type="place")
    return store, c


KEY = ["start_frame", "end_frame", "kind", "track_id_a", "part_a", "track_id_b", "part_b"]
WANT = [(2, 5, "clap", 0, "left_hand", 0, "right_hand"), (4, 13, "handshake", 0, "right_hand", 3, "right_hand"),
        (15, 19, "place", 3, "right_hand", 0, "")]


def _rows(df):
    return [tuple(r) for r in df[KEY].itertuples(index=False)]


def test_store_events_as_the_events_csv_table(stored):
    store, c = stored
    df = from_store(store.events(c.id))
    assert _rows(df) == WANT
    assert df.confidence.iloc[0] == 0.75 and df.ended_by.iloc[1] == "split"


def test_cvat_export_has_frame_range_tags_that_datumaro_reads(stored, tmp_path):
    store, c = stored
    out = export_clip(store, c.id, "cvat", tmp_path / "cvat")
    assert _rows(read_cvat_tags(out / "events.xml")) == WANT
    assert _rows(read_events(out / "events.csv")) == WANT
    ds = dm.Dataset.import_from(str(out / "events.xml"), "cvat")
    names = ds.categories()[dm.AnnotationType.label]
    tags = {(item.id, names[a.label].name) for item in ds for a in item.annotations
            if a.type == dm.AnnotationType.label}
    # one tag per frame of each range: 4 + 10 + 5 frames
    assert len(tags) == 19 and ("frame_000004", "clap") in tags and ("frame_000004", "handshake") in tags
    assert ("frame_000014", "handshake") not in tags and ("frame_000019", "place") in tags
    # the video XML stays tag-free: our import and Datumaro's read its boxes as before
    assert "<tag" not in (out / "annotations.xml").read_text()
    assert len(import_dataset(out, "cvat")) == len(store.tracks(c.id))


def test_coco_export_carries_an_events_extension_the_readers_ignore(stored, tmp_path):
    store, c = stored
    out = export_clip(store, c.id, "coco", tmp_path / "coco")
    doc = json.loads((out / "annotations/instances_default.json").read_text())
    assert [e["image_ids"] for e in doc["events"]] == [[3, 6], [5, 14], [16, 20]]
    assert {k["name"] for k in doc["event_categories"]} >= {"clap", "handshake", "exchange", "pick", "place"}
    assert _rows(read_coco_events(out / "labels.json")) == WANT  # the FiftyOne copy has them too
    coco = COCO(str(out / "annotations/instances_default.json"))
    assert len(coco.anns) == len(store.tracks(c.id))
    assert len(dm.Dataset.import_from(str(out), "coco")) == len(doc["images"])


def test_parquet_export_has_an_events_table(stored, tmp_path):
    store, c = stored
    out = export_clip(store, c.id, "parquet", tmp_path / "pq", frames=False)
    assert _rows(pd.read_parquet(out / "events.parquet")) == WANT


def test_a_clip_without_events_exports_no_event_files(tmp_path, truth, clip):
    path, _ = clip
    store = Store(f"sqlite:///{tmp_path / 'db.sqlite'}", clips_dir=tmp_path / "clips")
    c = store.add_clip(store.create_project("p").id, path)
    store.save_tracker_run(c.id, truth)
    out = export_clip(store, c.id, "cvat", tmp_path / "cvat", frames=False)
    assert not (out / "events.xml").exists() and not (out / "events.csv").exists()


def test_tags_made_in_cvat_become_one_event_per_run_of_frames(tmp_path):
    images = "".join(f'<image id="{f}" name="frame_{f:06d}"><tag label="{k}" source="manual"/></image>'
                     for f, k in ((3, "clap"), (4, "clap"), (5, "clap"), (9, "clap"), (4, "pick")))
    (tmp_path / "t.xml").write_text(f"<annotations><version>1.1</version>{images}</annotations>")
    df = read_cvat_tags(tmp_path / "t.xml")
    assert [(r.start_frame, r.end_frame, r.kind) for r in df.itertuples()] == [(3, 5, "clap"), (4, 4, "pick"),
                                                                                (9, 9, "clap")]
