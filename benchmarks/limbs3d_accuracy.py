"""Multi-camera head-and-hands tracking accuracy (3D tracking of the hands and head of interacting
people from several cameras, sec. 8: mean 3D error in mm per part).

Per scenario and seed one scene is rendered from 4 cameras (``--scene-cams``) at 640x480 (in
memory, no codec) and tracked with the first 2, 3 and 4 of them (``--tracker limbs3d`` from the truth's first frame).
Prints, per scenario and camera count, the mean 3D error per part (mean over seeds, +- standard
deviation over seeds), the median, the fraction of frames within 100 mm, hand swaps after the
clap/handshake (a hand nearer the other hand's truth than its own for 10+ frames after frame 85;
``swaps_on``: only a hand within 135 mm of that other hand's truth; ``swaps_exchanged``: pairs of
hands each on the other's truth, see :func:`exchanges`),
a run with camera 0 hidden for 30 frames (frames 60-89, ``--hide-from`` cameras and more: targets
in the lost state at any frame of 60-100 hidden / with every camera, error over the hidden stretch
and after it) and CPU frames/s of the tracker alone; last, per scenario and camera count, the mean
of all parts (sd over seeds), the seeds with a part over 50 mm and the sums over seeds.

With ``--learn K`` the prior variances are first fitted (sec. 6.4, :mod:`partlab.models.limbs3d`)
on K held-apart seeds per scenario (seeds 1000, 1001, ...: never among the evaluated ones) and every
evaluated take is tracked again with them (``learnt_mean``: mean 3D error of all parts).

    nice python benchmarks/limbs3d_accuracy.py --seeds 10 --scenarios standing seated --cams 3
    nice python benchmarks/limbs3d_accuracy.py --seeds 10 --cams 2 3 --learn 1
"""

from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout's partlab, not an installed one

from partlab.labelling.synth.multiview import make_multiview_scene  # noqa: E402
from partlab.models.limbs3d import PairErrors, fit_sigmas, true_pair_errors  # noqa: E402
from partlab.tracking.frame import Frame, FrameSet  # noqa: E402
from partlab.tracking.limbs3d.params import Limbs3DParams  # noqa: E402
from partlab.tracking.limbs3d.tracker import Limbs3DTracker  # noqa: E402


def run(scene, n_cams: int, params: Limbs3DParams, hide: tuple[int, int] | None = None, seed: int = 0):
    cams = {c.name: c for c in scene.cameras[:n_cams]}
    tr = Limbs3DTracker(params, np.random.default_rng(seed), cams, init=scene.init, backgrounds=scene.backgrounds)
    recs = []
    t0 = time.process_time()
    n = len(next(iter(scene.frames.values())))
    for i in range(n):
        views = {}
        for c in cams:
            img = scene.frames[c][i]
            if hide and c == "cam0" and hide[0] <= i < hide[1]:
                img = np.zeros_like(img)
            views[c] = Frame(i, img, None, c, cams[c])
        recs += tr.step(FrameSet(i, views), {c: None for c in cams})
    fps = n / (time.process_time() - t0)
    df = tr.table(recs).drop_duplicates(["frame", "track_id", "part"])
    e = df.merge(scene.truth3d, on=["frame", "track_id", "part"], suffixes=("", "_t"))
    e["err"] = np.linalg.norm(e[["X", "Y", "Z"]].to_numpy(float) - e[["X_t", "Y_t", "Z_t"]].to_numpy(float), axis=1)
    return e, fps


def swaps(e: pd.DataFrame, after: int = 85, frames: int = 10) -> int:
    """Hands whose estimate is nearer another hand's truth than its own for ``frames``+ frames."""
    n = 0
    hands = e[e["part"].isin(["left_hand", "right_hand"]) & (e["frame"] >= after)]
    truth = {(r.frame, r.track_id, r.part): np.array([r.X_t, r.Y_t, r.Z_t]) for r in hands.itertuples()}
    for (tid, part), g in hands.groupby(["track_id", "part"]):
        bad = 0
        for r in g.itertuples():
            own = r.err
            others = [np.linalg.norm(np.array([r.X, r.Y, r.Z]) - v) for k, v in truth.items()
                      if k[0] == r.frame and (k[1], k[2]) != (tid, part)]
            bad += bool(others) and min(others) < own
        n += bad >= frames
    return n


def exchanges(e: pd.DataFrame, after: int = 85, frames: int = 10, near: float = 135.0) -> tuple[int, int]:
    """Hand swaps that are one: (a hand **on** another hand: its estimate within ``near`` mm of
    another hand's truth and nearer it than its own for ``frames``+ frames after ``after``; pairs of
    hands with **exchanged** labels: each on the other for ``frames``+ common frames).

    :func:`swaps` also counts a hand that is off by 250-650 mm, nowhere near any hand, but a little
    nearer another hand's truth than its own: a lost or drifting hand, which the mean error shows,
    not a swap of labels. ``near`` is the activities' ``decision.contact_mm`` (two hands within it
    touch)."""
    hands = e[e["part"].isin(["left_hand", "right_hand"]) & (e["frame"] >= after)]
    truth = hands.set_index(["frame", "track_id", "part"])[["X_t", "Y_t", "Z_t"]]
    keys = sorted(hands.groupby(["track_id", "part"]).groups)
    on: dict = {k: set() for k in keys}  # (frame, other hand) at which hand k is on the other hand
    for r in hands.itertuples():
        est = np.array([r.X, r.Y, r.Z])
        for o in keys:
            if o != (r.track_id, r.part) and (r.frame, *o) in truth.index:
                d = np.linalg.norm(est - truth.loc[(r.frame, *o)].to_numpy(float))
                if d < near and d < r.err:
                    on[(r.track_id, r.part)].add((r.frame, o))
    hand_on = sum(len(v) >= frames for v in on.values())
    pairs = 0
    for i, a in enumerate(keys):
        for b in keys[i + 1:]:
            fa = {f for f, o in on[a] if o == b}
            fb = {f for f, o in on[b] if o == a}
            pairs += len(fa & fb) >= frames
    return hand_on, pairs


def meetings(e: pd.DataFrame, events: pd.DataFrame, contact: float = 135.0) -> dict:
    """Per kind of the scene's events (clap, handshake, exchange): the fraction of the event's
    frames at which the two tracked hands are within ``contact`` mm of each other (the activities'
    ``decision.contact_mm``: what the recognition needs to see them touch)."""
    pos = e.set_index(["frame", "track_id", "part"])[["X", "Y", "Z"]]
    out: dict = {}
    for ev in events.itertuples():
        frames = range(int(ev.start_frame), int(ev.end_frame) + 1)
        a = pos.reindex([(f, ev.track_id_a, ev.part_a) for f in frames]).to_numpy(float)
        b = pos.reindex([(f, ev.track_id_b, ev.part_b) for f in frames]).to_numpy(float)
        met = np.linalg.norm(a - b, axis=1) < contact  # NaN (no estimate) counts as apart
        out.setdefault(f"meet_{ev.kind}", []).append(float(met.mean()))
    return {k: float(np.mean(v)) for k, v in out.items()}


def hidden(scene, n_cams: int, e: pd.DataFrame, seed: int, params: Limbs3DParams, start: int = 60,
           stop: int = 90) -> dict:
    """Camera 0 black for frames ``start``-``stop`` (30 frames): the error over that stretch and
    after it, and the targets lost at any frame from ``start`` to ``stop + 10`` with the camera
    hidden and in the same take with every camera (``e``: those lost anyway, a hand hidden by a
    body), also at frame ``stop + 10``."""
    eh, _ = run(scene, n_cams, params, hide=(start, stop), seed=seed)

    def lost(df, frames):
        sel = df[df["frame"].isin(frames) & (df["state"] == "lost")]
        return int(sel[["track_id", "part"]].drop_duplicates().shape[0])

    window = range(start, stop + 11)
    stretch = eh[(eh["frame"] >= start) & (eh["frame"] < stop)]
    return {"hidden_mean": stretch["err"].mean(), "hidden_after_mean": eh[eh["frame"] >= stop]["err"].mean(),
            "hidden_lost": lost(eh, window), "unhidden_lost": lost(e, window),
            "hidden_lost_at_100": lost(eh, [stop + 10]), "unhidden_lost_at_100": lost(e, [stop + 10])}


def learn(scenarios, k: int, n_cams: int, frames: int) -> Limbs3DParams:
    """Sigmas fitted on ``k`` held-apart seeds per scenario (``n_cams`` views)."""
    errors = []
    for name in scenarios:
        for seed in range(1000, 1000 + k):
            scene = make_multiview_scene(name, n_cams, seed=seed, n_frames=frames)
            cams = {c.name: c for c in scene.cameras}
            sets = (FrameSet(i, {c: Frame(i, scene.frames[c][i], None, c, cams[c]) for c in cams})
                    for i in range(frames))
            errors.append(true_pair_errors(sets, cams, scene.truth3d, backgrounds=scene.backgrounds))
    fitted, table = fit_sigmas(PairErrors.concat(errors))
    print(table.to_string(index=False), flush=True)
    return fitted


def _value(default, text: str):
    if isinstance(default, bool):
        return text.lower() in ("1", "true", "yes")
    return type(default)(float(text))


def _scene(args, name: str, seed: int):
    """The scene of one scenario and seed, rendered or (``--cache``) read back."""
    n = max(args.scene_cams, *args.cams)
    path = Path(args.cache) / f"{name}_{seed}_{n}cams_{args.frames}.pkl" if args.cache else None
    if path is not None and path.exists():
        with path.open("rb") as f:
            return pickle.load(f)
    scene = make_multiview_scene(name, n, seed=seed, n_frames=args.frames)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.with_suffix(".tmp").open("wb") as f:
            pickle.dump(scene, f)
        path.with_suffix(".tmp").rename(path)
    return scene


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first", type=int, default=0, help="the first seed (seeds first .. first + seeds - 1)")
    ap.add_argument("--scenarios", nargs="+", default=["standing", "seated", "handshake"])
    ap.add_argument("--cams", type=int, nargs="+", default=[2, 3, 4])
    ap.add_argument("--frames", type=int, default=150)
    ap.add_argument("--scene-cams", type=int, default=4,
                    help="cameras rendered (the camera arc depends on it); each run uses the first --cams of them")
    ap.add_argument("--hide-from", type=int, default=2, help="the hidden-camera run for this many cameras and more")
    ap.add_argument("--learn", type=int, default=0, help="fit the sigmas on this many held-apart seeds per scenario")
    ap.add_argument("--set", nargs="*", default=[], metavar="GROUP.NAME=VALUE",
                    help="tracker parameters other than the defaults (e.g. dynamics.single_view_support=8)")
    ap.add_argument("--cache", default="", help="keep the rendered scenes here (pickles, ~0.56 GB each) and reuse them")
    args = ap.parse_args()
    params = Limbs3DParams()
    if args.set:
        params = params.updated({k: _value(params.get(k), v) for k, v in (a.split("=", 1) for a in args.set)})
    learnt = learn(args.scenarios, args.learn, 3, args.frames) if args.learn else None
    rows = []
    for name in args.scenarios:
        for seed in range(args.first, args.first + args.seeds):
            scene = _scene(args, name, seed)
            for n_cams in args.cams:
                e, fps = run(scene, n_cams, params, seed=seed)
                row = {"scenario": name, "seed": seed, "cams": n_cams, "fps": fps, "swaps": swaps(e)}
                row["swaps_on"], row["swaps_exchanged"] = exchanges(e)
                row.update(meetings(e, scene.events))
                for part, g in e.groupby("part"):
                    row[f"{part}_mean"] = g["err"].mean()
                    row[f"{part}_median"] = g["err"].median()
                    row[f"{part}_within100"] = (g["err"] < 100).mean()
                if learnt is not None:
                    row["learnt_mean"] = run(scene, n_cams, learnt, seed=seed)[0]["err"].mean()
                if n_cams >= args.hide_from:
                    row.update(hidden(scene, n_cams, e, seed, params))
                rows.append(row)
                print({k: (round(v, 2) if isinstance(v, float) else v) for k, v in row.items()}, flush=True)
    df = pd.DataFrame(rows)
    cols = [c for c in df.columns if c.endswith(("_mean", "_median", "_within100")) or c.startswith("meet_") or c in
            ("fps", "swaps", "swaps_on", "swaps_exchanged", "hidden_lost", "unhidden_lost", "hidden_lost_at_100",
             "unhidden_lost_at_100")]
    summary = df.groupby(["scenario", "cams"])[cols].agg(["mean", "std"])
    pd.set_option("display.width", 250)
    pd.set_option("display.max_columns", 60)
    print(summary.round(2).T.to_string())
    parts = [c for c in df.columns if c.endswith("hand_mean") or c == "head_mean"]
    for (name, n_cams), g in df.groupby(["scenario", "cams"]):
        over = [f"{r.seed} ({', '.join(f'{c[:-5]} {getattr(r, c):.0f}' for c in parts if getattr(r, c) > 50)})"
                for r in g.itertuples() if max(getattr(r, c) for c in parts) > 50]
        sums = {c: int(g[c].sum()) for c in ("swaps", "swaps_on", "swaps_exchanged", "hidden_lost", "unhidden_lost")
                if c in g}
        sums.update({c: round(float(g[c].mean()), 2) for c in g.columns
                     if c.startswith("meet_") and g[c].notna().any()})
        print(f"{name} {n_cams} cameras, {len(g)} seeds: all parts {g[parts].mean(axis=1).mean():.1f} "
              f"({g[parts].mean(axis=1).std():.1f}) mm; seeds with a part > 50 mm: {'; '.join(over) or 'none'}; "
              f"summed over seeds: {sums}")


if __name__ == "__main__":
    main()
