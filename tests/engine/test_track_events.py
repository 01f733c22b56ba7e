"""A tracking job of the app stores the events its tracker recognises, as a run stores its boxes."""

import numpy as np
import pandas as pd

from partlab.engine import tasks
from partlab.labelling.events import store_run_events, temporal_iou
from partlab.labelling.store import Store
from partlab.labelling.synth import make_scene
from partlab.labelling.video import write_video


def test_a_track_job_stores_the_clap_it_finds_and_a_retrack_replaces_it_but_not_a_human_edit(tmp_path):
    scene = make_scene("clap", seed=2, n_frames=120, width=480, height=320)
    store = Store()
    project = store.create_project("p")
    clip = store.add_clip(project.id, write_video(tmp_path / "clap.mp4", iter(scene.frames), scene.fps))
    truth = scene.events.iloc[0]
    kw = dict(url=store.url, clip_id=clip.id, tracker="limbs", bundle_path=None, seed=2,
              init=scene.init.to_dict("records"))
    result = tasks.track_clip(lambda d, t: None, **kw)
    events = store.events(clip.id)
    claps = events[events.type == "clap"]
    assert result["events"] == len(events) >= 1 and len(claps) == 1
    c = claps.iloc[0]
    assert temporal_iou((c.start_frame, c.end_frame), (truth.start_frame, truth.end_frame)) >= 0.5
    assert c.source == "tracker" and c.tracks == [1] and sorted(c.parts) == ["left_hand", "right_hand"]
    # a person stretched the clap: the same job again keeps their event and adds no second clap over it
    store.edit_event(clip.id, int(c.event_id), expected_revision=1, end_frame=int(c.end_frame) + 3)
    tasks.track_clip(lambda d, t: None, **kw)
    again = store.events(clip.id)
    assert list(again[again.type == "clap"].event_id) == [c.event_id] and len(again) == len(events)


def test_stored_run_events_are_clipped_to_the_run_and_other_tracks_are_kept(tmp_path):
    store = Store()
    project = store.create_project("p")
    clip = store.add_clip(project.id, write_video(tmp_path / "c.mp4", (np.zeros((32, 32, 3), np.uint8)
                                                                      for _ in range(40)), 25))
    other = store.add_event(clip.id, 5, 9, "handshake", tracks=[3, 4], parts=["right_hand", "right_hand"],
                            source="tracker")
    old = store.add_event(clip.id, 12, 20, "clap", tracks=[1], parts=["left_hand", "right_hand"], source="tracker")
    found = pd.DataFrame(dict(start_frame=[8, 30], end_frame=[14, 45], kind=["clap", "pick"], track_id_a=[1, 1],
                              part_a=["left_hand", "right_hand"], track_id_b=[1, 0], part_b=["right_hand", ""],
                              ended_by=["contact", "still"], object_colour=["", "#20c040"], confidence=[0.9, 0.7]))
    ids = store_run_events(store, clip.id, found, start=10, stop=40, track_ids=[1])
    got = store.events(clip.id)
    assert len(ids) == 2 and other in set(got.event_id)  # track 3's event is not this re-track's
    assert old not in set(got.event_id)  # the earlier run's clap of track 1 is replaced (kept in the history)
    assert bool(store.events(clip.id, history=True).query("event_id == @old").deleted.iloc[-1])
    new = got[got.event_id.isin(ids)].set_index("type")
    assert (new.loc["clap", "start_frame"], new.loc["clap", "end_frame"]) == (10, 14)
    assert (new.loc["pick", "start_frame"], new.loc["pick", "end_frame"]) == (30, 39)
    assert new.loc["pick", "attributes"] == {"ended_by": "still", "object_colour": "#20c040"}
