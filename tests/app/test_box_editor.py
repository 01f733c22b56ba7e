"""The box editor's Python side: what it sends to the browser."""

from __future__ import annotations

import base64

import cv2
import numpy as np

from partlab.app.box_editor import PALETTE, encode_image, pack_boxes, track_colour
from partlab.tracking.core.box import Box
from partlab.tracking.parts import PART_NAMES


def test_frame_is_sent_as_a_jpeg_of_the_same_size(boxes):
    frame = np.zeros((72, 96, 3), np.uint8)
    frame[10:20, 30:40] = (0, 0, 255)
    url = encode_image(frame)
    assert url.startswith("data:image/jpeg;base64,")
    back = cv2.imdecode(np.frombuffer(base64.b64decode(url.split(",", 1)[1]), np.uint8), cv2.IMREAD_COLOR)
    assert back.shape == (72, 96, 3)
    assert back[15, 35, 2] > 200 and back[15, 35, 0] < 60 and back[50, 50].max() < 10


def test_boxes_are_packed_by_frame_with_revision_and_flags(store, tracked_clip):
    _, clip = tracked_clip
    store.edit_box(clip.id, 2, 1, "head", Box(20, 21, 8, 10), failure=True, expected_revision=0)
    packed = pack_boxes(store.tracks(clip.id))
    assert sorted(packed) == list(range(12))
    person, head = sorted(packed[2], key=lambda r: r[1])  # [track, part index, x, y, w, h, flags, occluded, rev]
    assert person == [1, PART_NAMES.index("person"), 16.0, 20.0, 14.0, 44.0, 0, 0.0, 0]
    assert head == [1, PART_NAMES.index("head"), 20.0, 21.0, 8.0, 10.0, 1 + 2, 0.0, 1]  # failure, human
    assert track_colour(1) == PALETTE[1] and track_colour(11) == PALETTE[1]
