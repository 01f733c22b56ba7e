"""Revision 4: what an edit is, re-tracks that can be undone, and the review pass.

- ``edits.kind``: ``box`` (a box the user drew, moved or flagged: a keyframe, a corrected frame,
  training truth), ``restore`` (the key goes back to the tracker: an undone first edit is no
  correction) or ``track`` (an identity operation: merge, split, change id, delete from a frame
  on moved or removed the tracker's box without checking it). Existing edits are ``box``.
- ``tracker_boxes.superseded_by``: the run that replaced a box (NULL: in effect), so a re-track
  keeps what it replaced and is undone as one step (``Store.undo_run``).
- ``reviews``: a reviewer's verdict (accepted or not) on frames ``start..stop`` of one track.
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0004"
down_revision = "0003"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("edits") as batch:
        batch.add_column(sa.Column("kind", sa.String(length=12), nullable=False, server_default="box"))
    with op.batch_alter_table("tracker_boxes") as batch:
        batch.add_column(sa.Column("superseded_by", sa.Integer(), nullable=True))
    op.create_index("ix_tracker_boxes_superseded_by", "tracker_boxes", ["superseded_by"])
    op.create_table(
        "reviews",
        sa.Column("id", sa.Integer(), nullable=False),
        sa.Column("clip_id", sa.Integer(), nullable=False),
        sa.Column("track_id", sa.Integer(), nullable=False),
        sa.Column("start", sa.Integer(), nullable=False),
        sa.Column("stop", sa.Integer(), nullable=False),
        sa.Column("accepted", sa.Boolean(), nullable=False),
        sa.Column("author", sa.String(length=100), nullable=False),
        sa.Column("created", sa.DateTime(timezone=True), nullable=False),
        sa.ForeignKeyConstraint(["clip_id"], ["clips.id"]),
        sa.PrimaryKeyConstraint("id"),
    )
    op.create_index("ix_reviews_clip_id", "reviews", ["clip_id"])


def downgrade() -> None:
    op.drop_index("ix_reviews_clip_id", "reviews")
    op.drop_table("reviews")
    op.drop_index("ix_tracker_boxes_superseded_by", "tracker_boxes")
    with op.batch_alter_table("tracker_boxes") as batch:
        batch.drop_column("superseded_by")
    with op.batch_alter_table("edits") as batch:
        batch.drop_column("kind")
