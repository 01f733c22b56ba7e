"""The top-level handler: one line and an exit code, never a traceback; nothing saved is lost."""

import csv
import errno

import numpy as np
import pandas as pd
import pytest

from partlab import cli
from partlab.files import replacing
from partlab.labelling.video import write_video


@pytest.fixture
def clip(tmp_path):
    frames = [np.full((48, 64, 3), 40 + i, np.uint8) for i in range(4)]
    return write_video(tmp_path / "c.mp4", frames, fps=25)


def test_a_full_disk_leaves_the_earlier_tracks_file(tmp_path, clip, monkeypatch, capsys):
    out, init = tmp_path / "tracks.csv", tmp_path / "init.csv"
    init.write_text("frame,track_id,part,x,y,w,h\n0,1,person,10,5,20,40\n")  # rows to write after the header
    out.write_text("frame,track_id,part,x,y,w,h\n0,1,head,1,2,3,4\n")
    before = out.read_text()
    real_csv, real_writer = pd.DataFrame.to_csv, csv.writer

    def half_then_full(self, path, *a, **k):
        real_csv(self.head(0), path, *a, **k)  # a partial file that would still parse
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    class HeaderThenFull:  # the writer without pandas (partlab track's): the header, then a full disk
        def __init__(self, fh, **k):
            self.inner, self.rows = real_writer(fh, **k), 0

        def writerow(self, row):
            if self.rows:
                raise OSError(errno.ENOSPC, "No space left on device")
            self.rows += 1
            return self.inner.writerow(row)

    monkeypatch.setattr(pd.DataFrame, "to_csv", half_then_full)
    monkeypatch.setattr(csv, "writer", HeaderThenFull)
    assert cli.main(["track", str(clip), "-o", str(out), "--no-progress", "--init", str(init)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no space left" in err[0]
    assert out.read_text() == before
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".tracks")] == []


def test_an_unexpected_error_is_one_line_with_a_hint(clip, tmp_path, monkeypatch, capsys):
    from partlab.tracking import run

    def boom(*a, **k):
        raise KeyError("lost")

    monkeypatch.setattr(run, "_step_all", boom)  # the loop both run_frames and run_records use
    assert cli.main(["track", str(clip), "-o", str(tmp_path / "t.csv"), "--no-progress"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["partlab track: unexpected KeyError: 'lost' (rerun with --debug for the traceback)"]
    with pytest.raises(KeyError):
        cli.main(["--debug", "track", str(clip), "-o", str(tmp_path / "t.csv"), "--no-progress"])


def test_replacing_refuses_a_directory_and_keeps_nothing_half_written(tmp_path):
    with pytest.raises(IsADirectoryError):
        with replacing(tmp_path):
            pass
    target = tmp_path / "a.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with replacing(target) as tmp:
            tmp.write_text("new, half")
            raise RuntimeError("crash")
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
