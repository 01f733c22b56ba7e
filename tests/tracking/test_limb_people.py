"""Found automatically, limbs live only on people (partlab.tracking.limbs.people, issue 13)."""

from __future__ import annotations

import cv2
import numpy as np

from partlab.tracking.core.skin import SkinModel
from partlab.tracking.limbs.people import foreground_people, in_regions, merge_boxes, on_regions
from partlab.tracking.limbs.tracker import LimbTracker
from partlab.tracking.params import LimbParams
from partlab.tracking.tracks import records_to_frame

SKIN = (110, 150, 210)
BG = (90, 110, 70)
COAT = (60, 40, 30)
P = LimbParams().updated({"dynamics.particles": 150})


def walker_mask(shape, x, top, height):
    """A standing person's silhouette: head, body and two legs with a gap between them."""
    m = np.zeros(shape, np.uint8)
    w = height // 4
    cv2.circle(m, (x, top + height // 14), height // 14, 255, -1)
    cv2.rectangle(m, (x - w // 2, top + height // 7), (x + w // 2, top + height // 2), 255, -1)
    for dx in (-w // 3, w // 3):
        cv2.rectangle(m, (x + dx - w // 8, top + height // 2), (x + dx + w // 8, top + height - 1), 255, -1)
    return m


def test_person_regions_are_tall_foreground_components_joined_across_the_legs():
    fg = walker_mask((240, 320), 100, 60, 120)
    cv2.rectangle(fg, (250, 200), (259, 207), 255, -1)  # a road cone's flicker: too short
    boxes = foreground_people(fg, P)
    assert boxes.shape == (1, 4)
    x, y, w, h = boxes[0]
    ys, xs = np.nonzero(walker_mask((240, 320), 100, 60, 120))
    # the walker's box to within the shrunk grid (4 px)
    assert abs(y - ys.min()) <= 4 and abs(y + h - ys.max()) <= 4 and abs(x - xs.min()) <= 4
    assert abs(x + w - xs.max()) <= 4


def test_in_regions_top_part_and_margin():
    boxes = np.array([[10, 20, 20, 60]], float)
    pts = np.array([[20, 25], [20, 60], [5, 25], [40, 40]], float)
    assert in_regions(pts, boxes).tolist() == [True, True, False, False]
    assert in_regions(pts, boxes, top=0.25).tolist() == [True, False, False, False]  # rows 20..35
    assert in_regions(pts, boxes, margin=6).tolist() == [True, True, True, False]
    assert in_regions(pts, np.zeros((0, 4))).tolist() == [False] * 4


def test_merge_boxes_joins_overlaps_clips_and_drops_empty_ones():
    r = merge_boxes(np.array([[0, 0, 10, 10], [5, 5, 10, 10], [30, 30, 5, 5], [-5, 90, 20, 20], [50, 50, 0, 4]]),
                    (100, 60))
    assert sorted(map(tuple, r)) == [(0, 0, 15, 15), (0, 90, 15, 100), (30, 30, 35, 35)]


def test_on_regions_equals_the_whole_frame_inside_and_fills_outside():
    rng = np.random.default_rng(0)
    frame = rng.integers(0, 256, (80, 100, 3), dtype=np.uint8)
    skin = SkinModel.default()
    regions = merge_boxes(np.array([[3, 4, 30, 20], [60, 50, 40, 30]]), frame.shape[:2])
    got = on_regions(skin.probability, frame, regions, -1.0, np.float32, pad=skin.blur)
    whole = skin.probability(frame)
    inside = np.zeros(frame.shape[:2], bool)
    for x1, y1, x2, y2 in regions:
        inside[y1:y2, x1:x2] = True
    np.testing.assert_array_equal(got[inside], whole[inside])
    assert (got[~inside] == -1).all()


def test_without_init_limbs_start_on_the_walker_never_on_a_skin_coloured_wall_patch():
    """A walker crosses the frame; a skin-coloured patch on the wall is in the foreground for 8
    frames (a lighting change), longer than a tracker needs to start. Only the walker's limbs are
    reported, its head in the top of its silhouette."""
    rows, shape = [], (200, 320)
    tr = LimbTracker(P, np.random.default_rng(1), face_detector=False)
    for t in range(30):
        x = 60 + 4 * t
        f = np.full(shape + (3,), BG, np.uint8)
        cv2.rectangle(f, (250, 30), (270, 46), SKIN, -1)  # the wall patch
        fg = walker_mask(shape, x, 50, 140)
        f[fg > 0] = COAT
        cv2.circle(f, (x, 60), 8, SKIN, -1)  # face
        for dx in (-22, 22):
            cv2.circle(f, (x + dx, 120), 5, SKIN, -1)  # hands beside the body
            cv2.circle(fg, (x + dx, 120), 6, 255, -1)
        if 5 <= t < 13:
            cv2.rectangle(fg, (248, 28), (272, 48), 255, -1)
        rows += tr.step(t, f, fg)
    out = records_to_frame(rows)
    assert len(out) > 0
    cx, cy = out.x + out.w / 2, out.y + out.h / 2
    on_patch = (cx > 240) & (cx < 280) & (cy < 56)
    assert not on_patch.any()
    heads = out[out.part == "head"]
    assert len(heads) >= 15
    walker_x = 60 + 4 * heads.frame
    assert (np.hypot(heads.x + heads.w / 2 - walker_x, heads.y + heads.h / 2 - 60) < 6).all()
