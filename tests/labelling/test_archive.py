import io
import tarfile
import zipfile

import pytest

from partlab.labelling.archive import ArchiveError, safe_extract


def _zip(path, members):
    with zipfile.ZipFile(path, "w") as z:
        for name, data in members:
            z.writestr(name, data)
    return path


def _tar(path, members):
    with tarfile.open(path, "w:gz") as t:
        for name, kind, data in members:
            info = tarfile.TarInfo(name)
            if kind == "file":
                info.size = len(data)
                t.addfile(info, io.BytesIO(data))
            elif kind == "sym":
                info.type, info.linkname = tarfile.SYMTYPE, data
                t.addfile(info)
            elif kind == "fifo":
                info.type = tarfile.FIFOTYPE
                t.addfile(info)
    return path


def test_zip_unpacks_inside_the_target(tmp_path):
    a = _zip(tmp_path / "a.zip", [("seq/gt/gt.txt", b"1,1,1,1,1,1,1,1,1\n"), ("./seq/labels.txt", b"person\n")])
    out = safe_extract(a, tmp_path / "out")
    assert (out / "seq" / "gt" / "gt.txt").read_bytes() == b"1,1,1,1,1,1,1,1,1\n"
    assert (out / "seq" / "labels.txt").is_file()


@pytest.mark.parametrize("name, reason", [("../evil.txt", "climbs out"), ("a/../../evil.txt", "climbs out"),
                                          ("/etc/evil.txt", "absolute path"), ("C:\\evil.txt", "absolute path")])
def test_zip_members_that_could_escape_are_refused(tmp_path, name, reason):
    a = _zip(tmp_path / "a.zip", [("ok.txt", b"x"), (name, b"y")])
    with pytest.raises(ArchiveError, match=reason):
        safe_extract(a, tmp_path / "out")
    assert not (tmp_path / "evil.txt").exists()
    assert list((tmp_path / "out").iterdir()) == []  # nothing half-unpacked is left


def test_tar_links_outside_are_refused_and_inside_are_copied(tmp_path):
    bad = _tar(tmp_path / "bad.tgz", [("a.txt", "file", b"x"), ("link", "sym", "../../etc/passwd")])
    with pytest.raises(ArchiveError, match="link 'link' points outside the target"):
        safe_extract(bad, tmp_path / "o1")
    absolute = _tar(tmp_path / "abs.tgz", [("link", "sym", "/etc/passwd")])
    with pytest.raises(ArchiveError, match="points to absolute path"):
        safe_extract(absolute, tmp_path / "o2")
    good = _tar(tmp_path / "good.tgz", [("d/a.txt", "file", b"hello"), ("d/b.txt", "sym", "a.txt")])
    out = safe_extract(good, tmp_path / "o3")
    assert (out / "d" / "b.txt").read_bytes() == b"hello" and not (out / "d" / "b.txt").is_symlink()
    fifo = _tar(tmp_path / "fifo.tgz", [("p", "fifo", None)])
    with pytest.raises(ArchiveError, match="device or FIFO"):
        safe_extract(fifo, tmp_path / "o4")


def test_size_and_member_limits(tmp_path):
    big = _zip(tmp_path / "big.zip", [("a.bin", b"\0" * 5000), ("b.bin", b"\0" * 5000)])
    with pytest.raises(ArchiveError, match="more than 8000 bytes"):
        safe_extract(big, tmp_path / "o1", max_bytes=8000)
    safe_extract(big, tmp_path / "o2", max_bytes=10000)
    many = _tar(tmp_path / "many.tgz", [(f"f{i}", "file", b"x") for i in range(6)])
    with pytest.raises(ArchiveError, match="more than the limit of 5 members"):
        safe_extract(many, tmp_path / "o3", max_members=5)


def test_not_an_archive(tmp_path):
    f = tmp_path / "x.zip"
    f.write_bytes(b"hello")
    with pytest.raises(ArchiveError, match="not a zip or tar archive"):
        safe_extract(f, tmp_path / "o")


def test_a_refused_archive_leaves_earlier_content_alone(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    a = _zip(tmp_path / "a.zip", [("new/ok.txt", b"x"), ("../evil.txt", b"y")])
    with pytest.raises(ArchiveError):
        safe_extract(a, out)
    assert [p.name for p in out.iterdir()] == ["mine.txt"]
