"""partlab as a CVAT auto-annotation tracking function, driven the way CVAT's agent drives one
(preprocess, init on the drawn frame, track frame by frame) through cvat_sdk's own interface types."""

from __future__ import annotations

import cvat_sdk.auto_annotation as cvataa
import numpy as np
import PIL.Image

from partlab.labelling import cvat_function
from partlab.tracking.core.box import Box
from tests.tracking.walkers import background, correct, draw_walker


def test_tracks_a_drawn_person_through_the_sdk_interface():
    assert isinstance(cvat_function.spec, cvataa.TrackingFunctionSpec)
    assert cvat_function.spec.supported_shape_types == frozenset({"rectangle"})
    rng = np.random.default_rng(3)
    bg = background(rng, 320, 200)
    frames, truths = [], []
    for t in range(16):
        f = bg.copy()
        truths.append(draw_walker(f, 60 + 3 * t, 50, 110, (40, 40, 160), (120, 60, 30), phase=t / 3))
        frames.append(PIL.Image.fromarray(f[:, :, ::-1].copy()))  # CVAT hands the function RGB PIL images
    b = truths[0]["person"]
    shape = cvataa.TrackableShape(type="rectangle", points=[b.x, b.y, b.x + b.w, b.y + b.h])
    pp = cvat_function.preprocess_image(None, frames[0])
    assert pp.shape == (200, 320, 3) and np.array_equal(pp[:, :, ::-1], np.asarray(frames[0]))
    state = cvat_function.init_tracking_state(None, pp, shape)
    hits = []
    for t in range(1, 16):
        out = cvat_function.track(None, cvat_function.preprocess_image(None, frames[t]), state)
        assert isinstance(out, cvataa.TrackableShape) and out.type == "rectangle"
        x1, y1, x2, y2 = out.points
        hits.append(correct(Box(x1, y1, x2 - x1, y2 - y1), truths[t]["person"]))
    assert np.mean(hits) >= 0.9
