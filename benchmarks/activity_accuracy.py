"""Activities on the synthetic activity scenes: per kind precision and recall at temporal IoU 0.5.

For each scenario (pick_place, exchange, handshake, clap) and seed: render the scene, track its
hands with ``--tracker limbs`` from the truth's first boxes (``init.csv``), recognise activities
(:mod:`partlab.tracking.activities`) and match them to the scene's event truth
(:func:`partlab.labelling.events.evaluate_events`). Prints the table per kind over all seeds, the
spread of per-seed recall, how often a handshake scene was called an exchange, and seconds per frame.

``--cameras 3`` measures the 3-camera takes instead (``partlab synth --cameras 3``: standing and
seated with a clap, handshake with a handshake and an exchange), hands from ``--tracker limbs3d``
(the 3D heads and hands projected into every view; the colour around each hand fused over the
views, eq. 29) from the truth's first frame; the colour analysis reads each view's silhouettes
against the take's empty-scene images, with tracked or true hands.

``--cache DIR`` keeps each run's hands and the colour seen round them (the state of
:class:`~partlab.tracking.activities.recognise.ActivityTracker` before the recognition) per
scene, seed, cameras and hands, and later runs re-run only the recognition from it: changes of
``decision.*`` parameters are then measured in seconds (a 3-camera take takes minutes to track).
Other ``--set`` changes are part of the cache's key; the code is not: after changing a tracker
(or the colour analysis), use a new directory.

``--hands truth`` feeds the recognition the scene's true head and hand boxes instead of the limb
tracker's (what the recognition gets right when the hands are right); ``--hands both`` runs both,
which separates the recognition's errors from the hand tracker's.

    python benchmarks/activity_accuracy.py [--seeds 0-9] [--size 720x480] [--frames 150] [--hands tracked|truth|both]
                                           [--cameras 3] [--set GROUP.NAME=VALUE ...] [--dump DIR]
                                           [--cache DIR]
"""

from __future__ import annotations

import argparse
import hashlib
import pickle
import sys
import time
from pathlib import Path
from types import SimpleNamespace

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
SCENES_3D = ("standing", "seated", "handshake")


def _seeds(text: str) -> list[int]:
    if "-" in text:
        a, b = text.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(s) for s in text.split(",")]


class TruthHands:
    """A 'tracker' that reports the scene's true head and hand boxes (wherever some of the part is
    seen), with the truth's share of each that is hidden (``occluded``)."""

    events = None

    def __init__(self, truth: pd.DataFrame):
        t = truth[truth.part.isin(["head", "left_hand", "right_hand"]) & (truth.occluded < 0.95)]
        self.by_frame = {int(f): g for f, g in t.groupby("frame")}

    def step(self, frames, foreground):
        from partlab.tracking.core.box import Box
        from partlab.tracking.tracks import TrackRecord

        g = self.by_frame.get(frames.index)
        if g is None:
            return []
        return [TrackRecord(frames.index, int(r.track_id), r.part, Box(r.x, r.y, r.w, r.h), state="truth",
                            occluded=float(r.occluded),
                            camera=getattr(r, "camera", "") or "", X=getattr(r, "X", float("nan")),
                            Y=getattr(r, "Y", float("nan")), Z=getattr(r, "Z", float("nan")))
                for r in g.itertuples()]

    def table(self, records):
        from partlab.tracking.tracks import records_to_frame

        return records_to_frame(records)


STATE = ("_colours", "_centres", "_clothes", "_clothes_n", "_where")


def cache_path(cache: Path | None, name: str, seed: int, cameras: int, hands: str, changes: dict | None) -> Path | None:
    """Where a run's tracks and colours are kept (``--cache``): one file per scene, seed, cameras,
    hands and the ``--set`` changes other than the recognition's decision parameters."""
    if cache is None:
        return None
    kept = sorted(f"{k}={v}" for k, v in (changes or {}).items() if not k.startswith("decision."))
    tag = hashlib.sha1(";".join(kept).encode()).hexdigest()[:8] if kept else "defaults"
    return cache / f"{name}_{seed}_{cameras}cam_{hands}_{tag}.pkl"


def run_cached(path: Path | None, run, activity_params,
               frames: int) -> tuple[pd.DataFrame, pd.DataFrame, float]:
    """The activities of one run: ``run()`` (which returns the ActivityTracker it ran, its tracks
    and the scene's true events), its state kept at ``path``; or, where ``path`` holds one, the
    recognition alone (with ``activity_params``) on the kept state. Returns the true events, the
    activities found and seconds per frame."""
    from partlab.tracking.activities.recognise import ActivityTracker

    if path is not None and path.exists():
        with path.open("rb") as fh:
            kept = pickle.load(fh)
        inner = SimpleNamespace(table=lambda records: kept["tracks"], events=kept["joins"], params=None)
        tracker = ActivityTracker(inner, activity_params)
        for k in STATE:
            getattr(tracker, k).update(kept[k])
        t0 = time.perf_counter()
        tracker.table([])
        return kept["truth"], tracker.events, (time.perf_counter() - t0) / frames
    t0 = time.perf_counter()
    tracker, tracks, truth = run()
    spf = (time.perf_counter() - t0) / frames
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        kept = {k: {key: (dict(v) if isinstance(v, dict) else v) for key, v in getattr(tracker, k).items()}
                for k in STATE}
        kept.update(tracks=tracks, joins=getattr(tracker.inner, "events", None), truth=truth)
        with path.open("wb") as fh:
            pickle.dump(kept, fh)
    return truth, tracker.events, spf


def run_take(name: str, seed: int, frames: int, cameras: int, hands: str,
             changes: dict | None = None, cache: Path | None = None) -> tuple[pd.DataFrame, pd.DataFrame, float]:
    """One 3-camera take (640x480, in memory): activities from limbs3d's heads and hands (its
    parameters with ``changes``, ``{"group.field": value}``; ``decision.*`` ones are the
    recognition's), or the truth's."""
    from partlab.labelling.synth.multiview import make_multiview_scene
    from partlab.tracking.activities import with_activities
    from partlab.tracking.frame import Frame

    changes = dict(changes or {})
    params = model_params(None, "activities")
    decision = {k: v for k, v in changes.items() if k.startswith("decision.")}
    if decision:
        params = params.updated({k: _value(params.get(k), v) for k, v in decision.items()})
    changes = {k: v for k, v in changes.items() if k not in decision}
    path = cache_path(cache, name, seed, cameras, hands, changes)
    if path is not None and path.exists():
        return run_cached(path, None, params, frames)
    scene = make_multiview_scene(name, cameras, seed, frames, 640, 480)
    cams = {c.name: c for c in scene.cameras}
    if hands == "truth":
        tracker = with_activities(TruthHands(scene.truth), params, scene.backgrounds)
    else:
        from partlab.tracking.limbs3d.tracker import Limbs3DTracker

        limbs3d = model_params(None, "limbs3d")
        if changes:
            limbs3d = limbs3d.updated({k: _value(limbs3d.get(k), v) for k, v in changes.items()})
        inner = Limbs3DTracker(limbs3d, np.random.default_rng(seed), cams, init=scene.init,
                               backgrounds=scene.backgrounds)
        tracker = with_activities(inner, params, scene.backgrounds)
    sets = (FrameSet(i, {c: Frame(i, scene.frames[c][i], None, c, cams[c]) for c in cams}) for i in range(frames))
    return run_cached(path, lambda: (tracker, run_frames(tracker, sets, None), scene.events), params, frames)


def _value(default, text: str):
    if isinstance(default, bool):
        return text.lower() in ("1", "true", "yes")
    return type(default)(float(text))


def one_camera_model(changes: dict | None) -> SimpleNamespace | None:
    """The limb tracker's and the recognition's parameters with ``changes`` (``{"group.field":
    value}``, each read as a limb parameter where ``limbs`` has that group, else as an
    activities one), as a model :func:`build_tracker` reads; None without changes."""
    if not changes:
        return None
    params = {k: model_params(None, k) for k in ("limbs", "activities")}
    for dotted, text in changes.items():
        key = "limbs" if hasattr(params["limbs"], dotted.partition(".")[0]) else "activities"
        params[key] = params[key].updated({dotted: _value(params[key].get(dotted), text)})
    return SimpleNamespace(params=params)


def run_one(name: str, seed: int, frames: int, width: int, height: int,
            hands: str = "tracked", changes: dict | None = None,
            dump: Path | None = None, cache: Path | None = None) -> tuple[pd.DataFrame, pd.DataFrame, float]:
    model = one_camera_model(changes)
    path = cache_path(cache, name, seed, 1, hands, changes)
    if path is not None and path.exists() and dump is None:
        return run_cached(path, None, model_params(model, "activities"), frames)
    scene = make_scene(name, seed=seed, n_frames=frames, width=width, height=height)
    if hands == "truth":
        from partlab.tracking.activities import with_activities

        tracker = with_activities(TruthHands(scene.truth), model_params(model, "activities"))
    else:
        tracker = build_tracker("limbs", model=model, seed=seed,
                                context=TrackContext(init=scene.init, fps=scene.fps))
    body = model_params(None, "body")
    t0 = time.perf_counter()
    out = run_frames(tracker, (FrameSet.single(i, f) for i, f in enumerate(scene.frames)),
                     lambda s: BackgroundModel(body))
    spf = (time.perf_counter() - t0) / frames
    if path is not None and not path.exists():
        run_cached(path, lambda: (tracker, out, scene.events), None, frames)
    if dump is not None:  # tracks, truth and events of the scene, to trace an event by hand
        dump.mkdir(parents=True, exist_ok=True)
        out.to_csv(dump / f"{name}_{seed}_{hands}_tracks.csv", index=False)
        scene.truth.to_csv(dump / f"{name}_{seed}_truth.csv", index=False)
        tracker.events.to_csv(dump / f"{name}_{seed}_{hands}_events.csv", index=False)
    return scene.events, tracker.events, spf


def handshakes_called_exchanges(truth: pd.DataFrame, pred: pd.DataFrame) -> int:
    """Predicted exchanges that overlap a true handshake and no true exchange."""
    from partlab.labelling.events import temporal_iou

    def spans(df, kind):
        return [(int(r.start_frame), int(r.end_frame)) for r in df[df["kind"] == kind].itertuples()]

    shakes, exchanges = spans(truth, "handshake"), spans(truth, "exchange")
    return sum(1 for p in spans(pred, "exchange") if any(temporal_iou(p, t) > 0 for t in shakes)
               and not any(temporal_iou(p, t) > 0 for t in exchanges))


def per_seed(truths: list[pd.DataFrame], preds: list[pd.DataFrame], kind: str) -> list[dict]:
    """Per seed (the clips ``name/seed`` of one seed summed): precision and recall of ``kind`` (NaN
    where the seed has no such truth or prediction)."""
    counts: dict[str, np.ndarray] = {}
    for t, p in zip(truths, preds):
        seed = str(t["clip"].iloc[0]).split("/")[1] if len(t) else str(p["clip"].iloc[0]).split("/")[1]
        table = evaluate_events(t, p)
        row = table.loc[kind, ["truth", "predicted", "matched"]].to_numpy(float) if kind in table.index else np.zeros(3)
        counts[seed] = counts.get(seed, np.zeros(3)) + row
    return [dict(precision=m / n_p if n_p else float("nan"), recall=m / n_t if n_t else float("nan"))
            for n_t, n_p, m in counts.values()]


def _spread(values: list[float]) -> str:
    return f"{np.mean(values):.2f} +- {np.std(values):.2f} (min {np.min(values):.2f}, n {len(values)})" if values \
        else "-"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0-9")
    ap.add_argument("--size", default="720x480")
    ap.add_argument("--frames", type=int, default=150)
    ap.add_argument("--cameras", type=int, default=1,
                    help="1: the one-camera activity scenes; 2 or more: the multi-camera takes with limbs3d")
    ap.add_argument("--hands", choices=("tracked", "truth", "both"), default="tracked",
                    help="the hands the recognition reads: the limb tracker's, the scene's truth, or both runs")
    ap.add_argument("--set", nargs="*", default=[], metavar="GROUP.NAME=VALUE",
                    help="parameters other than the defaults: limbs3d's (multi-camera takes; e.g. "
                         "dynamics.line_of_sight=0), or on one camera the limb tracker's or the "
                         "recognition's (e.g. skin.keep_min_side=12)")
    ap.add_argument("--dump", type=Path, default=None,
                    help="one camera: write each scene's tracks, truth and events here as CSV")
    ap.add_argument("--cache", type=Path, default=None,
                    help="keep each run's hands and colours here, and re-run only the recognition "
                         "where they are kept (decision.* changes; other --set changes are in the key)")
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    for hands in (("tracked", "truth") if args.hands == "both" else (args.hands,)):
        print(f"\n=== hands: {hands} ===", flush=True)
        report(args, w, h, hands)
    return 0


def report(args, w: int, h: int, hands: str) -> None:
    truths, preds, recalls, swaps, spf = [], [], {}, 0, []
    for seed in _seeds(args.seeds):  # seed by seed, so that a run cut short covers every scene
        for name in SCENES if args.cameras == 1 else SCENES_3D:
            if args.cameras == 1:
                truth, pred, s = run_one(name, seed, args.frames, w, h, hands,
                                         dict(a.split("=", 1) for a in args.set), args.dump, args.cache)
            else:
                truth, pred, s = run_take(name, seed, args.frames, args.cameras, hands,
                                          dict(a.split("=", 1) for a in args.set), args.cache)
            spf.append(s)
            truth = truth.assign(clip=f"{name}/{seed}")
            pred = pred.assign(clip=f"{name}/{seed}")
            table = evaluate_events(truth, pred)
            recalls.setdefault(name, []).append(float(table.loc["all", "recall"]))
            swaps += handshakes_called_exchanges(truth, pred)
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
    print("\nper kind, mean +- sd over seeds (a seed's precision/recall over its scenes; n = seeds with that kind):")
    for kind in total.index.drop("all", errors="ignore"):
        pr = {m: [v[m] for v in per_seed(truths, preds, kind) if v[m] == v[m]] for m in ("precision", "recall")}
        print(f"  {kind:10s} precision {_spread(pr['precision'])}  recall {_spread(pr['recall'])}")
    print("\nper-scene recall over seeds: " + "; ".join(
        f"{k} {np.mean(v):.2f} +- {np.std(v):.2f} (min {np.min(v):.2f})" for k, v in recalls.items()))
    print(f"handshakes called an exchange: {swaps}")
    print(f"tracking + recognition: {1000 * np.mean(spf):.1f} ms per frame (median {1000 * np.median(spf):.1f})")


if __name__ == "__main__":
    sys.exit(main())
