"""Each page's logic through Streamlit's AppTest (no browser): upload refused/accepted,
a tracking run stored, corrections shown, a training run producing a bundle, export."""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
from streamlit.testing.v1 import AppTest

from partlab.app import jobs
from partlab.tracking.core.box import Box

PAGES = Path(__file__).resolve().parents[2] / "partlab" / "app" / "views"


def page(name: str, **session) -> AppTest:
    at = AppTest.from_file(str(PAGES / f"{name}.py"), default_timeout=60)
    for k, v in session.items():
        at.session_state[k] = v
    return at.run()


def texts(at: AppTest, kind: str) -> list[str]:
    """The texts of one kind of element as a reader sees them (names are escaped Markdown: ``\\:`` shows ``:``)."""
    return [re.sub(r"\\(.)", r"\1", e.value) for e in getattr(at, kind)]


def test_projects_page_creates_a_project_and_accepts_a_clip(store, clip_file):
    at = page("projects")
    assert not at.exception
    at.text_input[0].input("street")
    at.button[0].click().run()
    assert "Created project 'street'." in texts(at, "success")
    at.file_uploader[0].upload("walker.mp4", clip_file.read_bytes(), "video/mp4").run()
    assert not at.exception
    assert any(t.startswith("Added walker.mp4: 12 frames, 10.0 fps, 96x72") for t in texts(at, "success"))
    project = store.project_by_name("street")
    [clip] = store.clips(project.id)
    table = at.dataframe[0].value
    assert table.loc[0, "name"] == "walker.mp4" and table.loc[0, "frames"] == 12
    assert table.loc[0, "state"] == "untracked" and table.loc[0, "thumbnail"].startswith("data:image/jpeg;base64,")
    assert at.session_state["clip_id"] == clip.id


def test_projects_page_refuses_bad_uploads_and_says_why(store, monkeypatch):
    monkeypatch.setenv("PARTLAB_MAX_UPLOAD_MB", "1")
    project = store.create_project("p")
    at = page("projects", project_id=project.id)
    at.file_uploader[0].upload("noise.mp4", b"\x00garbage" * 100, "video/mp4")
    at.file_uploader[0].upload("huge.mp4", b"\x00" * (2**20 + 1), "video/mp4").run()
    errors = texts(at, "error")
    assert any("noise.mp4: not a video OpenCV can decode" in e for e in errors), errors
    assert any("huge.mp4: refused, 1.0 MB is over the 1 MB limit" in e for e in errors), errors
    assert store.clips(project.id) == []


def test_track_page_imports_boxes_as_a_run(store, clip_file, boxes):
    project = store.create_project("p")
    clip = store.add_clip(project.id, clip_file)
    at = page("track", project_id=project.id)
    assert not at.exception
    csv = boxes.to_csv(index=False).encode()
    at.file_uploader[0].upload("init.csv", csv, "text/csv").run()
    [store_button] = [b for b in at.button if b.label == "Store these boxes as a tracker run"]
    store_button.click().run()
    assert any("Stored 24 boxes as run" in t for t in texts(at, "success"))
    assert len(store.tracks(clip.id)) == 24 and store.runs(clip.id).tracker.tolist() == ["import"]


def test_track_page_runs_the_tracker_in_the_background_and_stores_the_run(store, clip_file):
    project = store.create_project("p")
    clip = store.add_clip(project.id, clip_file)
    at = page("track", project_id=project.id)
    [go] = [b for b in at.button if b.label == "Track the whole clip"]
    go.click().run()
    [job] = jobs.jobs("track", clip_id=clip.id)
    jobs.wait(job.id, 120)
    assert job.status == "done", job.error
    assert store.runs(clip.id).tracker.tolist() == ["body"]
    assert job.result["boxes"] == len(store.tracks(clip.id))


def test_correct_page_shows_its_counts_track_list_and_retrack_window(store, tracked_clip):
    project, clip = tracked_clip
    store.edit_box(clip.id, 4, 1, "head", Box(22, 20, 8, 10), expected_revision=0)  # one human correction
    at = page("correct", project_id=project.id, clip_id=clip.id, **{f"frame:{clip.id}": 6})
    assert not at.exception
    assert any("1 corrected · 0 accepted of 12 frames" in c for c in texts(at, "caption"))
    table = at.dataframe[0].value
    assert table.loc[0, "track"] == 1 and (table.loc[0, "frames"], table.loc[0, "keyframes"]) == (12, 1)
    # re-track from frame 6 starts at the keyframe before it (4) and runs to the end for track 1 only
    assert any("from frame 4 (a keyframe) to the end of the clip for tracks #1" in m for m in texts(at, "markdown"))


def test_names_are_shown_as_text_not_markdown(store):
    at = page("projects")
    at.text_input[0].input("**big** :red[x]")
    at.button[0].click().run()
    escaped = "\\*\\*big\\*\\* \\:red\\[x\\]"  # what Markdown shows as **big** :red[x]
    assert [e.value for e in at.success] == [f"Created project '{escaped}'."]
    assert [h.value for h in at.subheader] == [f"Project: {escaped}"]


def test_evaluate_page_plots_trajectories(store, tracked_clip):
    project, clip = tracked_clip
    at = page("evaluate", project_id=project.id, clip_id=clip.id)
    assert not at.exception
    charts = at.get("plotly_chart")
    assert len(charts) >= 1


def test_train_page_produces_a_bundle(store, tracked_clip, boxes):
    project, clip = tracked_clip
    # correct every frame: the walker's boxes, with its torso and hip-leg drawn (a head and a person
    # box alone teach the failure SVMs nothing: the page would refuse, as the test below shows)
    parts = boxes[boxes.part == "person"].copy()
    body = [parts.assign(part="torso", y=parts.y + 10, h=16), parts.assign(part="hipleg", y=parts.y + 26, h=18)]
    for r in pd.concat([boxes, *body]).itertuples():
        store.edit_box(clip.id, r.frame, r.track_id, r.part, Box(r.x, r.y, r.w, r.h),
                       expected_revision=store.revision(clip.id, r.frame, r.track_id, r.part))
    at = page("train", project_id=project.id)
    assert not at.exception
    [go] = [b for b in at.button if b.label == "Train"]
    go.click().run()
    [job] = jobs.jobs("train", project_id=project.id)
    jobs.wait(job.id, 300)
    assert job.status == "done", job.error
    [bundle] = store.bundles(project.id)
    assert bundle.name == "bundle-1" and Path(bundle.path).is_dir()
    assert store.project(project.id).default_bundle_id == bundle.id
    at.run()  # the bundle's summary: a row per SVM with its cross-validated rates, the variance chart
    assert not at.exception
    svms = at.dataframe[0].value
    assert svms.svm.tolist() == list(bundle.summary["svms"]) and {"CV TNR", "CV TPR"} <= set(svms.columns)
    assert len(at.get("plotly_chart")) >= 1


def test_train_page_refuses_to_learn_from_one_corrected_frame(store, tracked_clip, boxes):
    project, clip = tracked_clip
    for r in boxes[boxes.frame == 0].itertuples():
        store.edit_box(clip.id, r.frame, r.track_id, r.part, Box(r.x, r.y, r.w, r.h),
                       expected_revision=store.revision(clip.id, r.frame, r.track_id, r.part))
    at = page("train", project_id=project.id)
    [go] = [b for b in at.button if b.label == "Train"]
    go.click().run()
    assert not at.exception
    assert any("Nothing to learn yet: the corrections span 1 frame(s)" in t for t in texts(at, "error")), \
        texts(at, "error")
    assert not jobs.jobs("train", project_id=project.id) and not store.bundles(project.id)
    assert store.project(project.id).default_bundle_id is None


def test_export_page_builds_an_archive_and_marks_clips_exported(store, tracked_clip):
    project, clip = tracked_clip
    at = page("export", project_id=project.id)
    assert not at.exception
    [go] = [b for b in at.button if b.label == "Build archive"]
    go.click().run()
    assert any("Exported 1 clip(s) as mot" in t for t in texts(at, "success")), texts(at, "error")
    assert store.clip(clip.id).exported


def test_retrack_runs_between_keyframes_keeps_other_tracks_and_undoes_as_one_step(store, tracked_clip, boxes):
    project, clip = tracked_clip
    other = boxes.query("part == 'person'").assign(track_id=2, y=2.0)  # a second person, never asked about
    store.save_tracker_run(clip.id, other, tracker="import")
    head = boxes[(boxes.frame == 3) & (boxes.part == "head")].iloc[0]
    store.edit_box(clip.id, 3, 1, "head", Box(head.x + 1, head.y, head.w, head.h), expected_revision=0)
    store.edit_box(clip.id, 8, 1, "head", Box(70, 20, 8, 10), expected_revision=0)
    before = store.tracks(clip.id)
    at = page("correct", project_id=project.id, clip_id=clip.id, **{f"frame:{clip.id}": 5})
    at.selectbox(key=f"rt_tracks:{clip.id}").set_value("#1").run()
    assert any("from frame 3 (a keyframe) to frame 8 (the next keyframe) for tracks #1" in m
               for m in texts(at, "markdown"))
    [go] = [b for b in at.button if b.label == "Re-track"]
    go.click().run()
    [job] = jobs.jobs("track", clip_id=clip.id)
    jobs.wait(job.id, 120)
    assert job.status == "done", job.error
    assert (job.result["start"], job.result["stop"], job.result["track_ids"]) == (3, 8, [1])
    after = store.tracks(clip.id)
    cols = ["frame", "track_id", "part", "x", "y", "source"]

    def kept(df):  # frames outside the window, and track 2 everywhere
        return df[(df.frame < 3) | (df.frame >= 8) | (df.track_id == 2)].reset_index(drop=True)[cols]

    assert kept(after).equals(kept(before))
    fixed = after[(after.frame == 3) & (after.part == "head")].iloc[0]
    assert (fixed.source, fixed.x) == ("human", head.x + 1)  # the fix itself is never overwritten
    assert set(after[(after.frame > 3) & (after.frame < 8) & (after.track_id == 1)].source) == {"tracker"}
    # one step back: the boxes the run replaced return
    at.run()
    [undo] = [b for b in at.button if b.label.startswith("Undo the newest tracker run")]
    undo.click().run()
    pd.testing.assert_frame_equal(store.tracks(clip.id), before)


def test_evaluate_page_compares_two_runs_against_the_truth(store, tracked_clip, boxes, tmp_path):
    project, clip = tracked_clip
    at = page("evaluate", project_id=project.id, clip_id=clip.id)
    at.file_uploader[0].upload("truth.csv", boxes.to_csv(index=False).encode(), "text/csv").run()
    [go] = [b for b in at.button if b.label == "Track with both and compare"]
    go.click().run()
    runs = jobs.jobs("compare", clip_id=clip.id)  # A: built-in parameters, B: the shipped bundle
    assert {j.meta["bundle"] for j in runs} == {"built-in parameters", "partlab's shipped bundle"}
    for job in runs:
        jobs.wait(job.id, 120)
        assert job.status == "done", job.error
        assert job.result.frame.min() == 0 and set(job.result.track_id) == {1}  # started from the truth's boxes
    at.run()
    assert not at.exception
    assert len(at.get("plotly_chart")) == 3  # two rate curves and the trajectories


def test_pages_without_a_project_say_what_to_do_first():
    for name in ("track", "correct", "train", "evaluate"):
        at = page(name)
        assert not at.exception, name
        assert any("No project yet" in i for i in texts(at, "info")), name


def test_projects_page_adds_a_take_folder_with_its_tracks_in_every_view(store, tmp_path):
    import numpy as np

    from partlab.labelling.calibration import write_calibration
    from partlab.labelling.synth.multiview import look_at
    from partlab.labelling.video import write_video

    take = tmp_path / "take"
    take.mkdir()
    cams = [look_at("cam0", (3000, 0, 1500), (0, 0, 1200), 300.0, (160, 120)),
            look_at("cam1", (0, 3000, 1800), (0, 0, 1200), 260.0, (160, 120))]
    for k, c in enumerate(cams):
        write_video(take / f"{c.name}.mp4", [np.full((120, 160, 3), 50 + 40 * k, np.uint8)] * 3, fps=10)
    write_calibration(cams, take / "calibration.json")
    pd.DataFrame([dict(frame=f, track_id=1, part="head", x=70 + k, y=40, w=12, h=12, camera=c.name, X=0.0, Y=0.0,
                       Z=1600.0) for f in range(3) for k, c in enumerate(cams)]).to_csv(tmp_path / "t.csv", index=False)
    pd.DataFrame([dict(frame=0, track_id=1, part="head", x=1, y=1, w=5, h=5)]).to_csv(tmp_path / "bad.csv", index=False)
    project = store.create_project("p")
    at = page("projects")
    at.text_input(key=f"take_path:{project.id}").input(str(take))
    at.text_input(key=f"take_tracks:{project.id}").input(str(tmp_path / "bad.csv"))
    at.button(key=f"take_add:{project.id}").click().run()
    assert any("no camera column" in e for e in texts(at, "error")) and store.takes(project.id) == []
    at.text_input(key=f"take_tracks:{project.id}").input(str(tmp_path / "t.csv"))
    at.button(key=f"take_add:{project.id}").click().run()
    assert any("Added take 'take': views cam0, cam1" in m for m in texts(at, "success")), texts(at, "error")
    [rec] = store.takes(project.id)
    for k, st_ in enumerate(rec.streams):
        df = store.tracks(st_.clip_id)
        assert len(df) == 3 and set(df.camera) == {st_.name} and df.x.tolist() == [70.0 + k] * 3
