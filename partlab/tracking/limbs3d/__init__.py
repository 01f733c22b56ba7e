"""The multi-camera head-and-hands tracker (*3D tracking of the hands and head of interacting
people from several cameras*, sec. 4-6).

Read it in the paper's order: :mod:`.geometry` (lines of sight and candidate points from pairs of
views, eq. 16, 18, 20-24), :mod:`.priors` (p_o p_t p_b, eq. 19, 25-27; pruning and merging, sec.
6.4), :mod:`.filter` (one particle filter per 3D target, eq. 17), :mod:`.tracker` (the per-frame
loop and the five-state machine of sec. 5.2 on 3D targets); every number is in :mod:`.params`.
"""


def build(params, rngs, context):
    """The registry's factory (:mod:`partlab.tracking.registry`)."""
    from partlab.errors import UserError
    from partlab.tracking.limbs3d.tracker import Limbs3DTracker

    cameras = {s: c for s, c in context.cameras.items() if c is not None}
    if len(cameras) < 2:
        raise UserError(f"tracker 'limbs3d' needs two or more calibrated views, the take has {len(cameras)}")
    backgrounds = getattr(context, "backgrounds", None)
    try:
        tracker = Limbs3DTracker(params["limbs3d"], rngs["limbs3d"], cameras, init=context.init_table(),
                                 backgrounds=backgrounds)
    except ValueError as exc:
        raise UserError(f"bad init table: {exc}") from None
    if "activities" in params:  # carried objects and activities, fused over the views (eq. 29)
        from partlab.tracking.activities import with_activities

        return with_activities(tracker, params["activities"], backgrounds)
    return tracker
