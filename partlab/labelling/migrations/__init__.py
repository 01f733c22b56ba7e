"""Schema migrations of the annotation store (Alembic), run by partlab itself.

:func:`upgrade` brings a database to the newest revision this partlab knows (``head``):

- a new, empty database is created by running every revision;
- a database made by partlab 0.2.0 (its tables, no ``alembic_version``) is stamped at
  revision ``0001`` (that release's schema, exactly) and upgraded from there;
- a database at a revision this partlab does not know (made by a newer partlab) is refused
  with a :class:`SchemaError` that says so, before anything is written.

Users never need ``alembic.ini``: the scripts ship inside the package (``versions/``). Two
processes opening a new database at once are serialised (a lock file beside a SQLite file, an
advisory lock on PostgreSQL), so the second finds the first's tables.
"""

from __future__ import annotations

import contextlib
from pathlib import Path

from sqlalchemy import inspect, text
from sqlalchemy.engine import Connection, Engine

HERE = Path(__file__).resolve().parent
#: the oldest revision: the schema partlab 0.2.0 created without migrations
BASELINE = "0001"
#: a table every partlab database has had since the first release
_MARKER_TABLE = "projects"
_PG_LOCK_KEY = 0x7061_7274_6C61_62  # "partlab", any constant the application owns


class SchemaError(RuntimeError):
    """A database this partlab cannot open; the message says why and what to do."""


def _config(connection: Connection | None = None):
    from alembic.config import Config

    cfg = Config()
    cfg.set_main_option("script_location", str(HERE))
    if connection is not None:
        cfg.attributes["connection"] = connection
    return cfg


def head() -> str:
    """The newest revision shipped with this partlab."""
    from alembic.script import ScriptDirectory

    return ScriptDirectory.from_config(_config()).get_current_head()


def known_revisions() -> list[str]:
    """Every shipped revision, oldest first."""
    from alembic.script import ScriptDirectory

    return [s.revision for s in reversed(list(ScriptDirectory.from_config(_config()).walk_revisions()))]


def current(connection: Connection) -> str | None:
    """The database's revision (None: no ``alembic_version`` table or no row in it)."""
    from alembic.migration import MigrationContext

    return MigrationContext.configure(connection).get_current_revision()


@contextlib.contextmanager
def _exclusive(engine: Engine):
    """Serialise migrations between processes opening the same database."""
    if engine.dialect.name == "postgresql":
        with engine.connect() as conn:
            conn.execute(text("SELECT pg_advisory_lock(:k)"), {"k": _PG_LOCK_KEY})
            conn.commit()
            try:
                yield
            finally:
                conn.execute(text("SELECT pg_advisory_unlock(:k)"), {"k": _PG_LOCK_KEY})
                conn.commit()
        return
    database = engine.url.database if engine.dialect.name == "sqlite" else None
    if not database or database == ":memory:":
        yield
        return
    try:
        import fcntl
    except ImportError:  # Windows: no advisory file locks; one process migrates at a time by hand
        yield
        return
    with open(f"{database}.migrate-lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def upgrade(engine: Engine, revision: str = "head") -> str:
    """Bring the database to ``revision`` (default: head); returns the revision it is at."""
    from alembic import command

    with _exclusive(engine):
        with engine.connect() as conn:
            found = current(conn)
            tables = set(inspect(conn).get_table_names())
        known = known_revisions()
        if found is not None and found not in known:
            raise SchemaError(
                f"{engine.url.render_as_string(hide_password=True)}: the database is at schema revision {found!r}, "
                f"made by a newer partlab; this partlab knows revisions up to {known[-1]!r}. "
                "Upgrade partlab (pip install -U partlab) to open it; nothing was changed")
        target = known[-1] if revision == "head" else revision
        if found == target:
            return found
        ddl = _transactional(engine)
        try:
            with ddl.begin() as conn:
                cfg = _config(conn)
                if found is None and _MARKER_TABLE in tables:
                    command.stamp(cfg, BASELINE)  # made by partlab 0.2.0: its schema is revision 1
                command.upgrade(cfg, revision)
            with ddl.connect() as conn:
                return current(conn)
        finally:
            if ddl is not engine:
                ddl.dispose()


def _transactional(engine: Engine) -> Engine:
    """An engine whose transactions really hold the DDL: all of a migration or none of it.

    PostgreSQL's DDL is transactional as it is. Python's sqlite3 driver commits before DDL on its
    own, so a migration that fails half-way would leave half a schema; for the migration only, a
    separate engine turns that off and issues BEGIN itself (the SQLAlchemy documentation's recipe
    for the pysqlite driver). The store's own engine keeps the driver's usual behaviour.
    """
    if engine.dialect.name != "sqlite":
        return engine
    from sqlalchemy import create_engine, event

    ddl = create_engine(engine.url, connect_args={"timeout": 30})

    @event.listens_for(ddl, "connect")
    def _autocommit_driver(dbapi_conn, _record):
        dbapi_conn.isolation_level = None

    @event.listens_for(ddl, "begin")
    def _begin(conn):
        conn.exec_driver_sql("BEGIN IMMEDIATE")

    return ddl
