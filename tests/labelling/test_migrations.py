"""The store's Alembic migrations: a database made by partlab 0.2.0 opens, migrated, with every edit."""

from datetime import UTC, datetime

import numpy as np
import pandas as pd
import pytest
from alembic.autogenerate import compare_metadata
from alembic.migration import MigrationContext
from legacy_schema import LEGACY
from sqlalchemy import create_engine, insert, text

from partlab.labelling import migrations
from partlab.labelling.config import database_url
from partlab.labelling.store import Base, Store, StoreError
from partlab.tracking.core.box import Box

T0 = datetime(2026, 11, 1, 12, 0, tzinfo=UTC)


def _schema_diff(url, metadata):
    eng = create_engine(url)
    try:
        with eng.connect() as conn:
            diff = compare_metadata(MigrationContext.configure(conn), metadata)
    finally:
        eng.dispose()
    return diff


def _legacy_database(url):
    """What partlab 0.2.0 left behind: its tables (no alembic_version), a clip with a tracker run
    and human edits: two revisions of one box, a deletion, an added box, an occluder, a bundle."""
    eng = create_engine(url)
    t = LEGACY.tables
    LEGACY.create_all(eng)
    with eng.begin() as c:
        c.execute(insert(t["projects"]), [dict(id=1, name="lab", default_bundle_id=1, created=T0)])
        c.execute(insert(t["clips"]), [dict(id=1, project_id=1, name="walk.mp4", path="/nowhere/walk.mp4",
                                            sha256="ab" * 32, fps=25.0, width=320, height=240, frame_count=50,
                                            exported=False, created=T0)])
        c.execute(insert(t["tracker_runs"]), [dict(id=1, clip_id=1, tracker="body", bundle="default", seed=3,
                                                   start_frame=0, created=T0)])
        c.execute(insert(t["tracker_boxes"]), [
            dict(clip_id=1, run_id=1, frame=f, track_id=1, part=p, x=10.0 + f, y=20.0 + i, w=30.0, h=40.0,
                 score=0.25 * (i + 1), failure=False, occluded=0.0, state="normal")
            for f in range(5) for i, p in enumerate(("head", "torso"))])
        c.execute(insert(t["edits"]), [
            dict(clip_id=1, frame=2, track_id=1, part="head", revision=1, x=50.5, y=21.0, w=30.0, h=40.0,
                 failure=False, occluded=0.0, deleted=False, author="ann", created=T0),
            dict(clip_id=1, frame=2, track_id=1, part="head", revision=2, x=51.5, y=22.0, w=31.0, h=41.0,
                 failure=True, occluded=0.5, deleted=False, author="bob", created=T0),
            dict(clip_id=1, frame=3, track_id=1, part="torso", revision=1, x=13.0, y=21.0, w=30.0, h=40.0,
                 failure=False, occluded=0.0, deleted=True, author="ann", created=T0),
            dict(clip_id=1, frame=4, track_id=2, part="head", revision=1, x=200.0, y=30.0, w=12.0, h=14.0,
                 failure=False, occluded=0.0, deleted=False, author="ann", created=T0)])
        c.execute(insert(t["occluders"]), [dict(clip_id=1, x=1.0, y=2.0, w=3.0, h=4.0)])
        c.execute(insert(t["bundles"]), [dict(id=1, project_id=1, name="b1", path="/nowhere/b1", summary="{}",
                                              created=T0)])
    eng.dispose()


def test_revision_1_is_exactly_the_previous_release_schema(backend):
    url = database_url()
    eng = create_engine(url)
    assert migrations.upgrade(eng, migrations.BASELINE) == "0001"
    eng.dispose()
    diff = [d for d in _schema_diff(url, LEGACY) if not (d[0] == "remove_table" and d[1].name == "alembic_version")]
    assert diff == []


def test_a_new_database_is_created_at_head_matching_the_models(backend, tmp_path):
    store = Store(clips_dir=tmp_path)
    with store.engine.connect() as conn:
        assert migrations.current(conn) == migrations.head() == "0005"
    assert _schema_diff(store.url, Base.metadata) == []
    assert migrations.known_revisions() == ["0001", "0002", "0003", "0004", "0005"]


def test_previous_release_database_is_migrated_and_keeps_every_edit(backend, tmp_path):
    url = database_url()
    _legacy_database(url)
    store = Store(clips_dir=tmp_path)
    with store.engine.connect() as conn:
        assert migrations.current(conn) == "0005"
        assert conn.execute(text("SELECT count(*) FROM edits")).scalar() == 4
    assert [p.name for p in store.projects()] == ["lab"] and store.project(1).default_bundle_id == 1
    hist = store.history(1, 2, 1, "head")
    assert hist["revision"].tolist() == [1, 2] and hist["author"].tolist() == ["ann", "bob"]
    assert hist["x"].tolist() == [50.5, 51.5] and hist["failure"].tolist() == [False, True]
    assert (hist["camera"] == "").all() and hist["X"].isna().all()
    df = store.tracks(1)
    # 10 tracker boxes, one replaced by the head edit, one deleted, one added by hand: 10 rows
    assert len(df) == 10
    head2 = df[(df.frame == 2) & (df.part == "head") & (df.track_id == 1)].iloc[0]
    assert (head2.x, head2.w, bool(head2.failure), head2.occluded, head2.source, head2.revision) == \
           (51.5, 31.0, True, 0.5, "human", 2)
    assert df[(df.frame == 3) & (df.part == "torso")].empty
    assert df[(df.track_id == 2)][["frame", "x"]].values.tolist() == [[4, 200.0]]
    torso1 = df[(df.frame == 1) & (df.part == "torso")].iloc[0]
    assert (torso1.x, torso1.score, torso1.state, torso1.camera) == (11.0, 0.5, "normal", "")
    assert store.occluders(1) == [Box(1.0, 2.0, 3.0, 4.0)] and store.runs(1)["seed"].tolist() == [3]
    # the migrated database takes 3D points: on an old edit, keeping its revisions going
    rev = store.edit_box(1, 2, 1, "head", Box(52, 22, 31, 41), expected_revision=2, author="cy", camera="cam1",
                         xyz=(1200.5, -340.25, 1710.0))
    assert rev == 3
    row = store.frame_boxes(1, 2).query("part == 'head' and track_id == 1").iloc[0]
    assert (row.camera, row.X, row.Y, row.Z, row.revision) == ("cam1", 1200.5, -340.25, 1710.0, 3)
    # failure flag and point carried on when an edit leaves them out
    store.edit_box(1, 2, 1, "head", Box(53, 22, 31, 41), expected_revision=3)
    row = store.frame_boxes(1, 2).query("part == 'head' and track_id == 1").iloc[0]
    assert (row.x, bool(row.failure), row.camera, row.Z) == (53.0, True, "cam1", 1710.0)
    assert store.undo(1, 2, 1, "head", expected_revision=4) == 5
    assert store.frame_boxes(1, 2).query("part == 'head' and track_id == 1").iloc[0].x == 52.0
    # opening again is a no-op
    assert migrations.upgrade(store.engine) == "0005"


def test_a_newer_schema_is_refused_and_left_alone(backend, tmp_path):
    url = database_url()
    eng = create_engine(url)
    migrations.upgrade(eng)
    with eng.begin() as c:
        c.execute(text("UPDATE alembic_version SET version_num = '0099'"))
    with pytest.raises(StoreError, match=r"revision '0099', made by a newer partlab; .* up to '0005'"):
        Store(clips_dir=tmp_path)
    with eng.connect() as c:
        assert c.execute(text("SELECT version_num FROM alembic_version")).scalar() == "0099"
    eng.dispose()


def test_a_failing_migration_leaves_the_database_as_it_was(tmp_path, monkeypatch):
    """SQLite runs DDL outside transactions unless told: a half-applied revision would strand the file."""
    url = f"sqlite:///{tmp_path / 'half.db'}"
    _legacy_database(url)
    from alembic.operations import Operations

    real = Operations.create_table

    def create_table(self, name, *cols, **kw):
        if name == "events":  # after takes, streams and the new columns of revision 2
            raise RuntimeError("disk full")
        return real(self, name, *cols, **kw)

    monkeypatch.setattr(Operations, "create_table", create_table)
    with pytest.raises(RuntimeError, match="disk full"):
        migrations.upgrade(create_engine(url))
    eng = create_engine(url)
    with eng.connect() as c:
        assert migrations.current(c) is None  # not even stamped
    assert _schema_diff(url, LEGACY) == []  # no takes table, no camera column
    monkeypatch.setattr(Operations, "create_table", real)
    assert migrations.upgrade(eng) == "0005"
    eng.dispose()


def test_tracks_with_camera_and_xyz_round_trip_through_the_store(backend, tmp_path):
    from partlab.labelling.video import write_video

    store = Store(clips_dir=tmp_path / "clips")
    clip = store.add_clip(store.create_project("p").id,
                          write_video(tmp_path / "c.mp4", [np.zeros((32, 48, 3), np.uint8)] * 6, fps=5))
    rows = [dict(frame=f, track_id=t, part="head", x=4.0 + f, y=5.0, w=6.0, h=7.0, score=0.5,
                 camera=f"cam{t}", X=100.25 * f, Y=-50.5 * t, Z=1500.0 + f if f != 3 else np.nan)
            for f in range(6) for t in (0, 1)]
    store.save_tracker_run(clip.id, pd.DataFrame(rows), tracker="limbs", seed=7)
    back = store.tracks(clip.id)
    assert back["camera"].tolist() == [f"cam{t}" for _ in range(6) for t in (0, 1)]
    assert back["X"].tolist() == [100.25 * f for f in range(6) for _ in (0, 1)]
    assert back["Y"].tolist() == [-50.5 * t for _ in range(6) for t in (0, 1)]
    assert back["Z"].isna().tolist() == [f == 3 for f in range(6) for _ in (0, 1)]
    assert back.loc[back.frame == 5, "Z"].tolist() == [1505.0, 1505.0]
