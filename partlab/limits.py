"""Limits on what partlab accepts, so that a hostile or mistaken input is refused in seconds
instead of filling memory or disk. Each is configurable by an environment variable.

| limit | variable | default | why |
|---|---|---|---|
| pixels per frame | ``PARTLAB_MAX_FRAME_PIXELS`` | 4096 x 4096 | 4K video fits; a frame is decoded, converted and histogrammed several times |
| frames per clip | ``PARTLAB_MAX_FRAMES`` | 360 000 | four hours at 25 fps |
| rows of a tracks CSV | ``PARTLAB_MAX_CSV_ROWS`` | 20 000 000 | 8 people x 6 parts x four hours at 25 fps is 17 M |
| coordinates | ``PARTLAB_MAX_COORD`` | 1 000 000 px | far beyond any frame; larger numbers are typos or attacks |
| bytes of one model bundle array | ``PARTLAB_MAX_BUNDLE_ARRAY_BYTES`` | 256 MiB | a failure SVM of 100 000 support vectors x 40 features is 32 MB; checked from the .npy header before reading |

Ids (``track_id``) and frame indexes must fit a signed 32-bit integer (the store's column type).
"""

from __future__ import annotations

import os

from partlab.errors import UserError

MAX_ID = 2**31 - 1


def _env(name: str, default: float) -> float:
    raw = os.environ.get(name)
    if raw is None or raw.strip() == "":
        return default
    try:
        value = float(raw)
    except ValueError:
        raise UserError(f"{name} must be a number, got {raw!r}") from None
    if not value > 0:
        raise UserError(f"{name} must be positive, got {raw!r}")
    return value


def max_frame_pixels() -> int:
    return int(_env("PARTLAB_MAX_FRAME_PIXELS", 4096 * 4096))


def max_frames() -> int:
    return int(_env("PARTLAB_MAX_FRAMES", 360_000))


def max_csv_rows() -> int:
    return int(_env("PARTLAB_MAX_CSV_ROWS", 20_000_000))


def max_bundle_array_bytes() -> int:
    return int(_env("PARTLAB_MAX_BUNDLE_ARRAY_BYTES", 256 * 2**20))


def max_coord() -> float:
    return _env("PARTLAB_MAX_COORD", 1e6)


def check_frame_size(width: int, height: int, where: str, error: type[UserError] = UserError) -> None:
    """Refuse frames larger than :func:`max_frame_pixels` (before decoding them) with ``error``."""
    if width <= 0 or height <= 0:
        raise error(f"{where}: frame size {width}x{height} is not a picture size")
    if width * height > max_frame_pixels():
        raise error(f"{where}: frames of {width}x{height} are larger than the limit of "
                        f"{max_frame_pixels()} pixels (set PARTLAB_MAX_FRAME_PIXELS to change it)")
