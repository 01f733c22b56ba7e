"""Users, passwords and per-project roles, and the guarded store a signed-in user reads and writes
through (SQLite and PostgreSQL)."""

from __future__ import annotations

import inspect

import pytest
from sqlalchemy import text

from partlab.labelling import access
from partlab.labelling.access import AccessError, GuardedStore
from partlab.labelling.store import Store, StoreError
from partlab.labelling.video import write_video
from partlab.tracking.core.box import Box


@pytest.fixture
def lab(backend, tmp_path):
    """Two projects with a clip each; ana annotates 'street', vic views it, olga owns 'hidden'."""
    import numpy as np

    store = Store(clips_dir=tmp_path / "clips")
    frames = [np.full((48, 64, 3), 40 + 10 * i, np.uint8) for i in range(6)]
    street, hidden = store.create_project("street"), store.create_project("hidden")
    c1 = store.add_clip(street.id, write_video(tmp_path / "a.mp4", frames, fps=10))
    c2 = store.add_clip(hidden.id, write_video(tmp_path / "b.mp4", frames[::-1], fps=10))
    store.save_tracker_run(c1.id, _boxes(), tracker="body")
    for name, project, role in (("ana", street, "annotator"), ("vic", street, "viewer"), ("olga", hidden, "owner")):
        access.add_user(store, name, f"{name}-password")
        access.grant(store, name, project.id, role)
    return store, street, hidden, c1, c2


def _boxes():
    import pandas as pd

    return pd.DataFrame([dict(frame=f, track_id=1, part="head", x=10 + f, y=5, w=8, h=9) for f in range(6)])


def test_passwords_are_stored_as_argon2id_hashes_and_checked(lab):
    store = lab[0]
    with store.engine.connect() as c:
        stored = dict(c.execute(text("SELECT name, password FROM users")).all())
    assert stored["ana"].startswith("$argon2id$v=19$m=19456,t=2,p=1$") and "ana-password" not in stored["ana"]
    assert stored["ana"] != stored["vic"]  # own salt each
    assert access.authenticate(store, "ana", "ana-password").roles == {lab[1].id: "annotator"}
    assert access.authenticate(store, "ana", "vic-password") is None
    assert access.authenticate(store, "nobody", "ana-password") is None
    with pytest.raises(StoreError, match="at least 8 characters"):
        access.add_user(store, "bo", "short")
    with pytest.raises(StoreError, match="a user named 'ana' exists already"):
        access.add_user(store, "ana", "another-password")
    for bad, why in ((" ana", "starts or ends with a space"), ("a\x00b", "control characters"), ("", "needs a name"),
                     ("x" * 101, "at most 100")):
        with pytest.raises(StoreError, match=why):
            access.add_user(store, bad, "long-enough")
    access.set_password(store, "ana", "a-new-password")
    assert access.authenticate(store, "ana", "ana-password") is None
    assert access.authenticate(store, "ana", "a-new-password").name == "ana"


def test_an_old_hash_is_upgraded_at_sign_in(lab):
    from argon2 import PasswordHasher

    store = lab[0]
    weak = PasswordHasher(time_cost=1, memory_cost=8, parallelism=1).hash("ana-password")
    with store.engine.begin() as c:
        c.execute(text("UPDATE users SET password = :p WHERE name = 'ana'"), {"p": weak})
    assert access.authenticate(store, "ana", "ana-password") is not None
    with store.engine.connect() as c:
        now = c.execute(text("SELECT password FROM users WHERE name = 'ana'")).scalar()
    assert now != weak and now.startswith("$argon2id$v=19$m=19456,t=2,p=1$")


def test_a_user_sees_only_the_projects_they_hold_a_role_in(lab):
    store, street, hidden, c1, c2 = lab
    vic = GuardedStore("vic")
    assert [p.name for p in vic.projects()] == ["street"]
    assert vic.project_by_name("hidden") is None
    # the other project and its clips do not exist for vic, said the same way as an id nobody uses
    with pytest.raises(StoreError, match=f"no project with id {hidden.id}"):
        vic.clips(hidden.id)
    with pytest.raises(StoreError, match=f"no clip with id {c2.id}"):
        vic.tracks(c2.id)
    with pytest.raises(StoreError, match="no clip with id 999"):
        vic.clip(999)
    assert len(vic.tracks(c1.id)) == 6 and vic.clip(c1.id).name == "a.mp4"
    assert [p.name for p in GuardedStore("olga").projects()] == ["hidden"]
    with pytest.raises(AccessError, match="no user named 'ghost'"):
        GuardedStore("ghost")


def test_a_viewer_cannot_change_anything(lab):
    store, street, _, c1, _ = lab
    vic = GuardedStore("vic")
    refused = "vic is a viewer of project 'street' and cannot change it"
    with pytest.raises(AccessError, match=refused):
        vic.edit_box(c1.id, 2, 1, "head", Box(1, 2, 3, 4), expected_revision=0, author="vic")
    with pytest.raises(AccessError, match=refused):
        vic.save_tracker_run(c1.id, _boxes())
    with pytest.raises(AccessError, match=refused):
        vic.review(c1.id, 1, 0, 5, True)
    with pytest.raises(AccessError, match=refused):
        vic.add_clip(street.id, c1.path)
    # default deny: every store method taking a clip, project or take id that is not a read is refused
    # for a viewer before it reads its other arguments
    writes = [name for name, fn in inspect.getmembers(Store, inspect.isfunction)
              if not name.startswith("_") and name not in access.READS
              and list(inspect.signature(fn).parameters)[1:2] in (["clip_id"], ["project_id"], ["take_id"])]
    assert {"edit_boxes", "undo_many", "undo_run", "set_occluders", "add_bundle", "set_default_bundle",
            "add_take", "import_take", "add_event", "edit_event", "undo_review"} <= set(writes)
    for name in writes:
        key = c1.id if "clip_id" in inspect.signature(getattr(Store, name)).parameters else street.id
        with pytest.raises(AccessError, match=refused):
            getattr(vic, name)(key, *([None] * 8))
    assert store.revisions(c1.id) == {} and len(store.runs(c1.id)) == 1 and store.reviews(c1.id).empty
    assert not access.may(vic, street.id) and access.may(vic, street.id, "viewer")


def test_an_annotator_edits_under_their_name_and_a_new_project_is_its_makers(lab):
    store, street, _, c1, _ = lab
    ana = GuardedStore("ana")
    assert ana.edit_box(c1.id, 2, 1, "head", Box(30, 5, 8, 9), expected_revision=0, author=ana.user) == 1
    assert store.history(c1.id, 2, 1, "head").author.tolist() == ["ana"]
    mine = ana.create_project("ana's own")
    assert ana.role(mine.id) == "owner" and access.members(store, mine.id) == {"ana": "owner"}
    assert [p.name for p in GuardedStore("ana").projects()] == ["street", "ana's own"]
    # a revoked role is gone at the next page run (a new guarded store)
    assert access.revoke(store, "ana", street.id)
    with pytest.raises(StoreError, match=f"no clip with id {c1.id}"):
        GuardedStore("ana").edit_box(c1.id, 3, 1, "head", Box(30, 5, 8, 9), expected_revision=0)
    access.remove_user(store, "vic")
    assert [u.name for u in access.users(store)] == ["ana", "olga"]
    assert access.members(store, street.id) == {}
