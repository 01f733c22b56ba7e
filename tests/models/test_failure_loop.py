"""The whole loop of seed 002 sec. 4.2-4.3 on a scene the shipped bundle never saw: its SVMs
flag the bending walker's lost head and the adjustment puts it back on the head."""

from __future__ import annotations

import pytest

from partlab.labelling.synth import make_scene
from partlab.models.bundle import default_bundle
from partlab.models.runner import run_body_tracker
from partlab.models.selection import part_rates
from partlab.models.training import first_boxes


@pytest.mark.parametrize("seed", [3, 4])
def test_shipped_detector_and_adjustment_keep_the_head_the_plain_tracker_loses(seed):
    bundle = default_bundle()
    assert bundle.failure_detector is not None  # validation kept it (it lowered nothing)
    scene = make_scene("bend", seed=seed, n_frames=100, width=480, height=320)
    frames = lambda: ((i, scene.frames[i]) for i in range(len(scene.frames)))  # noqa: E731
    rates = {}
    for name, det in (("plain", None), ("adjusted", bundle.failure_detector)):
        tracks = run_body_tracker(frames, scene.fps, first_boxes(scene.truth), seed=seed,
                                  params=bundle.body_params, failure_detector=det)
        rates[name] = part_rates(tracks, scene.truth)
        if det is not None:
            assert (tracks[tracks.part == "person"].state == "adjusted").sum() >= 5
    # measured (seeds 3 / 4): plain head 0.87 / 0.77 (it stays above the torso while the head hangs
    # in front; 0.72 / 0.76 before dynamics.start_velocity_frames), with detection and adjustment
    # 1.00 / 0.96; torso and hip-leg no worse
    assert rates["plain"]["head"] < 0.9
    assert rates["adjusted"]["head"] >= 0.95
    assert rates["adjusted"]["head"] - rates["plain"]["head"] >= 0.1
    for part in ("torso", "hipleg"):
        assert rates["adjusted"][part] >= rates["plain"][part] - 0.02
