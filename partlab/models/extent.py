"""How the body tracker's inner rectangles are reported as part boxes, fitted from corrections.

The filters track inner rectangles (seed 002 sec. 4.1); ``BodyParams.output.extent``
widens them to the part's extent for output. People correct the boxes they see, so the
corrected boxes say how far off that widening is: per part, the median ratio of the
corrected to the reported size, and the median offset of the corrected centre, in units
of the tracked inner size. Medians keep a few badly tracked frames from pulling the fit.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from partlab.tracking.parts import BODY_PARTS

#: corrected/reported pairs needed before a part's extent is refitted
MIN_PAIRS = 20


def fit_output_extent(tracked: list[pd.DataFrame], truths: list[pd.DataFrame],
                      current: dict[str, tuple[float, float, float, float]]
                      ) -> dict[str, tuple[float, float, float, float]]:
    """New ``output_extent`` from tracker output (reported with ``current``) and the
    corrected boxes of the same clips; parts with too few well-tracked pairs keep theirs."""
    pairs = []
    for t, g in zip(tracked, truths):
        m = t.merge(g, on=["frame", "track_id", "part"], suffixes=("", "_t"))
        pairs.append(m)
    if not pairs:
        return dict(current)
    m = pd.concat(pairs, ignore_index=True)
    m = m[m.part.isin(BODY_PARTS) & (m.w > 0) & (m.h > 0) & (m.w_t > 0) & (m.h_t > 0)]
    if "occluded_t" in m:
        m = m[m.occluded_t < 0.1]
    # only frames where the tracker is on the part (its centre inside the corrected box)
    cx, cy = m.x + m.w / 2, m.y + m.h / 2
    m = m[(cx >= m.x_t) & (cx <= m.x_t + m.w_t) & (cy >= m.y_t) & (cy <= m.y_t + m.h_t)]
    out = dict(current)
    for part, g in m.groupby("part"):
        if len(g) < MIN_PAIRS:
            continue
        sw, sh, dx, dy = current.get(part, (1.0, 1.0, 0.0, 0.0))
        inner_w, inner_h = g.w / sw, g.h / sh
        new_sw = sw * float(np.median(g.w_t / g.w))
        new_sh = sh * float(np.median(g.h_t / g.h))
        new_dx = dx + float(np.median(((g.x_t + g.w_t / 2) - (g.x + g.w / 2)) / inner_w))
        new_dy = dy + float(np.median(((g.y_t + g.h_t / 2) - (g.y + g.h / 2)) / inner_h))
        out[part] = (round(new_sw, 3), round(new_sh, 3), round(new_dx, 3), round(new_dy, 3))
    return out


def extent_table(fitted: dict, default: dict) -> pd.DataFrame:
    """Fitted against default extent, one row per part and term (for the CLI and the app)."""
    rows = []
    for part in BODY_PARTS:
        for k, name in enumerate(("scale_w", "scale_h", "shift_x", "shift_y")):
            rows.append(dict(part=part, term=name, default=default.get(part, (1, 1, 0, 0))[k],
                             fitted=fitted.get(part, (1, 1, 0, 0))[k]))
    return pd.DataFrame(rows)
