"""Export PETS09-S2L1 truth in every format, read it back with the peers' parsers and ours,
and check the evaluation on real data (motmetrics' TUD sequences with published numbers).

    PYTHONPATH=. python benchmarks/formats_real_data.py [--data ../shared/data] [--every 10]

Prints counts, round-trip errors and timings; writes into a temporary directory only.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout's partlab, not an installed one


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=str(Path(__file__).resolve().parents[1].parent / "shared" / "data"),
                    help="the shared data folder (default: ../shared/data beside the repository)")
    ap.add_argument("--every", type=int, default=10, help="frame thinning for the image formats")
    args = ap.parse_args()

    import motmetrics as mm
    from datumaro.components.dataset import Dataset
    from pycocotools.coco import COCO

    from partlab.labelling.evaluation import evaluate
    from partlab.labelling.formats import export_dataset, import_dataset
    from partlab.labelling.video import probe
    from partlab.tracking.tracks import normalise_tracks

    pets = Path(args.data) / "pets09_s2l1_vtest"
    gt = pd.read_csv(pets / "gt.csv")
    truth = normalise_tracks(gt.assign(part="person"))
    t0 = time.perf_counter()
    info = probe(pets / "vtest.avi")
    print(f"PETS09-S2L1: {len(truth)} boxes, {truth.track_id.nunique()} tracks; clip {info.frame_count} frames "
          f"{info.width}x{info.height} at {info.fps:g} fps (probe {time.perf_counter() - t0:.1f} s)")
    core = ["frame", "track_id", "part", "x", "y", "w", "h"]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for fmt in ("mot", "cvat", "coco", "yolo", "voc", "parquet"):
            every = args.every if fmt in ("coco", "yolo", "voc") else 1
            t0 = time.perf_counter()
            out = export_dataset(truth, fmt, tmp / fmt, info, video_path=pets / "vtest.avi", every=every,
                                 frames=fmt in ("coco", "yolo", "voc"))
            dt = time.perf_counter() - t0
            n_files = sum(1 for p in out.rglob("*") if p.is_file())
            size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file()) / 1e6
            line = f"  {fmt:8s} every={every:<3d} export {dt:5.2f} s, {n_files:4d} files, {size:6.1f} MB"
            kept = truth[truth.frame % every == 0]
            if fmt == "mot":
                g = mm.io.loadtxt(str(out / "gt" / "gt.txt"), fmt="mot15-2D")
                line += f"; motmetrics rows {len(g)} (truth {len(kept)})"
            elif fmt == "coco":
                c = COCO(str(out / "annotations" / "instances_default.json"))
                line += f"; pycocotools images {len(c.getImgIds())} anns {len(c.getAnnIds())} (truth {len(kept)})"
            if fmt in ("cvat", "voc", "yolo"):
                t1 = time.perf_counter()
                ds = Dataset.import_from(str(out), "voc") if fmt == "voc" else Dataset.import_from(str(out))  # detected
                anns = [a for it in ds for a in it.annotations if not a.attributes.get("outside", False)]
                line += (f"; datumaro items {len(ds)} boxes {len(anns)} (truth {len(kept)}, "
                         f"{time.perf_counter() - t1:.1f} s)")
            if fmt in ("mot", "cvat", "coco", "parquet"):
                back = import_dataset(out, fmt)
                err = np.abs(back[["x", "y", "w", "h"]].to_numpy() - kept[["x", "y", "w", "h"]].to_numpy()).max()
                same = back[core[:3]].equals(kept[core[:3]].reset_index(drop=True))
                line += f"; our import: ids/frames/parts equal {same}, max box error {err:.2g} px"
            print(line)

    rng = np.random.default_rng(0)
    noisy = truth.copy()
    noisy[["x", "y"]] += rng.normal(0, 3.0, (len(noisy), 2))
    noisy = noisy.drop(index=rng.choice(len(noisy), len(noisy) // 20, replace=False))
    t0 = time.perf_counter()
    r = evaluate(truth, noisy, at=105)
    print(f"PETS09 truth vs truth + N(0, 3 px) with 5 % boxes dropped ({time.perf_counter() - t0:.1f} s): "
          f"{r.note}")
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(r.summary.round(3))
        print(r.mot.round(3))
    ids = noisy.assign(track_id=noisy.track_id + 100)
    r2 = evaluate(truth, ids, at=105, hota=False)
    print(f"same with ids shifted by 100: matching={r2.matching}, person rate at 105 "
          f"{r2.rate_at('person'):.3f} (ids kept: {r.rate_at('person'):.3f})")

    data = Path(mm.__file__).parent / "data"
    for seq in ("TUD-Campus", "TUD-Stadtmitte"):
        m = evaluate(import_dataset(data / seq / "gt.txt", "mot"), import_dataset(data / seq / "test.txt", "mot")).mot
        print(f"{seq}: MOTA {m.loc['person', 'mota']:.6f} IDF1 {m.loc['person', 'idf1']:.6f} "
              f"MOTP {m.loc['person', 'motp']:.6f} HOTA {m.loc['person'].get('hota', float('nan')):.4f}")
    print("motmetrics' published (its test_metrics.py): TUD-Campus MOTA 0.526462 IDF1 0.557659 MOTP 0.277201; "
          "TUD-Stadtmitte MOTA 0.564014 IDF1 0.644619 MOTP 0.345904")


if __name__ == "__main__":
    main()
