"""Revision 5: users who sign in, and their role in each project.

- ``users``: a name and an Argon2id hash of the password (never the password itself).
- ``project_roles``: one role per user and project, ``viewer`` (reads), ``annotator`` (also edits,
  tracks, trains, uploads) or ``owner`` (also grants roles). A project nobody holds a role in is
  seen only by an app run without sign-in (``partlab app --auth none``, loopback only).
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0005"
down_revision = "0004"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "users",
        sa.Column("id", sa.Integer(), nullable=False),
        sa.Column("name", sa.String(length=100), nullable=False),
        sa.Column("password", sa.Text(), nullable=False),
        sa.Column("created", sa.DateTime(timezone=True), nullable=False),
        sa.PrimaryKeyConstraint("id"),
        sa.UniqueConstraint("name"),
    )
    op.create_table(
        "project_roles",
        sa.Column("id", sa.Integer(), nullable=False),
        sa.Column("user_id", sa.Integer(), nullable=False),
        sa.Column("project_id", sa.Integer(), nullable=False),
        sa.Column("role", sa.String(length=20), nullable=False),
        sa.ForeignKeyConstraint(["user_id"], ["users.id"]),
        sa.ForeignKeyConstraint(["project_id"], ["projects.id"]),
        sa.PrimaryKeyConstraint("id"),
        sa.UniqueConstraint("user_id", "project_id"),
    )
    op.create_index("ix_project_roles_user_id", "project_roles", ["user_id"])
    op.create_index("ix_project_roles_project_id", "project_roles", ["project_id"])


def downgrade() -> None:
    op.drop_index("ix_project_roles_project_id", "project_roles")
    op.drop_index("ix_project_roles_user_id", "project_roles")
    op.drop_table("project_roles")
    op.drop_table("users")
