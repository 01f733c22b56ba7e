"""The built-in demo project: made once, with both synthetic scenes, truth and init files."""

from __future__ import annotations

from partlab.app.demo import DEMO_SCENES, demo_files, ensure_demo


def test_demo_project_is_made_once_with_its_scenes(store):
    assert ensure_demo(store)
    project = store.project_by_name("demo")
    clips = store.clips(project.id)
    assert [c.name for c in clips] == [f"{s}.mp4" for s in DEMO_SCENES]
    assert all((c.frame_count, c.width, c.height) == (100, 480, 320) for c in clips)
    assert ensure_demo(store)  # second start: nothing new
    assert len(store.clips(project.id)) == 2 and len(store.projects()) == 1
    files = demo_files("pair_cross.mp4")
    assert sorted(files) == ["init", "truth"] and files["truth"].exists()
    assert demo_files("walker.mp4") == {}


def test_the_demo_is_tracked_on_first_start_from_its_init_boxes(store, monkeypatch):
    from partlab.app import jobs, pipeline
    from partlab.app.demo import track_demo

    seen = []

    def fake_track(path, tracker="body", init=None, start=0, **kw):  # the glue, not the tracker, is tested here
        seen.append((tracker, int(init.frame.min()), sorted(set(init.track_id))))
        return init.assign(frame=init.frame + 1)

    monkeypatch.setattr(pipeline, "track_video", fake_track)
    assert ensure_demo(store)
    started = track_demo(store)
    assert len(started) == len(DEMO_SCENES)
    for job in started:
        jobs.wait(job.id, 60)
        assert job.status == "done", job.error
    project = store.project_by_name("demo")
    assert all(len(store.runs(c.id)) == 1 and len(store.tracks(c.id)) for c in store.clips(project.id))
    assert {t for t, _, _ in seen} == {"body"} and len(seen) == len(DEMO_SCENES)
    assert track_demo(store) == []  # tracked once: a second start starts nothing
