"""partlab batch on a local Dask cluster: same rows as partlab track, resumable, failures per clip."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from partlab.cli import main
from partlab.engine import batch, cluster
from partlab.tracking.core.box import iou_xywh
from partlab.tracking.tracks import normalise_tracks, read_tracks_csv

SETTINGS = batch.Settings(tracker="body", model="default", seed=5, chunk=0, overlap=0)


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    """Two short synthetic scenes (one walker; two crossing) and a file that is no video."""
    d = tmp_path_factory.mktemp("clips")
    for name, scenario, seed in (("a", "single", 0), ("b", "pair_cross", 1)):
        assert main(["synth", str(d / name), "--scenario", scenario, "--seed", str(seed), "--frames", "30",
                     "--size", "320x240"]) == 0
    (d / "broken.mp4").write_bytes(b"\0not a video" * 50)
    return d


@pytest.fixture(scope="module")
def client():
    with cluster.client(workers=1, dashboard=None) as c:
        yield c


def test_plan_chunks():
    assert batch.plan_chunks(120, 0, 10) == [(0, 0, 120)]
    assert batch.plan_chunks(110, 100, 10) == [(0, 0, 110)]  # fits in chunk + overlap: one task
    assert batch.plan_chunks(250, 100, 10) == [(0, 0, 100), (90, 100, 200), (190, 200, 250)]


def _walk(frames, tid, x0, dx, y=40.0):
    return [dict(frame=f, track_id=tid, part=p, x=x0 + dx * f + off, y=y + yo, w=w, h=h)
            for f in frames for p, off, yo, w, h in (("head", 4.0, 0.0, 10.0, 10.0), ("torso", 0.0, 12.0, 18.0, 30.0))]


def test_join_chunks_matches_identities_on_the_overlap():
    first = pd.DataFrame(_walk(range(0, 20), 1, 10.0, 2.0) + _walk(range(0, 20), 4, 200.0, -2.0))
    # the second chunk ran frames 15..39 and numbered the same two people 0 and 1 (swapped), plus a
    # newcomer 2 who appears at frame 30; its rows at 15..19 are the overlap
    second = pd.DataFrame(_walk(range(15, 40), 0, 200.0, -2.0, 40.5) + _walk(range(15, 40), 1, 10.5, 2.0)
                          + _walk(range(30, 40), 2, 100.0, 0.0, 150.0))
    joined = batch.join_chunks([(0, first), (20, second)], overlap=5)
    assert joined["frame"].min() == 0 and joined["frame"].max() == 39
    assert len(joined) == 2 * (2 * 40) + 2 * 10  # no overlap row twice
    at = joined[(joined.frame == 30) & (joined.part == "head")].set_index("track_id")["x"]
    assert at.to_dict() == {1: 10.5 + 60.0 + 4.0, 4: 200.0 - 60.0 + 4.0, 5: 104.0}  # newcomer: id 5 = max + 1
    assert not joined.duplicated(["frame", "track_id", "part"]).any()


def test_batch_gives_partlab_track_rows_and_resumes(client, clips, tmp_path):
    from partlab.app.pipeline import track_path
    from partlab.models.bundle import default_bundle

    jobs = batch.discover(clips)
    assert [j.name for j in jobs] == ["a", "b", "broken"]
    sink = batch.FolderSink(tmp_path / "out")
    report = batch.run_batch(client, jobs, SETTINGS, sink)
    assert sorted(d["name"] for d in report.done) == ["a", "b"]
    assert [f["name"] for f in report.failed] == ["broken"] and "not a video" in report.failed[0]["error"]
    for name in ("a", "b"):
        expected = track_path(clips / name, "body", model=default_bundle(), seed=5).tracks
        got = read_tracks_csv(tmp_path / "out" / f"{name}.csv")
        assert len(got) > 20
        pd.testing.assert_frame_equal(got, read_tracks_csv(_csv(expected, tmp_path / f"{name}-track.csv")))
    assert read_tracks_csv(tmp_path / "out" / "b.csv")["track_id"].nunique() == 2
    # rerun: a and b are skipped; changing the seed makes them due again
    again = batch.run_batch(client, jobs, SETTINGS, sink)
    assert again.skipped == ["a", "b"] and [f["name"] for f in again.failed] == ["broken"] and not again.done
    other = batch.Settings(**{**SETTINGS.__dict__, "seed": 6})
    assert not sink.done(jobs[0], other)


def test_a_long_clip_in_chunks_keeps_one_identity_per_person(client, clips, tmp_path):
    job = batch.ClipJob("a", str(clips / "a"))
    # the second chunk starts at frame 1: its detector has found the walker well before frame 15
    # (about 5-10 frames after a start on this clip; the default overlap is 50)
    chunked = batch.Settings(tracker="body", model="default", seed=5, chunk=15, overlap=14)
    report = batch.run_batch(client, [job], chunked, batch.FolderSink(tmp_path))
    assert report.done[0]["chunks"] == 2
    got = read_tracks_csv(tmp_path / "a.csv")
    whole = read_tracks_csv(_csv(track_one(clips / "a"), tmp_path / "whole.csv"))
    # the walker keeps its id across the boundary at frame 15: one track of the same frames and parts
    # as the whole run's. Each run may also start a short-lived track on a spurious blob near the end
    # (where the detector scans depends on the chunk's first frame), never more than a few frames
    keys = ["frame", "track_id", "part"]
    walker = whole.track_id.value_counts().idxmax()
    assert got.track_id.value_counts().idxmax() == walker == 1
    w_got, w_whole = got[got.track_id == walker], whole[whole.track_id == walker]
    pd.testing.assert_frame_equal(w_got[keys].reset_index(drop=True), w_whole[keys].reset_index(drop=True))
    for run in (got, whole):
        others = run[run.track_id != walker]
        assert others.frame.nunique() <= 4, others.groupby("track_id").frame.agg(["min", "max"])
    # before the boundary the chunked run is the whole run; after it, the chunk that started one
    # frame later (its own particles, its own detections) keeps the walker's person box on the
    # whole run's
    pd.testing.assert_frame_equal(got[got.frame < 15].reset_index(drop=True),
                                  whole[whole.frame < 15].reset_index(drop=True))
    a, b = (w[(w.part == "person") & (w.frame >= 15)][["x", "y", "w", "h"]].to_numpy() for w in (w_got, w_whole))
    iou = iou_xywh(a, b).diagonal()
    assert len(iou) == 15 and np.median(iou) >= 0.6, iou.round(2)


def track_one(path):
    from partlab.app.pipeline import track_path
    from partlab.models.bundle import default_bundle

    return track_path(path, "body", model=default_bundle(), seed=5).tracks


def _csv(df, path):
    from partlab.tracking.tracks import write_tracks_csv

    write_tracks_csv(normalise_tracks(df), path)
    return path


def test_batch_into_the_store_skips_what_is_stored(backend, client, clips, tmp_path):
    from partlab.labelling.store import Store

    store = Store()
    project = store.create_project("pre")
    clip = store.add_clip(project.id, clips / "a" / "clip.mp4")
    jobs = batch.project_clips(store, "pre")
    report = batch.run_batch(client, jobs, SETTINGS, batch.StoreSink(store.url))
    assert [d["name"] for d in report.done] == [f"{clip.id}-clip.mp4".replace(".mp4", "")]
    stored = store.tracks(clip.id).drop(columns="revision")
    assert len(stored) == report.done[0]["boxes"] > 20
    runs = store.runs(clip.id)
    assert runs[["tracker", "bundle", "seed"]].values.tolist() == [["body", "default", 5]]
    assert batch.run_batch(client, jobs, SETTINGS, batch.StoreSink(store.url)).skipped == [jobs[0].name]


def test_killed_batch_finishes_only_the_rest(clips, tmp_path):
    """Kill `partlab batch` once its first clip is written; the rerun tracks only the others."""
    out = tmp_path / "out"
    manifest = tmp_path / "m.csv"
    manifest.write_text("path,name\n" + "".join(f"{clips / n},{n}{k}\n" for k in range(2) for n in "ab"))
    cmd = [sys.executable, "-m", "partlab", "batch", str(manifest), "-o", str(out), "--model", "default",
           "--seed", "5", "--workers", "1", "--no-progress"]
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    proc = subprocess.Popen(cmd, env=env, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 300
        while not list(out.glob("*.done.json")) and time.time() < deadline and proc.poll() is None:
            time.sleep(0.2)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    first = {p.name: p.stat().st_mtime_ns for p in out.glob("*.done.json")}
    assert 1 <= len(first) < 4
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert f"{4 - len(first)} clip(s) tracked, {len(first)} already done, 0 failed" in done.stdout
    assert {p.name: p.stat().st_mtime_ns for p in out.glob("*.done.json") if p.name in first} == first
    a0, a1 = read_tracks_csv(out / "a0.csv"), read_tracks_csv(out / "a1.csv")
    pd.testing.assert_frame_equal(a0, a1)  # same clip, same seed: same rows, killed or not
    assert json.loads((out / "b1.done.json").read_text())["settings"]["seed"] == 5
    assert np.all(pd.read_csv(out / "batch.csv")["status"] == "done")
