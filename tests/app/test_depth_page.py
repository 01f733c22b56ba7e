"""The Depth page shows a take's depth beside its colour; the colour map itself."""

from pathlib import Path

import numpy as np
from streamlit.testing.v1 import AppTest

from partlab.labelling.depth_view import depth_colours

PAGE = Path(__file__).resolve().parents[2] / "partlab" / "app" / "views" / "depth.py"


def test_depth_colours_near_red_far_blue_missing_black():
    d = np.array([[1000.0, 2000.0, np.nan]], np.float32)
    c = depth_colours(d, near=1000, far=2000)
    assert c.shape == (1, 3, 3) and c.dtype == np.uint8
    assert c[0, 0, 2] > c[0, 0, 0]  # near: red over blue (BGR)
    assert c[0, 1, 0] > c[0, 1, 2]  # far: blue over red
    assert (c[0, 2] == 0).all()


def test_page_shows_colour_and_depth_of_a_take(tmp_path):
    from partlab.labelling.synth.depth_scene import render_depth_scenario

    out = render_depth_scenario("desk_depth", tmp_path / "t", seed=1, n_frames=2, width=96, height=72)
    at = AppTest.from_file(str(PAGE), default_timeout=60)
    at.session_state["depth_take"] = str(out)
    at.run()
    assert not at.exception
    assert not at.error and not at.warning
    assert at.slider[0].max == 1  # the take's two frames
    at.session_state["depth_take"] = str(tmp_path / "nowhere")
    at.run()
    assert any("no such file or folder" in e.value for e in at.error)
