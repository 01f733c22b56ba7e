"""Writing files so that nothing already saved is lost.

:func:`replacing` yields a temporary path beside the target; the target is replaced by it only
when the block finishes (``os.replace``, atomic on one file system). A full disk or a crash
half-way leaves the earlier file as it was and no partial file behind.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from os import PathLike
from pathlib import Path


@contextlib.contextmanager
def replacing(path: str | PathLike) -> Iterator[Path]:
    """``with replacing(p) as tmp: write(tmp)`` writes ``p`` all at once or not at all."""
    target = Path(path)
    if target.is_dir():
        raise IsADirectoryError(21, "is a directory, expected a file path", str(target))
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_text(path: str | PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with replacing(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)
