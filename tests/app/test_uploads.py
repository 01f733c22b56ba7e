"""Upload checks: extension, size limit from PARTLAB_MAX_UPLOAD_MB, undecodable content."""

from __future__ import annotations

import pytest

from partlab.app.uploads import UploadRefused, check_upload, max_upload_mb, save_upload


def test_limit_comes_from_the_environment(monkeypatch):
    assert max_upload_mb() == 1024
    monkeypatch.setenv("PARTLAB_MAX_UPLOAD_MB", "5")
    assert max_upload_mb() == 5
    monkeypatch.setenv("PARTLAB_MAX_UPLOAD_MB", "lots")
    with pytest.raises(UploadRefused, match="whole number of megabytes"):
        max_upload_mb()


def test_refusals_say_why():
    with pytest.raises(UploadRefused, match=r"\.pdf is not a video type"):
        check_upload("paper.pdf", 1000, limit_mb=10)
    with pytest.raises(UploadRefused, match=r"11\.0 MB is over the 10 MB limit"):
        check_upload("clip.mp4", 11 * 2**20, limit_mb=10)
    with pytest.raises(UploadRefused, match="empty"):
        check_upload("clip.MOV", 0, limit_mb=10)
    check_upload("clip.MKV", 10 * 2**20, limit_mb=10)  # exactly at the limit is fine


def test_save_upload_adds_a_clip_or_refuses_garbage(store, clip_file, tmp_path):
    project = store.create_project("p")
    clip = save_upload(store, project.id, "walker.mp4", clip_file.read_bytes())
    assert (clip.name, clip.frame_count, clip.width, clip.height) == ("walker.mp4", 12, 96, 72)
    with pytest.raises(UploadRefused, match=r"refused: broken\.mp4: not a video OpenCV can decode"):
        save_upload(store, project.id, "broken.mp4", b"this is not a video" * 100)
    assert [c.name for c in store.clips(project.id)] == ["walker.mp4"]
    assert not any((tmp_path / "partlab-data" / "uploads").iterdir())  # temporary files removed


def test_a_zip_of_frames_uploads_as_a_clip(store, clip_file, tmp_path):
    import io
    import zipfile

    import cv2

    from partlab.labelling.video import VideoClip

    cap = cv2.VideoCapture(str(clip_file))
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for k in range(5):
            ok, frame = cap.read()
            zf.writestr(f"seq/{k + 1:06d}.png", cv2.imencode(".png", frame)[1].tobytes())
    cap.release()
    project = store.create_project("z")
    clip = save_upload(store, project.id, "frames.zip", buf.getvalue())
    assert (clip.name, clip.frame_count, clip.width, clip.height, clip.fps) == ("frames.zip", 5, 96, 72, 25.0)
    assert VideoClip(clip.path).read(4).shape == (72, 96, 3)
    with pytest.raises(UploadRefused, match=r"refused: notes\.zip: not a video OpenCV can decode"):
        save_upload(store, project.id, "notes.zip", b"PK\x03\x04 not really a zip" * 10)
