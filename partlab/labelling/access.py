"""Who may do what: users who sign in, their role in each project, and a store that enforces it.

A user has a name and a password, kept as an Argon2id hash (argon2-cffi's ``PasswordHasher``,
OWASP's baseline parameters; never the password). In each project a user holds at most one role
(:data:`partlab.labelling.roles.ROLES`):

- ``viewer`` sees the project's clips, boxes, runs and bundles, evaluates and exports;
- ``annotator`` also uploads clips, tracks, corrects boxes, reviews and trains;
- ``owner`` also grants and revokes roles in the project (``partlab users grant``).

:class:`GuardedStore` is a :class:`~partlab.labelling.store.Store` seen by one signed-in user:
projects without a role of theirs do not exist for it (``projects()`` leaves them out, ``project(id)``
says "no project"), and every write needs ``annotator`` (default deny: a store method taking a
``clip_id``, ``project_id`` or ``take_id`` that is not listed in :data:`READS` is a write). The app
hands pages a guarded store when sign-in is on (:mod:`partlab.app.auth`), so a page that forgets a
check still cannot let a viewer change anything.

Example::

    store = Store()
    add_user(store, "ana", "correct horse battery")
    grant(store, "ana", store.create_project("street").id, "annotator")
    user = authenticate(store, "ana", "correct horse battery")   # a User, or None
    ana = GuardedStore(user.name)                                 # what ana's pages read and write
"""

from __future__ import annotations

import functools
import inspect
import unicodedata
from dataclasses import dataclass

from argon2 import PasswordHasher
from argon2.exceptions import InvalidHashError, VerificationError
from sqlalchemy import delete, select

from partlab.labelling.roles import ROLES
from partlab.labelling.store import RoleRow, Store, StoreError, UserRow

#: shortest password accepted (NIST SP 800-63B asks for at least 8 characters)
MIN_PASSWORD = 8
#: longest user name (the column's size)
MAX_NAME = 100

#: Argon2id with OWASP's baseline (Password Storage Cheat Sheet): 19 MiB, 2 passes, 1 lane. About 30 ms on an
#: idle core, so a sign-in is quick while a guess costs an attacker the same 19 MiB each; argon2-cffi's own
#: default (RFC 9106 low-memory, 64 MiB, t=3, p=4) took 1.5-1.9 s per sign-in on our loaded 2-core machine.
#: Hashes made with other parameters still verify and are rehashed at the next sign-in.
_HASHER = PasswordHasher(time_cost=2, memory_cost=19 * 1024, parallelism=1)


@functools.lru_cache(maxsize=1)
def _dummy_hash() -> str:
    """Hashed once (on the first unknown name) so that a sign-in with an unknown name costs as much as
    one with a wrong password."""
    return _HASHER.hash("partlab: no such user")


class AccessError(StoreError):
    """A request the signed-in user's role does not allow; the message says which role it needs."""


@dataclass(frozen=True)
class User:
    id: int
    name: str
    #: project id -> role
    roles: dict


def check_name(name: str) -> str:
    """A user name as stored: 1..100 printable characters, no spaces at either end."""
    if not isinstance(name, str) or not name.strip():
        raise StoreError("a user needs a name")
    if name != name.strip():
        raise StoreError(f"user name {name!r} starts or ends with a space")
    if len(name) > MAX_NAME:
        raise StoreError(f"user name is {len(name)} characters long; at most {MAX_NAME}")
    if any(unicodedata.category(c).startswith("C") for c in name):
        raise StoreError(f"user name {name!r} holds control characters")
    return name


def check_role(role: str) -> str:
    if role not in ROLES:
        raise StoreError(f"role must be one of {', '.join(ROLES)}, got {role!r}")
    return role


def hash_password(password: str) -> str:
    """The Argon2id hash (a PHC string with its own salt and parameters) of a new password."""
    if not isinstance(password, str) or len(password) < MIN_PASSWORD:
        raise StoreError(f"a password needs at least {MIN_PASSWORD} characters")
    return _HASHER.hash(password)


def verify_password(stored: str, password: str) -> bool:
    """Whether ``password`` matches the stored hash (a malformed hash matches nothing)."""
    try:
        return _HASHER.verify(stored, password)
    except (VerificationError, InvalidHashError):
        return False


# ------------------------------------------------------------------------------------- users
def _user_row(s, name: str) -> UserRow:
    row = s.scalar(select(UserRow).where(UserRow.name == name))
    if row is None:
        raise StoreError(f"no user named {name!r}")
    return row


def _roles(s, user_id: int) -> dict:
    return {r.project_id: r.role for r in s.scalars(select(RoleRow).where(RoleRow.user_id == user_id))}


def add_user(store: Store, name: str, password: str) -> User:
    """A new user; refused if the name is taken (names are unique)."""
    name = check_name(name)
    hashed = hash_password(password)
    with store._session() as s:
        if s.scalar(select(UserRow).where(UserRow.name == name)) is not None:
            raise StoreError(f"a user named {name!r} exists already")
        row = UserRow(name=name, password=hashed)
        s.add(row)
        s.commit()
        return User(row.id, row.name, {})


def set_password(store: Store, name: str, password: str) -> None:
    hashed = hash_password(password)
    with store._session() as s:
        _user_row(s, name).password = hashed
        s.commit()


def remove_user(store: Store, name: str) -> None:
    """Remove a user and their roles; their edits keep their name."""
    with store._session() as s:
        row = _user_row(s, name)
        s.execute(delete(RoleRow).where(RoleRow.user_id == row.id))
        s.delete(row)
        s.commit()


def users(store: Store) -> list[User]:
    with store._session() as s:
        return [User(r.id, r.name, _roles(s, r.id)) for r in s.scalars(select(UserRow).order_by(UserRow.name))]


def user(store: Store, name: str) -> User | None:
    with store._session() as s:
        row = s.scalar(select(UserRow).where(UserRow.name == name))
        return User(row.id, row.name, _roles(s, row.id)) if row is not None else None


def has_users(store: Store) -> bool:
    with store._session() as s:
        return s.scalar(select(UserRow.id).limit(1)) is not None


def grant(store: Store, name: str, project_id: int, role: str) -> None:
    """Give ``name`` the ``role`` in a project (replacing any role they held there)."""
    check_role(role)
    store.project(project_id)
    with store._session() as s:
        uid = _user_row(s, name).id
        row = s.scalar(select(RoleRow).where(RoleRow.user_id == uid, RoleRow.project_id == project_id))
        if row is None:
            s.add(RoleRow(user_id=uid, project_id=project_id, role=role))
        else:
            row.role = role
        s.commit()


def revoke(store: Store, name: str, project_id: int) -> bool:
    """Take ``name``'s role in a project away; False if they held none."""
    with store._session() as s:
        uid = _user_row(s, name).id
        gone = s.execute(delete(RoleRow).where(RoleRow.user_id == uid, RoleRow.project_id == project_id)).rowcount
        s.commit()
        return bool(gone)


def members(store: Store, project_id: int) -> dict[str, str]:
    """user name -> role in one project."""
    with store._session() as s:
        rows = s.execute(select(UserRow.name, RoleRow.role).join(RoleRow, RoleRow.user_id == UserRow.id)
                         .where(RoleRow.project_id == project_id).order_by(UserRow.name))
        return {n: r for n, r in rows}


def authenticate(store: Store, name: str, password: str) -> User | None:
    """The user if the password is theirs, else None (an unknown name costs one hash as well, so
    timing does not tell which names exist). An old hash is upgraded to the current parameters."""
    with store._session() as s:
        row = s.scalar(select(UserRow).where(UserRow.name == str(name)))
        if row is None:
            verify_password(_dummy_hash(), str(password))
            return None
        if not verify_password(row.password, str(password)):
            return None
        if _HASHER.check_needs_rehash(row.password):
            row.password = _HASHER.hash(str(password))
            s.commit()
        return User(row.id, row.name, _roles(s, row.id))


def at_least(role: str | None, needed: str) -> bool:
    """Whether ``role`` allows what ``needed`` allows (owner > annotator > viewer > None)."""
    return role is not None and ROLES.index(role) >= ROLES.index(needed)


# ----------------------------------------------------------------------------- guarded store
#: store methods a viewer may call (everything else taking a clip, project or take id is a write)
READS: frozenset[str] = frozenset({
    "project", "clips", "clip", "data_version", "runs", "tracks", "frame_boxes", "revision", "history",
    "next_track_id", "edit_state", "revisions", "keyframes", "human_frames", "progress", "reviews", "accepted",
    "accepted_frames", "occluders", "bundles", "take", "takes", "take_of_clip", "events",
    "mark_exported",  # a viewer may export; the flag only says that the clip left partlab once
})

_OWNERS = {"clip_id", "project_id", "take_id"}


class GuardedStore(Store):
    """The store as one signed-in user may see and change it (see the module's docstring).

    Roles are read once when it is made: the app makes one per page run, so a role granted or
    revoked takes effect on the user's next click.
    """

    def __init__(self, user_name: str, url: str | None = None, clips_dir=None):
        super().__init__(url, clips_dir)
        self.user = user_name
        self._plain = Store(self.url, self.clips_dir)  # the same engine, unguarded: for the checks themselves
        found = user(self._plain, user_name)
        if found is None:
            raise AccessError(f"no user named {user_name!r} (removed?); sign in again")
        self.roles: dict[int, str] = dict(found.roles)
        self._clip_project: dict[int, int] = {}

    # ---------------------------------------------------------------- who owns what
    def role(self, project_id: int) -> str | None:
        return self.roles.get(int(project_id))

    def may(self, project_id: int, needed: str = "annotator") -> bool:
        return at_least(self.role(project_id), needed)

    def _project_of(self, kind: str, key: int) -> int:
        if kind == "project_id":
            return int(key)
        if kind == "take_id":
            return self._plain.take(int(key)).project_id
        key = int(key)
        if key not in self._clip_project:
            self._clip_project[key] = self._plain.clip(key).project_id
        return self._clip_project[key]

    def require(self, kind: str, key: int, needed: str) -> int:
        """The project that ``key`` (a clip, project or take id) belongs to, if this user holds at
        least ``needed`` there; a project without their role is reported as not existing."""
        try:
            pid = self._project_of(kind, key)
        except StoreError:
            raise StoreError(f"no {kind[:-3]} with id {key}") from None
        role = self.role(pid)
        if role is None:
            raise StoreError(f"no {kind[:-3]} with id {key}")
        if not at_least(role, needed):
            name = self._plain.project(pid).name
            raise AccessError(f"{self.user} is a {role} of project {name!r} and cannot change it "
                              f"(an {needed} can; ask the project's owner)")
        return pid

    # --------------------------------------------------------------- project level
    def projects(self):
        return [p for p in super().projects() if p.id in self.roles]

    def project_by_name(self, name: str):
        found = super().project_by_name(name)
        return found if found is not None and found.id in self.roles else None

    def create_project(self, name: str):
        """Any signed-in user may start a project; they become its owner."""
        project = super().create_project(name)
        grant(self._plain, self.user, project.id, "owner")
        self.roles[project.id] = "owner"
        return project


def _guard(name: str, method, kind: str):
    needed = "viewer" if name in READS else "annotator"

    @functools.wraps(method)
    def guarded(self, *args, **kwargs):
        key = args[0] if args else kwargs[kind]
        self.require(kind, key, needed)
        return method(self, *args, **kwargs)

    return guarded


for _name, _method in inspect.getmembers(Store, inspect.isfunction):
    _params = list(inspect.signature(_method).parameters)
    if not _name.startswith("_") and len(_params) > 1 and _params[1] in _OWNERS:
        setattr(GuardedStore, _name, _guard(_name, _method, _params[1]))


def require(store: Store, project_id: int, needed: str = "annotator") -> None:
    """Refuse (:class:`AccessError`) unless the store's user holds ``needed`` in the project; a plain
    store (no sign-in) allows everything. For work that leaves the store, such as a background job
    that opens its own."""
    if isinstance(store, GuardedStore):
        store.require("project_id", project_id, needed)


def may(store: Store, project_id: int, needed: str = "annotator") -> bool:
    return not isinstance(store, GuardedStore) or store.may(project_id, needed)
