"""The top-view tracker: part-based 3D tracking of several people's upper bodies from a depth
camera on the ceiling (Migniot & Ababsa, *Part-based 3D multi-person tracking using depth cue
in a top view*).

Read in the paper's order: :mod:`.model` (sec. 2.3, the 17-degree-of-freedom articulated model and
its primitives), :mod:`.likelihood` (eq. 1-3, distances of depth points to the model and the
colour term), :mod:`.filter` (sec. 2.2 and 2.4, one person's filter with part-based or global
resampling, eq. 4), :mod:`.tracker` (sec. 2.1's ROI and sec. 4's exclusion principle, eq. 5);
every number is in :mod:`.params`.
"""


def build(params, rngs, context):
    """The registry's factory (:mod:`partlab.tracking.registry`)."""
    from partlab.tracking.topview.tracker import TopViewTracker

    return TopViewTracker(params["topview"], rngs["topview"], init=context.init_table(), cameras=context.cameras)
