"""Activities on the synthetic activity scenes: per kind precision and recall at temporal IoU 0.5.

For each scenario (pick_place, exchange, handshake, clap) and seed: render the scene, track its
hands with ``--tracker limbs`` from the truth's first boxes (``init.csv``), recognise activities
(:mod:`partlab.tracking.activities`) and match them to the scene's event truth
(:func:`partlab.labelling.events.evaluate_events`). Prints the table per kind over all seeds, the
spread of per-seed recall, how often a handshake scene was called an exchange, and seconds per frame.

``--hands truth`` feeds the recognition the scene's true head and hand boxes instead of the limb
tracker's (what the recognition gets right when the hands are right); ``--hands both`` runs both,
which separates the recognition's errors from the hand tracker's.

    python benchmarks/activity_accuracy.py [--seeds 0-9] [--size 720x480] [--frames 150] [--hands tracked|truth|both]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from partlab.labelling.events import evaluate_events  # noqa: E402
from partlab.labelling.synth import make_scene  # noqa: E402
from partlab.tracking.core.background import BackgroundModel  # noqa: E402
from partlab.tracking.frame import FrameSet  # noqa: E402
from partlab.tracking.protocol import TrackContext  # noqa: E402
from partlab.tracking.run import build_tracker, model_params, run_frames  # noqa: E402

SCENES = ("pick_place", "exchange", "handshake", "clap")


def _seeds(text: str) -> list[int]:
    if "-" in text:
        a, b = text.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(s) for s in text.split(",")]


class TruthHands:
    """A 'tracker' that reports the scene's true head and hand boxes (those at least half visible)."""

    events = None

    def __init__(self, truth: pd.DataFrame):
        t = truth[truth.part.isin(["head", "left_hand", "right_hand"]) & (truth.occluded < 0.5)]
        self.by_frame = {int(f): g for f, g in t.groupby("frame")}

    def step(self, frames, foreground):
        from partlab.tracking.core.box import Box
        from partlab.tracking.tracks import TrackRecord

        g = self.by_frame.get(frames.index)
        if g is None:
            return []
        return [TrackRecord(frames.index, int(r.track_id), r.part, Box(r.x, r.y, r.w, r.h), state="truth",
                            camera=getattr(r, "camera", "") or "") for r in g.itertuples()]

    def table(self, records):
        from partlab.tracking.tracks import records_to_frame

        return records_to_frame(records)


def run_one(name: str, seed: int, frames: int, width: int, height: int,
            hands: str = "tracked") -> tuple[pd.DataFrame, pd.DataFrame, float]:
    scene = make_scene(name, seed=seed, n_frames=frames, width=width, height=height)
    if hands == "truth":
        from partlab.tracking.activities import with_activities

        tracker = with_activities(TruthHands(scene.truth), model_params(None, "activities"))
    else:
        tracker = build_tracker("limbs", seed=seed, context=TrackContext(init=scene.init, fps=scene.fps))
    body = model_params(None, "body")
    t0 = time.perf_counter()
    run_frames(tracker, (FrameSet.single(i, f) for i, f in enumerate(scene.frames)), lambda s: BackgroundModel(body))
    return scene.events, tracker.events, (time.perf_counter() - t0) / frames


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0-9")
    ap.add_argument("--size", default="720x480")
    ap.add_argument("--frames", type=int, default=150)
    ap.add_argument("--hands", choices=("tracked", "truth", "both"), default="tracked",
                    help="the hands the recognition reads: the limb tracker's, the scene's truth, or both runs")
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    for hands in (("tracked", "truth") if args.hands == "both" else (args.hands,)):
        print(f"\n=== hands: {hands} ===", flush=True)
        report(args, w, h, hands)
    return 0


def report(args, w: int, h: int, hands: str) -> None:
    truths, preds, recalls, swaps, spf = [], [], {}, 0, []
    for name in SCENES:
        for seed in _seeds(args.seeds):
            truth, pred, s = run_one(name, seed, args.frames, w, h, hands)
            spf.append(s)
            truth = truth.assign(clip=f"{name}/{seed}")
            pred = pred.assign(clip=f"{name}/{seed}")
            table = evaluate_events(truth, pred)
            recalls.setdefault(name, []).append(float(table.loc["all", "recall"]))
            if name == "handshake":
                swaps += int((pred["kind"] == "exchange").sum())
            kinds = ", ".join(f"{r.kind} {r.start_frame}-{r.end_frame}" for r in pred.itertuples()) or "none"
            said = ", ".join(f"{r.kind} {r.start_frame}-{r.end_frame}" for r in truth.itertuples())
            print(f"{name:10s} seed {seed}: truth {said} | found {kinds}", flush=True)
            truths.append(truth)
            preds.append(pred)
    # evaluate per clip (frames of different clips never match), then sum the counts
    total = None
    for t, p in zip(truths, preds):
        table = evaluate_events(t, p)[["truth", "predicted", "matched"]]
        total = table if total is None else total.add(table, fill_value=0)
    total["precision"] = total["matched"] / total["predicted"].replace(0, np.nan)
    total["recall"] = total["matched"] / total["truth"].replace(0, np.nan)
    print("\nper kind, all seeds (temporal IoU >= 0.5):")
    print(total.astype({"truth": int, "predicted": int, "matched": int}).round(3).to_string())
    print("\nper-scene recall over seeds: " + "; ".join(
        f"{k} {np.mean(v):.2f} +- {np.std(v):.2f} (min {np.min(v):.2f})" for k, v in recalls.items()))
    print(f"handshake scenes called an exchange: {swaps}")
    print(f"tracking + recognition: {1000 * np.mean(spf):.1f} ms per frame (median {1000 * np.median(spf):.1f})")


if __name__ == "__main__":
    sys.exit(main())
