"""``partlab users``: who may sign in to the app, and their role in each project.

    partlab users add ana --project street --role annotator   # asks for the password twice
    partlab users grant bo --project street --role viewer
    partlab users revoke bo --project street
    partlab users passwd ana
    partlab users list
    partlab users remove bo

Passwords are read from the terminal (twice, not echoed), or from the first line of
``--password-file FILE`` (``-`` for standard input, for scripts); they are stored as Argon2id hashes
(:mod:`partlab.labelling.access`). The users live in the annotation store (``PARTLAB_DATA`` /
``PARTLAB_DATABASE_URL``), so run this with the same settings as ``partlab app``.
"""

from __future__ import annotations

import sys

from partlab.cli import CommandError
from partlab.labelling.roles import ROLES

ACTIONS = ("add", "grant", "revoke", "passwd", "list", "remove")


def add_arguments(p) -> None:
    p.add_argument("action", choices=ACTIONS, help="what to do: " + ", ".join(ACTIONS))
    p.add_argument("name", nargs="?", help="the user's name (not for list)")
    p.add_argument("--project", metavar="NAME_OR_ID", help="the project a role is granted in or revoked from")
    p.add_argument("--role", choices=ROLES, help="viewer (reads, exports), annotator (also edits, tracks, trains, "
                                                 "uploads) or owner (also grants roles)")
    p.add_argument("--create-project", action="store_true", help="make --project first if there is none of that name")
    p.add_argument("--password-file", metavar="FILE", help="read the password from the first line of FILE "
                                                           "('-': standard input) instead of asking")


def _password(args) -> str:
    if args.password_file:
        try:
            if args.password_file == "-":
                text = sys.stdin.readline()
            else:
                with open(args.password_file, encoding="utf-8") as f:
                    text = f.readline()
        except (OSError, UnicodeDecodeError) as exc:
            raise CommandError(f"cannot read the password from {args.password_file}: {exc}") from None
        return text.rstrip("\r\n")
    if not sys.stdin.isatty():
        raise CommandError("no terminal to ask the password on: give --password-file FILE (or - for stdin)")
    import getpass

    first = getpass.getpass(f"Password for {args.name}: ")
    if getpass.getpass("Again: ") != first:
        raise CommandError("the two passwords differ; nothing was changed")
    return first


def _project(store, args, needed: bool):
    if not args.project:
        if needed:
            raise CommandError(f"users {args.action} needs --project NAME_OR_ID")
        return None
    project = store.project_by_name(args.project)
    if project is None and args.project.isdigit():
        project = next((p for p in store.projects() if p.id == int(args.project)), None)
    if project is None and args.create_project:
        project = store.create_project(args.project)
    if project is None:
        known = ", ".join(repr(p.name) for p in store.projects()) or "none yet"
        raise CommandError(f"no project {args.project!r} (projects: {known}; --create-project makes it)")
    return project


def _list(store, access) -> None:
    names = {p.id: p.name for p in store.projects()}
    found = access.users(store)
    if not found:
        print("no users yet: partlab users add NAME --project PROJECT --role owner")
    for u in found:
        roles = ", ".join(f"{names.get(pid, pid)}: {role}" for pid, role in sorted(u.roles.items())) or "no roles"
        print(f"{u.name}\t{roles}")


def _act(store, access, args) -> str:
    """Do the action; returns the line to print."""
    if args.action == "add":
        project = _project(store, args, needed=False)
        if project is not None and not args.role:
            raise CommandError("--project needs --role (viewer, annotator or owner)")
        access.add_user(store, args.name, _password(args))
        if project is not None:
            access.grant(store, args.name, project.id, args.role)
            return f"added {args.name} ({args.role} of {project.name!r})"
        return f"added {args.name} (no roles yet: partlab users grant {args.name} --project P --role R)"
    if args.action == "grant":
        if not args.role:
            raise CommandError("users grant needs --role (viewer, annotator or owner)")
        project = _project(store, args, needed=True)
        access.grant(store, args.name, project.id, args.role)
        return f"{args.name} is now {args.role} of {project.name!r}"
    if args.action == "revoke":
        project = _project(store, args, needed=True)
        held = access.revoke(store, args.name, project.id)
        return f"{args.name} no longer has a role in {project.name!r}" if held else \
            f"{args.name} had no role in {project.name!r}"
    if args.action == "passwd":
        if access.user(store, args.name) is None:
            raise CommandError(f"no user named {args.name!r}")
        access.set_password(store, args.name, _password(args))
        return f"changed the password of {args.name}"
    access.remove_user(store, args.name)
    return f"removed {args.name} (their edits keep their name)"


def run(args) -> int:
    from partlab.labelling import access
    from partlab.labelling.store import Store, StoreError

    if args.action != "list" and not args.name:
        raise CommandError(f"users {args.action} needs a user name")
    try:
        store = Store()
        if args.action == "list":
            _list(store, access)
            return 0
        print(_act(store, access, args))
    except StoreError as exc:
        raise CommandError(str(exc)) from None
    return 0
