"""``--tracker all``: the body and limb trackers on the same frames, one track id per person.

Started from ``init`` both trackers use its ids. Found automatically, a limb person takes the id
of the body person whose box holds its head (:mod:`partlab.tracking.identity`), and unmatched
limb people get ids from :data:`LIMB_ID_OFFSET` on, so the two never share an id. A person's head
is written once per frame (the body tracker's where both have it). The limbs' join events name
the tracks as written.

Found automatically, heads and hands are written only on people (issue 13). In a frame where the
body tracker has people, the limb tracker starts, labels, writes and keeps its trackers only on
their boxes (:mod:`partlab.tracking.limbs.people`; other frames are not gated). And when the body
tracker finds people in the clip, a limb row is kept when its box's centre lies inside a body
person box of the same frame, a head's in the top :data:`HEAD_TOP` of it (skin-coloured walls,
grass and parked cars move in a real background model's foreground now and then, but the body
tracker starts no person there). A clip where the body tracker finds nobody (a person seated at a
desk, whom its walker detection does not start) keeps the limbs' own rows; events of limb tracks
no longer written are dropped with them.

Found automatically, a head is written where a tracker *measured* it: the body tracker's head of a
person it is coasting (behind another person or an obstacle, or lost: the row's ``occluded`` is 1)
is a guess from the dynamics, so it is not written, and the limb tracker's head of that person,
found on skin, is written instead where there is one. On PETS09-S2L1 (seed 1, whole clip) the
coasted heads lay in the top third of a truth person box in 0.73 of frames against 0.90 for the
measured ones (docs/trackers/limbs.md). The person row and the other parts stay.

Found automatically, the limb people no body person was matched to are not written as people of
their own (the limb tracker restarts a person it lost, so one walker was several limb people:
PETS09 seed 1, 37 limb ids beside 29 body ids): each of their rows goes to the body person it lies
on in its frame (:func:`partlab.tracking.identity.relabel_on_people`), so under ``all`` the ids
written are the body tracker's.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from partlab.tracking.frame import FrameSet
from partlab.tracking.identity import match_limb_people, merge_tracks, relabel_on_people, remap_ids
from partlab.tracking.tracks import TrackRecord, empty_tracks, records_to_frame

#: limb people not matched to a body person get ids from here
LIMB_ID_OFFSET = 100000
#: a limb head is kept only in the top third of a body person's box: a standing or walking person's
#: head centre lies at 0.04-0.2 of their box from the top (PETS09 truth), and a skin blob between a
#: third and 0.4 of the way down is a red sleeve or a hand at the chest as often as a head (PETS09
#: seed 1, whole clip: heads written in the top third of a truth box 0.903 with 0.4, 0.906 with 1/3)
HEAD_TOP = 1.0 / 3.0


def measured_heads(body: pd.DataFrame) -> pd.DataFrame:
    """The body tracker's rows without the heads of people it coasts (``occluded`` 1: behind another
    person, behind an obstacle, or lost), whose head boxes are where the dynamics put them."""
    if "occluded" not in body or body.empty:
        return body
    coasted = (body["part"] == "head") & (body["occluded"].fillna(0) > 0)
    return body[~coasted]


def on_people(limbs: pd.DataFrame, body: pd.DataFrame, head_top: float = HEAD_TOP) -> pd.DataFrame:
    """The limb rows whose centre lies inside some body ``person`` box of the same frame (a head's
    within the top ``head_top`` of it)."""
    if limbs.empty:
        return limbs
    people = body[body["part"] == "person"][["frame", "x", "y", "w", "h"]]
    if people.empty:
        return limbs.iloc[:0]
    lim = limbs.reset_index(drop=True)
    m = lim[["frame", "part", "x", "y", "w", "h"]].reset_index().merge(people, on="frame", suffixes=("", "_p"))
    cx, cy = m["x"] + m["w"] / 2, m["y"] + m["h"] / 2
    top = np.where(m["part"] == "head", head_top, 1.0)
    inside = (cx >= m["x_p"]) & (cx <= m["x_p"] + m["w_p"]) & (cy >= m["y_p"]) & (cy <= m["y_p"] + top * m["h_p"])
    keep = np.zeros(len(lim), bool)
    keep[m.loc[inside.to_numpy(), "index"].to_numpy()] = True
    return lim[keep]


class Combined:
    def __init__(self, body, limbs, from_init: bool):
        self.body, self.limbs = body, limbs
        self.params = {"body": body.params, "limbs": limbs.params}
        self.from_init = from_init
        self._body_rows: list[TrackRecord] = []
        self._limb_rows: list[TrackRecord] = []
        self.events: pd.DataFrame | None = None

    def step(self, frames: FrameSet, foreground: Mapping[str, np.ndarray | None]) -> list[TrackRecord]:
        body = self.body.step(frames, foreground)
        people = [(r.box.x, r.box.y, r.box.w, r.box.h) for r in body if r.part == "person" and not r.failure]
        if not self.from_init:  # found automatically: limbs start and live on these people
            self.limbs.tracker.set_people(people or None)
        limbs = self.limbs.step(frames, foreground)
        self._body_rows.extend(body)
        self._limb_rows.extend(limbs)
        return body + limbs

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        body = self.body.table(self._body_rows)
        limbs = records_to_frame(self._limb_rows) if self._limb_rows else empty_tracks()
        given: dict[int, int] = {}
        on_bodies = not self.from_init and (body["part"] == "person").any()
        if on_bodies:
            limbs = on_people(limbs, body)
            body = measured_heads(body)
        mapping = {} if self.from_init else match_limb_people(body, limbs)
        written = set(limbs["track_id"])
        if on_bodies:  # the others' rows go to the body person they are on, frame by frame
            limbs, given = relabel_on_people(body, limbs, mapping, HEAD_TOP)
            written = set(mapping) | set(given)
        offset = 0 if self.from_init else LIMB_ID_OFFSET
        events = self.limbs.events
        if events is not None and len(events):
            ids = {**given, **mapping}
            kept = events["track_id_a"].isin(written) & (events["track_id_b"].isna()
                                                          | events["track_id_b"].isin(written))
            events = events[kept].copy()
            for col in ("track_id_a", "track_id_b"):
                events[col] = remap_ids(events[col], ids, offset)
        self.events = events
        out = merge_tracks(body, limbs, mapping, offset)
        return out.sort_values(["frame", "track_id"], kind="stable").reset_index(drop=True)


def build(params, rngs, context):
    """The registry's factory for ``all``."""
    from partlab.tracking import body, limbs

    plain = {k: v for k, v in params.items() if k != "activities"}
    combined = Combined(body.build(plain, rngs, context), limbs.build(plain, rngs, context),
                        from_init=context.init is not None)
    if "activities" in params:  # activities over the merged tracks, so they name the ids as written
        from partlab.tracking.activities import with_activities

        return with_activities(combined, params["activities"], getattr(context, "backgrounds", None))
    return combined
