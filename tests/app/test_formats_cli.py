"""partlab export / import / eval end to end on the tiny synthetic clip."""

import importlib.util
import json
from pathlib import Path

import pandas as pd
import pytest

from partlab.cli import main
from partlab.tracking.tracks import read_tracks_csv, write_tracks_csv

# the tiny synthetic clip of the format tests
_spec = importlib.util.spec_from_file_location(
    "formats_scene", Path(__file__).resolve().parents[1] / "labelling" / "formats" / "conftest.py")
_scene = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_scene)
make_truth, render = _scene.make_truth, _scene.render


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    from partlab.labelling.video import write_video

    d = tmp_path_factory.mktemp("cli")
    truth = make_truth()
    write_tracks_csv(truth, d / "truth.csv")
    write_video(d / "clip.avi", render(truth), fps=10.0)
    return d


def test_export_then_import_gives_the_tracks_back(files, tmp_path, capsys):
    assert main(["export", str(files / "truth.csv"), "--video", str(files / "clip.avi"), "--format", "cvat",
                 "-o", str(tmp_path / "cvat"), "--no-frames"]) == 0
    assert "exported 144 boxes of 2 tracks as cvat" in capsys.readouterr().out
    assert not (tmp_path / "cvat" / "images").exists()
    assert main(["import", str(tmp_path / "cvat"), "--format", "cvat", "-o", str(tmp_path / "back.csv"),
                 "--video", str(files / "clip.avi")]) == 0
    pd.testing.assert_frame_equal(read_tracks_csv(tmp_path / "back.csv"), read_tracks_csv(files / "truth.csv"))


def test_export_every_with_frames(files, tmp_path):
    assert main(["export", str(files / "truth.csv"), "--video", str(files / "clip.avi"), "--format", "coco",
                 "-o", str(tmp_path / "coco"), "--every", "10"]) == 0
    assert sorted(p.name for p in (tmp_path / "coco" / "images").iterdir()) == ["frame_000000.jpg", "frame_000010.jpg"]


def test_import_with_mapping_reports_skipped_labels(tmp_path, capsys):
    gt = tmp_path / "gt.txt"
    gt.write_text("1,1,11,21,30,60,1,1,1\n1,2,50,20,30,60,1,4,1\n")
    assert main(["import", str(gt), "--format", "mot", "-o", str(tmp_path / "a.csv")]) == 0
    assert "skipped 1 boxes labelled '4'" in capsys.readouterr().err
    assert main(["import", str(gt), "--format", "mot", "-o", str(tmp_path / "b.csv"), "--mapping", "4=head"]) == 0
    assert sorted(read_tracks_csv(tmp_path / "b.csv")["part"]) == ["head", "person"]


def test_eval_json_and_plot(files, tmp_path, capsys):
    assert main(["eval", str(files / "truth.csv"), str(files / "truth.csv"), "--at", "3", "--json",
                 "--plot", str(tmp_path / "rate.html")]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["at"] == 3 and report["matching"] == "track_id"
    assert report["summary"]["torso"]["rate_at"] == 1.0 and report["mot"]["overall"]["mota"] == 1.0
    html = (tmp_path / "rate.html").read_text()
    assert "plotly" in html and "person_mbr" in html


def test_eval_text(files, capsys):
    assert main(["eval", str(files / "truth.csv"), str(files / "truth.csv")]) == 0
    out = capsys.readouterr().out
    assert "matched to truth by track_id" in out and "MOT metrics" in out and "mota" in out


@pytest.mark.parametrize("argv, message", [
    (["import", "{d}/nothing", "--format", "coco", "-o", "{t}/x.csv"], "no such file or directory"),
    (["import", "{d}/truth.csv", "--format", "cvat", "-o", "{t}/x.csv"], "not a readable XML file"),
    (["export", "{d}/truth.csv", "--video", "{d}/truth.csv", "--format", "mot", "-o", "{t}/o"], "not a video"),
    (["export", "{d}/truth.csv", "--video", "{d}/clip.avi", "--format", "mot", "-o", "{t}/o", "--every", "0"],
     "--every must be at least 1"),
    (["eval", "{d}/truth.csv", "{d}/nothing.csv"], "no such file"),
])
def test_clear_errors(files, tmp_path, capsys, argv, message):
    argv = [a.format(d=files, t=tmp_path) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"partlab {argv[0]}: ") and message in err


def test_export_with_events_writes_tags_and_refuses_events_of_another_clip(files, tmp_path, capsys):
    ev = tmp_path / "events.csv"
    ev.write_text("start_frame,end_frame,kind,track_id_a,part_a,track_id_b,part_b\n3,6,handshake,0,right_hand,3,"
                  "right_hand\n")
    args = ["export", str(files / "truth.csv"), "--video", str(files / "clip.avi"), "--format", "cvat", "--no-frames"]
    assert main(args + ["-o", str(tmp_path / "cvat"), "--events", str(ev)]) == 0
    xml = (tmp_path / "cvat" / "events.xml").read_text()
    assert xml.count('<tag label="handshake"') == 4  # frames 3, 4, 5, 6
    ev.write_text("start_frame,end_frame,kind\n15,25,clap\n")  # the clip has 20 frames
    assert main(args + ["-o", str(tmp_path / "late"), "--events", str(ev)]) == 2
    assert "the clap event 15-25 ends after the clip's last frame (19)" in capsys.readouterr().err
