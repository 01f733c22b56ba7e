"""Alembic environment of the annotation store.

partlab runs its migrations itself when a store is opened (``partlab.labelling.migrations.upgrade``),
passing its own connection in ``config.attributes["connection"]``; no ``alembic.ini`` is needed.
Developers writing a new revision can still use the alembic command line from a scratch
``alembic.ini`` whose ``script_location`` points here (``sqlalchemy.url`` names a database).
"""

from __future__ import annotations

from alembic import context
from sqlalchemy import create_engine


def _run(connection) -> None:
    from partlab.labelling.store import Base  # for `alembic revision --autogenerate` only

    context.configure(connection=connection, target_metadata=Base.metadata,
                      render_as_batch=connection.dialect.name == "sqlite")
    with context.begin_transaction():
        context.run_migrations()


connection = context.config.attributes.get("connection")
if connection is not None:
    _run(connection)
else:
    from partlab.labelling.config import database_url

    engine = create_engine(context.config.get_main_option("sqlalchemy.url") or database_url())
    with engine.begin() as conn:
        _run(conn)
