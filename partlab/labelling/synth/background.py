"""Static backgrounds of the synthetic scenes and the per-frame camera effects.

The room is a textured wall behind a tiled floor seen from the raised camera (tile
lines converge to the horizon). Props are drawn into the background (they never move,
so a background model learns them). Per frame the whole image gets a brightness gain
(slow flicker, as from mains lighting and auto exposure) and Gaussian sensor noise;
the mp4 codec adds compression artefacts when the clip is written.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from partlab.labelling.synth.camera import Camera

WALL_DEPTH = 15.0  # metres from the camera to the back wall


def smooth_noise(rng: np.random.Generator, height: int, width: int, cell: int) -> np.ndarray:
    """``(height, width) float32`` noise of unit scale varying over about ``cell`` pixels."""
    small = rng.standard_normal((height // cell + 3, width // cell + 3)).astype(np.float32)
    big = cv2.resize(small, (width + 3 * cell, height + 3 * cell), interpolation=cv2.INTER_CUBIC)
    return big[cell: cell + height, cell: cell + width]


@dataclass(frozen=True)
class Prop:
    """A static object drawn into the background.

    ``kind``: ``rect`` (poster, box front), ``ellipse``, ``poster_person`` (a poster of
    a person: shirt-coloured body under a skin-coloured face), ``desk`` or ``cup``;
    ``box``: ``(x, y, w, h)`` in pixels; ``colours``: BGR triples the kind uses.
    """

    kind: str
    box: tuple[float, float, float, float]
    colours: tuple = field(default_factory=tuple)


def room(rng: np.random.Generator, camera: Camera) -> np.ndarray:
    """``(H, W, 3) uint8`` wall and tiled floor with plaster/tile texture and a lighting gradient."""
    W, H = camera.width, camera.height
    _, wall_y = camera.floor_point(0.0, WALL_DEPTH)
    wall_y = int(round(float(wall_y)))
    wall_col = np.array([178, 192, 200], np.float32) + rng.uniform(-12, 12, 3)
    floor_col = np.array([118, 128, 134], np.float32) + rng.uniform(-10, 10, 3)
    img = np.empty((H, W, 3), np.float32)
    img[:wall_y] = wall_col
    img[wall_y:] = floor_col
    # tiles: lines of constant depth and lines of constant lateral position
    tile = np.zeros((H, W), np.uint8)
    step = 0.9
    for z in np.arange(WALL_DEPTH, 1.0, -step):
        y = int(round(float(camera.floor_point(0.0, z)[1])))
        if y >= H:
            break
        cv2.line(tile, (0, y), (W - 1, y), 1, max(1, int(round(camera.scale(z) * 0.02))))
    for xw in np.arange(-12, 12.01, step):
        p1 = camera.floor_point(xw, WALL_DEPTH)
        p2 = camera.floor_point(xw, 1.5)
        cv2.line(tile, (int(p1[0]), int(p1[1])), (int(p2[0]), int(p2[1])), 1, 1, cv2.LINE_AA)
    img[tile.astype(bool)] *= 0.8
    # skirting board, a door and a window on the wall
    board = max(2, int(0.02 * H))
    img[max(wall_y - board, 0):wall_y] = wall_col * 0.55
    dx = int(rng.uniform(0.05, 0.25) * W)
    dw, dh = int(0.08 * W), int(0.62 * wall_y)
    img[wall_y - dh:wall_y - board, dx:dx + dw] = np.array([70, 95, 125], np.float32) + rng.uniform(-8, 8, 3)
    wx = int(rng.uniform(0.6, 0.8) * W)
    img[int(0.15 * wall_y):int(0.55 * wall_y), wx:wx + int(0.14 * W)] = np.array([205, 200, 185], np.float32)
    # texture: plaster/tile mottling at two scales, lighting falling off to the sides
    tex = 7.0 * smooth_noise(rng, H, W, max(4, H // 20)) + 3.0 * smooth_noise(rng, H, W, 3)
    img += tex[..., None]
    xs = (np.arange(W, dtype=np.float32) - W / 2) / (W / 2)
    img *= (1.0 - 0.12 * xs**2)[None, :, None]
    return np.clip(img, 0, 255).astype(np.uint8)


def draw_props(img: np.ndarray, props: list[Prop]) -> np.ndarray:
    """Draw ``props`` into ``img`` (in place) and return it."""
    for p in props:
        x, y, w, h = (int(round(v)) for v in p.box)
        if p.kind == "rect":
            cv2.rectangle(img, (x, y), (x + w, y + h), p.colours[0], -1)
            cv2.rectangle(img, (x, y), (x + w, y + h), tuple(int(c * 0.6) for c in p.colours[0]), 1)
        elif p.kind == "ellipse":
            cv2.ellipse(img, (x + w // 2, y + h // 2), (w // 2, h // 2), 0, 0, 360, p.colours[0], -1, cv2.LINE_AA)
        elif p.kind == "poster_person":
            bg, shirt, skin = p.colours
            cv2.rectangle(img, (x, y), (x + w, y + h), bg, -1)
            cv2.rectangle(img, (x + w // 5, y + int(0.45 * h)), (x + 4 * w // 5, y + h), shirt, -1)
            cv2.ellipse(img, (x + w // 2, y + int(0.28 * h)), (w // 5, int(0.15 * h)), 0, 0, 360, skin, -1, cv2.LINE_AA)
        elif p.kind == "desk":
            top, front = p.colours
            # p.box is the desk top's far edge (x, y, w) and the front panel height h
            near = int(round(p.box[3]))
            cv2.fillConvexPoly(img, np.array([[x, y], [x + w, y], [x + w + w // 10, y + near],
                                              [x - w // 10, y + near]], np.int32), top, cv2.LINE_AA)
            cv2.rectangle(img, (x - w // 10, y + near), (x + w + w // 10, img.shape[0]), front, -1)
        elif p.kind == "cup":
            col = p.colours[0]
            cv2.rectangle(img, (x, y), (x + w, y + h), col, -1)
            cv2.ellipse(img, (x + w // 2, y), (w // 2, max(1, h // 6)), 0, 0, 360, tuple(int(c * 0.7) for c in col), -1)
        else:
            raise ValueError(f"unknown prop kind {p.kind!r}")
    return img


@dataclass(frozen=True, eq=False)
class CameraEffects:
    """Per-frame brightness gain ``gains: (T,)`` and a bank of noise fields to crop from.

    The defaults give a decoded 720x480 clip a frame-to-frame brightness spread of
    0.7-1 % and a median temporal pixel std of about 2 grey levels, a little more than
    PETS09-S2L1 (0.37 % and 1.6 on its first 60 frames; ``benchmarks/synth_realism.py``).
    """

    gains: np.ndarray
    noise: np.ndarray  # (K, H + M, W + M, 3) int16
    picks: np.ndarray  # (T, 3) int: bank index, row offset, column offset

    @classmethod
    def make(cls, rng: np.random.Generator, n_frames: int, width: int, height: int, fps: float,
             flicker: float = 0.012, sigma: float = 3.0, bank: int = 4, margin: int = 16) -> CameraEffects:
        t = np.arange(n_frames) / fps
        walk = np.cumsum(rng.normal(0, 0.0015, n_frames))
        walk -= np.linspace(walk[0], walk[-1], n_frames)  # no drift over the clip
        gains = 1.0 + flicker * np.sin(2 * np.pi * t / rng.uniform(1.2, 2.5) + rng.uniform(0, 6.3)) + walk
        noise = np.round(rng.normal(0, sigma, (bank, height + margin, width + margin, 3))).astype(np.int16)
        picks = np.stack([rng.integers(0, bank, n_frames), rng.integers(0, margin, n_frames),
                          rng.integers(0, margin, n_frames)], axis=1)
        return cls(gains.astype(np.float32), noise, picks)

    def apply(self, frame: np.ndarray, i: int) -> np.ndarray:
        """Frame ``i`` as the sensor sees it (uint8)."""
        h, w = frame.shape[:2]
        k, dy, dx = self.picks[i]
        out = frame.astype(np.int16) * 1  # copy
        if self.gains[i] != 1.0:
            out = (frame.astype(np.float32) * self.gains[i]).astype(np.int16)
        out += self.noise[k, dy:dy + h, dx:dx + w]
        return np.clip(out, 0, 255).astype(np.uint8)
