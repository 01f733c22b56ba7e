"""Cameras and calibration files: projection agrees with OpenCV, files round-trip, XML imports."""

import cv2
import numpy as np
import pytest

from partlab.labelling.calibration import CalibrationError, read_calibration, read_opencv_xml, write_calibration
from partlab.tracking.camera import Camera

K = [[800.0, 0, 320], [0, 800.0, 240], [0, 0, 1]]


def _cam(name="c", rvec=(0.1, -0.2, 0.05), t=(50.0, -20.0, 3000.0), dist=(-0.1, 0.01, 0, 0, 0)):
    return Camera(name, K=K, size=(640, 480), dist=dist, R=cv2.Rodrigues(np.array(rvec))[0], t=t)


def test_projection_rays_and_back_projection_agree():
    cam = _cam()
    pts = np.array([[0, 0, 0], [200, -100, 300], [-400, 250, -150.0]])
    uv = cam.project(pts)
    # a point on the line of sight of its own pixel: centre + s * ray
    rays = cam.rays(uv)
    for p, d in zip(pts, rays):
        v = p - cam.centre
        assert np.linalg.norm(np.cross(v / np.linalg.norm(v), d)) < 1e-6
    z = cam.to_camera(pts)[:, 2]
    assert cam.back_project(uv, z) == pytest.approx(pts, abs=1e-6)


def test_json_round_trip(tmp_path):
    cams = [_cam("a"), _cam("b", rvec=(0, 0.5, 0), t=(-800, 0, 3000))]
    path = write_calibration(cams, tmp_path / "calibration.json")
    back = read_calibration(path)
    assert list(back) == ["a", "b"]
    assert back["b"].P == pytest.approx(cams[1].P)
    path.write_text('{"cameras": [{"name": "a", "K": [1, 2], "image_size": [640, 480]}]}')
    with pytest.raises(CalibrationError, match=r"cameras\[0\]: camera 'a' K: expected 3x3 numbers, got 2"):
        read_calibration(path)


def test_opencv_filestorage_xml(tmp_path):
    cam = _cam()
    path = tmp_path / "cam.xml"
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("image_width", 640)
    fs.write("image_height", 480)
    fs.write("camera_matrix", np.array(K))
    fs.write("distortion_coefficients", cam.dist.reshape(1, 5))
    fs.write("rvec", cv2.Rodrigues(cam.R)[0])
    fs.write("tvec", cam.t.reshape(3, 1))
    fs.release()
    back = read_opencv_xml(path)
    assert back.size == (640, 480) and back.P == pytest.approx(cam.P)


def test_tsai_xml_as_pets_writes_it(tmp_path):
    # PETS 2009's layout (Tsai's model); the numbers are made up for this test
    path = tmp_path / "View_009_calibration.xml"
    path.write_text('<?xml version="1.0"?>\n<Camera name="View_009">'
                    '<Geometry width="768" height="576" ncx="795" nfx="752" dx="4.85e-03" dy="4.65e-03" '
                    'dpx="5.0e-03" dpy="5.0e-03"/>'
                    '<Intrinsic focal="5.0" kappa1="0" cx="384" cy="288" sx="1.0"/>'
                    '<Extrinsic tx="0" ty="0" tz="10000" rx="0" ry="0" rz="0"/></Camera>')
    cam = read_calibration(path)["View_009"]
    assert cam.K[0, 0] == pytest.approx(1000.0) and cam.K[1, 1] == pytest.approx(1000.0)
    # a point 1 m right of the axis at 10 m depth lands 100 px right of the principal point
    assert cam.project(np.array([[1000.0, 0, 0]]))[0] == pytest.approx([484.0, 288.0])
