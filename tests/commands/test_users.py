"""partlab users (add, grant, revoke, passwd, list, remove) and partlab app's sign-in options: what a
server's administrator types, and the one-line refusals."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from partlab.cli import main
from partlab.labelling import access
from partlab.labelling.store import Store


def _password_file(tmp_path, text: str):
    path = tmp_path / f"pw{abs(hash(text))}"
    path.write_text(text + "\n", encoding="utf-8")
    return str(path)


def _err(capsys) -> list[str]:
    return capsys.readouterr().err.strip().splitlines()


def test_users_are_added_granted_listed_and_removed(tmp_path, capsys):
    pw = _password_file(tmp_path, "ana-password")
    assert main(["users", "add", "ana", "--project", "street", "--create-project", "--role", "owner",
                 "--password-file", pw]) == 0
    assert capsys.readouterr().out.strip() == "added ana (owner of 'street')"
    assert main(["users", "add", "vic", "--password-file", _password_file(tmp_path, "vic-password")]) == 0
    assert main(["users", "grant", "vic", "--project", "street", "--role", "viewer"]) == 0
    capsys.readouterr()
    assert main(["users", "list"]) == 0
    assert capsys.readouterr().out.splitlines() == ["ana\tstreet: owner", "vic\tstreet: viewer"]
    store = Store()
    assert access.authenticate(store, "ana", "ana-password").roles == {store.project_by_name("street").id: "owner"}
    assert main(["users", "passwd", "ana", "--password-file", _password_file(tmp_path, "new-password")]) == 0
    assert access.authenticate(store, "ana", "ana-password") is None
    assert access.authenticate(store, "ana", "new-password") is not None
    assert main(["users", "revoke", "vic", "--project", "street"]) == 0
    assert main(["users", "remove", "vic"]) == 0
    assert [u.name for u in access.users(store)] == ["ana"]


@pytest.mark.parametrize("argv, message", [
    (["users", "add", "bo", "--password-file", "SHORT"], "partlab users: a password needs at least 8 characters"),
    (["users", "add", "bo", "--project", "nowhere", "--role", "viewer", "--password-file", "LONG"],
     "partlab users: no project 'nowhere' (projects: none yet; --create-project makes it)"),
    (["users", "grant", "ghost", "--project", "p", "--create-project", "--role", "viewer"],
     "partlab users: no user named 'ghost'"),
    (["users", "grant", "bo", "--project", "p"],
     "partlab users: users grant needs --role (viewer, annotator or owner)"),
    (["users", "add"], "partlab users: users add needs a user name"),
    (["users", "add", "bo", "--password-file", "MISSING"], "partlab users: cannot read the password from"),
])
def test_bad_requests_are_one_line_and_exit_2(tmp_path, capsys, argv, message):
    files = dict(SHORT=_password_file(tmp_path, "short"), LONG=_password_file(tmp_path, "long-enough"),
                 MISSING=str(tmp_path / "missing"))
    assert main([files.get(a, a) for a in argv]) == 2
    [line] = _err(capsys)
    assert line.startswith(message), line
    assert access.users(Store()) == []


def test_the_app_refuses_to_serve_other_machines_without_sign_in(capsys):
    assert main(["app", "--host", "0.0.0.0", "--auth", "none"]) == 2
    [line] = _err(capsys)
    assert line.startswith("partlab app: refusing to serve 0.0.0.0 without sign-in (--auth none is for loopback only)")
    # sign-in is the default off loopback, and needs a user
    for host in ("0.0.0.0", "10.1.2.3", "::"):
        assert main(["app", "--host", host]) == 2
        [line] = _err(capsys)
        assert line.startswith("partlab app: sign-in is on but there are no users yet: add one with"), line
    from partlab.commands.app import auth_mode

    assert [auth_mode(h, None) for h in ("127.0.0.1", "localhost", "::1", "127.0.0.2", "192.168.1.4")] == \
        ["none", "none", "none", "none", "password"]


def _read_only(path):
    """Make ``path`` unwritable even for root (an immutable directory), or say why not."""
    if os.geteuid() != 0:
        os.chmod(path, 0o555)
        return lambda: os.chmod(path, 0o755)
    subprocess.run(["chattr", "+i", str(path)], check=True, capture_output=True)
    return lambda: subprocess.run(["chattr", "-i", str(path)], check=True)


def test_a_read_only_data_directory_is_a_sentence_and_keeps_the_data(tmp_path, capsys, monkeypatch):
    data = tmp_path / "data"
    monkeypatch.setenv("PARTLAB_DATA", str(data))
    store = Store()
    store.create_project("kept")
    store.engine.dispose()
    undo = _read_only(data)
    try:
        assert main(["app"]) == 2
        [line] = _err(capsys)
        assert line.startswith(f"partlab app: the data directory {data} cannot be written (not allowed to write here")
        # the app itself, started some other way, says it on the page (tests/app/test_auth.py) and the store
        # refuses with the reason, in a fresh process (no engine cached)
        code = ("from partlab.labelling.store import Store, StoreError\n"
                "try:\n    Store().create_project('new')\nexcept StoreError as e:\n    print(e)\n")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=os.environ).stdout
        assert "the database file cannot be opened (a missing or read-only data directory?)" in out, out
    finally:
        undo()
    from partlab.labelling import store as store_module

    store_module._ENGINES.clear()
    assert [p.name for p in Store().projects()] == ["kept"]
