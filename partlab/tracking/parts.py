"""Part names: the contract shared by trackers, the store, the formats and users' scripts.

One table, :data:`PARTS`, says what each part is. ``person`` is the whole body (for the body
tracker, the minimum bounding rectangle of its three parts); ``head/torso/hipleg`` are Zhao &
Lee's body parts and ``head/left_hand/right_hand`` the limbs of the multi-camera head-and-hands
paper (``head`` is shared by both). Shoulders and elbows are *joints* of the 3D posture trackers
(Xu, Deng & Jia sec. 5; Migniot & Ababsa): rows with ``X,Y,Z`` and a small box around the joint's
image. New parts are added at the end of the table (the order numbers MOT ids and colours).
"""

from __future__ import annotations

#: name -> (kind, description); kind is "box" (a region people draw) or "joint" (a 3D point)
PARTS: dict[str, tuple[str, str]] = {
    "person": ("box", "the whole body"),
    "head": ("box", "head (face and hair)"),
    "torso": ("box", "torso, shoulders to hips"),
    "hipleg": ("box", "hips and legs"),
    "left_hand": ("box", "the person's left hand"),
    "right_hand": ("box", "the person's right hand"),
    "left_shoulder": ("joint", "left shoulder joint"),
    "right_shoulder": ("joint", "right shoulder joint"),
    "left_elbow": ("joint", "left elbow joint"),
    "right_elbow": ("joint", "right elbow joint"),
}

PART_NAMES: tuple[str, ...] = tuple(PARTS)
BOX_PARTS: tuple[str, ...] = tuple(p for p, (kind, _) in PARTS.items() if kind == "box")
JOINT_PARTS: tuple[str, ...] = tuple(p for p, (kind, _) in PARTS.items() if kind == "joint")
BODY_PARTS: tuple[str, ...] = ("head", "torso", "hipleg")
LIMB_PARTS: tuple[str, ...] = ("head", "left_hand", "right_hand")


def check_part(name: str) -> str:
    """Return ``name`` if it is a known part, else raise ``ValueError`` listing the known ones."""
    if name not in PARTS:
        raise ValueError(f"unknown part {name!r}; expected one of {', '.join(PART_NAMES)}")
    return name
