"""The trackers' parameters objects, in one import.

Each tracker keeps its own next to its code, grouped by what the numbers tune:
:class:`~partlab.tracking.body.params.BodyParams` (Zhao & Lee) and
:class:`~partlab.tracking.limbs.params.LimbParams` (head and hands). How they are checked, saved
and read back (also partlab 0.2's flat form) is :mod:`partlab.tracking.core.params`; every field,
its default and why is in docs/parameters.md.
"""

from partlab.tracking.body.params import BodyParams, PartNoise
from partlab.tracking.limbs.params import LimbParams

__all__ = ["BodyParams", "LimbParams", "PartNoise"]
