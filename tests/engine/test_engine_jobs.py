"""App jobs on Dask workers outside the server: they survive the server, show progress, cancel."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from partlab.app import jobs
from partlab.cli import main
from partlab.engine import jobs as engine
from partlab.labelling.store import Store

ROOT = Path(__file__).resolve().parents[2]
LONG = 2000  # frames of the job that is cancelled while it runs

SERVER = """
from partlab.app import runs
from partlab.labelling.store import Store
store = Store()
for clip_id in (1, 2):
    job = runs.start_tracking(store, store.clip(clip_id), "body", None, seed=3)
    print(job.id, flush=True)
"""


@pytest.fixture
def service(monkeypatch, tmp_path):
    monkeypatch.setenv("PARTLAB_JOBS", "engine")
    monkeypatch.setenv("PARTLAB_WORKERS", "1")
    yield
    try:
        pid = json.loads(engine.service_file().read_text())["pid"]
        os.kill(pid, signal.SIGTERM)
    except (OSError, ValueError, KeyError):
        pass


def test_a_track_job_outlives_its_server_shows_progress_and_cancels(service, tmp_path):
    # the long clip takes the worker well over the test's polling of the job list (a 400-frame one
    # was tracked to its end between two polls of a loaded PostgreSQL pass)
    for name, frames in (("short", 40), ("long", LONG)):
        assert main(["synth", str(tmp_path / name), "--scenario", "single", "--seed", "2", "--frames", str(frames),
                     "--size", "320x240"]) == 0
    store = Store()
    project = store.create_project("p")
    short = store.add_clip(project.id, tmp_path / "short" / "clip.mp4")
    long = store.add_clip(project.id, tmp_path / "long" / "clip.mp4")
    assert (short.id, long.id) == (1, 2)
    # "server 1" starts both jobs and stops at once (killed before its jobs could end)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    assert jobs.get("none") is None  # reads the job table once (imports the engine) before the clock matters
    started = subprocess.run([sys.executable, "-c", SERVER], env=env, capture_output=True, text=True, timeout=300)
    assert started.returncode == 0, started.stderr
    short_id, long_id = started.stdout.split()
    # this process is the restarted server: it sees both jobs. The second (run after the first on the
    # one worker) shows live progress, then is cancelled from the job list before it ends
    deadline = time.time() + 300
    while time.time() < deadline:
        job = jobs.get(long_id)
        if job.status == "running" and job.done >= 5:
            break
        time.sleep(0.1)
    assert job.active and job.total == LONG and 0 < job.fraction < 1
    assert [j.id for j in jobs.active("track", clip_id=long.id)] == [long_id]
    jobs.cancel(long_id)
    ended = jobs.wait(long_id, timeout=60)
    assert ended.status == "cancelled" and ended.done < LONG
    assert store.runs(long.id).empty  # nothing half-stored
    # the first finished and was stored
    done = jobs.wait(short_id, timeout=300)
    assert done.status == "done", done.error
    from partlab.app.pipeline import track_video

    stored = store.tracks(short.id).drop(columns="revision")
    assert len(stored) == done.result["boxes"] > 20
    expected = track_video(tmp_path / "short" / "clip.mp4", "body", seed=3)
    expected = expected.sort_values(["frame", "track_id", "part"], kind="stable").reset_index(drop=True)
    pd.testing.assert_frame_equal(stored[["frame", "track_id", "part"]], expected[["frame", "track_id", "part"]])
    assert abs(stored[["x", "y", "w", "h"]].to_numpy() - expected[["x", "y", "w", "h"]].to_numpy()).max() < 1e-9
    assert store.runs(short.id)[["tracker", "seed"]].values.tolist() == [["body", 3]]
    assert jobs.clear_finished() >= 2 and jobs.get(short_id) is None


def test_a_queued_job_cancelled_never_runs(service, tmp_path):
    store = Store()
    with store._session():
        pass
    job_id = engine.submit("test", "sleepy", _never, meta={})
    engine.cancel(job_id)
    row = engine.wait(job_id, timeout=60)
    assert row["status"] == "cancelled" and row["done"] == 0
    assert pd.isna(row["result"]) or row["result"] is None


def _never(progress):  # pragma: no cover - cancelled before it runs
    raise AssertionError("a cancelled job ran")
