"""The app with sign-in on (AppTest, no browser): nobody signed in sees no project, a user sees only
theirs, a viewer's changes are refused with a sentence, edits carry the signed-in name; a full disk
and a read-only data directory are sentences, not tracebacks, and lose nothing."""

from __future__ import annotations

import errno
import os
import re
import subprocess
from pathlib import Path

import pytest
from sqlalchemy import event, text
from streamlit.testing.v1 import AppTest

from partlab.app.editing import EditHistory, apply_events
from partlab.labelling import access
from partlab.labelling.access import GuardedStore
from partlab.labelling.store import StoreError

APP = Path(__file__).resolve().parents[2] / "partlab" / "app"


def shown(element) -> str:
    """What a reader sees of a Markdown element (names are escaped: ``\\:`` shows ``:``)."""
    return re.sub(r"\\(.)", r"\1", str(element.value))


def everything(at: AppTest) -> str:
    kinds = ("title", "subheader", "markdown", "caption", "info", "success", "error", "warning")
    out = [shown(e) for k in kinds for e in getattr(at, k)]
    out += [str(o) for s in at.selectbox for o in s.options] + [str(t.value) for t in at.text_input]
    return "\n".join(out)


@pytest.fixture
def signed(monkeypatch, store, tracked_clip):
    """Sign-in on; ana annotates the walker's project 'test', vic views it, olga owns 'secret'."""
    monkeypatch.setenv("PARTLAB_AUTH", "password")
    monkeypatch.setenv("PARTLAB_DEMO", "0")
    project, clip = tracked_clip
    secret = store.create_project("secret")
    for name, pid, role in (("ana", project.id, "annotator"), ("vic", project.id, "viewer"),
                            ("olga", secret.id, "owner")):
        access.add_user(store, name, f"{name}-password")
        access.grant(store, name, pid, role)
    return project, clip


def app() -> AppTest:
    return AppTest.from_file(str(APP / "streamlit_app.py"), default_timeout=60).run()


def page(name: str, **session) -> AppTest:
    at = AppTest.from_file(str(APP / "views" / f"{name}.py"), default_timeout=60)
    for k, v in session.items():
        at.session_state[k] = v
    return at.run()


def test_without_credentials_no_project_is_seen(signed):
    at = app()
    assert not at.exception
    assert [t.label for t in at.text_input] == ["User name", "Password"]
    assert "test" not in everything(at) and "secret" not in everything(at) and "walker" not in everything(at)
    # every page opened directly (a link) stops at the same sentence
    for name in ("projects", "track", "correct", "train", "evaluate", "export"):
        at = page(name)
        assert not at.exception, name
        assert [i.value for i in at.info] == ["Sign in to see your projects."], name
        assert "walker" not in everything(at) and "secret" not in everything(at), name


def test_signing_in_shows_only_the_users_projects_and_edits_carry_their_name(signed, store):
    project, clip = signed
    at = app()
    at.text_input[0].input("ana")
    at.text_input[1].input("vic-password")
    at.button[0].click().run()
    assert [e.value for e in at.error] == ["Wrong user name or password."]
    at.text_input[0].input("ana")
    at.text_input[1].input("ana-password")
    at.button[0].click().run()
    assert not at.exception
    assert [s.options for s in at.selectbox if s.label == "Project"] == [["test"]]
    assert "Signed in as ana" in [shown(c) for c in at.caption]
    assert not [t for t in at.text_input if t.label.startswith("Your name")]  # the name is the signed-in one
    # a verdict on the Correct page is saved under ana's name
    at = page("correct", signed_in_user="ana", project_id=project.id, clip_id=clip.id)
    [accept] = [b for b in at.button if b.label == "Accept"]
    accept.click().run()
    assert not at.exception
    assert store.reviews(clip.id).author.tolist() == ["ana"]


def test_a_viewer_cannot_edit_and_is_told_why(signed, store):
    project, clip = signed
    at = page("correct", signed_in_user="vic", project_id=project.id, clip_id=clip.id)
    assert not at.exception
    assert any("You are a viewer of test: you can look and export; changes are refused" in shown(c)
               for c in at.caption)
    [accept] = [b for b in at.button if b.label == "Accept"]
    accept.click().run()
    assert [shown(e) for e in at.error] == [
        "vic is a viewer of project 'test' and cannot change it (an annotator can; ask the project's owner)"]
    # the editor's events (a dragged box) take the same way through the store
    result = apply_events(GuardedStore("vic"), clip.id, [dict(kind="edit", frame=3, track_id=1, part="head",
                                                              box=[1, 2, 3, 4], revision=0)], EditHistory(), "vic")
    assert result.errors == ["Not saved (edit): vic is a viewer of project 'test' and cannot change it "
                             "(an annotator can; ask the project's owner)"]
    assert store.reviews(clip.id).empty and store.revisions(clip.id) == {}
    # no uploader for a viewer; the project of someone else is not there at all
    at = page("projects", signed_in_user="vic", project_id=project.id)
    assert not at.exception and len(at.file_uploader) == 0
    assert [s.options for s in at.selectbox] == [] and "secret" not in everything(at)


def _full(store):
    """From now on the SQLite file cannot grow: SQLite's own 'database or disk is full'."""
    with store.engine.connect() as c:
        pages = c.execute(text("PRAGMA page_count")).scalar()

    @event.listens_for(store.engine, "connect")
    def _limit(dbapi_conn, _record):
        dbapi_conn.execute(f"PRAGMA max_page_count = {pages}")

    store.engine.dispose()  # every connection from now on has the limit
    return lambda: (event.remove(store.engine, "connect", _limit), store.engine.dispose())


@pytest.mark.skipif(os.environ.get("PARTLAB_TEST_BACKEND", "sqlite") != "sqlite", reason="SQLite's page limit")
def test_a_full_disk_is_a_sentence_and_keeps_what_was_saved(store, tracked_clip, clip_file, monkeypatch):
    project, clip = tracked_clip
    store.review(clip.id, 1, 0, 3, True, author="ana")
    undo = _full(store)
    try:
        with pytest.raises(StoreError, match="the disk holding the database is full"):
            for _ in range(5000):  # verdicts fill the file's last pages
                store.review(clip.id, 1, 4, 5, False, author="filler")
        at = page("correct", project_id=project.id, clip_id=clip.id)
        [accept] = [b for b in at.button if b.label == "Accept"]
        accept.click().run()
        assert not at.exception
        [said] = [shown(e) for e in at.error]
        assert said.endswith("partlab.db: the disk holding the database is full; this change was not saved "
                             "(what was saved before is intact)"), said
    finally:
        undo()
    verdicts = store.reviews(clip.id)
    assert verdicts.author.iloc[0] == "ana" and set(verdicts.author) == {"ana", "filler"}
    # an upload on a full disk: a sentence, no half file left, the earlier clip kept
    import partlab.app.uploads as uploads

    def no_space(src, dst, length=0):
        dst.write(src.read(100))
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(uploads.shutil, "copyfileobj", no_space)
    at = page("projects", project_id=project.id)
    at.file_uploader[0].upload("more.mp4", clip_file.read_bytes()[::-1], "video/mp4").run()
    assert not at.exception
    assert [shown(e) for e in at.error] == ["Upload more.mp4: not stored, no space left on the device "
                                            "(earlier outputs are left as they were)"]
    from partlab.labelling.config import data_dir

    assert list((data_dir() / "uploads").iterdir()) == [] and [c.id for c in store.clips(project.id)] == [clip.id]


@pytest.mark.skipif(os.environ.get("PARTLAB_TEST_BACKEND", "sqlite") != "sqlite",
                    reason="the SQLite store lives in the data directory; a PostgreSQL one does not")
def test_a_read_only_data_directory_is_a_sentence(tmp_path, monkeypatch):
    data = tmp_path / "read-only"
    data.mkdir()
    monkeypatch.setenv("PARTLAB_DATA", str(data))
    monkeypatch.setenv("PARTLAB_DEMO", "0")
    if os.geteuid() == 0:
        subprocess.run(["chattr", "+i", str(data)], check=True)
    else:
        os.chmod(data, 0o555)
    try:
        at = app()
    finally:
        if os.geteuid() == 0:
            subprocess.run(["chattr", "-i", str(data)], check=True)
        else:
            os.chmod(data, 0o755)
    assert not at.exception
    [said] = [shown(e) for e in at.error]
    assert said == (f"Cannot write {data}/partlab.db.migrate-lock: not allowed to write here (Operation not "
                    "permitted). Nothing was changed; what was saved before is intact."), said


def test_a_viewer_cannot_start_a_tracking_run(signed):
    from partlab.app import jobs

    project, clip = signed
    at = page("track", signed_in_user="vic", project_id=project.id, clip_id=clip.id)
    [go] = [b for b in at.button if b.label == "Track the whole clip"]
    go.click().run()
    assert not at.exception
    assert any("vic is a viewer of project 'test' and cannot change it" in shown(e) for e in at.error)
    assert jobs.jobs("track", clip_id=clip.id) == []


HOSTILE = ("[x](http://evil.example/a) ![i](http://evil.example/i.png) <img src=http://evil.example/b> "
           "**bold-x** :red[r]")


def unescaped(markdown: str) -> bool:
    """Whether Markdown source would render a link, an image, HTML or emphasis of HOSTILE's."""
    return bool(re.search(r"(?<!\\)(\]\(http|<img|\*\*bold-x|:red\[)", markdown))


def test_names_are_text_on_every_page(store, clip_file, tmp_path):
    """A project, clip and bundle named with Markdown and HTML: no element carries them unescaped."""
    project = store.create_project(HOSTILE)
    clip = store.add_clip(project.id, clip_file, name=HOSTILE + ".mp4")
    store.add_bundle(project.id, HOSTILE, tmp_path / "b")
    for name in ("projects", "track", "correct", "train", "evaluate", "export"):
        at = page(name, project_id=project.id, clip_id=clip.id)
        assert not at.exception, name
        kinds = ("title", "subheader", "markdown", "caption", "info", "success", "error", "warning")
        bad = [e.value for k in kinds for e in getattr(at, k) if unescaped(str(e.value))]
        bad += [b.label for b in at.button if unescaped(b.label)]
        assert bad == [], (name, bad)


def test_an_export_on_a_full_disk_is_a_sentence_and_leaves_no_half_archive(store, tracked_clip, monkeypatch):
    import shutil

    from partlab.labelling.config import data_dir

    project, clip = tracked_clip

    def no_space(base_name, *args, **kwargs):
        Path(base_name + ".zip").write_bytes(b"PK\x03\x04 half")
        raise OSError(errno.ENOSPC, "No space left on device", base_name + ".zip")

    monkeypatch.setattr(shutil, "make_archive", no_space)
    at = page("export", project_id=project.id)
    at.button[0].click().run()
    assert not at.exception
    [said] = [shown(e) for e in at.error]
    assert said.startswith("Cannot write ") and said.endswith(
        "-mot.zip: no space left on the device (earlier outputs are left as they were)."), said
    assert list((data_dir() / "exports").iterdir()) == []
    assert len(store.tracks(clip.id)) == 24
