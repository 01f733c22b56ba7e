"""``--tracker all``: the body and limb trackers on the same frames, one track id per person.

Started from ``init`` both trackers use its ids. Found automatically, a limb person takes the id
of the body person whose box holds its head (:mod:`partlab.tracking.identity`), and unmatched
limb people get ids from :data:`LIMB_ID_OFFSET` on, so the two never share an id. A person's head
is written once per frame (the body tracker's where both have it). The limbs' join events name
the tracks as written.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from partlab.tracking.frame import FrameSet
from partlab.tracking.identity import match_limb_people, merge_tracks, remap_ids
from partlab.tracking.tracks import TrackRecord, empty_tracks, records_to_frame

#: limb people not matched to a body person get ids from here
LIMB_ID_OFFSET = 100000


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
        limbs = self.limbs.step(frames, foreground)
        self._body_rows.extend(body)
        self._limb_rows.extend(limbs)
        return body + limbs

    def table(self, records: list[TrackRecord]) -> pd.DataFrame:
        body = records_to_frame(self._body_rows) if self._body_rows else empty_tracks()
        limbs = records_to_frame(self._limb_rows) if self._limb_rows else empty_tracks()
        mapping = {} if self.from_init else match_limb_people(body, limbs)
        offset = 0 if self.from_init else LIMB_ID_OFFSET
        events = self.limbs.events
        if events is not None and len(events):
            events = events.copy()
            for col in ("track_id_a", "track_id_b"):
                events[col] = remap_ids(events[col], mapping, offset)
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

        return with_activities(combined, params["activities"])
    return combined
