"""One track id per person when body and limb trackers run together (tracking/identity.py)."""

from __future__ import annotations

import pandas as pd

from partlab.tracking.identity import match_limb_people, merge_tracks


def _rows(track_id, part, boxes):
    return [dict(frame=f, track_id=track_id, part=part, x=x, y=y, w=w, h=h) for f, (x, y, w, h) in boxes]


def _scene():
    frames = range(30)
    # body people 1 (walks right) and 2 (stands at x = 300)
    body = pd.DataFrame(
        _rows(1, "person", [(f, (10 + 3 * f, 50, 40, 120)) for f in frames])
        + _rows(1, "head", [(f, (20 + 3 * f, 50, 20, 22)) for f in frames])
        + _rows(2, "person", [(f, (300, 60, 40, 110)) for f in frames])
        + _rows(2, "head", [(f, (310, 60, 20, 20)) for f in frames[:20]]))
    # limb people: 7 is person 2 (head inside its box), 8 is person 1, 9 is on the wall
    limbs = pd.DataFrame(
        _rows(7, "head", [(f, (312, 62, 14, 14)) for f in frames])
        + _rows(7, "left_hand", [(f, (290, 120, 10, 10)) for f in frames])
        + _rows(8, "head", [(f, (22 + 3 * f, 52, 14, 14)) for f in frames[5:]])
        + _rows(9, "head", [(f, (600, 20, 14, 14)) for f in frames]))
    return body, limbs


def test_limb_people_take_the_id_of_the_body_person_around_their_head():
    body, limbs = _scene()
    assert match_limb_people(body, limbs) == {7: 2, 8: 1}
    # a head inside the box in too few frames is not matched
    assert match_limb_people(body, limbs, min_frames=26) == {7: 2}


def test_merged_table_has_one_head_per_person_and_frame():
    body, limbs = _scene()
    out = merge_tracks(body, limbs, match_limb_people(body, limbs), offset=100000)
    assert sorted(out.track_id.unique()) == [1, 2, 100009]
    heads = out[out.part == "head"].groupby(["frame", "track_id"]).size()
    assert heads.max() == 1
    # person 2's body head ends at frame 20: the limb head fills frames 20..29
    p2 = out[(out.track_id == 2) & (out.part == "head")]
    assert len(p2) == 30 and (p2[p2.frame >= 20].w == 14).all()
    assert len(out[(out.track_id == 2) & (out.part == "left_hand")]) == 30


def test_automatic_limb_rows_are_kept_only_on_people():
    import pandas as pd

    from partlab.tracking.combined import on_people

    body = pd.DataFrame([(0, 1, "person", 100, 50, 40, 120), (1, 1, "person", 104, 50, 40, 120)],
                        columns=["frame", "track_id", "part", "x", "y", "w", "h"])
    limbs = pd.DataFrame([
        (0, 7, "head", 110, 55, 16, 16),        # top of the person: kept
        (0, 7, "left_hand", 100, 110, 10, 10),  # inside the box: kept
        (0, 8, "head", 112, 120, 16, 16),       # centre 128 below the top third (50 + 40 = 90): dropped
        (1, 8, "head", 114, 82, 16, 16),        # centre 90 at the top third's edge: kept
        (1, 8, "left_hand", 114, 86, 16, 16),   # ... a hand there is inside the box: kept
        (1, 9, "head", 400, 60, 16, 16),        # on a wall, nobody there: dropped
        (2, 7, "head", 110, 55, 16, 16),        # a frame without people: dropped
    ], columns=["frame", "track_id", "part", "x", "y", "w", "h"])
    kept = on_people(limbs, body)
    assert list(zip(kept.frame, kept.part, kept.track_id)) == [(0, "head", 7), (0, "left_hand", 7),
                                                                (1, "head", 8), (1, "left_hand", 8)]
    limbs.loc[3, "y"] = 84  # centre 92: below the top third
    assert (1, "head") not in set(zip(on_people(limbs, body).frame, on_people(limbs, body).part))


def test_coasted_body_heads_give_way_to_the_limb_trackers_measured_head():
    from partlab.tracking.combined import measured_heads

    body, limbs = _scene()
    body["occluded"] = 0.0
    hidden = (body.track_id == 1) & body.frame.between(10, 14)  # person 1 coasts behind someone
    body.loc[hidden, "occluded"] = 1.0
    kept = measured_heads(body)
    assert len(kept[(kept.track_id == 1) & (kept.part == "person")]) == 30  # the person stays
    assert set(kept[(kept.track_id == 1) & (kept.part == "head")].frame) == set(range(30)) - set(range(10, 15))
    out = merge_tracks(kept, limbs, match_limb_people(kept, limbs), offset=100000)
    p1 = out[(out.track_id == 1) & (out.part == "head")].set_index("frame").sort_index()
    assert len(p1) == 30 and (p1.loc[10:14, "w"] == 14).all() and (p1.loc[15:, "w"] == 20).all()


def test_unmatched_limb_rows_go_to_the_body_person_they_are_on():
    from partlab.tracking.identity import relabel_on_people

    body, limbs = _scene()
    # limb person 11: a fragment whose head is on person 2 (frames 0-4) then on person 1 (frames 5-9),
    # never long enough on one body person to be matched; a left hand on person 2 where 7's is too
    extra = pd.DataFrame(
        _rows(11, "head", [(f, (312, 64, 14, 14)) for f in range(5)])
        + _rows(11, "head", [(f, (22 + 3 * f, 54, 14, 14)) for f in range(5, 10)])
        + _rows(11, "left_hand", [(f, (295, 125, 10, 10)) for f in range(3)]))
    limbs = pd.concat([limbs, extra], ignore_index=True)
    mapping = match_limb_people(body, limbs)
    assert 11 not in mapping and mapping == {7: 2, 8: 1}
    out, given = relabel_on_people(body, limbs, mapping, head_top=1 / 3)
    assert not (out.x == 600).any()  # limb person 9's head on the wall: on nobody, dropped
    moved = out[out.relabelled]
    heads = moved[moved.part == "head"].set_index("frame").sort_index()["track_id"]
    assert heads.loc[0:4].eq(2).all() and heads.loc[5:9].eq(1).all()
    assert given == {11: 2} or given == {11: 1}
    # person 2's own (matched) left hand wins over the relabelled one in frames 0-2
    assert moved[moved.part == "left_hand"].empty
    merged = merge_tracks(body, out, mapping, offset=100000)
    assert sorted(merged.track_id.unique()) == [1, 2]
    assert not merged.duplicated(["frame", "track_id", "part"]).any()
