"""Stereo depth (partlab.labelling.stereo): row holes between two matches are occlusions and take
the farther match; what nothing measures stays unmatched."""

import numpy as np

from partlab.labelling.stereo import fill_occlusions


def test_a_hole_between_two_matches_takes_the_farther_and_one_at_the_edge_stays_unmatched():
    d = np.array([[-1, -1, 30, 30, -1, -1, 10, 10, -1],  # edge band, hole next to a near object, edge
                  [12, -1, -1, 40, 40, -1, 12, 12, 12],  # holes on both sides of a near object
                  [-1, -1, -1, -1, -1, -1, -1, -1, -1]], np.float32)  # a row with no match at all
    got = fill_occlusions(d)
    assert got[0].tolist() == [-1, -1, 30, 30, 10, 10, 10, 10, -1]
    assert got[1].tolist() == [12, 12, 12, 40, 40, 12, 12, 12, 12]
    assert (got[2] == -1).all()
    assert got.dtype == np.float32 and (d[d > 0] == got[d > 0]).all()  # matches are kept as they are


def test_what_the_right_camera_cannot_see_is_unmeasured_not_wrong():
    from partlab.labelling.stereo import StereoMatching, StereoRig
    from partlab.labelling.synth.depth_scene import make_depth_scene

    scene = make_depth_scene("desk_depth", seed=5, n_frames=2, width=160, height=120)
    left, right = scene.cameras["cam0"], scene.cameras["cam0_right"]
    truth = scene.depth[0]
    # the band along the left edge: x < disparity = f B / Z (the right camera sits B to the right)
    band = np.arange(160)[None, :] < left.K[0, 0] * np.linalg.norm(right.centre) / truth
    checked = StereoRig(left, right).depth(scene.frames[0], scene.right[0])
    unchecked = StereoRig(left, right, StereoMatching(left_right=-1)).depth(scene.frames[0], scene.right[0])
    assert np.isnan(checked[band]).mean() > 0.8  # unmeasured (0.96)
    assert (np.abs(checked - truth)[band] > 100).mean() < 0.1  # and hardly ever wrong (0.04)
    assert (np.abs(unchecked - truth)[band] > 100).mean() > 0.25  # without the check: wrong matches (0.39)
    err = np.abs(checked - truth)
    person = (scene.labels[0] > 0) & (scene.labels[0] != 9) & ~band
    assert np.isfinite(err[person]).mean() > 0.9 and np.nanmedian(err[person]) < 30
