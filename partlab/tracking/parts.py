"""Part names: the contract shared by trackers, the store, the formats and users' scripts.

``person`` is the whole body (for the body tracker, the minimum bounding rectangle of
its three parts); ``head/torso/hipleg`` are the body parts of seed 002 and
``head/left_hand/right_hand`` the limbs of seed 000. ``head`` is shared by both.
"""

from __future__ import annotations

PART_NAMES: tuple[str, ...] = ("person", "head", "torso", "hipleg", "left_hand", "right_hand")
BODY_PARTS: tuple[str, ...] = ("head", "torso", "hipleg")
LIMB_PARTS: tuple[str, ...] = ("head", "left_hand", "right_hand")


def check_part(name: str) -> str:
    """Return ``name`` if it is a known part, else raise ``ValueError`` listing the known ones."""
    if name not in PART_NAMES:
        raise ValueError(f"unknown part {name!r}; expected one of {', '.join(PART_NAMES)}")
    return name
