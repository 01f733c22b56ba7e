"""Re-identifying a track given by the user that ended (``detector.reid_hits``)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from partlab.tracking.body.tracker import BodyTracker
from partlab.tracking.core.background import BackgroundModel
from partlab.tracking.core.box import Box
from partlab.tracking.params import BodyParams
from partlab.tracking.tracks import records_to_frame
from tests.tracking.walkers import background, correct, draw_walker

W, H = 320, 200
BLUE, BROWN = (40, 40, 160), (120, 60, 30)  # BGR shirt and trousers of the walker who comes back
RED, GREEN = (30, 30, 200), (40, 150, 40)  # someone else


def _out_and_back(n=190, back=BLUE + BROWN):
    """A walker going right out of the frame (gone from about frame 90), then someone walking back in
    through the same border from frame ~110 (the same walker, or ``back``'s colours); per frame the
    truth of whoever is in view (id 1 the walker, 2 someone else)."""
    rng = np.random.default_rng(0)
    bg = background(rng, W, H)
    frames, truths = [], []
    for t in range(n):
        f = bg.copy()
        cx = 60 + 3.0 * t if t <= 100 else 360 - 3.0 * (t - 100)
        who, colours = (1, BLUE + BROWN) if t <= 100 else ((1 if back == BLUE + BROWN else 2), back)
        truth = draw_walker(f, cx, 50, 110, colours[:3], colours[3:], phase=t / 3)
        f = np.clip(f.astype(np.int16) + rng.integers(-6, 7, f.shape), 0, 255).astype(np.uint8)
        frames.append(f)
        inside = truth["person"].intersection(Box(0, 0, W, H)) >= 0.5 * truth["person"].area
        truths.append({who: truth} if inside else {})
    return frames, truths


def _run(frames, truths, reid_hits, also=None):
    """The body tracker from walker 1's first box (and ``also``: ``(frame, track id)`` of another
    first box, walker 1's box at that frame), its detector replaced by one that reports every person
    box in view (HOG finds drawn walkers only now and then)."""
    p = BodyParams().updated({"detector.reid_hits": reid_hits})
    firsts = [(0, 1)] + ([also] if also else [])
    init = pd.DataFrame([dict(frame=f, track_id=k, part="person", x=b.x, y=b.y, w=b.w, h=b.h)
                         for f, k in firsts for b in [truths[f][1]["person"]]])
    tracker = BodyTracker(p, np.random.default_rng(0), init=init)
    seen = {"index": 0}
    tracker.cue.detector.detect = lambda frame, regions: np.array(
        [[*tb["person"].as_tuple(), 1.0] for tb in truths[seen["index"]].values()]).reshape(-1, 5)
    bgm = BackgroundModel(p)
    out = []
    for i, f in enumerate(frames):
        seen["index"] = i
        out.extend(tracker.step(i, f, bgm.apply(f)))
    return tracker, records_to_frame(tracker.finish(out))


def test_a_walker_who_comes_back_is_re_identified_with_their_id():
    """The walker's track ends at the right border; when he walks back in there his track comes back
    with id 1 after ``reid_hits`` scans (3 frames apart) and stays on him; without re-identification
    (``reid_hits`` 0) nobody tracks him after he left."""
    frames, truths = _out_and_back()
    back = [i for i in range(101, len(frames)) if 1 in truths[i]]
    tracker, tracks = _run(frames, truths, reid_hits=3)
    assert tracker.revived and tracker.revived[0][0] == 1
    first_back, revived_at = back[0], tracker.revived[0][1]
    assert revived_at - first_back <= 3 * 3 + 3  # three scans running, one scan every 3 frames
    rows = tracks[(tracks.track_id == 1) & (tracks.part == "person") & (tracks.frame > revived_at)]
    hits = [correct(Box(r.x, r.y, r.w, r.h), truths[r.frame][1]["person"]) for r in rows.itertuples()]
    assert len(rows) >= len(frames) - revived_at - 5 and np.mean(hits) >= 0.9
    assert set(tracks.track_id) == {1}
    _, without = _run(frames, truths, reid_hits=0)
    assert without[(without.track_id == 1) & (without.frame > 100)].empty


def test_someone_else_coming_in_where_the_walker_left_is_not_taken_for_him():
    """Someone in other colours walking in through the same border does not bring track 1 back."""
    frames, truths = _out_and_back(back=RED + GREEN)
    tracker, tracks = _run(frames, truths, reid_hits=3)
    assert tracker.revived == []
    assert tracks[(tracks.track_id == 1) & (tracks.frame > 100)].empty


def test_a_first_box_given_on_a_re_identified_track_undoes_the_re_identification():
    """``reid_undo_iou``: when someone's first box is given on the person a re-identified track
    stands on, that person was new to the tracker: the re-identification is undone (its rows
    withdrawn, the track ended again) and the given track goes on there."""
    frames, truths = _out_and_back()
    tracker, _ = _run(frames, truths, reid_hits=3)
    revived_at = tracker.revived[0][1]
    tracker, tracks = _run(frames, truths, reid_hits=3, also=(revived_at + 6, 2))
    assert tracker.revived[0] == (1, revived_at) and 1 not in tracker.people
    assert tracks[(tracks.track_id == 1) & (tracks.frame > 100)].empty
    rows = tracks[(tracks.track_id == 2) & (tracks.part == "person")]
    hits = [correct(Box(r.x, r.y, r.w, r.h), truths[r.frame][1]["person"]) for r in rows.itertuples()]
    assert rows.frame.min() == revived_at + 6 and np.mean(hits) >= 0.9
