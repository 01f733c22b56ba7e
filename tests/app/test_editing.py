"""The editor events -> store glue: edits, flags, deletes, undo/redo, stale refusals."""

from __future__ import annotations

from partlab.app.editing import EditHistory, apply_events


def _box(store, clip_id, frame, part, track=1):
    df = store.frame_boxes(clip_id, frame)
    row = df[(df.track_id == track) & (df.part == part)]
    return None if row.empty else row.iloc[0]


def test_move_then_failure_flag_are_stored_as_revisions(store, tracked_clip):
    _, clip = tracked_clip
    hist = EditHistory()
    res = apply_events(store, clip.id, [
        dict(seq=1, kind="edit", frame=3, track_id=1, part="head", box=[25.5, 22, 8, 10], failure=False,
             occluded=0, revision=0),
        dict(seq=2, kind="edit", frame=3, track_id=1, part="head", box=[25.5, 22, 8, 10], failure=True,
             occluded=0, revision=1),
    ], hist)
    assert res.errors == [] and res.written == 2
    head = _box(store, clip.id, 3, "head")
    assert (head.x, head.y, bool(head.failure), head.source, int(head.revision)) == (25.5, 22.0, True, "human", 2)
    # the person box of that frame is still the tracker's (a head is not enough for the MBR)
    assert _box(store, clip.id, 3, "person").source == "tracker"
    assert [[k[3] for k in step.keys] for step in hist.undo] == [[1], [2]]


def test_stale_edit_is_refused_with_the_store_message(store, tracked_clip):
    _, clip = tracked_clip
    apply_events(store, clip.id, [dict(kind="edit", frame=0, track_id=1, part="head", box=[1, 2, 3, 4],
                                       failure=False, occluded=0, revision=0)], EditHistory())
    # a second session that still saw revision 0 tries to move the same box
    res = apply_events(store, clip.id, [dict(kind="edit", frame=0, track_id=1, part="head", box=[9, 9, 3, 4],
                                             failure=False, occluded=0, revision=0)], EditHistory())
    assert res.written == 0 and len(res.errors) == 1
    assert "changed by someone else" in res.errors[0] and "revision 1, you had 0" in res.errors[0]
    assert _box(store, clip.id, 0, "head").x == 1.0  # the first edit was not lost


def test_a_drag_made_on_top_of_a_refused_edit_does_not_overwrite_the_other_users_box(store, tracked_clip):
    """The editor counts a box's revision up when it sends an edit. When that edit is refused
    (someone else's edit came first), a drag made before the page's answer arrives expects the
    other user's revision: it is refused too (``based_on`` names the refused edit), and the other
    user's box stays. Once the page showed the stored box, the same user's edit is saved."""
    _, clip = tracked_clip
    edit = dict(kind="edit", frame=0, track_id=1, part="head", failure=False, occluded=0)
    assert apply_events(store, clip.id, [dict(edit, seq=1, box=[1, 2, 3, 4], revision=0)], EditHistory()).errors == []
    mine = EditHistory()  # this session still saw revision 0
    res = apply_events(store, clip.id, [dict(edit, seq=1, box=[9, 9, 3, 4], revision=0)], mine)
    assert res.written == 0 and "changed by someone else" in res.errors[0]
    res = apply_events(store, clip.id, [dict(edit, seq=2, box=[20, 20, 3, 4], revision=1, based_on=1)], mine)
    assert res.written == 0 and "before your previous edit" in res.errors[0], res.errors
    res = apply_events(store, clip.id, [dict(kind="delete", frame=0, track_id=1, part="head", seq=3, revision=2,
                                             based_on=2)], mine)
    assert res.written == 0 and len(res.errors) == 1  # a chain of them, deletes too
    assert (_box(store, clip.id, 0, "head").x, int(_box(store, clip.id, 0, "head").revision)) == (1.0, 1)
    # after the rerun the editor has the stored box (revision 1, from Python): saved
    res = apply_events(store, clip.id, [dict(edit, seq=4, box=[20, 20, 3, 4], revision=1, based_on=0)], mine)
    assert res.errors == [] and _box(store, clip.id, 0, "head").x == 20.0
    # and this session's own chain of edits goes on as before
    res = apply_events(store, clip.id, [dict(edit, seq=5, box=[21, 20, 3, 4], revision=2, based_on=4)], mine)
    assert res.errors == [] and int(_box(store, clip.id, 0, "head").revision) == 3


def test_undo_and_redo_walk_this_sessions_edits(store, tracked_clip):
    _, clip = tracked_clip
    hist = EditHistory()
    apply_events(store, clip.id, [dict(kind="edit", frame=5, track_id=1, part="person", box=[40, 21, 15, 44],
                                       failure=False, occluded=0, revision=0)], hist)
    res = apply_events(store, clip.id, [dict(kind="undo")], hist)
    assert res.errors == [] and res.frame == 5
    assert _box(store, clip.id, 5, "person").x == 25.0  # the tracker's box (10 + 3*5) is back
    res = apply_events(store, clip.id, [dict(kind="redo")], hist)
    assert res.errors == []
    assert _box(store, clip.id, 5, "person").x == 40.0
    assert len(hist.undo) == 1 and hist.redo == []
    assert "nothing to redo" in apply_events(store, clip.id, [dict(kind="redo")], hist).notes[0]


def test_add_and_delete_boxes_and_occluders(store, tracked_clip):
    _, clip = tracked_clip
    new_id = store.next_track_id(clip.id)
    hist = EditHistory()
    res = apply_events(store, clip.id, [
        dict(kind="edit", added=True, frame=2, track_id=new_id, part="left_hand", box=[50, 40, 5, 5],
             failure=False, occluded=1, revision=None),
        dict(kind="delete", frame=2, track_id=1, part="head", revision=0),
        dict(kind="occluders", boxes=[[0, 0, 20, 72]]),
        dict(kind="frame", target=7),
    ], hist)
    assert res.errors == [] and res.frame == 7
    hand = _box(store, clip.id, 2, "left_hand", track=new_id)
    assert (hand.x, hand.w, float(hand.occluded)) == (50.0, 5.0, 1.0)
    assert _box(store, clip.id, 2, "head") is None
    assert [(b.x, b.w, b.h) for b in store.occluders(clip.id)] == [(0.0, 20.0, 72.0)]
    # undoing the delete brings the tracker's head back
    apply_events(store, clip.id, [dict(kind="undo")], hist)
    assert _box(store, clip.id, 2, "head").x == 19.0


def test_bad_event_is_reported_not_raised(store, tracked_clip):
    _, clip = tracked_clip
    res = apply_events(store, clip.id, [dict(kind="edit", frame=99, track_id=1, part="head", box=[1, 1, 2, 2],
                                             failure=False, occluded=0, revision=0),
                                        dict(kind="edit", frame=0, track_id=1, part="elbow", box=[1, 1, 2, 2],
                                             revision=0)], EditHistory())
    assert res.written == 0
    assert "outside clip" in res.errors[0] and "unknown part 'elbow'" in res.errors[1]


def test_nan_inf_and_negative_boxes_are_refused_as_such_and_never_stored(store, tracked_clip):
    _, clip = tracked_clip
    before = store.tracks(clip.id)
    events = [dict(kind="edit", frame=2, track_id=1, part="head", box=box, failure=flag, occluded=occ, revision=0)
              for box, flag, occ in (([float("nan"), 1, 2, 2], False, 0), ([1, 1, float("inf"), 2], False, 0),
                                     ([1, 1, -4, 2], False, 0), ([1, 1, 2, 1e308], False, 0),
                                     ([1, 1, 2, 2], "maybe", 0), ([1, 1, 2, 2], False, float("nan")),
                                     ([1, 1, 2], False, 0), ("1,1,2,2", False, 0))]
    res = apply_events(store, clip.id, events, EditHistory())
    assert res.written == 0 and len(res.errors) == len(events)
    assert not any("changed by someone else" in e for e in res.errors)
    assert "box x: 'nan' is not a finite number" in res.errors[0]
    assert "box w: 'inf' is not a finite number" in res.errors[1]
    assert "box w: negative size -4" in res.errors[2]
    assert "box h: '1e+308' is beyond the limit" in res.errors[3]
    assert "'maybe' is not a boolean" in res.errors[4]
    assert "occluded: 'nan' is not a fraction" in res.errors[5]
    assert "a box is [x, y, w, h]" in res.errors[6] and "a box is [x, y, w, h]" in res.errors[7]
    after = store.tracks(clip.id)
    assert after.equals(before)  # nothing stored, nothing exported


def test_the_failure_flag_as_text_is_a_boolean(store, tracked_clip):
    _, clip = tracked_clip
    res = apply_events(store, clip.id, [dict(kind="edit", frame=2, track_id=1, part="head", box=[1, 1, 2, 2],
                                             failure="false", occluded=0, revision=0)], EditHistory())
    assert res.errors == [] and not bool(_box(store, clip.id, 2, "head").failure)


def test_an_undone_edit_is_no_correction(store, tracked_clip):
    _, clip = tracked_clip
    hist = EditHistory()
    apply_events(store, clip.id, [dict(kind="edit", frame=4, track_id=1, part="head", box=[30, 20, 8, 10],
                                       failure=True, occluded=0, revision=0)], hist)
    assert store.human_frames(clip.id) == [4] and len(store.keyframes(clip.id)) == 1
    apply_events(store, clip.id, [dict(kind="undo")], hist)
    head = _box(store, clip.id, 4, "head")
    assert (head.source, head.x, bool(head.failure), int(head.revision)) == ("tracker", 25.0, False, 2)
    assert store.human_frames(clip.id) == [] and store.progress(clip.id)["corrected_frames"] == 0
    apply_events(store, clip.id, [dict(kind="redo")], hist)
    assert _box(store, clip.id, 4, "head").source == "human" and store.human_frames(clip.id) == [4]


def _events(store, clip_id):
    return [(int(r.event_id), int(r.start_frame), int(r.end_frame), r.type) for r in store.events(clip_id).itertuples()]


def test_events_are_added_stretched_retyped_deleted_and_undone_as_steps(store, tracked_clip):
    _, clip = tracked_clip
    hist = EditHistory()
    res = apply_events(store, clip.id, [dict(seq=1, kind="event_add", frame=2, type="clap", start_frame=2,
                                             end_frame=4, tracks=[1], parts=["left_hand", "right_hand"])], hist)
    assert res.errors == [] and _events(store, clip.id) == [(1, 2, 4, "clap")]
    apply_events(store, clip.id, [dict(seq=2, kind="event_edit", event_id=1, revision=1, end_frame=9)], hist)
    apply_events(store, clip.id, [dict(seq=3, kind="event_edit", event_id=1, revision=2, type="handshake")], hist)
    assert _events(store, clip.id) == [(1, 2, 9, "handshake")]
    apply_events(store, clip.id, [dict(seq=4, kind="undo")], hist)
    assert _events(store, clip.id) == [(1, 2, 9, "clap")]
    apply_events(store, clip.id, [dict(seq=5, kind="undo")], hist)
    assert _events(store, clip.id) == [(1, 2, 4, "clap")]  # the stretch undone, a new revision
    apply_events(store, clip.id, [dict(seq=6, kind="redo")], hist)
    assert _events(store, clip.id) == [(1, 2, 9, "clap")]
    apply_events(store, clip.id, [dict(seq=7, kind="event_delete", event_id=1, revision=6)], hist)
    assert _events(store, clip.id) == []
    res = apply_events(store, clip.id, [dict(seq=8, kind="undo")], hist)
    assert _events(store, clip.id) == [(1, 2, 9, "clap")] and res.notes == ["undid the deletion of the clap event 2-9"]
    assert store.events(clip.id).iloc[0].parts == ["left_hand", "right_hand"]  # the fields came back whole
    apply_events(store, clip.id, [dict(seq=9, kind="undo"), dict(seq=10, kind="undo")], hist)
    assert _events(store, clip.id) == []  # the add undone: the event is deleted
    assert len(store.events(clip.id, history=True)) == 10  # every step is a revision, nothing is overwritten


def test_a_stale_or_impossible_event_edit_is_refused(store, tracked_clip):
    _, clip = tracked_clip
    eid = store.add_event(clip.id, 1, 3, "pick")
    store.edit_event(clip.id, eid, expected_revision=1, end_frame=5, author="someone else")
    hist = EditHistory()
    res = apply_events(store, clip.id, [dict(seq=1, kind="event_edit", event_id=eid, revision=1, end_frame=8)], hist)
    assert "was changed by someone else (revision 2, you had 1)" in res.errors[0]
    res = apply_events(store, clip.id, [dict(seq=2, kind="event_edit", event_id=eid, revision=2, end_frame=99)], hist)
    assert "not an interval inside clip" in res.errors[0] and not hist.undo
    assert _events(store, clip.id) == [(eid, 1, 5, "pick")]


def _head_clip(store, tmp_path, n=60):
    import numpy as np
    import pandas as pd

    from partlab.labelling.video import write_video

    project = store.create_project("modes")
    clip = store.add_clip(project.id, write_video(tmp_path / "c.mp4", [np.zeros((80, 200, 3), np.uint8)] * n, fps=10))
    rows = [dict(frame=f, track_id=t, part=p, x=5.0 + f + 60 * t, y=10.0, w=8.0, h=8.0)
            for f in range(n) for t in (1, 2) for p in ("head", "torso")]
    store.save_tracker_run(clip.id, pd.DataFrame(rows))
    return clip


def _move(frame, y, revision):
    return dict(kind="edit", frame=frame, track_id=1, part="head", box=[100.0 + frame, y, 10, 10], failure=False,
                occluded=0, revision=revision)


def test_track_mode_refines_the_straight_line_with_the_tracker_inside_the_same_step(store, tmp_path):
    import pandas as pd
    import pytest

    from partlab.app.editing import refine_step

    clip = _head_clip(store, tmp_path)
    hist = EditHistory()
    for f in (0, 25, 50):  # keyframes every 25 frames on track 1's head
        apply_events(store, clip.id, [_move(f, 40.0, 0)], hist, fill=True)
    others = store.tracks(clip.id).query("not (track_id == 1 and part == 'head')").drop(columns="revision")
    res = apply_events(store, clip.id, [_move(25, 60.0, 1)], hist, fill=True)  # the middle keyframe 20 px down
    assert [s.refill for s in res.refills] == [[(1, "head", 25)]]
    assert _box(store, clip.id, 10, "head").y == pytest.approx(40 + 20 * 10 / 25)  # the line, at once
    seen = []

    def tracker(keys, track_id, part, start, end):  # stands for keyframe-guided tracking
        seen.append((start, end, sorted(set(zip(keys.frame, keys.track_id, keys.part)))))
        frames = range(start + 1, end)
        return pd.DataFrame(dict(frame=list(frames), x=500.0, y=[float(f) for f in frames], w=9.0, h=9.0,
                                 state="tracked"))

    out = refine_step(store, clip.id, hist, res.refills[0], tracker)
    assert seen == [(0, 25, [(0, 1, "head"), (0, 1, "torso"), (25, 1, "head"), (25, 1, "torso")]),
                    (25, 50, [(25, 1, "head"), (25, 1, "torso"), (50, 1, "head"), (50, 1, "torso")])]
    assert out["boxes"] == 48 and hist.undo[-1].refined == [out["run_id"]]
    head = store.tracks(clip.id).query("track_id == 1 and part == 'head'").set_index("frame")
    assert (head.loc[10].x, head.loc[40].y, head.loc[25].y, head.loc[55].x) == (500.0, 40.0, 60.0, 5 + 55 + 60)
    pd.testing.assert_frame_equal(  # every other track and part as it was
        store.tracks(clip.id).query("not (track_id == 1 and part == 'head')").drop(columns="revision")
        .reset_index(drop=True), others.reset_index(drop=True))
    apply_events(store, clip.id, [dict(kind="undo")], hist)  # one step: the move, its line and the tracker's boxes
    head = store.tracks(clip.id).query("track_id == 1 and part == 'head'").set_index("frame")
    assert (head.loc[25].y, head.loc[10].y, head.loc[10].x) == (40.0, 40.0, pytest.approx(110.0))
    # a refinement that ends after its step was undone, or after a newer refill of the track, writes nothing
    redo = apply_events(store, clip.id, [dict(kind="redo")], hist).refills[0]
    apply_events(store, clip.id, [dict(kind="undo")], hist)
    assert refine_step(store, clip.id, hist, redo, tracker) is None
    old = apply_events(store, clip.id, [dict(kind="redo")], hist).refills[0]
    apply_events(store, clip.id, [_move(25, 70.0, int(_box(store, clip.id, 25, "head").revision))], hist, fill=True)
    assert refine_step(store, clip.id, hist, old, tracker) is None
    assert _box(store, clip.id, 10, "head").y == pytest.approx(40 + 30 * 10 / 25)
