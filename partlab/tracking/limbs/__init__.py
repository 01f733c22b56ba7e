"""The limb tracker: head and both hands of every person in one camera.

From *3D tracking of the hands and head of interacting people from several cameras* (parallel
particle filters over skin blobs, sec. 4-5; the five-state machine, sec. 5.2) and Xu, Deng & Jia
(hue histograms refined by mean shift, sec. 3). Read :mod:`.filter` (one filter per target),
:mod:`.state_machine` (sec. 5.2) and :mod:`.tracker` (the per-frame loop).
"""


def build(params, rngs, context):
    """The registry's factory (:mod:`partlab.tracking.registry`)."""
    from partlab.errors import UserError
    from partlab.tracking.limbs.tracker import LimbTracker
    from partlab.tracking.protocol import SingleView

    p = params["limbs"]
    try:
        tracker = LimbTracker(p, rngs["limbs"], init=context.init_table())
    except ValueError as exc:
        raise UserError(f"bad init table: {exc}") from None
    view = SingleView(tracker, p)
    if "activities" in params:  # carried objects and activities over the hands it tracks
        from partlab.tracking.activities import with_activities

        return with_activities(view, params["activities"], getattr(context, "backgrounds", None))
    return view
