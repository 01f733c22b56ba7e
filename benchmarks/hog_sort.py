"""The baseline a user would pick instead (issue 13): OpenCV's HOG people detector with SORT on top.

Detector: ``cv2.HOGDescriptor_getDefaultPeopleDetector`` (Dalal & Triggs; ships with OpenCV) on
frames upscaled 1.5x (PETS walkers are 50-100 px tall, the detector's window 128), windows shrunk
to the body (0.6 x 0.75 about their centre: the window has a margin around the person), kept at an
SVM score >= ``min_score`` after non-maximum suppression.

Tracker: SORT (Bewley et al. 2016, "Simple online and realtime tracking"): one constant-velocity
Kalman filter per track on the box centre and size, detections assigned to predictions by the
Hungarian method on IoU (at least ``iou_min``), a track reported once it has ``min_hits``
detections and dropped after ``max_age`` frames without one. Written here because no SORT package
is installed; numbers as in the paper's defaults.

ByteTrack (Zhang et al. 2022): the same Kalman tracks, associated first with the confident
detections (score >= ``high``), then the tracks left over with the weak ones (IoU >= 0.5), so a
person the detector sees faintly keeps their track; new tracks start from confident detections
only, and a lost track waits ``max_age`` frames for its person.

Run as a script it is the tuned baseline: HOG once over PETS09-S2L1 (cached in ``--dets``), then
SORT and ByteTrack over a grid of their settings, each scored like ``annotation_effort.py``
(tuned on the clip it is scored on: the most a user could get from them there).

    nice python benchmarks/hog_sort.py --dets pets_hog.npz   # cache file of your choosing
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # this checkout's partlab, not an installed one

from partlab.tracking.core.box import iou_xywh  # noqa: E402


def hog_detector() -> cv2.HOGDescriptor:
    hog = cv2.HOGDescriptor()
    hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())
    return hog


def detect_people(hog: cv2.HOGDescriptor, frame: np.ndarray, upscale: float = 1.5, shrink=(0.6, 0.75),
                  min_score: float = 0.3, nms: float = 0.4) -> np.ndarray:
    """``(N, 5)`` boxes ``x, y, w, h, score`` of the people HOG finds in ``frame``."""
    big = cv2.resize(frame, None, fx=upscale, fy=upscale, interpolation=cv2.INTER_LINEAR)
    rects, weights = hog.detectMultiScale(big, winStride=(8, 8), padding=(8, 8), scale=1.05)
    if len(rects) == 0:
        return np.zeros((0, 5))
    rects = np.asarray(rects, float) / upscale
    weights = np.asarray(weights, float).ravel()
    keep = cv2.dnn.NMSBoxes(rects.tolist(), weights.tolist(), min_score, nms)
    keep = np.asarray(keep, int).ravel()
    r, w = rects[keep], weights[keep]
    cx, cy = r[:, 0] + r[:, 2] / 2, r[:, 1] + r[:, 3] / 2
    bw, bh = r[:, 2] * shrink[0], r[:, 3] * shrink[1]
    return np.stack([cx - bw / 2, cy - bh / 2, bw, bh, w], axis=1)


class _Track:
    def __init__(self, box: np.ndarray, track_id: int):
        kf = cv2.KalmanFilter(8, 4)
        kf.transitionMatrix = np.eye(8, dtype=np.float32)
        kf.transitionMatrix[:4, 4:] = np.eye(4, dtype=np.float32)
        kf.measurementMatrix = np.eye(4, 8, dtype=np.float32)
        kf.processNoiseCov = np.diag([1, 1, 1, 1, 0.01, 0.01, 0.0001, 0.0001]).astype(np.float32)
        kf.measurementNoiseCov = np.diag([1, 1, 10, 10]).astype(np.float32)
        kf.errorCovPost = np.diag([10, 10, 10, 10, 1e4, 1e4, 1e4, 1e4]).astype(np.float32)
        kf.statePost = np.r_[self._z(box), np.zeros(4)].astype(np.float32).reshape(8, 1)
        self.kf, self.id, self.hits, self.misses = kf, track_id, 1, 0

    @staticmethod
    def _z(box):
        x, y, w, h = box[:4]
        return np.array([x + w / 2, y + h / 2, w, h], np.float32)

    def predict(self) -> np.ndarray:
        s = self.kf.predict().ravel()
        w, h = max(s[2], 1.0), max(s[3], 1.0)
        return np.array([s[0] - w / 2, s[1] - h / 2, w, h])

    def update(self, box) -> None:
        self.kf.correct(self._z(box).reshape(4, 1))
        self.hits += 1
        self.misses = 0

    def box(self) -> np.ndarray:
        s = self.kf.statePost.ravel()
        return np.array([s[0] - s[2] / 2, s[1] - s[3] / 2, s[2], s[3]])


def sort_tracks(detections: list[np.ndarray], iou_min: float = 0.3, min_hits: int = 3,
                max_age: int = 1) -> pd.DataFrame:
    """SORT over per-frame detections (``(N, >=4)`` arrays); a tracks table of ``person`` rows."""
    tracks: list[_Track] = []
    next_id = 1
    rows = []
    for frame, dets in enumerate(detections):
        preds = np.array([t.predict() for t in tracks]).reshape(-1, 4)
        matched_t, matched_d = _associate(tracks, preds, dets, iou_min, list(range(len(tracks))))
        tracks, next_id = _age_and_birth(tracks, matched_t, dets, matched_d, next_id, max_age)
        rows += _reported(tracks, frame, min_hits)
    return pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h"])


def _age_and_birth(tracks, matched_t, births, matched_b, next_id: int, max_age: int):
    """Unmatched tracks age (dropped past ``max_age``); unmatched ``births`` start tracks."""
    for t, tr in enumerate(tracks):
        if t not in matched_t:
            tr.misses += 1
    for d in range(len(births)):
        if d not in matched_b:
            tracks.append(_Track(births[d], next_id))
            next_id += 1
    return [t for t in tracks if t.misses <= max_age], next_id


def _reported(tracks, frame: int, min_hits: int) -> list[tuple]:
    """The rows of the tracks matched this frame and confirmed (or in the first frames)."""
    return [(frame, t.id, "person", *t.box()) for t in tracks
            if t.misses == 0 and (t.hits >= min_hits or frame < min_hits)]


def _associate(tracks, preds, dets, iou_min: float, pool) -> tuple[set, set]:
    """Hungarian on IoU between ``tracks[pool]`` and ``dets``; updates the matched tracks."""
    mt, md = set(), set()
    if not len(pool) or not len(dets):
        return mt, md
    iou = iou_xywh(dets[:, :4], preds[pool])
    r, c = linear_sum_assignment(-iou)
    for d, k in zip(r, c):
        if iou[d, k] >= iou_min:
            tracks[pool[k]].update(dets[d])
            mt.add(pool[k])
            md.add(d)
    return mt, md


def byte_tracks(detections: list[np.ndarray], high: float = 0.5, low: float = 0.0, iou_min: float = 0.2,
                min_hits: int = 2, max_age: int = 30) -> pd.DataFrame:
    """ByteTrack over per-frame detections (``(N, 5)``: box and score); ``person`` rows."""
    tracks: list[_Track] = []
    next_id = 1
    rows = []
    for frame, dets in enumerate(detections):
        dets = dets[dets[:, 4] >= low] if len(dets) else dets
        preds = np.array([t.predict() for t in tracks]).reshape(-1, 4)
        strong = dets[dets[:, 4] >= high] if len(dets) else dets
        weak = dets[dets[:, 4] < high] if len(dets) else dets
        m1, d1 = _associate(tracks, preds, strong, iou_min, list(range(len(tracks))))
        m2, _ = _associate(tracks, preds, weak, 0.5, [t for t in range(len(tracks)) if t not in m1])
        tracks, next_id = _age_and_birth(tracks, m1 | m2, strong, d1, next_id, max_age)
        rows += _reported(tracks, frame, min_hits)
    return pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h"])


def hog_sort(take) -> pd.DataFrame:
    """HOG + SORT over every frame of ``take`` (frame indexes of the take)."""
    hog = hog_detector()
    dets, first = [], None
    for fs in take.frames():
        first = fs.index if first is None else first
        dets.append(detect_people(hog, fs.first.color))
    out = sort_tracks(dets)
    out["frame"] += first or 0
    return out


def _cached_detections(path: Path | None, frames) -> list[np.ndarray]:
    """HOG (score >= 0, after NMS: thresholding after NMS is the same as before it) per frame."""
    if path is not None and path.exists():
        with np.load(path) as z:
            return [z[f"f{i}"] for i in range(len(z.files))]
    import time

    hog, dets, t0 = hog_detector(), [], time.process_time()
    for i, frame in enumerate(frames):
        dets.append(detect_people(hog, frame, min_score=0.0))
        if i % 100 == 0:
            print(f"  HOG frame {i}, {1000 * (time.process_time() - t0) / (i + 1):.0f} CPU ms/frame", flush=True)
    print(f"HOG: {1000 * (time.process_time() - t0) / max(len(dets), 1):.0f} CPU ms/frame", flush=True)
    if path is not None:
        np.savez_compressed(path, **{f"f{i}": d for i, d in enumerate(dets)})
    return dets


def main() -> None:
    import argparse
    import itertools

    from annotation_effort import PETS, load_frames, measure, read_truth

    ap = argparse.ArgumentParser(description="HOG + SORT / ByteTrack on PETS09-S2L1 over a grid of settings")
    ap.add_argument("--dets", type=Path, help="cache of the HOG detections (written if missing)")
    ap.add_argument("--frames", type=int, default=None, help="only the first N frames")
    a = ap.parse_args()
    truth = read_truth(PETS, a.frames)
    frames, _fps = load_frames(PETS, a.frames) if a.dets is None or not a.dets.exists() else ([], 25.0)
    dets = _cached_detections(a.dets, frames)
    rows = []
    for score, hits, age in itertools.product((0.0, 0.3, 0.6, 1.0, 1.5), (1, 3), (1, 5, 15, 30)):
        kept = [d[d[:, 4] >= score] for d in dets]
        rows.append(dict(tracker="SORT", min_score=score, high=None, min_hits=hits, max_age=age,
                         **measure(truth, sort_tracks(kept, min_hits=hits, max_age=age), 0)))
    for high, low, hits, age in itertools.product((0.3, 0.6, 1.0, 1.5), (0.0, 0.3), (1, 2, 3), (15, 30)):
        if low >= high:
            continue
        rows.append(dict(tracker="ByteTrack", min_score=low, high=high, min_hits=hits, max_age=age,
                         **measure(truth, byte_tracks(dets, high=high, low=low, min_hits=hits, max_age=age), 0)))
    df = pd.DataFrame(rows)
    pd.set_option("display.width", 200)
    cols = [c for c in df.columns if c in ("tracker", "min_score", "high", "min_hits", "max_age", "rate", "mota",
                                           "idf1", "edits/100", "tracks")]
    print(df[cols].sort_values("mota", ascending=False).head(15).to_string(index=False, float_format="%.3f"))
    for name, g in df.groupby("tracker"):
        best = g.sort_values("mota").iloc[-1]
        print(f"best {name} by MOTA: " + ", ".join(f"{c} {best[c]}" for c in cols if c != "tracker"))


if __name__ == "__main__":
    main()
