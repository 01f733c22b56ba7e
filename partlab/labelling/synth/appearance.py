"""How a synthetic person looks: clothes, skin and hair colours, body height.

Colours are BGR (OpenCV order), drawn from palettes of plausible clothes, skin tones
and hair; every walker of a scene gets a different shirt and trousers (sampled
without replacement), each jittered a little so that two seeds never look the same.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SHIRTS: tuple[tuple[int, int, int], ...] = (
    (45, 45, 185),  # red
    (95, 45, 30),  # navy
    (60, 135, 55),  # green
    (222, 222, 215),  # white
    (60, 195, 225),  # yellow
    (215, 165, 115),  # light blue
    (55, 30, 115),  # maroon
    (35, 120, 225),  # orange
    (125, 55, 110),  # purple
    (135, 125, 25),  # teal
    (150, 150, 150),  # grey
    (175, 135, 225),  # pink
)
TROUSERS: tuple[tuple[int, int, int], ...] = (
    (115, 75, 45),  # jeans
    (75, 50, 35),  # dark jeans
    (38, 36, 36),  # black
    (125, 170, 190),  # khaki
    (105, 102, 100),  # grey
    (45, 65, 95),  # brown
    (55, 95, 85),  # olive
)
SKINS: tuple[tuple[int, int, int], ...] = (
    (160, 185, 228),
    (130, 165, 215),
    (105, 145, 195),
    (85, 115, 165),
    (60, 85, 125),
    (175, 200, 238),
)
HAIRS: tuple[tuple[int, int, int], ...] = (
    (25, 25, 30),  # black
    (25, 40, 60),  # dark brown
    (40, 70, 110),  # brown
    (100, 165, 205),  # blonde
    (150, 150, 152),  # grey
    (30, 55, 125),  # auburn
)
SHOES: tuple[tuple[int, int, int], ...] = ((30, 30, 32), (205, 205, 205), (40, 55, 75))


@dataclass(frozen=True)
class Appearance:
    """One person's colours (BGR uint8 triples) and size."""

    shirt: tuple[int, int, int]
    trousers: tuple[int, int, int]
    skin: tuple[int, int, int]
    hair: tuple[int, int, int]
    shoes: tuple[int, int, int]
    height_m: float = 1.75
    short_sleeves: bool = False
    long_hair: bool = False
    girth: float = 1.0  # body width against the built-in adult proportions (lateral scale)
    head_scale: float = 1.0  # head size against the built-in proportions
    legs: float = 1.0  # leg length (waist height) against the built-in proportions


def _jitter(rng: np.random.Generator, colour, amount: int = 8) -> tuple[int, int, int]:
    c = np.asarray(colour, int) + rng.integers(-amount, amount + 1, size=3)
    return tuple(int(v) for v in np.clip(c, 0, 255))


def _distinct(rng: np.random.Generator, palette, n: int, min_dist: float) -> list[int]:
    """``n`` palette indices in random order, each at least ``min_dist`` (BGR distance) from the others
    when the palette allows it (else the farthest remaining ones)."""
    cols = np.asarray(palette, float)
    chosen: list[int] = []
    for i in rng.permutation(len(palette)):
        if len(chosen) == n:
            break
        if all(np.linalg.norm(cols[i] - cols[j]) >= min_dist for j in chosen):
            chosen.append(int(i))
    while len(chosen) < n:  # relax: add the colour farthest from those already chosen
        rest = [i for i in range(len(palette)) if i not in chosen]
        chosen.append(max(rest, key=lambda i: min(np.linalg.norm(cols[i] - cols[j]) for j in chosen)))
    return chosen


def sample_appearances(rng: np.random.Generator, n: int) -> list[Appearance]:
    """``n`` people with clearly different shirts and different trousers (n <= 7)."""
    if n > len(TROUSERS):
        raise ValueError(f"at most {len(TROUSERS)} people have distinct clothes, asked for {n}")
    shirts = _distinct(rng, SHIRTS, n, 90.0)
    trousers = _distinct(rng, TROUSERS, n, 50.0)
    out = []
    for i in range(n):
        out.append(Appearance(
            shirt=_jitter(rng, SHIRTS[shirts[i]]),
            trousers=_jitter(rng, TROUSERS[trousers[i]]),
            skin=_jitter(rng, SKINS[rng.integers(len(SKINS))], 5),
            hair=_jitter(rng, HAIRS[rng.integers(len(HAIRS))], 5),
            shoes=_jitter(rng, SHOES[rng.integers(len(SHOES))], 5),
            height_m=float(rng.uniform(1.62, 1.86)),
            short_sleeves=bool(rng.random() < 0.4),
            long_hair=bool(rng.random() < 0.35),
        ))
    return out


def _random_colour(rng: np.random.Generator) -> tuple[int, int, int]:
    """Any clothing colour: hue uniform, saturation and value over their whole plausible range."""
    import cv2

    hsv = np.array([[[rng.integers(0, 180), rng.integers(0, 256), rng.integers(25, 256)]]], np.uint8)
    return tuple(int(v) for v in cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR)[0, 0])


def random_appearances(rng: np.random.Generator, n: int) -> list[Appearance]:
    """``n`` people of any look (any number; colours may repeat, as in real crowds): clothes of any
    colour, skin anywhere between the palette's darkest and lightest tones, heights 1.50-1.95 m,
    body width 0.8-1.3, head size 0.85-1.15 and leg length 0.92-1.08 of the built-in proportions
    (waist at 0.49-0.57 of the height: adults' sitting-height ratios span about that)."""
    skins = np.asarray(SKINS, float)
    dark, light = skins[np.argmin(skins.sum(1))], skins[np.argmax(skins.sum(1))]
    out = []
    for _ in range(n):
        skin = dark + rng.uniform(0, 1) * (light - dark)
        out.append(Appearance(
            shirt=_random_colour(rng), trousers=_random_colour(rng),
            skin=_jitter(rng, tuple(int(v) for v in skin), 8),
            hair=_jitter(rng, HAIRS[rng.integers(len(HAIRS))], 10),
            shoes=_random_colour(rng),
            height_m=float(rng.uniform(1.50, 1.95)),
            short_sleeves=bool(rng.random() < 0.4), long_hair=bool(rng.random() < 0.35),
            girth=float(rng.uniform(0.8, 1.3)), head_scale=float(rng.uniform(0.85, 1.15)),
            legs=float(rng.uniform(0.92, 1.08)),
        ))
    return out
