"""The top-view tracker's accuracy and speed as in Migniot & Ababsa sec. 3-4, on synthetic takes.

For S1-like (dark clothes) and S2-like (bright clothes) takes of one person, over ``--seeds``
seeds, for every particle count of ``--particles`` and both resamplings (``part``: Table 1's
five parts weighted and resampled on their own and shuffled, eq. 3-4; ``global``: whole
particles, the paper's "3D model"), and at the default count also without the colour term
(eq. 1 only), prints:

* ``eps``: the paper's epsilon, the mean 3D distance (mm) of the true arm pixels (the renderer's
  part labels) to the estimated model, averaged over frames;
* ``cpu ms`` / ``wall ms``: tracker time per frame (process CPU time, and elapsed);
* ``arm<80``: share of (frame, elbow-or-hand) pairs within 80 mm of the truth, and ``frames<80``:
  share of frames where all four arm joints are;
* ``survival``: per part, distinct particles kept by resampling / N (the paper does not define
  its survival rate; this is ours), mean over frames.

For S3-like takes (two people whose arms cross) it prints the share of ROI pixels of people that
eq. 5 gives to the right person, and the same joint shares. Each figure is the mean over seeds
and its standard deviation. ``--plot PNG`` draws epsilon against time per frame (Fig. 5).

    nice python benchmarks/topview_accuracy.py --seeds 10 --frames 50 --plot docs/trackers/topview_eps_time.png

Numbers depend on the machine and its load: CPU times are less sensitive than elapsed times.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from partlab.labelling.synth.topview import make_topview  # noqa: E402
from partlab.tracking.frame import FrameSet  # noqa: E402
from partlab.tracking.topview.likelihood import nearest  # noqa: E402
from partlab.tracking.topview.model import JOINTS, WEIGHT_PARTS, joints, primitives  # noqa: E402
from partlab.tracking.topview.params import (  # noqa: E402
    ExclusionParams,
    LikelihoodParams,
    ResamplingParams,
    TopViewParams,
)
from partlab.tracking.topview.tracker import Geometry, TopViewTracker  # noqa: E402

_HANDS = ((5, 4), (8, 5))  # (hand primitive, weighting part + 1 of its arm), right then left


def hand_pixels(scene, f: int, k: int, geo: Geometry, min_height_mm: float) -> list[int]:
    """Per hand (right, left) of person ``k`` at frame ``f``: how many measured depth pixels of
    the ROI's height see its true hand (the arm's labelled pixels within 15 mm of the hand's plane)."""
    person = scene.people[k - 1]
    prims = primitives(person.states[f][None], person.body)[0]
    out = []
    for prim, label in _HANDS:
        px = np.flatnonzero(((scene.person[f] == k) & (scene.part[f] == label)).ravel()
                            & np.isfinite(scene.depth[f]).ravel())
        if not len(px):
            out.append(0)
            continue
        pts = geo.points(scene.depth[f], px)
        only = prims.copy()
        only[np.arange(len(prims)) != prim, 0:3] = 1e6  # the other primitives moved far away: the hand alone
        d, _ = nearest(pts, only)
        out.append(int(((d < 15.0) & (pts[:, 2] >= min_height_mm)).sum()))
    return out


def run(scene, params: TopViewParams, seed: int) -> dict:
    """Track ``scene`` from its frame-0 truth and measure it."""
    tr = TopViewTracker(params, np.random.default_rng(seed), init=scene.init, cameras={"cam0": scene.camera})
    geo = Geometry(scene.camera)
    eps, errs, surv, assign, seen = [], [], [], [], []
    cpu = wall = 0.0
    for f in range(len(scene.depth)):
        fs = FrameSet.single(f, scene.color[f], scene.depth[f], camera=scene.camera)
        c0, w0 = time.process_time(), time.perf_counter()
        tr.step(fs)
        if f > 0:  # frame 0 fits the model to the init joints (least squares): not tracking time
            cpu += time.process_time() - c0
            wall += time.perf_counter() - w0
        truth_roi = tr.roi(fs.first).mask & (scene.person[f] > 0)
        right = tr.assignment[truth_roi] == scene.person[f][truth_roi]
        assign.append(np.mean(right) if truth_roi.any() else np.nan)
        for t in tr.targets:
            k = t.track_id
            person = scene.people[k - 1]
            arm_px = np.flatnonzero(((scene.person[f] == k) & (scene.part[f] >= 4)).ravel()
                                    & np.isfinite(scene.depth[f]).ravel())
            if len(arm_px):
                model = primitives(t.filter.estimate[None], t.filter.body)[0]
                d, _ = nearest(geo.points(scene.depth[f], arm_px), model)
                eps.append(float(d.mean()))
            e = np.linalg.norm(joints(t.filter.estimate[None], t.filter.body)[0]
                               - joints(person.states[f][None], person.body)[0], axis=1)
            errs.append(e)
            surv.append(t.filter.survival.copy())
            seen.append(hand_pixels(scene, f, k, geo, params.roi.min_height_mm))
    e = np.array(errs)
    arm = e[:, 3:]  # elbows and hands (JOINTS order)
    # a missed frame (an arm joint 80 mm off or more) "with a hidden hand": a hand 80 mm off or
    # more whose true hand no depth pixel sees
    missed = arm.max(1) >= 80
    hidden = ((e[:, 5:7] >= 80) & (np.array(seen) == 0)).any(1)
    frames = max(len(scene.depth) - 1, 1)
    n = frames * len(scene.people)
    return {"eps": float(np.mean(eps)), "cpu_ms": 1000 * cpu / frames, "wall_ms": 1000 * wall / frames,
            "cpu_ms_per_person": 1000 * cpu / n, "arm80": float((arm < 80).mean()),
            "frames80": float((arm.max(1) < 80).mean()), "head_mm": float(e[:, 0].mean()),
            "arm_mm": float(arm.mean()), "survival": np.mean(surv, 0).tolist(), "assign": float(np.nanmean(assign)),
            "joint_mm": e.mean(0).tolist(), "joint80": (e < 80).mean(0).tolist(),
            "missed": int(missed.sum()), "missed_hidden": int((missed & hidden).sum()), "rows": len(e),
            "hand_hidden": float((np.array(seen) == 0).mean())}


def summary(rows: list[dict], key: str) -> str:
    v = np.array([r[key] for r in rows])
    if key == "assign":
        return f"{v.mean():.4f} +- {v.std():.4f}"
    if key in ("arm80", "frames80"):
        return f"{v.mean():.3f} +- {v.std():.3f}"
    return f"{v.mean():.1f} +- {v.std():.1f}"


def plot(results: dict, path: Path) -> None:
    """Epsilon against CPU ms per frame, one line per scenario and resampling (cv2, no matplotlib)."""
    import cv2

    W, H, m = 640, 420, 60
    img = np.full((H, W, 3), 255, np.uint8)
    pts = [(r["cpu_ms"], r["eps"]) for key, rows in results.items()
           if key.endswith("colour") and key[:2] in ("S1", "S2") for r in rows]
    xs, ys = zip(*pts)
    x1, y1 = max(xs) * 1.1, max(ys) * 1.15
    sx = lambda x: int(m + (W - 2 * m) * x / x1)  # noqa: E731
    sy = lambda y: int(H - m - (H - 2 * m) * y / y1)  # noqa: E731
    cv2.line(img, (m, H - m), (W - m, H - m), (0, 0, 0), 1)
    cv2.line(img, (m, H - m), (m, m), (0, 0, 0), 1)
    for k in range(6):
        x, y = x1 * k / 5, y1 * k / 5
        cv2.putText(img, f"{x:.0f}", (sx(x) - 10, H - m + 18), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 1)
        cv2.putText(img, f"{y:.0f}", (m - 30, sy(y) + 4), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 1)
    cv2.putText(img, "CPU ms per frame", (W // 2 - 60, H - 20), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 0, 0), 1)
    cv2.putText(img, "eps (mm)", (8, m - 20), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 0, 0), 1)
    colours = {"S1 part": (200, 60, 0), "S1 global": (200, 160, 120), "S2 part": (0, 0, 200),
               "S2 global": (120, 140, 230)}
    legend = 0
    for name, col in colours.items():
        scen, mode = name.split()
        key = f"{scen} {mode} colour"
        if key not in results:
            continue
        by_n: dict[int, list] = {}
        for r in results[key]:
            by_n.setdefault(r["n"], []).append(r)
        line = [(np.mean([r["cpu_ms"] for r in v]), np.mean([r["eps"] for r in v])) for _, v in sorted(by_n.items())]
        for (xa, ya), (xb, yb) in zip(line, line[1:]):
            cv2.line(img, (sx(xa), sy(ya)), (sx(xb), sy(yb)), col, 2, cv2.LINE_AA)
        for n, (x, y) in zip(sorted(by_n), line):
            cv2.circle(img, (sx(x), sy(y)), 4, col, -1, cv2.LINE_AA)
            cv2.putText(img, str(n), (sx(x) + 5, sy(y) - 5), cv2.FONT_HERSHEY_SIMPLEX, 0.35, col, 1)
        cv2.putText(img, name, (W - m - 110, m + 18 * legend), cv2.FONT_HERSHEY_SIMPLEX, 0.5, col, 1)
        legend += 1
    path.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(path), img)


BONES = ((0, 1), (0, 2), (1, 2), (1, 3), (3, 5), (2, 4), (4, 6))  # JOINTS indexes: head-shoulders, arms


def figure(path: Path, seed: int = 0, frames: int = 40) -> None:
    """One S3 frame: depth colour-mapped with both tracked skeletons, and eq. 5's assignment."""
    import cv2

    scene = make_topview("topview_s3", seed, frames)
    tr = TopViewTracker(TopViewParams(), np.random.default_rng(seed), init=scene.init, cameras={"cam0": scene.camera})
    for f in range(frames):
        tr.step(FrameSet.single(f, scene.color[f], scene.depth[f], camera=scene.camera))
    d = scene.depth[-1]
    v = np.nan_to_num((3000.0 - d) / 2200.0 * 255).clip(0, 255).astype(np.uint8)
    left = cv2.applyColorMap(v, cv2.COLORMAP_TURBO)
    left[~np.isfinite(d)] = 0
    for t in tr.targets:
        uv = scene.camera.project(joints(t.filter.estimate[None], t.filter.body)[0])
        truth = scene.camera.project(joints(scene.people[t.track_id - 1].states[-1][None],
                                            scene.people[t.track_id - 1].body)[0])
        for a, b in BONES:
            ta, tb = (tuple(np.rint(truth[i]).astype(int)) for i in (a, b))
            cv2.line(left, ta, tb, (255, 255, 255), 1, cv2.LINE_AA)
            ea, eb = (tuple(np.rint(uv[i]).astype(int)) for i in (a, b))
            cv2.line(left, ea, eb, (0, 0, 0), 2, cv2.LINE_AA)
        for p in uv:
            cv2.circle(left, tuple(np.rint(p).astype(int)), 3, (255, 255, 255), -1, cv2.LINE_AA)
    right = np.zeros_like(left)
    right[tr.assignment == 1] = (60, 180, 255)
    right[tr.assignment == 2] = (255, 160, 60)
    wrong = (tr.assignment > 0) & (tr.assignment != scene.person[-1])
    right[wrong] = (0, 0, 255)
    img = cv2.resize(np.hstack([left, right]), None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST)
    path.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(path), img)


def measure(args, counts: list[int], scenarios: list[str], results: dict[str, list[dict]]) -> None:
    """Run every take, resampling and cue of ``args`` into ``results`` (saved after every seed)."""
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    modes = args.modes.split(",")
    for scen in [s for s in scenarios if s in ("s1", "s2")]:
        for seed in seeds:
            scene = make_topview(f"topview_{scen}", seed, args.frames)
            for mode in modes:
                for n in counts:
                    p = TopViewParams(resampling=ResamplingParams(mode=mode, n_particles=n))
                    results.setdefault(f"{scen.upper()} {mode} colour", []).append(
                        {"n": n, "seed": seed, **run(scene, p, seed)})
                if args.depth_only:
                    p = TopViewParams(resampling=ResamplingParams(mode=mode, n_particles=args.default_particles),
                                      likelihood=replace(LikelihoodParams(), use_colour=False))
                    results.setdefault(f"{scen.upper()} {mode} depth-only", []).append(
                        {"n": args.default_particles, "seed": seed, **run(scene, p, seed)})
            print(f"{scen} seed {seed} done", file=sys.stderr, flush=True)
            if args.json:  # after every seed, so that a long run interrupted keeps what it measured
                args.json.write_text(json.dumps(results, indent=1))
    if "s3" in scenarios:
        for seed in seeds:
            scene = make_topview("topview_s3", seed, args.frames)
            for mode in modes:
                p = TopViewParams(resampling=ResamplingParams(mode=mode, n_particles=args.default_particles),
                                  exclusion=replace(ExclusionParams(), colour_mm=args.eq5_colour_mm))
                results.setdefault(f"S3 {mode} colour", []).append(
                    {"n": args.default_particles, "seed": seed, **run(scene, p, seed)})
            print(f"s3 seed {seed} done", file=sys.stderr, flush=True)
            if args.json:
                args.json.write_text(json.dumps(results, indent=1))


def print_tables(results: dict[str, list[dict]], args) -> None:
    """The accuracy and time table, survival per part and each joint's share within 80 mm."""
    print(f"{args.frames} frames at 320x240, started from the frame-0 truth; mean +- sd over seeds")
    print(f"{'take / resampling / cue':28s} {'N':>4s} {'seeds':>5s} {'eps mm':>14s} {'cpu ms':>14s} "
          f"{'wall ms':>14s} {'cpu ms/person':>14s} {'arm<80':>16s} {'frames<80':>16s} {'assign':>16s}")
    for key, rows in results.items():
        for n in sorted({r["n"] for r in rows}):
            sel = [r for r in rows if r["n"] == n]
            cells = [summary(sel, k) for k in ("eps", "cpu_ms", "wall_ms", "cpu_ms_per_person")]
            cells += [summary(sel, k) for k in ("arm80", "frames80")]
            cells.append(summary(sel, "assign") if key.startswith("S3") else "")
            widths = (14, 14, 14, 14, 16, 16, 16)
            print(f"{key:28s} {n:4d} {len(sel):5d} " + " ".join(f"{c:>{w}s}" for c, w in zip(cells, widths)))
    print("\nmissed frames (an arm joint >= 80 mm off) and those with a hand >= 80 mm off that no depth pixel "
          "sees (the true hand hidden); share of (frame, hand) pairs hidden")
    for key, rows in results.items():
        sel = [r for r in rows if r["n"] == args.default_particles and "missed" in r]
        if sel:
            m, h = sum(r["missed"] for r in sel), sum(r["missed_hidden"] for r in sel)
            rows_n = sum(r["rows"] for r in sel)
            print(f"{key:28s} missed {m:4d} of {rows_n:5d}, with the hand hidden {h:4d} ({h / max(m, 1):.2f}); "
                  f"hands hidden {np.mean([r['hand_hidden'] for r in sel]):.3f}; frames<80 if those counted right "
                  f"{1 - (m - h) / max(rows_n, 1):.3f}")
    print_per_seed(results, args)
    print("\nsurvival (distinct particles kept / N, mean over frames and seeds) at N =", args.default_particles)
    print(f"{'':28s} " + " ".join(f"{p:>10s}" for p in WEIGHT_PARTS))
    for key, rows in results.items():
        sel = [r for r in rows if r["n"] == args.default_particles]
        if sel:
            print(f"{key:28s} " + " ".join(f"{v:10.3f}" for v in np.mean([r["survival"] for r in sel], 0)))
    print("\nshare of frames each joint is within 80 mm (min over seeds in brackets) at N =", args.default_particles)
    print(f"{'':28s} " + " ".join(f"{j:>16s}" for j in JOINTS))
    for key, rows in results.items():
        sel = [r["joint80"] for r in rows if r["n"] == args.default_particles and "joint80" in r]
        if sel:
            m, lo = np.mean(sel, 0), np.min(sel, 0)
            print(f"{key:28s} " + " ".join(f"{a:9.3f} ({b:4.2f})" for a, b in zip(m, lo)))


def print_per_seed(results: dict[str, list[dict]], args) -> None:
    """Each seed's frames<80 (and S3's assignment rate) at the default count, and the worst seed."""
    print("\nper seed at N =", args.default_particles, "(seed: frames<80, S3 also assign)")
    for key, rows in results.items():
        sel = [r for r in rows if r["n"] == args.default_particles and "seed" in r]
        if not sel:
            continue
        s3 = key.startswith("S3")
        cells = [f"{r['seed']}: {r['frames80']:.3f}" + (f" {r['assign']:.4f}" if s3 else "") for r in sel]
        worst = min(sel, key=lambda r: r["frames80"])
        line = f"worst frames<80 {worst['frames80']:.3f} (seed {worst['seed']})"
        if s3:
            wa = min(sel, key=lambda r: r["assign"])
            line += f", worst assign {wa['assign']:.4f} (seed {wa['seed']})"
        print(f"{key:28s} {line}\n{'':28s} " + ", ".join(cells))


def print_equal_time(results: dict[str, list[dict]]) -> None:
    """Each part-based count against the global count whose CPU time is nearest."""
    for scen in ("S1", "S2"):
        pk, gk = f"{scen} part colour", f"{scen} global colour"
        if pk not in results or gk not in results:
            continue
        ns = sorted({r["n"] for r in results[pk]})
        by = {(k, n): [r for r in results[k] if r["n"] == n] for k in (pk, gk) for n in ns}
        t = {key: np.mean([r["cpu_ms"] for r in rows]) for key, rows in by.items()}
        lines = []
        for n in ns:
            m = min(ns, key=lambda m: abs(t[(gk, m)] - t[(pk, n)]))
            pe = [r["eps"] for r in by[(pk, n)]]
            ge = [r["eps"] for r in by[(gk, m)]]
            lower = sum(a < b for a, b in zip(pe, ge))
            lines.append(f"part N={n} {np.mean(pe):.1f} mm in {t[(pk, n)]:.0f} ms vs global N={m} "
                         f"{np.mean(ge):.1f} mm in {t[(gk, m)]:.0f} ms: part lower on {lower}/{len(pe)} seeds")
        print(f"\n{scen} at about equal CPU time:\n  " + "\n  ".join(lines))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=0, help="seeds first-seed .. first-seed + seeds - 1")
    ap.add_argument("--modes", default="part,global", help="resamplings to run (part, global)")
    ap.add_argument("--no-depth-only", dest="depth_only", action="store_false",
                    help="leave out the runs without the colour term")
    ap.add_argument("--frames", type=int, default=50)
    ap.add_argument("--particles", default="50,100,200")
    ap.add_argument("--default-particles", type=int, default=200)
    ap.add_argument("--scenarios", default="s1,s2,s3")
    ap.add_argument("--eq5-colour-mm", type=float, default=ExclusionParams().colour_mm,
                    help="S3: eq. 5's colour term (exclusion.colour_mm; 0 = distance only, the paper's eq. 5)")
    ap.add_argument("--json", type=Path, help="write every run's figures here")
    ap.add_argument("--plot", type=Path, help="draw epsilon against time per frame here (PNG)")
    ap.add_argument("--figure", type=Path, help="only draw an S3 frame (skeletons on depth, eq. 5 assignment) here")
    ap.add_argument("--from-json", type=Path, nargs="*", help="only print and plot the runs saved by --json")
    args = ap.parse_args(argv)
    if args.figure:
        figure(args.figure)
        return 0
    counts = [int(x) for x in args.particles.split(",")]
    results: dict[str, list[dict]] = {}
    for saved in args.from_json or ():  # several files: their runs of one key are put together
        for key, rows in json.loads(saved.read_text()).items():
            results.setdefault(key, []).extend(rows)
    if args.from_json:
        counts = sorted({r["n"] for rows in results.values() for r in rows})
    else:
        measure(args, counts, args.scenarios.split(","), results)
    print_tables(results, args)
    print_equal_time(results)
    if args.json and not args.from_json:
        args.json.write_text(json.dumps(results, indent=1))
    if args.plot:
        plot(results, args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
