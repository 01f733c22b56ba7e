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
