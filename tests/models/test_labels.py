import numpy as np
import pandas as pd

from partlab.models.labels import LabelRule, inside_fraction, label_states, label_tracks, svm_targets
from partlab.tracking.tracks import normalise_tracks


def test_inside_fraction_and_labels():
    truth = np.array([50, 50, 20, 20.0])
    boxes = np.array([
        [50, 50, 10, 10],   # inside: on
        [60, 50, 20, 20],   # half inside, centre on the edge: on
        [65, 50, 20, 20],   # a quarter inside: dropped
        [90, 50, 20, 20],   # outside: off
        [50, 50, 80, 80],   # huge box around the part: 1/16 inside: off
    ])
    np.testing.assert_allclose(inside_fraction(boxes, truth), [1, 0.5, 0.25, 0, 400 / 6400])
    assert label_states(boxes, truth).tolist() == [1, 1, -1, 0, 0]
    assert label_states(boxes, truth, LabelRule(on_part=0.6, off_part=0.3)).tolist() == [1, -1, 0, 0, 0]


def _rows(tid, frame, boxes, **extra):
    return [dict(frame=frame, track_id=tid, part=p, x=b[0], y=b[1], w=b[2], h=b[3], **extra)
            for p, b in boxes.items()]


def test_label_tracks_with_human_flags():
    good = {"head": (10, 0, 10, 10), "torso": (5, 10, 20, 30), "hipleg": (5, 40, 20, 40)}
    truth = normalise_tracks(pd.DataFrame(_rows(1, 0, good) + _rows(1, 1, good)))
    moved = dict(good, head=(60, 0, 10, 10))
    tracked = normalise_tracks(pd.DataFrame(_rows(1, 0, good) + _rows(1, 1, moved) + _rows(1, 2, good)))
    lab = label_tracks(tracked, truth).set_index(["frame", "part"])["label"]
    assert lab[(0, "head")] == 1 and lab[(1, "head")] == 0 and lab[(1, "torso")] == 1
    assert lab[(2, "head")] == -1  # no truth at frame 2
    # a user flags the torso of frame 0 as failed by hand
    tracked.loc[(tracked["frame"] == 0) & (tracked["part"] == "torso"), ["failure", "source"]] = [True, "human"]
    lab = label_tracks(tracked, truth).set_index(["frame", "part"])["label"]
    assert lab[(0, "torso")] == 0 and lab[(0, "head")] == 1


def test_svm_targets():
    labels = np.array([[1, 1, 1], [0, 1, 1], [0, 0, 1], [0, -1, 1], [1, -1, 1]])
    t = svm_targets(labels)
    assert t["head"].tolist() == [1, 0, -1, 0, 1]      # frame with two failures left out
    assert t["torso"].tolist() == [1, 1, -1, -1, -1]
    assert t["multi"].tolist() == [-1, 1, 0, -1, -1]
