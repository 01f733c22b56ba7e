"""Would Xu, Deng & Jia's scale alpha be observable in the limb filter? (issue 13, item 9)

Their state is ``(x, y, alpha)`` with the window ``(x, y, alpha w, alpha h)`` scored by the hue
histogram of the whole window (sec. 3, eq. 1-2): a window grown past the hand takes in background
hues and scores lower, a shrunk one keeps fewer of the hand's, so alpha is seen. The limb tracker
scores the hue of skin pixels only (red cups and wood share skin's hue: ``limbs.tracker``), and its
blob term (eq. 17) compares centres. This script draws a skin disc (a hand) on a shirt, over
randomised sizes, colours and noise, and prints the mean score of windows of scale alpha centred
on it, relative to alpha = 1:

- ``skin-only hue`` (the limb filter's hue term, which the blob term leaves unchanged with alpha);
- ``whole-window hue`` (the paper's).

A flat row means the filter cannot tell the scale; the paper's row peaks at 1.

    PYTHONPATH=. python benchmarks/limb_scale.py [--seeds 0-19]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from partlab.tracking.core.hue_histogram import (  # noqa: E402
    hue_bin_image,
    hue_confidence,
    local_box_histograms,
    reference_histogram,
)
from partlab.tracking.core.skin import SkinModel  # noqa: E402
from partlab.tracking.params import LimbParams  # noqa: E402

ALPHAS = (0.5, 0.7, 0.85, 1.0, 1.2, 1.5, 2.0)


def scores(seed: int, p: LimbParams) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    r = int(rng.integers(6, 16))
    skin = tuple(int(v) for v in rng.integers([90, 130, 180], [130, 170, 235]))
    shirt = tuple(int(v) for v in rng.integers(30, 200, 3))
    f = np.full((160, 160, 3), shirt, np.uint8)
    cv2.circle(f, (80, 80), r, skin, -1)
    f = np.clip(f + rng.normal(0, 4, f.shape), 0, 255).astype(np.uint8)
    a = p.appearance
    bins = hue_bin_image(cv2.cvtColor(f, cv2.COLOR_BGR2HSV), a.hue_bins, a.hue_min_saturation, a.hue_min_value)
    skin_bins = np.where(SkinModel.default().probability(f) >= p.skin.threshold, bins, -1).astype(np.int16)
    side = 2.0 * r
    ref_box = (80 - side / 2, 80 - side / 2, side, side)
    out = []
    for img in (skin_bins, bins):
        ref = reference_histogram(img, ref_box, a.hue_bins)
        boxes = np.array([[80 - al * side / 2, 80 - al * side / 2, al * side, al * side] for al in ALPHAS])
        out.append(hue_confidence(local_box_histograms(img, boxes, a.hue_bins), ref, a.lam))
    return out[0], out[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0-19")
    args = ap.parse_args()
    lo, hi = (int(v) for v in args.seeds.split("-"))
    p = LimbParams()
    res = [scores(s, p) for s in range(lo, hi + 1)]
    one = ALPHAS.index(1.0)
    print(f"score of a window of scale alpha on a hand / score at alpha = 1, seeds {args.seeds} (mean +- std)")
    print("alpha              " + " ".join(f"{a:>11.2f}" for a in ALPHAS))
    for k, name in enumerate(("skin-only hue", "whole-window hue")):
        rel = np.array([r[k] / max(r[k][one], 1e-12) for r in res])
        print(f"{name:<18} " + " ".join(f"{m:>6.3f}+-{s:<4.2f}" for m, s in zip(rel.mean(0), rel.std(0))))


if __name__ == "__main__":
    main()
