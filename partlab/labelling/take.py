"""Takes: one or more synchronized streams, each a colour video (and optionally depth) with its
calibration. A single video is a take of one stream named ``cam0``.

A take folder (documented in docs/formats.md, "Takes")::

    TAKE_DIR/
      take.json           optional: {"fps": 25, "streams": [{"name": "cam0", "color": "cam0.mp4",
                                      "depth": "cam0_depth"}, ...]}
      calibration.json    optional: the cameras (partlab.labelling.calibration), named as the streams
      cam0.mp4 ...        colour video per stream
      cam0_depth/         optional depth per stream: 16-bit PNGs in mm (000000.png ...), or
      cam0_depth.npy|npz  a (T, H, W) stack in mm; 0 means unmeasured
      cam0_background.png optional: the empty scene seen by the stream (for fixed background subtraction)

A stream's depth may instead come from a calibrated stereo pair (:mod:`partlab.labelling.stereo`):
``{"name": "cam0", "color": "left.mp4", "stereo": {"left": "left.mp4", "right": "right.mp4",
"right_camera": "cam0_right"}}`` with both cameras in ``calibration.json`` (``right_camera``
defaults to ``<name>_right``); the depth is then computed per frame, aligned to the left image.

Without ``take.json`` the streams are the folder's videos in name order (a folder holding only
``clip.mp4``, as ``partlab synth`` writes, is a one-stream take), each with ``<stem>_depth``
beside it when present. Every stream must have the same frame count; the take's fps is the first
stream's.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import cv2
import numpy as np

from partlab.errors import UserError
from partlab.labelling.calibration import FILE_NAME as CALIBRATION_FILE
from partlab.labelling.calibration import read_calibration
from partlab.labelling.video import VIDEO_EXTENSIONS, VideoClip, is_image_sequence
from partlab.tracking.camera import Camera
from partlab.tracking.frame import DEFAULT_STREAM, Frame, FrameSet

TAKE_FILE = "take.json"


class TakeError(UserError):
    """A take that cannot be used; the message names the folder and the stream."""


class DepthSource:
    """Depth frames of one stream, in millimetres (``float32``, NaN where unmeasured).

    Refused: 8-bit images or stacks (a byte cannot hold millimetres: it is a picture of depth,
    not a measurement), anything not 2D per frame, and frames whose size differs from the first's.
    """

    def __init__(self, path: Path):
        self.path = path
        self._stack = None
        self._files: list[Path] = []
        self._shape: tuple[int, int] | None = None
        if path.is_dir():
            self._files = sorted(f for f in path.iterdir() if f.suffix.lower() == ".png")
            if not self._files:
                raise TakeError(f"{path}: no PNG depth frames")
        elif path.suffix.lower() == ".npy":
            self._stack = np.load(path, mmap_mode="r", allow_pickle=False)
        elif path.suffix.lower() == ".npz":
            with np.load(path, allow_pickle=False) as z:
                keys = list(z.keys())
                if not keys:
                    raise TakeError(f"{path}: empty npz")
                self._stack = z["depth"] if "depth" in keys else z[keys[0]]
        else:
            raise TakeError(f"{path}: depth must be a folder of 16-bit PNGs, a .npy or a .npz stack")
        if self._stack is not None and (self._stack.ndim != 3 or self._stack.dtype.kind not in "uif"):
            raise TakeError(f"{path}: depth stack must be (frames, height, width) numbers, "
                            f"got shape {self._stack.shape} {self._stack.dtype}")
        if self._stack is not None and self._stack.dtype.itemsize == 1:
            raise TakeError(f"{path}: depth stack is 8-bit ({self._stack.dtype}); depth must be millimetres "
                            f"(16-bit or float)")

    def __len__(self) -> int:
        return len(self._files) if self._stack is None else int(self._stack.shape[0])

    def read(self, index: int) -> np.ndarray:
        if self._stack is not None:
            raw = np.asarray(self._stack[index])
        else:
            f = self._files[index]
            raw = cv2.imread(str(f), cv2.IMREAD_UNCHANGED)
            if raw is None:
                raise TakeError(f"{f}: cannot read this depth image")
            if raw.dtype != np.uint16 or raw.ndim != 2:
                raise TakeError(f"{f}: depth PNGs must be 16-bit single-channel millimetres, "
                                f"got {raw.dtype} with shape {raw.shape}")
        if self._shape is None:
            self._shape = raw.shape
        elif raw.shape != self._shape:
            where = self._files[index] if self._stack is None else f"{self.path} frame {index}"
            raise TakeError(f"{where}: depth frame is {raw.shape[1]}x{raw.shape[0]}, the first was "
                            f"{self._shape[1]}x{self._shape[0]}")
        depth = raw.astype(np.float32)
        depth[~np.isfinite(depth) | (depth <= 0)] = np.nan  # 0 = unmeasured, not near
        return depth


class StereoDepth:
    """Depth of one stream computed from a rectified stereo pair (:class:`~partlab.labelling.stereo.StereoRig`)."""

    def __init__(self, path: Path, left: Path, right: Path, left_camera: Camera | None,
                 right_camera: Camera | None, right_name: str):
        from partlab.labelling.stereo import StereoRig

        self.path = path
        if left_camera is None or right_camera is None:
            missing = right_name if right_camera is None and left_camera is not None else "the left camera"
            raise TakeError(f"{path}: stereo depth needs both cameras calibrated; {missing} is not in "
                            f"{CALIBRATION_FILE}")
        self.left, self.right = VideoClip(left), VideoClip(right)
        if self.left.frame_count != self.right.frame_count:
            raise TakeError(f"{path}: stereo pair differs in frame count ({left.name} {self.left.frame_count}, "
                            f"{right.name} {self.right.frame_count})")
        for clip, cam in ((self.left, left_camera), (self.right, right_camera)):
            if (clip.width, clip.height) != tuple(cam.size):
                raise TakeError(f"{path}: {clip.path.name} is {clip.width}x{clip.height} but camera "
                                f"{cam.name!r} is calibrated for {cam.size[0]}x{cam.size[1]}")
        try:
            self.rig = StereoRig(left_camera, right_camera)
        except ValueError as exc:
            raise TakeError(f"{path}: {exc}") from None

    def __len__(self) -> int:
        return self.left.frame_count

    def read(self, index: int) -> np.ndarray:
        return self.rig.depth(self.left.read(index), self.right.read(index))

    def close(self) -> None:
        self.left.close()
        self.right.close()


@dataclass
class Stream:
    name: str
    color: VideoClip | None
    depth: DepthSource | StereoDepth | None = None
    camera: Camera | None = None

    @property
    def frame_count(self) -> int:
        return self.color.frame_count if self.color is not None else len(self.depth)


@dataclass
class Take:
    """Synchronized streams; :meth:`frames` yields a :class:`FrameSet` per index, decoding once."""

    path: Path
    streams_: list[Stream]
    fps: float = 25.0
    meta: dict = field(default_factory=dict)

    @property
    def streams(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.streams_)

    @property
    def cameras(self) -> Mapping[str, Camera | None]:
        return {s.name: s.camera for s in self.streams_}

    @property
    def frame_count(self) -> int:
        return self.streams_[0].frame_count

    @property
    def backgrounds(self) -> dict[str, np.ndarray]:
        """Per stream, the empty-scene image ``<stream>_background.png`` beside the take's videos."""
        out = {}
        if self.path.is_dir():
            for s in self.streams_:
                f = self.path / f"{s.name}_background.png"
                if f.is_file():
                    img = cv2.imread(str(f), cv2.IMREAD_COLOR)
                    if img is None:
                        raise TakeError(f"{f}: cannot read this background image")
                    out[s.name] = img
        return out

    @property
    def has_depth(self) -> bool:
        return any(s.depth is not None for s in self.streams_)

    def stream(self, name: str) -> Stream:
        for s in self.streams_:
            if s.name == name:
                return s
        raise TakeError(f"{self.path}: no stream {name!r}; streams are {', '.join(self.streams)}")

    def frames(self, start: int = 0, stop: int | None = None) -> Iterator[FrameSet]:
        stop = self.frame_count if stop is None else min(stop, self.frame_count)
        iters = [s.color.frames(start, stop) if s.color is not None else None for s in self.streams_]
        for index in range(start, stop):
            views = {}
            for s, it in zip(self.streams_, iters):
                color = None
                if it is not None:
                    got = next(it, None)
                    if got is None:  # the decoder stopped early: the take ends here
                        return
                    color = got[1]
                depth = s.depth.read(index) if s.depth is not None else None
                views[s.name] = Frame(index, color, depth, s.name, s.camera)
            yield FrameSet(index, views)

    def close(self) -> None:
        for s in self.streams_:
            if s.color is not None:
                s.color.close()
            if isinstance(s.depth, StereoDepth):
                s.depth.close()

    def __enter__(self) -> Take:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _depth_beside(video: Path) -> Path | None:
    for cand in (video.with_name(video.stem + "_depth"), video.with_name(video.stem + "_depth.npy"),
                 video.with_name(video.stem + "_depth.npz")):
        if cand.exists():
            return cand
    return None


def _stream_list(folder: Path) -> list[dict]:
    spec = folder / TAKE_FILE
    if spec.is_file():
        try:
            data = json.loads(spec.read_text(encoding="utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
            raise TakeError(f"{spec}: not valid JSON ({exc})") from None
        streams = data.get("streams") if isinstance(data, dict) else None
        if not isinstance(streams, list) or not streams:
            raise TakeError(f"{spec}: expected an object with a non-empty list 'streams'")
        out = []
        for i, s in enumerate(streams):
            if not isinstance(s, dict) or not isinstance(s.get("name", ""), str):
                raise TakeError(f"{spec}: streams[{i}] must be an object with a 'name'")
            stereo = s.get("stereo")
            if stereo is not None and (not isinstance(stereo, dict) or not stereo.get("left")
                                       or not stereo.get("right")):
                raise TakeError(f"{spec}: streams[{i}].stereo must be an object with 'left' and 'right' videos")
            if stereo is not None and s.get("depth"):
                raise TakeError(f"{spec}: streams[{i}] has both 'depth' and 'stereo'; give one")
            if not s.get("color") and not s.get("depth") and stereo is None:
                raise TakeError(f"{spec}: streams[{i}] has neither 'color' nor 'depth'")
            name = s.get("name") or f"cam{i}"
            out.append({"name": name, "color": s.get("color") or (stereo or {}).get("left"),
                        "depth": s.get("depth"), "stereo": stereo})
        return out
    videos = sorted(f for f in folder.iterdir() if f.suffix.lower() in VIDEO_EXTENSIONS and f.is_file())
    if not videos:
        raise TakeError(f"{folder}: no video in this folder and no {TAKE_FILE}")
    if len(videos) == 1:
        d = _depth_beside(videos[0])
        return [{"name": DEFAULT_STREAM, "color": videos[0].name, "depth": d.name if d else None}]
    return [{"name": v.stem, "color": v.name, "depth": (d.name if (d := _depth_beside(v)) else None)}
            for v in videos]


def open_take(path: str | PathLike) -> Take:
    """A take from a video file or a take folder; raises :class:`TakeError` naming what is wrong."""
    p = Path(path)
    if not p.exists() and not is_image_sequence(p):
        raise TakeError(f"{p}: no such file or folder")
    if p.is_file() or is_image_sequence(p):  # a video, or one stream of frames (folder, zip, %06d pattern)
        clip = VideoClip(p)
        return Take(p, [Stream(DEFAULT_STREAM, clip)], fps=clip.fps)
    specs = _stream_list(p)
    cameras: dict[str, Camera] = {}
    if (p / CALIBRATION_FILE).is_file():
        cameras = read_calibration(p / CALIBRATION_FILE)
        if len(specs) == 1 and len(cameras) == 1 and specs[0]["name"] not in cameras:
            cameras = {specs[0]["name"]: next(iter(cameras.values()))}
    streams = []
    for s in specs:
        color = VideoClip(p / s["color"]) if s["color"] else None
        depth = DepthSource(p / s["depth"]) if s["depth"] else None
        if s.get("stereo"):
            st = s["stereo"]
            right_name = str(st.get("right_camera") or f"{s['name']}_right")
            for key in ("left", "right"):
                if not (p / st[key]).is_file():
                    raise TakeError(f"{p / TAKE_FILE}: stream {s['name']!r} stereo {key} video {st[key]} not found")
            depth = StereoDepth(p, p / st["left"], p / st["right"], cameras.get(s["name"]),
                                cameras.get(right_name), right_name)
        streams.append(Stream(s["name"], color, depth, cameras.get(s["name"])))
    take = Take(p, streams, fps=next((s.color.fps for s in streams if s.color is not None), 25.0))
    _check_consistent(take)
    return take


def _check_consistent(take: Take) -> None:
    counts = {s.name: s.frame_count for s in take.streams_}
    if len(set(counts.values())) > 1:
        raise TakeError(f"{take.path}: streams differ in frame count "
                        f"({', '.join(f'{k} {v}' for k, v in counts.items())})")
    fps = {s.name: round(s.color.fps, 3) for s in take.streams_ if s.color is not None}
    if len(set(fps.values())) > 1:
        raise TakeError(f"{take.path}: streams differ in fps ({', '.join(f'{k} {v:g}' for k, v in fps.items())})")
    for s in take.streams_:
        if s.depth is not None and len(s.depth) != s.frame_count:
            raise TakeError(f"{take.path}: stream {s.name!r} has {s.frame_count} colour frames but "
                            f"{len(s.depth)} depth frames")
        if s.depth is not None and s.color is not None:
            d = s.depth.read(0)
            if d.shape != (s.color.height, s.color.width):
                raise TakeError(f"{take.path}: stream {s.name!r} depth is {d.shape[1]}x{d.shape[0]} but its "
                                f"colour is {s.color.width}x{s.color.height}")
