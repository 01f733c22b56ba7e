"""The box editor's Python side: what it sends to the browser."""

from __future__ import annotations

import base64

import cv2
import numpy as np

from partlab.app.box_editor import PALETTE, boxes_payload, encode_image, track_colour


def test_frame_is_sent_as_a_jpeg_of_the_same_size(boxes):
    frame = np.zeros((72, 96, 3), np.uint8)
    frame[10:20, 30:40] = (0, 0, 255)
    url = encode_image(frame)
    assert url.startswith("data:image/jpeg;base64,")
    back = cv2.imdecode(np.frombuffer(base64.b64decode(url.split(",", 1)[1]), np.uint8), cv2.IMREAD_COLOR)
    assert back.shape == (72, 96, 3)
    assert back[15, 35, 2] > 200 and back[15, 35, 0] < 60 and back[50, 50].max() < 10


def test_boxes_carry_revision_flags_and_track_colour(store, tracked_clip):
    _, clip = tracked_clip
    df = store.frame_boxes(clip.id, 2)
    [person, head] = sorted(boxes_payload(df), key=lambda b: b["part"] != "person")
    assert (person["x"], person["w"], person["revision"], person["failure"]) == (16.0, 14.0, 0, False)
    assert head["colour"] == track_colour(1) == PALETTE[1] and track_colour(11) == PALETTE[1]
