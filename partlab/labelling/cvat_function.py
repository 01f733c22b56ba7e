"""partlab's body tracker as a CVAT auto-annotation *tracking* function (``cvat_sdk.auto_annotation``).

A CVAT user draws a person's rectangle on one frame and asks CVAT to track it; CVAT calls the
function's ``init_tracking_state`` with that frame and shape, then ``track`` with each next frame.
Here the state is one run of partlab's body tracker (Zhao & Lee) started from the rectangle as the
person box, with its background model and the shipped bundle's failure detector; ``track`` steps it
one frame and returns the person box, or None when the tracker flags the person as lost (CVAT then
stops the track there). Register and serve it with the CVAT CLI::

    cvat-cli function create-native "partlab body" --function-module partlab.labelling.cvat_function
    cvat-cli function run-agent FUNCTION_ID --function-module partlab.labelling.cvat_function

Frames CVAT sends are consecutive frames of one task (``track`` is called in frame order); the fps is
taken as :data:`FPS` since CVAT does not pass it (it only scales the failure detector's time window).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import cvat_sdk.auto_annotation as cvataa
import numpy as np
import pandas as pd
import PIL.Image

from partlab.tracking.core.background import BackgroundModel
from partlab.tracking.frame import DEFAULT_STREAM, Frame, FrameSet
from partlab.tracking.protocol import TrackContext, Tracker
from partlab.tracking.run import build_tracker, model_params

FPS = 25.0  # CVAT passes no frame rate; PAL's, as for image sequences
TRACKER = "body"

spec = cvataa.TrackingFunctionSpec(supported_shape_types=["rectangle"])


@dataclass
class State:
    """One tracked person: its tracker run, background model and the index of the last frame seen."""

    tracker: Tracker
    background: BackgroundModel
    index: int = 0


def _model():
    from partlab.models.bundle import default_bundle

    return default_bundle()


def preprocess_image(context, image: PIL.Image.Image) -> np.ndarray:
    """CVAT's PIL image as the BGR ``uint8`` array partlab's trackers read."""
    return cv2.cvtColor(np.asarray(image.convert("RGB")), cv2.COLOR_RGB2BGR)


def _step(state: State, bgr: np.ndarray):
    frames = FrameSet(state.index, {DEFAULT_STREAM: Frame(state.index, bgr, None, DEFAULT_STREAM, None)})
    mask = state.background.apply(bgr)
    return state.tracker.step(frames, {DEFAULT_STREAM: mask})


def init_tracking_state(context, pp_image: np.ndarray, shape: cvataa.TrackableShape) -> State:
    x1, y1, x2, y2 = (float(v) for v in shape.points[:4])
    init = pd.DataFrame([dict(frame=0, track_id=0, part="person", x=x1, y=y1, w=x2 - x1, h=y2 - y1)])
    model = _model()
    tracker = build_tracker(TRACKER, model=model, seed=0,
                            context=TrackContext(init=init, fps=FPS, failure_detector=model.failure_detector))
    state = State(tracker, BackgroundModel(model_params(model, "body")))
    _step(state, pp_image)
    return state


def track(context, pp_image: np.ndarray, state: State) -> cvataa.TrackableShape | None:
    state.index += 1
    person = [r for r in _step(state, pp_image) if r.part == "person" and r.track_id == 0]
    if not person or person[0].failure:
        return None
    b = person[0].box
    return cvataa.TrackableShape(type="rectangle", points=[b.x, b.y, b.x + b.w, b.y + b.h])
