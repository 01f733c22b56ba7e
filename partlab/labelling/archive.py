"""Safe unpacking of zip and tar archives that users upload or pass to ``partlab import``.

A member is refused when its name is absolute, has a drive, or climbs out with ``..``;
when it is a link whose target lies outside the target directory; when it is a device
or FIFO; and the archive is refused when it has more than ``max_members`` members or
more than ``max_bytes`` of content (counted while writing, so a zip whose headers lie
about sizes is caught too). Nothing is written outside ``dest``.
"""

from __future__ import annotations

import os
import posixpath
import shutil
import stat
import tarfile
import zipfile
from pathlib import Path, PurePosixPath, PureWindowsPath

MAX_BYTES = 2 << 30  # 2 GiB: a long clip's frames as JPEG stay well below
MAX_MEMBERS = 200_000  # a frame per member for more than two hours at 25 fps
ARCHIVE_SUFFIXES: tuple[str, ...] = (".zip", ".tar", ".tar.gz", ".tgz", ".tar.bz2", ".tbz2", ".tar.xz", ".txz")
_CHUNK = 1 << 20


class ArchiveError(ValueError):
    """An archive that is not safe or not readable; the message names the member and the reason."""


def is_archive(path: str | os.PathLike) -> bool:
    """True for a file whose name ends like a zip or tar archive."""
    name = Path(path).name.lower()
    return Path(path).is_file() and any(name.endswith(s) for s in ARCHIVE_SUFFIXES)


def _safe_name(archive: Path, name: str) -> PurePosixPath:
    """The member's relative path, or :class:`ArchiveError` when it could leave the target."""
    if not name or "\x00" in name:
        raise ArchiveError(f"{archive}: a member has an empty or invalid name")
    win = PureWindowsPath(name)
    if name.startswith(("/", "\\")) or win.drive or win.root:
        raise ArchiveError(f"{archive}: member {name!r} has an absolute path; refusing to unpack")
    parts = PurePosixPath(name.replace("\\", "/")).parts
    if ".." in parts:
        raise ArchiveError(f"{archive}: member {name!r} climbs out of the target with '..'; refusing to unpack")
    parts = tuple(p for p in parts if p not in ("", "."))
    return PurePosixPath(*parts) if parts else PurePosixPath(".")


def _check_link(archive: Path, name: PurePosixPath, target: str, hard: bool) -> None:
    if target.startswith("/") or PureWindowsPath(target).drive:
        raise ArchiveError(f"{archive}: link {str(name)!r} points to absolute path {target!r}; refusing to unpack")
    base = "." if hard else posixpath.dirname(str(name))
    resolved = posixpath.normpath(posixpath.join(base, target))
    if resolved == ".." or resolved.startswith("../"):
        raise ArchiveError(f"{archive}: link {str(name)!r} points outside the target ({target!r}); "
                           "refusing to unpack")


def _copy(src, dest: Path, budget: list[int], archive: Path, max_bytes: int) -> None:
    dest.parent.mkdir(parents=True, exist_ok=True)
    with open(dest, "wb") as out:
        while block := src.read(_CHUNK):
            budget[0] += len(block)
            if budget[0] > max_bytes:
                raise ArchiveError(f"{archive}: more than {max_bytes} bytes of content; refusing to unpack")
            out.write(block)


def safe_extract(archive: str | os.PathLike, dest: str | os.PathLike, *, max_bytes: int = MAX_BYTES,
                 max_members: int = MAX_MEMBERS) -> Path:
    """Unpack a zip or tar archive into ``dest`` (created); returns ``dest``.

    Raises :class:`ArchiveError` naming the offending member; on error what this call
    wrote into ``dest`` is removed (what was there before is kept).
    """
    archive = Path(archive)
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    root = dest.resolve()
    before = set(root.iterdir())
    try:
        if zipfile.is_zipfile(archive):
            _extract_zip(archive, root, max_bytes, max_members)
        elif tarfile.is_tarfile(archive):
            _extract_tar(archive, root, max_bytes, max_members)
        else:
            raise ArchiveError(f"{archive}: not a zip or tar archive")
    except ArchiveError:
        for child in set(root.iterdir()) - before:  # only what this call wrote
            shutil.rmtree(child) if child.is_dir() and not child.is_symlink() else child.unlink()
        raise
    except (zipfile.BadZipFile, tarfile.TarError, EOFError, OSError) as exc:
        raise ArchiveError(f"{archive}: damaged archive ({exc})") from None
    return dest


def _inside(root: Path, rel: PurePosixPath) -> Path:
    target = (root / rel).resolve()
    if target != root and root not in target.parents:  # e.g. through a link unpacked earlier
        raise ArchiveError(f"member {str(rel)!r} would be written outside the target; refusing to unpack")
    return target


def _extract_zip(archive: Path, root: Path, max_bytes: int, max_members: int) -> None:
    with zipfile.ZipFile(archive) as zf:
        infos = zf.infolist()
        if len(infos) > max_members:
            raise ArchiveError(f"{archive}: {len(infos)} members, more than the limit of {max_members}")
        if sum(i.file_size for i in infos) > max_bytes:
            raise ArchiveError(f"{archive}: more than {max_bytes} bytes of content; refusing to unpack")
        names = [(_safe_name(archive, i.filename), i) for i in infos]
        budget = [0]
        for rel, info in names:
            mode = info.external_attr >> 16
            if stat.S_ISLNK(mode):
                target = zf.read(info).decode("utf-8", "replace")
                _check_link(archive, rel, target, hard=False)
                raise ArchiveError(f"{archive}: member {info.filename!r} is a symbolic link; zip archives with "
                                   "links are not accepted")
            path = _inside(root, rel)
            if info.is_dir():
                path.mkdir(parents=True, exist_ok=True)
                continue
            with zf.open(info) as src:
                _copy(src, path, budget, archive, max_bytes)


def _extract_tar(archive: Path, root: Path, max_bytes: int, max_members: int) -> None:
    with tarfile.open(archive) as tf:
        members = []
        for m in tf:
            members.append(m)
            if len(members) > max_members:
                raise ArchiveError(f"{archive}: more than the limit of {max_members} members")
        if sum(m.size for m in members if m.isfile()) > max_bytes:
            raise ArchiveError(f"{archive}: more than {max_bytes} bytes of content; refusing to unpack")
        budget = [0]
        links = []
        for m in members:
            rel = _safe_name(archive, m.name)
            if m.issym() or m.islnk():
                _check_link(archive, rel, m.linkname, hard=m.islnk())
                links.append((rel, m))
                continue
            if not (m.isfile() or m.isdir()):
                raise ArchiveError(f"{archive}: member {m.name!r} is a device or FIFO; refusing to unpack")
            path = _inside(root, rel)
            if m.isdir():
                path.mkdir(parents=True, exist_ok=True)
                continue
            src = tf.extractfile(m)
            _copy(src, path, budget, archive, max_bytes)
        for rel, m in links:  # links last, as copies, so no later member can be written through one
            path = _inside(root, rel)
            base = PurePosixPath(".") if m.islnk() else rel.parent
            source = _inside(root, PurePosixPath(posixpath.normpath(str(base / m.linkname))))
            if source.is_file():
                path.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(source, path)
