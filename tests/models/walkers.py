"""Truth tables of people walking, made by the tests (the synthetic scenes are for benchmarks)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from partlab.tracking.tracks import normalise_tracks


def walking_truth(n_people: int = 2, n_frames: int = 60, seed: int = 0) -> pd.DataFrame:
    """Head/torso/hip-leg/person boxes of people walking sideways with a little bob and sway."""
    rng = np.random.default_rng(seed)
    rows = []
    for tid in range(1, n_people + 1):
        height = rng.uniform(110, 200)
        width = height * 0.3
        x0, y0 = rng.uniform(50, 400), rng.uniform(100, 250)
        vx = rng.choice([-1, 1]) * rng.uniform(1.5, 3.5)
        phase = rng.uniform(0, 2 * np.pi)
        for f in range(n_frames):
            cx = x0 + vx * f + 2.0 * np.sin(0.3 * f + phase)
            top = y0 + 1.5 * np.sin(0.6 * f + phase)
            hh, th, lh = 0.15 * height, 0.33 * height, 0.52 * height
            legs = 1.0 + 0.25 * abs(np.sin(0.3 * f + phase))
            boxes = {
                "head": (cx - 0.4 * width / 2, top, 0.4 * width, hh),
                "torso": (cx - width / 2, top + hh, width, th),
                "hipleg": (cx - legs * width / 2, top + hh + th, legs * width, lh),
                "person": (cx - legs * width / 2, top, legs * width, height),
            }
            for part, (x, y, w, h) in boxes.items():
                rows.append(dict(frame=f, track_id=tid, part=part, x=x, y=y, w=w, h=h, source="truth"))
    return normalise_tracks(pd.DataFrame(rows))
