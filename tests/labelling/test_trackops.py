"""Track operations and keyframes in the store: merge, split, delete from a frame on,
change id, the person box from its parts, in-between boxes between keyframes, re-track
that keeps other tracks, each undone as one step."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from partlab.labelling import trackops
from partlab.labelling.store import Store, StoreError
from partlab.labelling.video import write_video
from partlab.tracking.core.box import Box

N = 60


def _tracks():
    rows = []
    for f in range(N):
        for t in (1, 2, 3):
            x = 5 + f + 60 * (t - 1)
            rows.append(dict(frame=f, track_id=t, part="person", x=x, y=10, w=20, h=50))
            rows.append(dict(frame=f, track_id=t, part="head", x=x + 6, y=10, w=8, h=8))
            rows.append(dict(frame=f, track_id=t, part="torso", x=x + 2, y=18, w=16, h=20))
    return pd.DataFrame(rows)


@pytest.fixture
def clip(tmp_path):
    store = Store()
    project = store.create_project("p")
    c = store.add_clip(project.id, write_video(tmp_path / "c.mp4", [np.zeros((80, 200, 3), np.uint8)] * N, fps=10))
    store.save_tracker_run(c.id, _tracks())
    return store, c


def _ids(store, clip_id, frame):
    return sorted(set(store.frame_boxes(clip_id, frame).track_id))


def test_merge_split_delete_and_undo_each_as_one_step(clip):
    store, c = clip
    before = store.tracks(c.id)
    # delete track 3 from frame 40 on
    keys = trackops.apply(store, c.id, trackops.delete_from(store, c.id, 3, 40))
    assert len(keys) == 20 * 3 and _ids(store, c.id, 39) == [1, 2, 3] and _ids(store, c.id, 40) == [1, 2]
    assert store.human_frames(c.id) == []  # identity operations are not corrections
    store.undo_many(c.id, keys)
    pd.testing.assert_frame_equal(store.tracks(c.id).drop(columns="revision"), before.drop(columns="revision"))
    # split track 2 at frame 30: frames 30.. become track 4 (through the app's undo history)
    from partlab.app.editing import EditHistory, record, redo_step, undo_step

    hist = EditHistory()
    record(store, c.id, trackops.split(store, c.id, 2, 30), hist, "split", 30)
    assert _ids(store, c.id, 29) == [1, 2, 3] and _ids(store, c.id, 30) == [1, 3, 4]
    t4 = store.tracks(c.id).query("track_id == 4")
    assert (t4.frame.min(), t4.frame.max(), len(t4)) == (30, 59, 90)
    # merge 4 back into 2: one track again, with the same boxes as before the split
    record(store, c.id, trackops.merge(store, c.id, 2, 4), hist, "merge", 30)
    after = store.tracks(c.id)
    assert 4 not in set(after.track_id)
    cols = ["frame", "part", "x", "y", "w", "h"]
    pd.testing.assert_frame_equal(after.query("track_id == 2")[cols].reset_index(drop=True),
                                  before.query("track_id == 2")[cols].reset_index(drop=True))
    undo_step(store, c.id, hist)
    assert _ids(store, c.id, 30) == [1, 3, 4]
    undo_step(store, c.id, hist)
    assert _ids(store, c.id, 30) == [1, 2, 3] and 4 not in set(store.tracks(c.id).track_id)
    redo_step(store, c.id, hist)
    assert _ids(store, c.id, 30) == [1, 3, 4]
    undo_step(store, c.id, hist)
    # change id: 1 -> 7, then 7 -> 3 merges (3's boxes win where both have a part)
    trackops.apply(store, c.id, trackops.change_id(store, c.id, 1, 7))
    assert sorted(set(store.tracks(c.id).track_id)) == [2, 3, 7]
    with pytest.raises(StoreError, match="exists already"):
        trackops.split(store, c.id, 2, 10, new_id=3)


def test_person_box_follows_an_edited_part(clip):
    store, c = clip
    from partlab.app.editing import EditHistory, apply_events

    hist = EditHistory()
    res = apply_events(store, c.id, [dict(kind="edit", frame=5, track_id=1, part="head", box=[0, 0, 8, 8],
                                          failure=False, occluded=0, revision=0)], hist)
    assert res.errors == []
    person = store.frame_boxes(c.id, 5).set_index(["track_id", "part"]).loc[(1, "person")]
    # the MBR of head (0,0,8,8) and torso (12,18,16,20): x 0..28, y 0..38
    assert (person.x, person.y, person.w, person.h) == (0.0, 0.0, 28.0, 38.0)
    assert store.frame_boxes(c.id, 5).set_index(["track_id", "part"]).loc[(2, "person")].x == 70.0  # others kept
    apply_events(store, c.id, [dict(kind="undo")], hist)  # one step: head and person come back
    person = store.frame_boxes(c.id, 5).set_index(["track_id", "part"]).loc[(1, "person")]
    assert (person.x, person.y, person.w, person.h, person.source) == (10.0, 10.0, 20.0, 50.0, "tracker")


def _edit(store, c, frame, track, part, box):
    return store.edit_box(c.id, frame, track, part, Box(*box), expected_revision=store.revision(c.id, frame, track,
                                                                                                   part))


def test_moving_a_keyframe_refills_that_tracks_in_betweens_only(clip):
    store, c = clip
    for f in (0, 25, 50):  # keyframes every 25 frames on track 1's head
        _edit(store, c, f, 1, "head", (100.0 + f, 40.0, 10.0, 10.0))
    trackops.fill_between(store, c.id, 1, "head", 25)
    head = store.tracks(c.id).query("track_id == 1 and part == 'head'").set_index("frame")
    assert head.loc[10].x == pytest.approx(110.0) and head.loc[40].x == pytest.approx(140.0)
    others = store.tracks(c.id).query("not (track_id == 1 and part == 'head')")
    # move the middle keyframe 20 px down: frames 1..49 change, linearly, nothing else does
    _edit(store, c, 25, 1, "head", (125.0, 60.0, 10.0, 10.0))
    run = trackops.fill_between(store, c.id, 1, "head", 25)
    head2 = store.tracks(c.id).query("track_id == 1 and part == 'head'").set_index("frame")
    assert head2.loc[10].y == pytest.approx(40 + 20 * 10 / 25) and head2.loc[40].y == pytest.approx(60 - 20 * 15 / 25)
    assert head2.loc[55].y == 10.0  # after the last keyframe: the tracker's box
    pd.testing.assert_frame_equal(store.tracks(c.id).query("not (track_id == 1 and part == 'head')")
                                  .drop(columns="revision").reset_index(drop=True),
                                  others.drop(columns="revision").reset_index(drop=True))
    store.undo_run(c.id, run)  # the in-betweens of the first fill come back
    assert store.tracks(c.id).query("track_id == 1 and part == 'head'").set_index("frame").loc[10].y == 40.0


def test_retrack_replaces_only_the_tracks_asked_and_is_undone_as_one_step(clip):
    store, c = clip
    before = store.tracks(c.id)
    moved = _tracks().query("track_id == 1 and frame >= 20").assign(y=30.0)
    moved = pd.concat([moved, _tracks().query("track_id == 9")])
    run = store.save_tracker_run(c.id, moved, tracker="body", start_frame=20, stop_frame=40, track_ids=[1])
    now = store.tracks(c.id)
    assert set(now.query("track_id == 1 and 20 <= frame < 40").y) == {30.0}
    assert set(now.query("track_id == 1 and frame >= 40").y) == {10.0, 18.0}  # after the stop: unchanged
    assert len(now.query("track_id in (2, 3)")) == len(before.query("track_id in (2, 3)"))
    with pytest.raises(StoreError, match="newest"):
        store.undo_run(c.id, run - 1)
    store.undo_run(c.id, run)
    pd.testing.assert_frame_equal(store.tracks(c.id), before)


def test_review_verdicts_limit_the_export_to_accepted_frames(clip, tmp_path):
    from partlab.labelling import formats

    store, c = clip
    store.review(c.id, 1, 0, 29, True)
    store.review(c.id, 2, 10, 19, True)
    rid = store.review(c.id, 1, 20, 24, False)  # newer: frames 20-24 of track 1 rejected
    acc = store.accepted(c.id)
    assert len(acc) == 25 + 10 and not ((acc.track_id == 1) & acc.frame.between(20, 24)).any()
    assert store.accepted_frames(c.id) == list(range(0, 20)) + list(range(25, 30))
    assert store.progress(c.id)["accepted_frames"] == 25
    out = formats.export_clip(store, c.id, "mot", tmp_path / "mot", frames=False, accepted_only=True)
    mot = pd.read_csv(next(out.rglob("gt.txt")), header=None).iloc[:, :2].set_axis(["frame", "id"], axis=1)
    # one MOT file per part; MOT numbers the tracks its own way: two tracks, 25 and 10 frames kept
    assert sorted(mot.groupby("id").frame.nunique()) == [10, 25]
    store.undo_review(c.id, rid)
    assert store.progress(c.id)["accepted_frames"] == 30
    with pytest.raises(StoreError, match="not a range"):
        store.review(c.id, 1, 50, 70, True)
