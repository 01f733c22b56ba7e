"""Accept or refuse an uploaded clip, saying why (size, extension, not decodable).

Streamlit's own uploader enforces ``server.maxUploadSize`` in the browser; the same
limit (``PARTLAB_MAX_UPLOAD_MB``, default 1024) and the extension list are checked
again here so a refused file always gets a sentence, whatever sent it.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from partlab.labelling.config import data_dir
from partlab.labelling.store import Clip, Store, StoreError
from partlab.labelling.video import VideoError

#: what the uploader offers (the issue's list plus common aliases OpenCV reads), and a zip of JPEG/PNG
#: frames (an image sequence, :class:`partlab.labelling.video.FrameFiles`)
UPLOAD_EXTENSIONS: tuple[str, ...] = ("mp4", "avi", "mov", "mkv", "m4v", "zip")
DEFAULT_MAX_UPLOAD_MB = 1024


class UploadRefused(ValueError):
    """An upload the app will not keep; the message says why."""


def max_upload_mb() -> int:
    """The upload size limit in MB from ``PARTLAB_MAX_UPLOAD_MB`` (default 1024)."""
    raw = os.environ.get("PARTLAB_MAX_UPLOAD_MB", str(DEFAULT_MAX_UPLOAD_MB))
    try:
        value = int(raw)
    except ValueError:
        raise UploadRefused(f"PARTLAB_MAX_UPLOAD_MB must be a whole number of megabytes, got {raw!r}") from None
    if value <= 0:
        raise UploadRefused(f"PARTLAB_MAX_UPLOAD_MB must be positive, got {value}")
    return value


def check_upload(name: str, size: int, limit_mb: int | None = None) -> None:
    """Refuse a file by name and size before reading it."""
    limit_mb = max_upload_mb() if limit_mb is None else limit_mb
    ext = Path(name).suffix.lower().lstrip(".")
    if ext not in UPLOAD_EXTENSIONS:
        raise UploadRefused(f"{name}: refused, .{ext or '(no extension)'} is not a video type partlab takes "
                            f"(use {', '.join('.' + e for e in UPLOAD_EXTENSIONS)})")
    if size <= 0:
        raise UploadRefused(f"{name}: refused, the file is empty")
    if size > limit_mb * 1024 * 1024:
        raise UploadRefused(f"{name}: refused, {size / 2**20:.1f} MB is over the {limit_mb} MB limit "
                            f"(set PARTLAB_MAX_UPLOAD_MB to change it)")


def save_upload(store: Store, project_id: int, name: str, data) -> Clip:
    """Check, write to a temporary file, and add the clip to the project (copied by hash).

    ``data`` is a binary file object (Streamlit's ``UploadedFile``) or bytes. A full disk, a
    read-only data directory or a refusal by the store (a viewer's upload) is an
    :class:`UploadRefused` saying so; the temporary file goes, earlier clips stay as they were.
    """
    content = data if isinstance(data, (bytes, bytearray)) else None
    size = len(content) if content is not None else int(getattr(data, "size", 0))
    check_upload(name, size)
    tmp_path = None
    try:
        tmp_dir = data_dir() / "uploads"
        tmp_dir.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=tmp_dir, suffix=Path(name).suffix.lower(), delete=False) as tmp:
            tmp_path = Path(tmp.name)
            if content is not None:
                tmp.write(content)
            else:
                data.seek(0)
                shutil.copyfileobj(data, tmp, length=1 << 20)
        return store.add_clip(project_id, tmp_path, name=Path(name).name)
    except VideoError as exc:
        reason = str(exc).replace(str(tmp_path), name)
        raise UploadRefused(f"refused: {reason}") from None
    except OSError as exc:
        from partlab.cli import describe_os_error

        raise UploadRefused(f"{name}: not stored, {describe_os_error(exc)}") from None
    except StoreError as exc:
        raise UploadRefused(f"{name}: not stored, {exc}") from None
    finally:
        if tmp_path is not None:
            try:
                tmp_path.unlink(missing_ok=True)
            except OSError:
                pass
