"""The three-part body tracker of Zhao & Lee, *Particle filter-based multi-part human tracking
with failure adjustment in video sequences*.

Read in the paper's order: :mod:`.part_filter` (sec. 3, 3.1, 3.2: one colour particle filter per
part), :mod:`.decomposition` (sec. 4.1: a person's foreground cut into head, torso, hip-leg),
:mod:`.detection` (sec. 4, 5: where new people are found), :mod:`.tracker` (sec. 4: the
multi-person tracker) and :mod:`.adjustment` (sec. 4.3: rebuilding failed parts).
"""


def build(params, rngs, context, whole: bool = False):
    """The registry's factory (:mod:`partlab.tracking.registry`)."""
    from partlab.errors import UserError
    from partlab.tracking.body.tracker import BodyTracker
    from partlab.tracking.protocol import SingleView

    p = params["body"]
    try:
        tracker = BodyTracker(p, rngs["body"], init=context.init, occluders=context.occluders,
                              failure_detector=context.failure_detector, whole=whole, fps=context.fps)
    except ValueError as exc:
        raise UserError(f"bad init table: {exc}") from None
    return SingleView(tracker, p)


def build_whole(params, rngs, context):
    """``--tracker whole``: one box per person."""
    return build(params, rngs, context, whole=True)
