import numpy as np
import pandas as pd
import pytest

from partlab.models.features import (
    FEATURE_NAMES,
    dt_frames,
    features_from_history,
    features_from_tracks,
    newest_features,
    person_scale,
    relative_states,
)
from partlab.tracking.tracks import normalise_tracks


def _history():
    # 3 frames; head, torso, hipleg [cx, cy, w, h]
    h = np.array([
        [[10, 10, 4, 6], [10, 20, 8, 12], [10, 35, 8, 18]],
        [[12, 10, 4, 6], [11, 20, 8, 12], [10, 35, 8, 18]],
        [[20, 12, 4, 6], [12, 21, 8, 12], [10, 36, 8, 18]],
    ], dtype=float)
    return h


def test_relative_states_hand_computed():
    rs = relative_states(_history()[0])
    # mean state [10, 65/3, 20/3, 12]
    np.testing.assert_allclose(rs[0], [0, 10 - 65 / 3, 4 - 20 / 3, -6])
    np.testing.assert_allclose(rs[2], [0, 35 - 65 / 3, 8 - 20 / 3, 6])
    np.testing.assert_allclose(rs.sum(axis=0), 0, atol=1e-12)


def test_features_hand_computed_pixels():
    # fps 4 -> dt = 0.5 s = 2 frames: frame 2 compares with frame 0
    x = features_from_history(_history(), fps=4.0, normalise=False)
    assert x.shape == (3, 24) and len(FEATURE_NAMES) == 24
    # frame 2: mean = [14, 23, 20/3, 12]; RS_H = [6, -11, 4-20/3, -6]
    np.testing.assert_allclose(x[2, 0:4], [6, -11, 4 - 20 / 3, -6])
    # RS_H(0) = [0, 10-65/3, 4-20/3, -6] -> change [6, -11-(10-65/3), 0, 0]
    np.testing.assert_allclose(x[2, 12:16], [6, -11 - (10 - 65 / 3), 0, 0])
    # frame 1: reference is frame 0 (track younger than dt)
    np.testing.assert_allclose(x[1, 12:16], [2 - 1, 0, 0, 0])
    # frame 0: no change
    np.testing.assert_allclose(x[0, 12:], 0)


def test_normalised_features_divide_by_median_height():
    h = _history()
    x_pix = features_from_history(h, fps=4.0, normalise=False)
    x = features_from_history(h, fps=4.0)
    assert person_scale(h[2]) == 12.0
    np.testing.assert_allclose(x, x_pix / 12.0)
    np.testing.assert_allclose(newest_features(h, 4.0), x[2])


def test_dt_frames_and_bad_input():
    assert dt_frames(25) == 12 and dt_frames(30) == 15 and dt_frames(1) == 1
    with pytest.raises(ValueError, match="fps"):
        dt_frames(0)
    with pytest.raises(ValueError, match="shape"):
        features_from_history(np.zeros((3, 2, 4)), 25)


def test_tracks_and_history_give_the_same_numbers():
    h = _history()
    rows = []
    for t in range(3):
        for k, part in enumerate(("head", "torso", "hipleg")):
            cx, cy, w, hh = h[t, k]
            rows.append(dict(frame=t + 5, track_id=7, part=part, x=cx - w / 2, y=cy - hh / 2, w=w, h=hh))
    rows.append(dict(frame=5, track_id=7, part="person", x=0, y=0, w=1, h=1))
    keys, x = features_from_tracks(normalise_tracks(pd.DataFrame(rows)), fps=4.0)
    assert keys["frame"].tolist() == [5, 6, 7] and keys["track_id"].tolist() == [7, 7, 7]
    np.testing.assert_allclose(x, features_from_history(h, 4.0))


def test_gaps_use_the_first_frame_after_t_minus_dt():
    h = _history()
    x = features_from_history(h, fps=4.0, frames=np.array([0, 3, 4]), normalise=False)
    # frame 4 - 2 = 2 -> first available at or after is frame 3 (row 1)
    rs = relative_states(h).reshape(3, 12)
    np.testing.assert_allclose(x[2, 12:], rs[2] - rs[1])
