"""Background jobs report progress, results and failures."""

from __future__ import annotations

import threading

from partlab.app import jobs


def test_job_progress_result_and_failure():
    gate = threading.Event()

    def work(progress):
        progress(3, 10)
        gate.wait(5)
        return 42

    job = jobs.submit("test", "count", work, clip_id=7)
    for _ in range(200):
        if job.done == 3:
            break
        threading.Event().wait(0.01)
    assert job.active and job.fraction == 0.3
    assert job in jobs.active("test", clip_id=7) and jobs.active("test", clip_id=8) == []
    gate.set()
    assert jobs.wait(job.id, 5).result == 42 and job.status == "done" and job.fraction == 1.0

    def boom(progress):
        raise ValueError("no frames")

    bad = jobs.wait(jobs.submit("test", "boom", boom).id, 5)
    assert bad.status == "failed" and bad.error == "ValueError: no frames"


def test_jobs_left_unfinished_by_a_stopped_server_are_reported_then_cleared():
    import json
    import os

    # a previous server process (another pid) journalled a tracking job that never ended,
    # and one that did
    old = [dict(id="a1", pid=os.getpid() + 1, kind="track", label="track walk.mp4 (body)", status="running",
                done=40, total=150, error="", time=1.0),
           dict(id="b2", pid=os.getpid() + 1, kind="track", label="track other.mp4", status="done",
                done=9, total=9, error="", time=2.0)]
    path = jobs.journal_path()
    path.write_text("".join(json.dumps(e) + "\n" for e in old) + "not json\n", encoding="utf-8")
    assert [(e["id"], e["done"], e["total"]) for e in jobs.interrupted()] == [("a1", 40, 150)]

    # this process's jobs are journalled, and never count as interrupted
    job = jobs.wait(jobs.submit("test", "quick", lambda progress: 1).id, 5)
    states = [json.loads(line)["status"] for line in path.read_text().splitlines()[3:]]
    assert states[0] == "queued" and states[-1] == "done" and job.id not in {e["id"] for e in jobs.interrupted()}

    assert jobs.clear_finished() >= 2 and jobs.interrupted() == []
    assert "a1" not in path.read_text()


def test_the_sidebar_reruns_the_page_once_when_a_job_it_saw_running_ends():
    gate = threading.Event()
    job = jobs.submit("test", "wait", lambda progress: gate.wait(5), clip_id=1)
    watched: set[str] = set()
    assert not jobs.ended_since(watched, jobs.active()) and watched == {job.id}
    assert not jobs.ended_since(watched, jobs.active())  # still running
    gate.set()
    jobs.wait(job.id, 5)
    assert jobs.ended_since(watched, jobs.active()) and watched == set()
    assert not jobs.ended_since(watched, jobs.active())  # once
    other = jobs.submit("test", "page's own", lambda progress: None)
    watched.add(other.id)
    jobs.wait(other.id, 5)
    assert not jobs.ended_since(watched, jobs.active(), ignore={other.id})  # its page's panel reruns it
