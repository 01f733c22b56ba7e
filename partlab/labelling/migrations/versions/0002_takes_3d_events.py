"""Revision 2: takes of several streams, 3D points on boxes, and events.

- ``takes`` and ``streams``: a take is one or more synchronized streams, each stream one clip
  (``clips`` stays the unit of video: a clip is at most one stream of one take), in the order
  ``position``; the calibration is JSON per stream (``partlab.tracking.camera.Camera.to_dict``)
  and per take (anything that belongs to the world frame, e.g. its units or origin).
- ``camera`` (the stream a box is in, '' for one-stream takes) and ``X, Y, Z`` (millimetres in the
  take's world frame, NULL when unknown; columns ``world_x, world_y, world_z``) on
  ``tracker_boxes`` and ``edits``: the optional columns
  of the tracks CSV, so they round-trip through the store.
- ``events``: something that happens between ``start_frame`` and ``end_frame`` (inclusive) of a
  clip, involving some tracks and parts (activities: clap, handshake, exchange, pick, place...),
  with a confidence and free attributes; like edits, every change appends a revision with its
  author, so nothing is overwritten and a change can be undone.
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0002"
down_revision = "0001"
branch_labels = None
depends_on = None

_POINT_TABLES = ("tracker_boxes", "edits")
#: X, Y, Z of the tracks CSV; not "X": SQLite's column names ignore case and these tables have "x"
_POINT_COLUMNS = ("world_x", "world_y", "world_z")


def upgrade() -> None:
    op.create_table(
        "takes",
        sa.Column("id", sa.Integer(), nullable=False),
        sa.Column("project_id", sa.Integer(), nullable=False),
        sa.Column("name", sa.String(length=300), nullable=False),
        sa.Column("path", sa.Text(), nullable=False),
        sa.Column("fps", sa.Float(), nullable=True),
        sa.Column("calibration", sa.JSON(), nullable=False),
        sa.Column("created", sa.DateTime(timezone=True), nullable=False),
        sa.ForeignKeyConstraint(["project_id"], ["projects.id"]),
        sa.PrimaryKeyConstraint("id"),
        sa.UniqueConstraint("project_id", "name"),
    )
    op.create_index("ix_takes_project_id", "takes", ["project_id"])
    op.create_table(
        "streams",
        sa.Column("id", sa.Integer(), nullable=False),
        sa.Column("take_id", sa.Integer(), nullable=False),
        sa.Column("name", sa.String(length=100), nullable=False),
        sa.Column("position", sa.Integer(), nullable=False),
        sa.Column("clip_id", sa.Integer(), nullable=True),
        sa.Column("depth_path", sa.Text(), nullable=False),
        sa.Column("calibration", sa.JSON(), nullable=True),
        sa.ForeignKeyConstraint(["take_id"], ["takes.id"]),
        sa.ForeignKeyConstraint(["clip_id"], ["clips.id"]),
        sa.PrimaryKeyConstraint("id"),
        sa.UniqueConstraint("take_id", "name"),
        sa.UniqueConstraint("take_id", "position"),
        sa.UniqueConstraint("clip_id"),
    )
    op.create_index("ix_streams_take_id", "streams", ["take_id"])
    for table in _POINT_TABLES:
        # server_default: rows written by revision 1 get '' (no camera), like a 2D tracks CSV
        op.add_column(table, sa.Column("camera", sa.String(length=100), nullable=False, server_default=""))
        for column in _POINT_COLUMNS:
            op.add_column(table, sa.Column(column, sa.Float(), nullable=True))
    op.create_table(
        "events",
        sa.Column("id", sa.Integer(), nullable=False),
        sa.Column("clip_id", sa.Integer(), nullable=False),
        sa.Column("take_id", sa.Integer(), nullable=True),
        sa.Column("event_id", sa.Integer(), nullable=False),
        sa.Column("revision", sa.Integer(), nullable=False),
        sa.Column("start_frame", sa.Integer(), nullable=False),
        sa.Column("end_frame", sa.Integer(), nullable=False),
        sa.Column("type", sa.String(length=40), nullable=False),
        sa.Column("tracks", sa.JSON(), nullable=False),
        sa.Column("parts", sa.JSON(), nullable=False),
        sa.Column("confidence", sa.Float(), nullable=True),
        sa.Column("attributes", sa.JSON(), nullable=False),
        sa.Column("source", sa.String(length=20), nullable=False),
        sa.Column("deleted", sa.Boolean(), nullable=False),
        sa.Column("author", sa.String(length=100), nullable=False),
        sa.Column("created", sa.DateTime(timezone=True), nullable=False),
        sa.ForeignKeyConstraint(["clip_id"], ["clips.id"]),
        sa.ForeignKeyConstraint(["take_id"], ["takes.id"]),
        sa.PrimaryKeyConstraint("id"),
        sa.UniqueConstraint("clip_id", "event_id", "revision"),
    )
    op.create_index("ix_events_clip_id", "events", ["clip_id"])


def downgrade() -> None:
    op.drop_table("events")
    for table in _POINT_TABLES:
        with op.batch_alter_table(table) as batch:
            for column in (*reversed(_POINT_COLUMNS), "camera"):
                batch.drop_column(column)
    op.drop_table("streams")
    op.drop_table("takes")
