"""Run the trackers over a clip: one decode, one background model, every tracker fed.

``track_video`` is what ``partlab track`` and the app's "track" button call. Frames are
decoded once (``partlab.labelling.video.VideoClip.frames``, the decoder's numbering), the
foreground mask is computed once per frame (``partlab.tracking.core.background``), and each
tracker's ``step`` gets both. ``start``/``stop`` re-track a stretch of the clip, e.g.
from a frame a user corrected (``init`` then holds the boxes at ``start``).
"""

from __future__ import annotations

from os import PathLike
from typing import Callable

import numpy as np
import pandas as pd

from partlab.cli import CommandError
from partlab.labelling.video import VideoClip, VideoError
from partlab.tracking.core.background import BackgroundModel
from partlab.tracking.identity import match_limb_people, merge_tracks, remap_ids
from partlab.tracking.params import BodyParams, LimbParams
from partlab.tracking.tracks import TracksCSVError, empty_tracks, normalise_tracks, records_to_frame

TRACKERS = ("body", "limbs", "all", "whole")
#: ``--tracker all`` without ``--init``: limb people not matched to a body person get ids from here
LIMB_ID_OFFSET = 100000


def _limb_tracker(params: LimbParams, rng: np.random.Generator, init: pd.DataFrame | None):
    try:
        from partlab.tracking.limbs.tracker import LimbTracker
    except ImportError:
        raise CommandError("the limb tracker is not available yet") from None
    return LimbTracker(params, rng, init=init)


def _split_model(model) -> tuple[BodyParams, LimbParams, object]:
    """``model``: None, a BodyParams, a LimbParams, or a bundle with ``.body_params``,
    ``.limb_params`` and ``.failure_detector``."""
    if model is None:
        return BodyParams(), LimbParams(), None
    if isinstance(model, BodyParams):
        return model, LimbParams(), None
    if isinstance(model, LimbParams):
        return BodyParams(), model, None
    body = getattr(model, "body_params", None) or BodyParams()
    limb = getattr(model, "limb_params", None) or LimbParams()
    return body, limb, getattr(model, "failure_detector", None)


def track_video(video_path: str | PathLike, tracker: str = "body", init: pd.DataFrame | None = None,
                model=None, occluders=(), seed: int = 0,
                progress: Callable[[int, int], None] | None = None, failure_detector=None,
                start: int = 0, stop: int | None = None, events_out: list | None = None) -> pd.DataFrame:
    """Track ``video_path`` and return the tracks table (frame indexes of the whole clip).

    ``tracker``: body (head/torso/hip-leg + person MBR), whole (one box per person),
    limbs (head and hands) or all (body and limbs). With ``all`` one person has one track id:
    from ``init`` both trackers use its ids; found automatically, a limb person takes the id of
    the body person whose box holds its head (``partlab.tracking.identity``), and unmatched limb people
    get ids from :data:`LIMB_ID_OFFSET` on. A person's head is written once per frame (the body
    tracker's where both have it). The same ``seed`` gives the same output. ``events_out``: a list
    that receives the limb tracker's join/separation events (a DataFrame). Raises :class:`partlab.cli.CommandError` with a clear message
    for an unreadable clip, a bad ``init`` table or an unknown tracker.
    """
    from partlab.tracking.body.tracker import BodyTracker  # heavy imports only when tracking

    if tracker not in TRACKERS:
        raise CommandError(f"unknown tracker {tracker!r}; expected one of {', '.join(TRACKERS)}")
    try:
        clip = VideoClip(video_path)
    except VideoError as exc:
        raise CommandError(str(exc)) from None
    n = clip.frame_count
    if start < 0 or start >= n:
        raise CommandError(f"start frame {start} is outside the clip (0..{n - 1})")
    stop = n if stop is None else min(int(stop), n)
    if stop <= start:
        raise CommandError(f"stop frame {stop} is not after start frame {start}")
    if init is not None:
        try:
            init = normalise_tracks(init)
        except (TracksCSVError, ValueError, KeyError) as exc:
            raise CommandError(f"bad init table: {exc}") from None
        init = init[init["frame"] >= start]

    body_params, limb_params, bundle_detector = _split_model(model)
    detector = failure_detector if failure_detector is not None else bundle_detector
    rng = np.random.default_rng(seed)
    # independent, repeatable streams per tracker (adding the limb tracker never changes body output)
    body_rng, limb_rng = (np.random.default_rng(s) for s in rng.bit_generator.seed_seq.spawn(2))
    trackers = []
    if tracker in ("body", "all", "whole"):
        try:
            trackers.append(BodyTracker(body_params, body_rng, init=init, occluders=occluders,
                                        failure_detector=detector, whole=tracker == "whole", fps=clip.fps))
        except ValueError as exc:
            raise CommandError(f"bad init table: {exc}") from None
    if tracker in ("limbs", "all"):
        trackers.append(_limb_tracker(limb_params, limb_rng, init))

    background = BackgroundModel(body_params)
    records: list[list] = [[] for _ in trackers]
    total = stop - start
    done = 0
    try:
        for index, frame in clip.frames(start, stop):
            mask = background.apply(frame)
            for k, t in enumerate(trackers):
                records[k].extend(t.step(index, frame, mask))
            done += 1
            if progress is not None:
                progress(done, total)
    except VideoError as exc:
        raise CommandError(str(exc)) from None
    finally:
        clip.close()
    events = trackers[-1].events if tracker in ("limbs", "all") else None
    tables = [records_to_frame(r) if r else empty_tracks() for r in records]
    if tracker == "all":
        body, limbs = tables
        # with init both trackers use its ids; found automatically, a limb person takes the id of
        # the body person around its head, the others are offset so the two never share an id
        mapping = {} if init is not None else match_limb_people(body, limbs)
        offset = 0 if init is not None else LIMB_ID_OFFSET
        if events is not None and len(events):
            events = events.copy()
            for col in ("track_id_a", "track_id_b"):
                events[col] = remap_ids(events[col], mapping, offset)
        out = merge_tracks(body, limbs, mapping, offset)
        out = out.sort_values(["frame", "track_id"], kind="stable").reset_index(drop=True)
    else:
        out = tables[0]
    if events_out is not None and events is not None:
        events_out.append(events)
    return out if len(out) else empty_tracks()
