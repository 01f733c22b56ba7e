from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from partlab.tracking.core.skin import SkinModel, find_blobs, train_skin_model

SKIN_BGR = [(110, 150, 210), (60, 90, 140), (150, 180, 230), (45, 70, 105)]  # light to dark skin tones
NON_SKIN_BGR = [(90, 110, 70), (200, 60, 40), (128, 128, 128), (20, 200, 20), (255, 255, 255)]


def _px(colour):
    return np.array([[colour]], np.uint8)


def test_default_rule_accepts_skin_tones_and_rejects_green_blue_grey():
    m = SkinModel.default()
    assert [float(m.probability(_px(c))[0, 0]) for c in SKIN_BGR] == [1.0] * 4
    assert [float(m.probability(_px(c))[0, 0]) for c in NON_SKIN_BGR] == [0.0] * 5


def test_mask_is_skin_and_foreground():
    frame = np.zeros((10, 20, 3), np.uint8)
    frame[:, :10] = SKIN_BGR[0]
    fg = np.zeros((10, 20), np.uint8)
    fg[:5] = 255
    mask = SkinModel.default(blur=1).mask(frame, fg)
    assert mask.dtype == np.uint8 and int((mask > 0).sum()) == 5 * 10
    with pytest.raises(ValueError, match="does not match"):
        SkinModel.default().mask(frame, fg[:4])


def test_blur_turns_a_noisy_skin_patch_into_a_solid_one():
    rng = np.random.default_rng(0)
    frame = np.clip(np.full((40, 40, 3), (120, 137, 160), float) + rng.normal(0, 12, (40, 40, 3)), 0, 255)
    frame = frame.astype(np.uint8)  # Cr ~ 141: near the rule edge (136), so noise flips pixels
    raw = SkinModel.default(blur=1).probability(frame)[5:35, 5:35].mean()
    smooth = SkinModel.default(blur=5).probability(frame)[5:35, 5:35].mean()
    assert raw < 0.8 and smooth > 0.95


def test_find_blobs_keeps_the_largest_ceil_3_alpha_people_and_drops_tiny_ones():
    mask = np.zeros((100, 200), np.uint8)
    radii = [12, 10, 8, 7, 6, 5, 2]  # areas ~ 450, 314, 200, 154, 113, 78, 13
    for i, r in enumerate(radii):
        cv2.circle(mask, (15 + 27 * i, 50), r, 255, -1)
    b = find_blobs(mask, people=1, alpha=1.5, min_area=30)  # ceil(4.5) = 5 kept
    assert len(b) == 5 == math.ceil(3 * 1.5 * 1)
    assert list(np.round(b.centres[:, 0])) == [15, 42, 69, 96, 123]
    assert np.all(np.diff(b.areas) <= 0)
    b = find_blobs(mask, people=2, alpha=1.5, min_area=30)  # 9 allowed, tiny r=2 dropped
    assert len(b) == 6
    b = find_blobs(mask, people=1, alpha=1.0, min_area=500)
    assert len(b) == 0


def test_training_learns_a_skin_colour_outside_the_rule_and_keeps_background_out():
    odd_skin = (80, 120, 230)  # Cr ~ 185: outside the default rule
    bg = (90, 110, 70)
    assert SkinModel.default().probability(_px(odd_skin))[0, 0] == 0.0
    frames, boxes = [], []
    for k in range(3):
        f = np.full((60, 80, 3), bg, np.uint8)
        cv2.circle(f, (20 + 10 * k, 30), 10, odd_skin, -1)
        frames.append(f)
        boxes.append(np.array([[10 + 10 * k, 20, 20, 20]]))
    m = train_skin_model(frames, boxes, bins=32)
    assert m.probability(_px(odd_skin))[0, 0] > 0.8
    assert m.probability(_px(bg))[0, 0] < 0.05
    assert m.probability(_px(SKIN_BGR[0]))[0, 0] == 1.0  # unseen skin keeps the rule's answer


def test_skin_model_round_trips_through_json_and_npz(tmp_path):
    table = np.random.default_rng(1).random((16, 16)).astype(np.float32)
    m = SkinModel(table, blur=7)
    for name in ("skin.json", "skin.npz"):
        m.save(tmp_path / name)
        back = SkinModel.load(tmp_path / name)
        np.testing.assert_allclose(back.table[0], table, atol=1e-5)
        assert back.blur == 7


def test_bad_inputs_get_clear_errors():
    with pytest.raises(ValueError, match="square"):
        SkinModel(np.zeros((10, 12)))
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        SkinModel(np.full((16, 16), 2.0))
    with pytest.raises(ValueError, match="BGR"):
        SkinModel.default().probability(np.zeros((4, 4), np.uint8))
    with pytest.raises(ValueError, match="no skin pixels"):
        train_skin_model([np.zeros((10, 10, 3), np.uint8)], [np.zeros((0, 4))])
    with pytest.raises(ValueError, match="odd kernel"):
        SkinModel(np.zeros((16, 16)), blur=4)
    with pytest.raises(ValueError, match="not a skin model"):
        SkinModel.from_dict({"kind": "other"})


def test_keep_mass_keeps_a_box_colour_that_fills_more_of_the_frame_elsewhere():
    # a hand whose colour also covers a large forearm/desk area outside its box: the plain
    # Bayes ratio drops below 0.5 and the refit model would no longer see the hand it was fit on
    skin, bg, other = SKIN_BGR[0], (90, 110, 70), SKIN_BGR[2]
    f = np.full((60, 120, 3), bg, np.uint8)
    f[:, 60:] = skin  # same colour as the hand, outside the box
    f[40:60, 0:30] = other  # a rule-skin colour that is not in the box
    cv2.circle(f, (20, 20), 10, skin, -1)
    box = [np.array([[10, 10, 20, 20]])]
    plain = train_skin_model([f], box, bins=32)
    kept = train_skin_model([f], box, bins=32, keep_mass=0.8)
    assert plain.probability(_px(skin))[0, 0] < 0.5
    assert kept.probability(_px(skin))[0, 0] == 1.0
    assert kept.probability(_px(bg))[0, 0] < 0.05
    assert kept.probability(_px(other))[0, 0] < 0.5  # colours not in the box still earn their ratio
    # a box under keep_min_side pixels (a distant walker's hand) keeps the plain ratio
    small = train_skin_model([f], box, bins=32, keep_mass=0.8, keep_min_side=21)
    assert small.probability(_px(skin))[0, 0] == plain.probability(_px(skin))[0, 0]
    with pytest.raises(ValueError, match="keep_mass"):
        train_skin_model([f], box, bins=32, keep_mass=1.5)


def test_keep_spread_keeps_a_small_hand_sharing_its_forearm_colour_but_not_the_floors():
    # one camera, 15 px hands of people standing with bare forearms (the synthetic exchange and
    # clap scenes at 720x480): the forearm shares the hand's colour, so the plain ratio sees
    # none of the hand; the box is under keep_min_side (17), so it used not to be kept and the
    # hand was lost at frame 4. Its colour is ~6 box areas in the frame (hand and forearm):
    # kept. Another small hand of a colour the floor has too (~300 box areas): not kept.
    hand, floor_hand, bg, shirt = SKIN_BGR[0], SKIN_BGR[2], (90, 110, 70), SKIN_BGR[3]
    f = np.full((240, 320, 3), bg, np.uint8)
    f[:120, 200:] = floor_hand  # the floor: 120 x 120 px of the second hand's colour
    f[40:100, 20:35] = hand  # a bare forearm, 15 x 60
    cv2.ellipse(f, (27, 107), (7, 7), 0, 0, 360, hand, -1)  # its hand below it
    cv2.ellipse(f, (127, 107), (7, 7), 0, 0, 360, floor_hand, -1)  # the other hand
    f[20:80, 120:135] = shirt  # a brown sleeve, behind which a hidden hand's box lies
    boxes = [np.array([[20, 100, 15, 15], [120, 100, 15, 15], [120, 45, 15, 15]], float)]
    args = dict(bins=32, keep_mass=0.8, keep_recall=0.1, keep_min_side=17, prior=SkinModel.default(32, blur=1))
    before = train_skin_model([f], boxes, **args)
    kept: list[bool] = []
    after = train_skin_model([f], boxes, keep_spread=50, kept=kept, keepable=[True, True, False], **args)
    assert before.probability(_px(hand))[0, 0] < 0.5  # the hand unseen: lost at frame 4
    assert after.probability(_px(hand))[0, 0] == 1.0
    assert after.probability(_px(floor_hand))[0, 0] < 0.5  # the floor stays no skin
    assert after.probability(_px(shirt))[0, 0] < 0.5  # a hidden hand's box is never kept
    assert kept == [True, False, False]
    # every box kept may keep the sleeve: the hidden box's bins would have been kept
    every = train_skin_model([f], boxes, keep_spread=50, **args)
    assert every.probability(_px(shirt))[0, 0] == 1.0


def test_find_blobs_region_by_region_equals_the_whole_mask():
    from partlab.tracking.limbs.people import merge_boxes

    rng = np.random.default_rng(4)
    mask = np.zeros((120, 200), np.uint8)
    for _ in range(12):
        x, y = int(rng.integers(5, 190)), int(rng.integers(5, 110))
        cv2.circle(mask, (x, y), int(rng.integers(2, 9)), 1, -1)
    regions = merge_boxes(np.array([[0, 0, 100, 60], [90, 50, 110, 70], [0, 60, 80, 60]]), mask.shape)
    inside = np.zeros(mask.shape, bool)
    for x1, y1, x2, y2 in regions:
        inside[y1:y2, x1:x2] = True
    mask[~inside] = 0
    whole, parts = find_blobs(mask, 3, 1.5, 5), find_blobs(mask, 3, 1.5, 5, regions)
    assert len(whole) == len(parts) > 3
    np.testing.assert_allclose(parts.centres, whole.centres)
    np.testing.assert_array_equal(parts.boxes, whole.boxes)
    np.testing.assert_array_equal(parts.areas, whole.areas)
    for i, j in zip(whole.ids, parts.ids):  # the same pixels under each blob's id
        np.testing.assert_array_equal(whole.labels == i, parts.labels == j)
