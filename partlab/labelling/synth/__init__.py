"""Synthetic scenes with exact ground truth (``partlab synth``).

Articulated walkers seen from a raised camera (``camera``), with clothes and skin
colours (``appearance``), moving along scripted paths (``motion``, ``scenarios``),
drawn part by part with OpenCV (``figure``) over a textured room with flicker and
sensor noise (``background``); ``scene`` composes frames and the truth table.
"""

from partlab.labelling.synth.scene import SCENARIOS, Scene, make_scene, render_scenario

__all__ = ["SCENARIOS", "Scene", "make_scene", "render_scenario"]
