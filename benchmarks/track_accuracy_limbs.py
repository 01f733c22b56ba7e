"""Accuracy of the limb tracker on the synthetic scenes (issue 4's limbs table).

For each scenario and seed: render the scene (``partlab.labelling.synth.make_scene``), run
``LimbTracker`` from the scene's init boxes with the shared background model, and
report per part (head, left hand, right hand)

- the tracking rate at frame ``--at`` (105 by default): the fraction of (seed, person)
  whose box is right there (:mod:`partlab.tracking.measures`: at least half of it on the true
  box and its centre inside it, Zhao & Lee sec. 5.2-5.3);
- the averaged rate (the rate curve's mean over frames 1 on);
- the number of identity swaps of the hands after the clap (in the left_hand row): a
  swap starts at a frame where each hand's box is nearer the other hand's true centre
  than its own.

Named so as not to clash with the body developer's ``benchmarks/track_accuracy.py``.
A script, not a test:

    PYTHONPATH=. python benchmarks/track_accuracy_limbs.py [--seeds 0 1 2] [--scenarios desk single] [--fg plate]
                                                           [--video]   # through the mp4 codec, as partlab track
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm import tqdm

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout's partlab, not an installed one

from partlab.tracking import measures  # noqa: E402
from partlab.tracking.core.background import BackgroundModel  # noqa: E402
from partlab.tracking.limbs.tracker import LimbTracker  # noqa: E402
from partlab.tracking.params import LimbParams  # noqa: E402
from partlab.tracking.parts import LIMB_PARTS  # noqa: E402
from partlab.tracking.run import run_single_view  # noqa: E402


class PlateForeground:
    """Foreground from the scene's empty-room plate (``Scene.background``): what a background
    model converges to, so the tracker is measured apart from the background model's warm-up
    (the desk scene's person sits there from frame 0, which an adaptive model learns as
    background)."""

    def __init__(self, plate: np.ndarray, threshold: float = 30.0):
        import cv2
        self.plate = cv2.GaussianBlur(plate, (5, 5), 0).astype(np.int16)
        self.threshold = threshold

    def apply(self, frame: np.ndarray) -> np.ndarray:
        import cv2
        diff = np.abs(cv2.GaussianBlur(frame, (5, 5), 0).astype(np.int16) - self.plate).max(axis=2)
        return (diff > self.threshold).astype(np.uint8) * 255


def through_codec(frames: np.ndarray, fps: float) -> list[np.ndarray]:
    """The frames as a user's tracker sees them: written to an mp4 (``partlab.labelling.video.write_video``)
    and decoded again. The codec shifts and blurs colours, which changes what the skin model sees."""
    import tempfile
    from pathlib import Path

    from partlab.labelling.video import VideoClip, write_video

    with tempfile.TemporaryDirectory() as tmp:
        path = write_video(Path(tmp) / "clip.mp4", frames, fps)
        clip = VideoClip(path)
        try:
            return [f for _, f in clip.frames(0, clip.frame_count)]
        finally:
            clip.close()


def run_scene(scene, params: LimbParams, seed: int, fg: str = "model",
              video: bool = False) -> tuple[pd.DataFrame, pd.DataFrame]:
    init = scene.init[scene.init["part"].isin(LIMB_PARTS)]
    tracker = LimbTracker(params, np.random.default_rng(seed), init=init)
    bg = PlateForeground(scene.background) if fg == "plate" else BackgroundModel()
    frames = through_codec(scene.frames, scene.fps) if video else scene.frames
    return run_single_view(tracker, frames, bg), tracker.events


def score(out: pd.DataFrame, truth: pd.DataFrame) -> pd.DataFrame:
    """Truth rows of the limb parts with ``correct`` (:func:`partlab.tracking.measures.judge`; missing
    predictions are wrong) and ``offset``; the tracked box in ``x, y, w, h`` and the truth in ``x_t ...``."""
    t = truth[truth["part"].isin(LIMB_PARTS)][["frame", "track_id", "part", "x", "y", "w", "h"]]
    m = measures.with_offsets(measures.judge(t, out), truth).merge(
        out[["frame", "track_id", "part", "state"]], on=["frame", "track_id", "part"], how="left")
    m = m.rename(columns={"x": "x_t", "y": "y_t", "w": "w_t", "h": "h_t"})
    return m.rename(columns={"x_k": "x", "y_k": "y", "w_k": "w", "h_k": "h", "right": "correct"})


def hand_swaps(m: pd.DataFrame, after: int) -> int:
    """Swap onsets after frame ``after``: frames where both hands are nearer the other's truth."""
    swaps = 0
    for _, g in m[m.frame > after].groupby("track_id"):
        lh = g[g.part == "left_hand"].set_index("frame")
        rh = g[g.part == "right_hand"].set_index("frame")
        frames = lh.index.intersection(rh.index)
        if len(frames) == 0:
            continue
        lh, rh = lh.loc[frames], rh.loc[frames]

        def c(df, s=""):
            return np.column_stack([df["x" + s] + df["w" + s] / 2, df["y" + s] + df["h" + s] / 2])
        pl, pr, tl, tr = c(lh), c(rh), c(lh, "_t"), c(rh, "_t")
        d = lambda a, b: np.hypot(*(a - b).T)  # noqa: E731
        swapped = (d(pl, tr) < d(pl, tl)) & (d(pr, tl) < d(pr, tr))
        swapped = np.nan_to_num(swapped, nan=0).astype(bool)
        swaps += int(swapped[0]) + int(((~swapped[:-1]) & swapped[1:]).sum())
    return swaps


def clap_end(truth: pd.DataFrame, gap: float) -> int:
    """Last frame at which some person's true hand centres are closer than ``gap`` (the clap)."""
    frames = []
    for (f, _tid), g in truth[truth.part.isin(["left_hand", "right_hand"])].groupby(["frame", "track_id"]):
        if len(g) == 2:
            c = g[["x", "y"]].to_numpy() + g[["w", "h"]].to_numpy() / 2
            if np.hypot(*(c[0] - c[1])) < gap:
                frames.append(f)
    return max(frames) if frames else -1


def limbs_table(scenarios=("desk", "single"), seeds=(0, 1, 2), n_frames: int = 150, width: int = 320,
                height: int = 240, at: int = 105, params: LimbParams | None = None,
                fg: str = "model", video: bool = False) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Per (scenario, seed, part) rows and the per (scenario, part) summary (rate at ``at``, mean
    rate, swaps after the clap); ``benchmarks/track_accuracy.py`` prints the summary as its limbs table."""
    from partlab.labelling.synth import make_scene

    params = params or LimbParams()
    rows = []
    for name in scenarios:
        for seed in tqdm(seeds, desc=name):
            scene = make_scene(name, seed, n_frames, width, height)
            out, events = run_scene(scene, params, seed, fg, video)
            m = score(out, scene.truth)
            hands = m[m.part.isin(["left_hand", "right_hand"])]
            gap = float(np.median(hands.w_t)) * 1.5 if len(hands) else 0.0
            end = clap_end(scene.truth, gap)
            for part in LIMB_PARTS:
                mp = m[m.part == part]
                curve = measures.rate_curve(mp.rename(columns={"correct": "right"}))
                rows.append({"scenario": name, "seed": seed, "part": part,
                             f"rate@{at}": measures.rate_at(curve, at),
                             "rate_mean": measures.averaged_rate(curve),
                             "swaps_after_clap": hand_swaps(m, end) if end >= 0 and part == "left_hand" else 0,
                             "clap_end": end, "events": len(events),
                             "lost_frames": int((mp.state == "lost").sum())})
    df = pd.DataFrame(rows)
    summary = df.groupby(["scenario", "part"]).agg(
        **{f"rate@{at}": (f"rate@{at}", "mean"), "rate_mean": ("rate_mean", "mean"),
           "swaps": ("swaps_after_clap", "sum")})
    return df, summary


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", nargs="+", default=["desk", "single"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2])
    ap.add_argument("--frames", type=int, default=150)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--at", type=int, default=105, help="frame of the tracking rate")
    ap.add_argument("--params", default="{}", help='LimbParams overrides as JSON, e.g. {"appearance.lam": 2}')
    ap.add_argument("--fg", choices=["model", "plate"], default="model",
                    help="foreground: the shared background model (MOG2 until tracking/background.py "
                         "lands) or the scene's empty-room plate")
    ap.add_argument("--video", action="store_true",
                    help="track the scene as written to an mp4 and decoded again (what `partlab track` sees), "
                         "not the rendered frames")
    args = ap.parse_args()
    params = LimbParams().updated(json.loads(args.params))
    df, summary = limbs_table(args.scenarios, args.seeds, args.frames, args.width, args.height, args.at,
                              params, args.fg, args.video)
    pd.set_option("display.width", 160)
    print(df.to_string(index=False, float_format="%.3f"))
    print()
    print(summary.to_string(float_format="%.3f"))


if __name__ == "__main__":
    main()
