"""Carried objects and activities (sec. 7 of *3D tracking of the hands and head of interacting
people from several cameras*).

Read :mod:`.objects` (the colour around each hand, sec. 7.2-7.3, eq. 28-29), :mod:`.table`
(Table 1: clap, handshake, exchange, pick, place) and :mod:`.recognise` (the decision points and the
:class:`~.recognise.ActivityTracker` that adds activities to any tracker reporting hands).
"""


def with_activities(tracker, params, backgrounds=None):
    """``tracker`` with activity recognition (its ``events`` become the activities table);
    ``backgrounds``: per stream the take's empty-scene image, whose silhouettes the colour analysis
    then reads (else the run loop's foreground masks)."""
    from partlab.tracking.activities.recognise import ActivityTracker

    return ActivityTracker(tracker, params, backgrounds)
