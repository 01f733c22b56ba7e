"""Background jobs report progress, results and failures."""

from __future__ import annotations

import threading

from app import jobs


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
