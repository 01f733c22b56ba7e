"""The depth face-and-hands tracker (``--tracker limbs-depth``): Xu, Deng & Jia, *A multi-cue-based
human body tracking system*.

Read in the paper's order: :mod:`.filter` (sec. 3, the hue particle filter with alpha, refined by
mean shift), :mod:`.regions` (sec. 2 depth foreground, Table 1 hand candidate regions),
:mod:`.sampling` (sec. 4, eq. 3 and the q / 1-q mixture with its f/g weight), :mod:`.posture`
(sec. 5), and :mod:`.tracker` (the per-frame loop, initialisation and re-acquisition). Every
number is in :mod:`.params`.
"""


def build(params, rngs, context):
    """The registry's factory (:mod:`partlab.tracking.registry`)."""
    from partlab.tracking.depth.tracker import DepthTracker

    return DepthTracker(params["depth"], rngs["depth"], init=context.init_table())
