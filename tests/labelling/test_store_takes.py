"""Takes of several streams and events with revisions in the store (schema revision 2)."""

import numpy as np
import pytest

from partlab.labelling.calibration import write_calibration
from partlab.labelling.store import StaleEditError, Store, StoreError
from partlab.labelling.video import write_video
from partlab.tracking.camera import Camera


def _take_dir(tmp_path):
    d = tmp_path / "take"
    d.mkdir()
    for k, name in enumerate(("cam0", "cam1")):
        write_video(d / f"{name}.mp4", [np.full((24, 32, 3), 30 * k + i, np.uint8) for i in range(8)], fps=8)
    K = np.array([[100.0, 0, 16], [0, 100.0, 12], [0, 0, 1]])
    cams = {n: Camera(n, K, (32, 24), np.zeros(5), np.eye(3), np.array([250.0 * k, 0, 0]))
            for k, n in enumerate(("cam0", "cam1"))}
    write_calibration(cams, d / "calibration.json")
    return d


def test_a_take_folder_becomes_a_take_of_two_stream_clips(backend, tmp_path):
    store = Store(clips_dir=tmp_path / "clips")
    p = store.create_project("p")
    take = store.import_take(p.id, _take_dir(tmp_path))
    assert [s.name for s in take.streams] == ["cam0", "cam1"] and [s.position for s in take.streams] == [0, 1]
    assert take.fps == pytest.approx(8.0) and len(store.clips(p.id)) == 2
    assert Camera.from_dict(take.streams[1].calibration).t.tolist() == [250.0, 0.0, 0.0]
    again, stream = store.take_of_clip(take.streams[1].clip_id)
    assert (again.id, stream) == (take.id, "cam1")
    with pytest.raises(StoreError, match="already a stream of another take"):
        store.add_take(p.id, "other", [dict(name="cam0", clip_id=take.streams[0].clip_id)])
    assert [t.name for t in store.takes(p.id)] == ["take"]


def test_events_keep_every_revision_and_refuse_stale_writes(backend, tmp_path):
    store = Store(clips_dir=tmp_path / "clips")
    p = store.create_project("p")
    clip = store.add_clip(p.id, write_video(tmp_path / "c.mp4", [np.zeros((24, 32, 3), np.uint8)] * 30, fps=10))
    e1 = store.add_event(clip.id, 4, 9, "handshake", tracks=[1, 2], parts=["right_hand", "right_hand"],
                         confidence=0.75, attributes={"object": None}, source="tracker", author="limbs")
    e2 = store.add_event(clip.id, 2, 3, "clap", tracks=[1], parts=["left_hand", "right_hand"], author="ann")
    assert (e1, e2) == (1, 2)
    assert store.events(clip.id)["type"].tolist() == ["clap", "handshake"]  # by start frame
    r = store.edit_event(clip.id, e1, expected_revision=1, author="ann", end_frame=11, confidence=1.0)
    assert r == 2
    with pytest.raises(StaleEditError, match="revision 2, you had 1"):
        store.edit_event(clip.id, e1, expected_revision=1, type="exchange")
    ev = store.events(clip.id).set_index("event_id").loc[e1]
    assert (ev.start_frame, ev.end_frame, ev.confidence, ev.tracks, ev.author) == (4, 11, 1.0, [1, 2], "ann")
    store.edit_event(clip.id, e2, expected_revision=1, delete=True, author="bob")
    assert store.events(clip.id)["event_id"].tolist() == [e1]
    hist = store.events(clip.id, history=True)
    assert hist[["event_id", "revision", "deleted"]].values.tolist() == [[1, 1, False], [1, 2, False],
                                                                         [2, 1, False], [2, 2, True]]
    with pytest.raises(StoreError, match="not an interval inside clip"):
        store.add_event(clip.id, 20, 30, "place")
    with pytest.raises(StoreError, match="no field"):
        store.edit_event(clip.id, e1, expected_revision=2, colour="red")
