"""Compose a scenario into frames with exact per-part ground truth.

Per frame, people are drawn far to near (by depth), each into an ``owner`` image
that records who is visible at every pixel; fixed occluders (the pillar) are drawn
last. A part's pixels are those the figure shows of it, as the person would look
alone (where the person's own parts overlap, e.g. the near arm over the torso or the
torso over the top of the trousers, the pixels go to the part in front); a part the
person's own body hides completely (a far hand behind the hips) falls back to its
whole drawn shape. A truth row's box is the tight extent of those pixels inside the
frame (``x, y`` the first column/row, ``w, h`` the number of columns/rows spanned),
and ``occluded`` is the fraction of them where another person or an occluder is
visible instead; a part its own body hides wholly is 1.0 occluded (until 2026-12-06 it was 0.0:
the whole drawn shape was counted as seen). Hidden parts keep their rows; a part with less than :data:`MIN_IN_FRAME`
of its pixels inside the frame has none (a person walking out leaves a shoe of 7 x 15 px, or a
single pixel at a corner, for several frames: a box there says nothing about where the part
is, and Zhao & Lee count only people in view). ``person`` is the extent of the whole drawn
figure (head, torso, hip-leg, arms and hands), written while any of it is in the frame.

A tilted camera (the randomized scenes, :meth:`Camera.drawing`) is drawn on a larger canvas
seen through a vertical image plane, then every frame is warped into the tilted camera's frame
by one homography; a truth box is then the extent of its pixels' corners carried by the same
homography, clipped to the frame (a homography keeps a set's convex hull, so the corners of each
row's first and last pixel give the exact extent).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
from tqdm import tqdm

from partlab.labelling.synth.activities import BUILDERS as ACTIVITY_BUILDERS
from partlab.labelling.synth.activities import HANDS
from partlab.labelling.synth.appearance import Appearance
from partlab.labelling.synth.background import CameraEffects, draw_props, room, smooth_noise
from partlab.labelling.synth.camera import Camera
from partlab.labelling.synth.figure import (
    FACE,
    FIGURE_PARTS,
    FOREARM,
    HAND_LEFT,
    HAND_RIGHT,
    NECK,
    PART_LABELS,
    FigurePose,
    colour_table,
    draw_figure,
)
from partlab.labelling.synth.scenarios import BUILDERS, Script
from partlab.tracking.core.box import Box
from partlab.tracking.parts import PART_NAMES
from partlab.tracking.tracks import normalise_tracks

SCENARIOS: tuple[str, ...] = ("single", "pair_cross", "pillar", "distractors", "crowd", "bend", "desk",
                              "pick_place", "exchange", "handshake", "clap", "random")
#: the columns of a scene's event truth (``events.csv``)
EVENT_TRUTH_COLUMNS = ("kind", "start_frame", "end_frame", "track_id_a", "part_a", "track_id_b", "part_b", "colour")
FPS = 25.0
OCCLUDER_ID = 255
SKIN_LABELS = (FACE, HAND_LEFT, HAND_RIGHT, FOREARM, NECK)
#: a body part (not the person) has a truth row only while at least this share of its pixels lies
#: inside the frame (the tracker's own rule for a person leaving: ``detection.leave_fraction``)
MIN_IN_FRAME = 0.5
#: a randomized scene's person starts (its ``init`` row) at the first frame it is wholly inside the
#: frame with at most this share of it hidden by others: nobody can draw, nor a tracker learn the
#: colours of, a person standing mostly behind someone else
MAX_START_HIDDEN = 0.25


@dataclass(frozen=True, eq=False)
class Scene:
    """A rendered scenario.

    ``frames: (T, H, W, 3) uint8`` BGR before codec compression; ``truth``: tracks table
    (``source = "truth"``) with rows for every person and part at every frame;
    ``init``: the rows of each track's first frame; ``occluders``: fixed occluder boxes
    (the pillar), else empty; ``fps``: frame rate; ``appearances``: each track's
    colours (track ``k`` is ``appearances[k - 1]``); ``background``: the empty room;
    ``owners``: per-pixel visibility maps (only with ``make_scene(..., owners=True)``),
    e.g. the true foreground for testing a background model is ``owners[t] % 255 > 0``.
    """

    frames: np.ndarray
    truth: pd.DataFrame
    init: pd.DataFrame
    occluders: list[Box]
    fps: float
    appearances: tuple[Appearance, ...] = ()  # the people's colours, by track_id - 1
    background: np.ndarray | None = None  # (H, W, 3) uint8: the empty room (no shadows, flicker or noise)
    owners: np.ndarray | None = None  # (T, H, W) uint8 who is seen where: 0 room, k track k, 255 occluder
    events: pd.DataFrame | None = None  # activity truth (EVENT_TRUTH_COLUMNS), scenes with activities only


def _check(name: str, seed: int, n_frames: int, width: int, height: int) -> None:
    if name not in SCENARIOS:
        raise ValueError(f"unknown scenario {name!r}; expected one of {', '.join(SCENARIOS)}")
    if not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    if n_frames < 1:
        raise ValueError(f"n_frames must be at least 1, got {n_frames}")
    if width < 64 or height < 48:
        raise ValueError(f"frame size {width}x{height} is too small (at least 64x48)")


def _pose(actor, i: int, fps: float) -> FigurePose:
    m = actor.motion
    hands = m.hands[i]
    return FigurePose(
        facing=float(m.facing[i]), phase=float(m.phase[i]), gait=float(m.gait[i]), wave=float(m.wave[i]),
        wave_phase=2 * np.pi * 2.2 * i / fps, bend=float(m.bend[i]), head_yaw=float(m.head_yaw[i]),
        hands=None if not np.all(np.isfinite(hands)) else hands, seated=m.seated, seat_cut=actor.seat_cut)


def _pillar_texture(rng: np.random.Generator, box: Box, colour) -> np.ndarray:
    w, h = int(box.w), int(box.h)
    tex = np.empty((h, w, 3), np.float32)
    tex[:] = colour
    xs = np.linspace(-1, 1, w, dtype=np.float32)
    tex *= (1.0 - 0.25 * xs**2 + 0.08 * xs)[None, :, None]  # a round column lit from the right
    tex += 5.0 * smooth_noise(rng, h, w, 6)[..., None]
    return np.clip(tex, 0, 255).astype(np.uint8)


def _shadow(frame: np.ndarray, camera: Camera, x: float, z: float, height_m: float) -> None:
    """Darken the floor under a person's feet (a soft contact shadow; never part of the truth)."""
    cx, cy = camera.floor_point(x, z)
    s = float(camera.scale(z))
    ax, ay = 0.28 * height_m * s, 0.28 * height_m * s * camera.cam_height / z
    x1, x2 = int(max(cx - ax - 2, 0)), int(min(cx + ax + 2, frame.shape[1]))
    y1, y2 = int(max(cy - ay - 2, 0)), int(min(cy + ay + 2, frame.shape[0]))
    if x1 >= x2 or y1 >= y2:
        return
    yy, xx = np.mgrid[y1:y2, x1:x2]
    r2 = ((xx - cx) / ax) ** 2 + ((yy - cy) / ay) ** 2
    gain = 1.0 - 0.35 * np.clip(1.0 - r2, 0.0, 1.0)
    frame[y1:y2, x1:x2] = (frame[y1:y2, x1:x2] * gain[..., None]).astype(np.uint8)


#: frame sizes of the randomized suite (:func:`random_size`)
RANDOM_SIZES: tuple[tuple[int, int], ...] = ((480, 360), (640, 360), (640, 480), (720, 480), (768, 576), (960, 540))


def random_size(seed: int) -> tuple[int, int]:
    """The frame size the randomized suite renders scene ``seed`` at (one of :data:`RANDOM_SIZES`)."""
    return RANDOM_SIZES[int(np.random.default_rng([seed, 99]).integers(len(RANDOM_SIZES)))]

def _warped_extent(mask: np.ndarray, x0: int, y0: int, warp: np.ndarray, width: int,
                   height: int, min_inside: float = 0.0) -> tuple[int, int, int, int] | None:
    """``(x, y, w, h)`` of the pixels of ``mask`` (placed at ``(x0, y0)`` on the canvas) carried
    into the frame by the homography ``warp``, those inside it only; None when less than
    ``min_inside`` of them (or none) land inside. Wholly inside: the corners of each row's first
    and last pixel; cut by the frame's edge: the centre of every pixel (the parts inside a
    slanted cut are not a box's corners)."""
    def carried(xs, ys):
        p = warp @ np.stack([xs + x0, ys + y0, np.ones_like(xs)])
        return p[0] / p[2], p[1] / p[2]

    rws = np.flatnonzero(mask.any(axis=1))
    first = mask[rws].argmax(axis=1)
    last = mask.shape[1] - 1 - mask[rws, ::-1].argmax(axis=1)
    px, py = carried(np.concatenate([first, last + 1, first, last + 1]).astype(np.float64),
                     np.concatenate([rws, rws, rws + 1, rws + 1]).astype(np.float64))
    if px.min() < 0 or py.min() < 0 or px.max() > width or py.max() > height:
        ys, xs = np.nonzero(mask)
        px, py = carried(xs + 0.5, ys + 0.5)
        inside = (px >= 0) & (py >= 0) & (px < width) & (py < height)
        if not inside.any() or inside.mean() < min_inside:
            return None
        px, py = px[inside], py[inside]
    x1, y1 = max(int(np.floor(px.min())), 0), max(int(np.floor(py.min())), 0)
    x2, y2 = min(int(np.ceil(px.max())), width), min(int(np.ceil(py.max())), height)
    if x2 <= x1 or y2 <= y1:
        return None
    return x1, y1, x2 - x1, y2 - y1


def _truth_rows(i: int, drawn: list, owner: np.ndarray, warp: np.ndarray | None = None,
                size: tuple[int, int] = (0, 0)) -> list[tuple]:
    """Truth rows of frame ``i``: every drawn person's box and each part's box (its visible
    pixels, or all of it when hidden), with the occluded fraction from the owner map; ``warp``
    (a tilted camera): boxes carried into the ``size (W, H)`` frame by that homography."""
    rows = []
    for a, fig, crop, (cx1, cy1, cx2, cy2) in drawn:
        own = owner[cy1:cy2, cx1:cx2]
        lab = fig.labels[crop]
        parts = {"person": lab > 0}
        self_hidden: set[str] = set()
        for p in FIGURE_PARTS:
            if p in fig.masks:
                whole = fig.masks[p]
                shown = whole & np.isin(fig.labels, PART_LABELS[p])
                shape = shown if shown[crop].any() else whole
                if warp is None and np.count_nonzero(shape[crop]) < MIN_IN_FRAME * np.count_nonzero(shape):
                    continue  # mostly outside the frame (the canvas is the frame)
                parts[p] = shape[crop]
                if shape is whole:
                    self_hidden.add(p)
        for part, mask in parts.items():
            total = int(mask.sum())
            if total == 0:
                continue
            # a part its own body hides wholly (a far hand at rest behind the torso) is not seen
            visible = 0 if part in self_hidden else int(np.count_nonzero(own[mask] == a + 1))
            if warp is not None:
                box = _warped_extent(mask, cx1, cy1, warp, *size, 0.0 if part == "person" else MIN_IN_FRAME)
                if box is None:
                    continue
                rows.append((i, a + 1, part, *box, round(1.0 - visible / total, 4)))
                continue
            cols = np.flatnonzero(mask.any(axis=0))
            rws = np.flatnonzero(mask.any(axis=1))
            rows.append((i, a + 1, part, cx1 + cols[0], cy1 + rws[0], cols[-1] - cols[0] + 1,
                         rws[-1] - rws[0] + 1, round(1.0 - visible / total, 4)))
    return rows


def _canvas(name: str, camera: Camera, script: Script) -> tuple[Camera, np.ndarray | None]:
    """Where the scene is drawn and the homography into the frame (:meth:`Camera.drawing`): a
    tilted camera's scene (the randomized ones) is drawn on a larger canvas, then warped."""
    canvas, warp = camera.drawing()
    if warp is not None and (script.props or script.occluders or script.objects):
        raise ValueError(f"scenario {name!r}: props, occluders and objects are placed in the frame, "
                         "not on a tilted camera's canvas")
    return canvas, warp


def _warped(image: np.ndarray, warp: np.ndarray | None, width: int, height: int,
            interpolation: int = cv2.INTER_LINEAR) -> np.ndarray:
    """``image`` drawn on the canvas as the ``width x height`` frame sees it (as it is: no warp)."""
    if warp is None:
        return image
    return cv2.warpPerspective(image, warp, (width, height), flags=interpolation)


def make_scene(name: str, seed: int = 0, n_frames: int = 150, width: int = 720, height: int = 480,
               *, clean: bool = False, owners: bool = False, progress: bool = False) -> Scene:
    """Render scenario ``name`` (one of :data:`SCENARIOS`) deterministically from ``seed``.

    ``clean`` leaves out every photometric effect (cloth shading, flicker, sensor noise)
    so that each pixel has its label's exact colour (for tests that check drawn colours);
    ``owners`` keeps every frame's visibility map in :attr:`Scene.owners`.
    """
    _check(name, seed, n_frames, width, height)
    rng = np.random.default_rng([seed, SCENARIOS.index(name)])  # scenarios differ at the same seed
    camera = Camera.random(rng, width, height) if name == "random" else Camera.for_frame(width, height)
    script: Script = {**BUILDERS, **ACTIVITY_BUILDERS}[name](rng, camera, n_frames, FPS)
    canvas, warp = _canvas(name, camera, script)
    cw, ch = canvas.width, canvas.height
    background = draw_props(room(rng, canvas), script.props)
    effects = None if clean else CameraEffects.make(rng, n_frames, width, height, FPS)
    occ_tex = [_pillar_texture(rng, o.box, o.colour) for o in script.occluders]
    luts = [colour_table(a.appearance) for a in script.actors]
    # cloth folds and lighting: a gain field per person that moves with them (none when clean)
    folds = [None if clean else 0.045 * smooth_noise(rng, ch + 64, cw + 64, max(3, height // 40))
             for _ in script.actors]
    frames = np.empty((n_frames, height, width, 3), np.uint8)
    owner = np.zeros((ch, cw), np.uint8)
    owner_maps = np.zeros((n_frames, height, width), np.uint8) if owners else None
    rows: list[tuple] = []
    for i in tqdm(range(n_frames), desc=f"synth {name}", unit="frame", disable=not progress):
        frame = background.copy()
        owner[:] = 0
        for actor in script.actors:
            if actor.view is None:
                _shadow(frame, canvas, float(actor.motion.x[i]), float(actor.motion.z[i]), actor.appearance.height_m)
        order = sorted(range(len(script.actors)), key=lambda a: -script.actors[a].motion.z[i])
        drawn = []
        for a in order:
            actor = script.actors[a]
            m = actor.motion
            view = actor.view or canvas.local_view(float(m.x[i]), float(m.z[i]))
            fig = draw_figure(_pose(actor, i, FPS), actor.appearance, view)
            x0, y0 = fig.origin
            fh, fw = fig.labels.shape
            cx1, cy1, cx2, cy2 = max(x0, 0), max(y0, 0), min(x0 + fw, cw), min(y0 + fh, ch)
            if cx1 >= cx2 or cy1 >= cy2:
                continue
            crop = (slice(cy1 - y0, cy2 - y0), slice(cx1 - x0, cx2 - x0))
            lab = fig.labels[crop]
            on = lab > 0
            colours = luts[a][lab[on]]
            if folds[a] is not None:  # lit from above: brighter shoulders, darker feet, plus folds
                ry = (np.arange(cy1 - y0, cy2 - y0, dtype=np.float32) / max(fh, 1))[:, None]
                fold = folds[a]
                if fold.shape[0] < fh or fold.shape[1] < fw:  # a figure larger than the frame
                    fold = np.pad(fold, ((0, max(0, fh - fold.shape[0])), (0, max(0, fw - fold.shape[1]))), "wrap")
                cloth = ~np.isin(lab, SKIN_LABELS)  # folds in clothes and hair, smooth skin
                gain = (1.06 - 0.14 * ry) * (1.0 + fold[: fh, : fw][crop] * cloth)
                colours = np.clip(colours * gain[on][:, None], 0, 255).astype(np.uint8)
            frame[cy1:cy2, cx1:cx2][on] = colours
            owner[cy1:cy2, cx1:cx2][on] = a + 1
            drawn.append((a, fig, crop, (cx1, cy1, cx2, cy2)))
        _draw_objects(frame, script.objects, drawn, i, owner)
        for o, tex in zip(script.occluders, occ_tex):
            x, y, w, h = int(o.box.x), int(o.box.y), int(o.box.w), int(o.box.h)
            frame[y:y + h, x:x + w] = tex[: max(0, min(h, height - y)), : max(0, min(w, width - x))]
            owner[y:y + h, x:x + w] = OCCLUDER_ID
        rows.extend(_truth_rows(i, drawn, owner, warp, (width, height)))
        frame = _warped(frame, warp, width, height)
        if script.lighting is not None:
            frame = np.clip(frame * script.lighting, 0, 255).astype(np.uint8)
        frames[i] = frame if effects is None else effects.apply(frame, i)
        if owner_maps is not None:
            owner_maps[i] = _warped(owner, warp, width, height, cv2.INTER_NEAREST)
    truth = pd.DataFrame(rows, columns=["frame", "track_id", "part", "x", "y", "w", "h", "occluded"])
    truth["source"] = "truth"
    order = {p: k for k, p in enumerate(PART_NAMES)}
    truth = truth.assign(_p=truth["part"].map(order)).sort_values(["frame", "track_id", "_p"], kind="stable")
    truth = normalise_tracks(truth.drop(columns="_p"))
    first = truth.groupby("track_id")["frame"].transform("min")
    if name == "random":  # people start where an annotator would: once wholly in view, not hidden
        person = truth[truth["part"] == "person"]
        inside = person[(person["x"] >= 2) & (person["y"] >= 2) & (person["x"] + person["w"] <= width - 2)
                        & (person["y"] + person["h"] <= height - 2) & (person["occluded"] <= MAX_START_HIDDEN)]
        start = inside.groupby("track_id")["frame"].min()
        # never wholly in view: start at the frame it shows most of itself
        largest = person.assign(a=person["w"] * person["h"]).sort_values("a").groupby("track_id")["frame"].last()
        first = truth["track_id"].map(start).fillna(truth["track_id"].map(largest)).fillna(first)
    init = truth[truth["frame"] == first].reset_index(drop=True)
    events = None
    if script.events:
        events = pd.DataFrame([(e.kind, e.start_frame, e.end_frame, e.track_id_a, e.part_a, e.track_id_b, e.part_b,
                                "" if e.colour is None else "#{:02x}{:02x}{:02x}".format(*reversed(e.colour)))
                               for e in script.events], columns=list(EVENT_TRUTH_COLUMNS))
    background = _warped(background, warp, width, height)
    return Scene(frames, truth, init, [o.box for o in script.occluders], FPS,
                 tuple(a.appearance for a in script.actors), background, owner_maps, events)


def _draw_objects(frame: np.ndarray, objects, drawn, i: int, owner: np.ndarray | None = None) -> None:
    """Carried objects at frame ``i``: in front of the holding hand (a little below its centre, so
    the hand still shows) and at its depth, or where they rest.

    A held object is hidden wherever something nearer than the hand is drawn: the holder's own
    solids in front of that hand (:attr:`Figure.front`: the torso over a far hand at rest behind the
    body) and, with the ``owner`` map, the people drawn after the holder (nearer the camera). Until
    2026-12-06 it was drawn over everything, floating in front of a hand hidden behind the body."""
    order = [a for a, _, _, _ in drawn]
    figs = {a: fig for a, fig, _, _ in drawn}
    for obj in objects:
        h = int(obj.holder[i])
        colour = tuple(int(c) for c in obj.colour)
        if h < 0:
            if not np.all(np.isfinite(obj.rest[i])):
                continue
            r = obj.rest_radius_px
            cv2.ellipse(frame, (int(round(obj.rest[i][0])), int(round(obj.rest[i][1]))),
                        (int(round(r)), int(round(0.8 * r))), 0, 0, 360, colour, -1, lineType=cv2.LINE_AA)
            continue
        fig = figs.get(h // 2)
        hand = HANDS[h % 2]
        mask = None if fig is None else fig.masks.get(hand)
        if mask is None or not mask.any():
            continue
        ys, xs = np.nonzero(mask)
        x0, y0 = fig.origin
        hand_r = max(2.0, 0.5 * (xs.max() - xs.min() + 1))
        centre = np.array([x0 + xs.mean(), y0 + ys.mean() + 1.1 * hand_r])
        r = obj.radius * hand_r
        axes, at = (int(round(r)), int(round(0.8 * r))), (int(round(centre[0])), int(round(centre[1])))
        hgt, wid = frame.shape[:2]
        hidden = np.zeros((hgt, wid), bool)  # what is nearer than the hand
        front = fig.front.get(hand)
        if front is not None and front.any():
            fh, fw = front.shape
            cx1, cy1, cx2, cy2 = max(x0, 0), max(y0, 0), min(x0 + fw, wid), min(y0 + fh, hgt)
            if cx1 < cx2 and cy1 < cy2:
                hidden[cy1:cy2, cx1:cx2] = front[cy1 - y0:cy2 - y0, cx1 - x0:cx2 - x0]
        if owner is not None:
            nearer = [a + 1 for a in order[order.index(h // 2) + 1:]]
            if nearer:
                hidden |= np.isin(owner[:hgt, :wid], nearer)
        cover = np.zeros((hgt, wid), np.uint8)  # the object's coverage, anti-aliased as drawn before
        cv2.ellipse(cover, at, axes, 0, 0, 360, 255, -1, lineType=cv2.LINE_AA)
        if not (hidden & (cover > 0)).any():  # nothing in front: drawn as it always was
            cv2.ellipse(frame, at, axes, 0, 0, 360, colour, -1, lineType=cv2.LINE_AA)
            continue
        alpha = np.where(hidden, 0.0, cover / 255.0).astype(np.float32)
        on = alpha > 0
        blend = frame[on] * (1.0 - alpha[on, None]) + np.asarray(colour, np.float32)[None, :] * alpha[on, None]
        frame[on] = np.clip(np.round(blend), 0, 255).astype(np.uint8)


def render_scenario(name: str, outdir: str | PathLike, seed: int = 0, n_frames: int = 150, width: int = 720,
                    height: int = 480, *, progress: bool = False) -> Path:
    """Render ``name`` into ``outdir``: clip.mp4, truth.csv, init.csv, scene.json (+ occluders.csv)."""
    from partlab.labelling.video import write_video
    from partlab.tracking.tracks import write_tracks_csv

    scene = make_scene(name, seed, n_frames, width, height, progress=progress)
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    write_video(out / "clip.mp4", scene.frames, scene.fps)
    write_tracks_csv(scene.truth, out / "truth.csv")
    write_tracks_csv(scene.init, out / "init.csv")
    occ = out / "occluders.csv"
    if scene.occluders:
        pd.DataFrame([b.as_tuple() for b in scene.occluders], columns=["x", "y", "w", "h"]).to_csv(
            occ, index=False, lineterminator="\n")
    elif occ.exists():
        occ.unlink()
    meta = {"name": name, "seed": seed, "fps": scene.fps, "size": f"{width}x{height}", "width": width,
            "height": height, "n_frames": n_frames, "tracks": int(scene.truth["track_id"].nunique()),
            "occluders": [list(b.as_tuple()) for b in scene.occluders],
            "people": [{"track_id": k + 1, "shirt": list(p.shirt), "trousers": list(p.trousers), "skin": list(p.skin),
                        "hair": list(p.hair), "height_m": round(p.height_m, 3)}
                       for k, p in enumerate(scene.appearances)]}
    (out / "scene.json").write_text(json.dumps(meta, indent=2) + "\n")
    if scene.events is not None:
        scene.events.to_csv(out / "events.csv", index=False, lineterminator="\n")
    return out
