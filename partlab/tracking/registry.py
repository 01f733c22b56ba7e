"""The trackers partlab knows, in one table read by the command line, the app, training,
evaluation and the benchmarks.

Adding a tracker is one sub-package of :mod:`partlab.tracking` and one :class:`TrackerEntry`
here. Entries name their code as ``"module:attribute"`` strings, imported only when the tracker
is built, so ``partlab --help`` and the app's menus stay instant.

A tracker's factory is called as ``factory(params, rngs, context)``: ``params`` maps each of the
entry's parameter keys (:data:`PARAMETERS`) to its parameters object, ``rngs`` maps the same keys
to independent ``numpy.random.Generator`` streams of the run's seed, ``context`` is a
:class:`~partlab.tracking.protocol.TrackContext`. It returns a
:class:`~partlab.tracking.protocol.Tracker`.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

from partlab.errors import UserError


@dataclass(frozen=True)
class ParameterEntry:
    """One kind of parameters object: the class (``"module:Class"``) and the slot of the run's
    seed its random stream comes from. Slots are fixed forever (adding a tracker must never change
    another one's output for the same ``--seed``), and a model bundle stores parameters by key."""

    key: str
    cls: str
    rng_slot: int


@dataclass(frozen=True)
class TrackerEntry:
    """``parts``: what it writes rows for; ``needs``: what every stream must carry
    (``color``, ``depth``), plus ``calibration`` when it works in 3D; ``min_streams``: how many
    streams the take must have; ``foreground``: the run loop computes the background model's
    masks for it."""

    name: str
    summary: str
    factory: str
    param_keys: tuple[str, ...]
    parts: tuple[str, ...]
    needs: frozenset[str] = frozenset({"color"})
    min_streams: int = 1
    foreground: bool = True


#: parameter key -> entry (the key is the name a model bundle stores the parameters under)
PARAMETERS: dict[str, ParameterEntry] = {}
#: tracker name -> entry, in the order ``partlab track --help`` lists them
TRACKERS: dict[str, TrackerEntry] = {}


def register_parameters(entry: ParameterEntry) -> ParameterEntry:
    if entry.key in PARAMETERS or any(e.rng_slot == entry.rng_slot for e in PARAMETERS.values()):
        raise ValueError(f"parameters {entry.key!r} or random slot {entry.rng_slot} already registered")
    PARAMETERS[entry.key] = entry
    return entry


def register(entry: TrackerEntry) -> TrackerEntry:
    if entry.name in TRACKERS:
        raise ValueError(f"tracker {entry.name!r} already registered")
    unknown = [k for k in entry.param_keys if k not in PARAMETERS]
    if unknown:
        raise ValueError(f"tracker {entry.name!r}: unknown parameter key(s) {unknown}")
    TRACKERS[entry.name] = entry
    return entry


def load(path: str) -> Any:
    """The object a ``"module:attribute"`` string names."""
    module, _, attr = path.partition(":")
    return getattr(importlib.import_module(module), attr)


def names() -> tuple[str, ...]:
    return tuple(TRACKERS)


def get(name: str) -> TrackerEntry:
    """The entry of tracker ``name``; a :class:`UserError` listing the known ones otherwise."""
    try:
        return TRACKERS[name]
    except KeyError:
        raise UserError(f"unknown tracker {name!r}; expected one of {', '.join(TRACKERS)}") from None


def default_params(key: str) -> Any:
    """A parameters object of kind ``key`` with every default."""
    return load(PARAMETERS[key].cls)()


def params_class(key: str) -> type:
    return load(PARAMETERS[key].cls)


# -- the table ---------------------------------------------------------------------------------

register_parameters(ParameterEntry("body", "partlab.tracking.body.params:BodyParams", rng_slot=0))
register_parameters(ParameterEntry("limbs", "partlab.tracking.limbs.params:LimbParams", rng_slot=1))
register_parameters(ParameterEntry("activities", "partlab.tracking.activities.params:ActivityParams", rng_slot=9))
# slots clear of each other: 16 the depth tracker's issue number
register_parameters(ParameterEntry("depth", "partlab.tracking.depth.params:DepthParams", rng_slot=16))

register(TrackerEntry(
    "body", "head, torso and hip-leg of every person, plus the person box (Zhao & Lee)",
    "partlab.tracking.body:build", ("body",), ("person", "head", "torso", "hipleg")))
register(TrackerEntry(
    "limbs", "head and both hands of every person (parallel filters over skin blobs, state machine), "
    "with their activities (clap, handshake, exchange, pick, place)",
    "partlab.tracking.limbs:build", ("limbs", "activities"), ("head", "left_hand", "right_hand")))
register(TrackerEntry(
    "all", "body and limbs together, one track id per person",
    "partlab.tracking.combined:build", ("body", "limbs", "activities"),
    ("person", "head", "torso", "hipleg", "left_hand", "right_hand")))
register(TrackerEntry(
    "whole", "one box per person (Zhao & Lee's whole-body baseline, Fig. 4(d))",
    "partlab.tracking.body:build_whole", ("body",), ("person",)))
register(TrackerEntry(
    "limbs-depth", "face and both hands of one person with depth, plus 3D shoulders and elbows (Xu, Deng & Jia)",
    "partlab.tracking.depth:build", ("depth",),
    ("head", "left_hand", "right_hand", "torso", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow"),
    needs=frozenset({"color", "depth"}), foreground=False))

# 17: the top-view tracker's issue number
register_parameters(ParameterEntry("topview", "partlab.tracking.topview.params:TopViewParams", rng_slot=17))
register(TrackerEntry(
    "topview", "3D head, shoulders, elbows and hands of several people seen from above by a depth camera "
    "(Migniot & Ababsa)", "partlab.tracking.topview:build", ("topview",),
    ("head", "right_shoulder", "left_shoulder", "right_elbow", "left_elbow", "right_hand", "left_hand"),
    needs=frozenset({"depth", "calibration"}), foreground=False))

# slot 14 (the issue that added it): far from the slots the other trackers take in order
register_parameters(ParameterEntry("limbs3d", "partlab.tracking.limbs3d.params:Limbs3DParams", rng_slot=14))
register(TrackerEntry(
    "limbs3d", "heads and hands in 3D from two or more calibrated cameras (candidates from pairs of views), "
    "with their activities", "partlab.tracking.limbs3d:build", ("limbs3d", "activities"),
    ("head", "left_hand", "right_hand"),
    needs=frozenset({"color", "calibration"}), min_streams=2))
