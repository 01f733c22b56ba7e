import io
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pandas as pd
import pytest

from partlab.labelling.store import StaleEditError, Store, StoreError
from partlab.labelling.video import VideoError, write_video
from partlab.tracking.core.box import Box
from partlab.tracking.tracks import read_tracks_csv, write_tracks_csv


def _clip(path, n=10):
    frames = [np.full((48, 64, 3), 20 * i, np.uint8) for i in range(n)]
    return write_video(path, frames, fps=10)


def _tracks(n_frames=10, tracks=(1, 2)):
    rows = []
    for f in range(n_frames):
        for t in tracks:
            rows.append(dict(frame=f, track_id=t, part="head", x=10 + f, y=5.0 * t, w=8, h=9, score=0.5))
            rows.append(dict(frame=f, track_id=t, part="torso", x=8 + f, y=14.0 * t, w=12, h=20, score=0.7))
    return pd.DataFrame(rows)


@pytest.fixture
def store_and_clip(tmp_path, backend):
    store = Store()
    project = store.create_project("p")
    clip = store.add_clip(project.id, _clip(tmp_path / "walk.mp4"))
    return store, clip


def test_project_and_clip(tmp_path, store_and_clip):
    store, clip = store_and_clip
    assert (clip.width, clip.height, clip.frame_count) == (64, 48, 10)
    assert clip.path.exists() and clip.path.name.startswith(clip.sha256)
    assert store.add_clip(clip.project_id, clip.path).id == clip.id  # same content, same clip
    with pytest.raises(StoreError, match="exists already"):
        store.create_project("p")
    bad = tmp_path / "notes.mp4"
    bad.write_text("hello" * 100)
    with pytest.raises(VideoError, match="not a video"):
        store.add_clip(clip.project_id, bad)


def test_round_trip_clip_store_csv_store(tmp_path, store_and_clip):
    store, clip = store_and_clip
    truth = _tracks()
    store.save_tracker_run(clip.id, truth)
    buf = io.StringIO()
    write_tracks_csv(store.tracks(clip.id), buf)
    back = read_tracks_csv(io.StringIO(buf.getvalue()))
    store2_clip = store.add_clip(store.create_project("q").id, clip.path)
    store.save_tracker_run(store2_clip.id, back)
    a = store.tracks(clip.id).drop(columns="revision")
    b = store.tracks(store2_clip.id).drop(columns="revision")
    pd.testing.assert_frame_equal(a, b)
    assert len(a) == 40
    assert a.loc[(a.frame == 3) & (a.track_id == 2) & (a.part == "torso"), "x"].item() == 11


def test_edits_are_revisions_and_survive_tracker_runs(store_and_clip):
    store, clip = store_and_clip
    store.save_tracker_run(clip.id, _tracks())
    assert store.revision(clip.id, 4, 1, "head") == 0
    r1 = store.edit_box(clip.id, 4, 1, "head", Box(30, 30, 10, 10), expected_revision=0, author="ann")
    r2 = store.edit_box(clip.id, 4, 1, "head", Box(30, 30, 10, 10), failure=True, expected_revision=r1)
    box = store.frame_boxes(clip.id, 4).query("track_id == 1 and part == 'head'").iloc[0]
    assert (box.x, box.w, bool(box.failure), box.source, box.revision) == (30, 10, True, "human", 2)
    r3 = store.edit_box(clip.id, 4, 1, "head", None, expected_revision=r2)  # None deletes
    assert store.frame_boxes(clip.id, 4).query("track_id == 1 and part == 'head'").empty
    r4 = store.undo(clip.id, 4, 1, "head", expected_revision=r3)
    box = store.frame_boxes(clip.id, 4).query("track_id == 1 and part == 'head'").iloc[0]
    assert (r1, r2, r3, r4) == (1, 2, 3, 4)
    assert (box.x, box.w, bool(box.failure), box.source) == (30, 10, True, "human")
    # a new tracker run replaces tracker boxes, never the human edit
    moved = _tracks().assign(x=lambda d: d.x + 100)
    store.save_tracker_run(clip.id, moved)
    boxes = store.frame_boxes(clip.id, 4).set_index(["track_id", "part"])
    assert boxes.loc[(1, "head"), "x"] == 30
    assert boxes.loc[(2, "head"), "x"] == 114
    assert len(store.history(clip.id, 4, 1, "head")) == 4


def test_retrack_from_frame_replaces_only_later_frames(store_and_clip):
    store, clip = store_and_clip
    store.save_tracker_run(clip.id, _tracks())
    store.save_tracker_run(clip.id, _tracks().assign(y=99.0), start_frame=6, stop_frame=8)
    t = store.tracks(clip.id)
    assert set(t[t.y == 99.0].frame) == {6, 7}
    assert (t[t.frame < 6].y != 99).all() and (t[t.frame >= 8].y != 99).all()


def test_stale_edit_refused_with_message(store_and_clip):
    store, clip = store_and_clip
    store.save_tracker_run(clip.id, _tracks())
    other = Store()  # a second browser session
    store.edit_box(clip.id, 2, 1, "torso", Box(1, 1, 5, 5), expected_revision=0, author="a")
    with pytest.raises(StaleEditError, match=r"changed by someone else \(revision 1, you had 0\)"):
        other.edit_box(clip.id, 2, 1, "torso", Box(9, 9, 5, 5), expected_revision=0, author="b")
    assert store.frame_boxes(clip.id, 2).query("track_id == 1 and part == 'torso'").x.item() == 1


def test_edit_outside_clip_and_unknown_part(store_and_clip):
    store, clip = store_and_clip
    with pytest.raises(StoreError, match="outside clip"):
        store.edit_box(clip.id, 10, 1, "head", Box(0, 0, 1, 1), expected_revision=0)
    with pytest.raises(ValueError, match="unknown part"):
        store.edit_box(clip.id, 1, 1, "elbow", Box(0, 0, 1, 1), expected_revision=0)


def test_occluders_bundles_progress(tmp_path, store_and_clip):
    store, clip = store_and_clip
    store.set_occluders(clip.id, [Box(1, 2, 3, 4)])
    assert store.occluders(clip.id) == [Box(1, 2, 3, 4)]
    b = store.add_bundle(clip.project_id, "v1", tmp_path / "b", {"tnr": 0.9})
    store.set_default_bundle(clip.project_id, b.id)
    assert store.project(clip.project_id).default_bundle_id == b.id
    assert store.bundles(clip.project_id)[0].summary == {"tnr": 0.9}
    store.edit_box(clip.id, 3, 5, "head", Box(0, 0, 2, 2), expected_revision=0)
    assert store.progress(clip.id)["corrected_frames"] == 1
    assert store.next_track_id(clip.id) == 6


def test_a_sqlite_store_writes_ahead(tmp_path):
    """WAL: readers (the app's pages) never wait for a writer (a tracking job)."""
    store = Store(f"sqlite:///{tmp_path / 'wal.db'}")
    with store.engine.connect() as c:
        assert c.exec_driver_sql("PRAGMA journal_mode").scalar() == "wal"


def test_killed_writer_loses_no_committed_edit(tmp_path, store_and_clip):
    """A process killed mid-way through a stream of edits: every edit it reported as
    committed is in the store afterwards, and the store still opens and accepts edits."""
    store, clip = store_and_clip
    script = textwrap.dedent(f"""
        import sys
        from partlab.labelling.store import Store
        from partlab.tracking.core.box import Box
        s = Store()
        revs = [0] * 10
        for i in range(100000):
            revs[i % 10] = s.edit_box({clip.id}, i % 10, 7, "head", Box(i, 0, 5, 5), expected_revision=revs[i % 10])
            print(i, revs[i % 10], flush=True)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=os.environ.copy())
    committed = []
    deadline = time.time() + 60
    while len(committed) < 150 and time.time() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        committed.append(tuple(map(int, line.split())))
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert len(committed) >= 150, "the writer did not start"
    fresh = Store()
    for i, rev in committed:
        hist = fresh.history(clip.id, i % 10, 7, "head")
        assert rev in set(hist.revision), f"edit {i} (revision {rev}) was lost"
        assert hist.set_index("revision").loc[rev, "x"] == i
    if fresh.url.startswith("sqlite"):
        with fresh.engine.connect() as c:
            assert c.exec_driver_sql("PRAGMA integrity_check").scalar() == "ok"
    last = fresh.revision(clip.id, 0, 7, "head")
    assert fresh.edit_box(clip.id, 0, 7, "head", Box(1, 1, 1, 1), expected_revision=last) == last + 1


def test_unusable_boxes_are_refused_by_the_store(store_and_clip):
    """NaN, inf, negative sizes and ids beyond int32 never reach the database (edits and tracker runs)."""
    import math

    _pytest = pytest
    store, clip = store_and_clip
    for box, says in ((Box(math.nan, 1, 2, 2), "x: 'nan' is not a finite number"),
                      (Box(1, 1, math.inf, 2), "w: 'inf' is not a finite number"),
                      (Box(1, 1, 2, 2e7), "h: '20000000.0' is beyond the limit")):
        with _pytest.raises(StoreError, match=says):
            store.edit_box(clip.id, 0, 1, "head", box, expected_revision=0)
    with _pytest.raises(StoreError, match="track_id: 2147483648 is larger than the limit"):
        store.edit_box(clip.id, 0, 2**31, "head", Box(1, 1, 2, 2), expected_revision=0)
    with _pytest.raises(StoreError, match="occluded: '2' is not a fraction"):
        store.edit_box(clip.id, 0, 1, "head", Box(1, 1, 2, 2), occluded=2, expected_revision=0)
    run = pd.DataFrame({"frame": [0, 1], "track_id": [0, 0], "part": ["head", "head"], "x": [1.0, 1.0],
                        "y": [1.0, 1.0], "w": [2.0, -3.0], "h": [2.0, 2.0]})
    with _pytest.raises(StoreError, match="row 2, column 'w': negative size -3"):
        store.save_tracker_run(clip.id, run)
    assert store.tracks(clip.id).empty


def test_an_unreachable_database_fails_fast_without_its_password(monkeypatch):
    """A server that accepts the connection and never answers: refused within the connect timeout, the
    message names the URL with its password hidden."""
    import socket
    import threading

    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)
    port = listener.getsockname()[1]
    held = []
    threading.Thread(target=lambda: held.append(listener.accept()), daemon=True).start()
    monkeypatch.setenv("PARTLAB_DB_CONNECT_TIMEOUT", "1")
    url = f"postgresql+psycopg://labeller:s3cret@127.0.0.1:{port}/partlab"
    start = time.monotonic()
    shown = rf"postgresql\+psycopg://labeller:\*\*\*@127.0.0.1:{port}/partlab"
    with pytest.raises(StoreError, match=rf"cannot reach the database {shown} within 1 s") as exc:
        Store(url)
    assert time.monotonic() - start < 10 and "s3cret" not in str(exc.value)
    listener.close()
