"""Calibration files: partlab's JSON (one file per take) and OpenCV's calibration XML.

partlab's form (``calibration.json`` in a take folder)::

    {"units": "mm",
     "cameras": [{"name": "cam0", "image_size": [768, 576],
                  "K": [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], "dist": [k1, k2, p1, p2, k3],
                  "R": [[...], [...], [...]], "t": [tx, ty, tz]}]}

``R, t`` take world points (mm) into the camera (``x_cam = R X + t``); every camera of a take
shares one world frame. OpenCV's XML (``cv2.FileStorage``, e.g. PETS 2009's
``View_001_calibration.xml`` written by Tsai's method, or what ``calibrateCamera`` tools save)
is read by :func:`read_opencv_xml`.
"""

from __future__ import annotations

import json
import math
from os import PathLike
from pathlib import Path

import numpy as np

from partlab.errors import UserError
from partlab.files import write_text
from partlab.tracking.camera import Camera

FILE_NAME = "calibration.json"


class CalibrationError(UserError):
    """A calibration file that cannot be used; the message names the file and the field."""


def read_calibration(path: str | PathLike) -> dict[str, Camera]:
    """Cameras by name from a partlab calibration JSON or an OpenCV/PETS XML file."""
    p = Path(path)
    if not p.is_file():
        raise CalibrationError(f"{p}: no such calibration file")
    if p.suffix.lower() in (".xml", ".yml", ".yaml"):
        return {c.name: c for c in [read_opencv_xml(p)]}
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise CalibrationError(f"{p}: not a calibration JSON ({exc})") from None
    cams = data.get("cameras") if isinstance(data, dict) else None
    if not isinstance(cams, list) or not cams:
        raise CalibrationError(f"{p}: expected an object with a non-empty list 'cameras'")
    if data.get("units", "mm") != "mm":
        raise CalibrationError(f"{p}: units {data.get('units')!r}; partlab calibrations are in mm")
    out: dict[str, Camera] = {}
    for i, cam in enumerate(cams):
        try:
            camera = Camera.from_dict(cam, name=f"cam{i}")
        except (ValueError, TypeError) as exc:
            raise CalibrationError(f"{p}: cameras[{i}]: {exc}") from None
        if camera.name in out:
            raise CalibrationError(f"{p}: cameras[{i}]: name {camera.name!r} is used twice")
        out[camera.name] = camera
    return out


def write_calibration(cameras, path: str | PathLike) -> Path:
    """Write ``cameras`` (a mapping or a list of :class:`Camera`) as partlab JSON, atomically."""
    cams = list(cameras.values()) if isinstance(cameras, dict) else list(cameras)
    p = Path(path)
    text = json.dumps({"units": "mm", "cameras": [c.to_dict() for c in cams]}, indent=1)
    write_text(p, text)
    return p


def _node(fs, names: tuple[str, ...]):
    for name in names:
        node = fs.getNode(name)
        if not node.empty():
            return node
    return None


def read_opencv_xml(path: str | PathLike, name: str | None = None) -> Camera:
    """One camera from an OpenCV ``FileStorage`` XML/YAML file.

    Two layouts are understood: OpenCV's own (``camera_matrix``/``cameraMatrix``,
    ``distortion_coefficients``/``distCoeffs``, optional ``rvec``/``R`` and ``tvec``/``T``,
    ``image_width``/``image_height``) and PETS 2009's Tsai calibration (``<Camera>`` with
    ``<Geometry width height dx dy ...>``, ``<Intrinsic focal kappa1 cx cy sx>`` and
    ``<Extrinsic tx ty tz rx ry rz>``, translation in mm, rotation angles in radians).
    """
    p = Path(path)
    text = p.read_text(encoding="utf-8", errors="replace")
    if "<Geometry" in text and "<Intrinsic" in text:
        return _read_tsai(p, text, name)
    import cv2

    fs = cv2.FileStorage(str(p), cv2.FILE_STORAGE_READ)
    if not fs.isOpened():
        raise CalibrationError(f"{p}: OpenCV cannot read this calibration file")
    try:
        k_node = _node(fs, ("camera_matrix", "cameraMatrix", "K", "M1"))
        if k_node is None:
            raise CalibrationError(f"{p}: no camera_matrix / cameraMatrix / K node")
        K = k_node.mat()
        d_node = _node(fs, ("distortion_coefficients", "distCoeffs", "dist", "D1"))
        dist = d_node.mat().ravel() if d_node is not None else np.zeros(5)
        R = np.eye(3)
        r_node = _node(fs, ("R", "rotation_matrix"))
        rv_node = _node(fs, ("rvec", "rotation_vector"))
        if r_node is not None:
            R = r_node.mat()
        elif rv_node is not None:
            R = cv2.Rodrigues(rv_node.mat().reshape(3))[0]
        t_node = _node(fs, ("tvec", "T", "translation_vector", "t"))
        t = t_node.mat().reshape(3) if t_node is not None else np.zeros(3)
        w_node, h_node = _node(fs, ("image_width", "width")), _node(fs, ("image_height", "height"))
        if w_node is None or h_node is None:
            raise CalibrationError(f"{p}: no image_width / image_height")
        size = (int(w_node.real()), int(h_node.real()))
    finally:
        fs.release()
    try:
        return Camera(name=name or p.stem, K=K, size=size, dist=dist, R=R, t=t)
    except ValueError as exc:
        raise CalibrationError(f"{p}: {exc}") from None


def _read_tsai(p: Path, text: str, name: str | None) -> Camera:
    """PETS 2009 / Tsai: pinhole with one radial term kappa1 on *undistorted* sensor coordinates.

    OpenCV's model distorts normalised coordinates, Tsai's undistorts sensor millimetres:
    ``X_u = X_d (1 + kappa1 r_d^2)``. With ``r_d ~ f r_n`` (``r_n`` normalised, ``f`` in mm) the
    first-order inverse is OpenCV's ``k1 = -kappa1 f^2``, which is what is stored. Pixels are
    ``u = sx X_d / dpx + cx``, ``v = Y_d / dpy + cy``."""
    import defusedxml.ElementTree as ET

    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise CalibrationError(f"{p}: not XML ({exc})") from None
    cam = root if root.tag == "Camera" else root.find(".//Camera")
    geo, intr, ext = (cam.find(t) if cam is not None else None for t in ("Geometry", "Intrinsic", "Extrinsic"))
    if geo is None or intr is None or ext is None:
        raise CalibrationError(f"{p}: expected <Camera> with <Geometry>, <Intrinsic> and <Extrinsic>")

    def num(node, key: str) -> float:
        try:
            value = float(node.attrib[key])
        except (KeyError, ValueError):
            raise CalibrationError(f"{p}: <{node.tag}> lacks a number {key!r}") from None
        if not math.isfinite(value):
            raise CalibrationError(f"{p}: <{node.tag}> {key}={node.attrib[key]!r} is not finite")
        return value

    width, height = int(num(geo, "width")), int(num(geo, "height"))
    dpx, dpy = num(geo, "dpx"), num(geo, "dpy")
    focal, kappa1 = num(intr, "focal"), num(intr, "kappa1")
    cx, cy, sx = num(intr, "cx"), num(intr, "cy"), num(intr, "sx")
    fx, fy = focal * sx / dpx, focal / dpy
    K = np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
    # first-order inverse of Tsai's undistortion in normalised coordinates
    k1 = -kappa1 * focal * focal
    rx, ry, rz = num(ext, "rx"), num(ext, "ry"), num(ext, "rz")
    t = np.array([num(ext, "tx"), num(ext, "ty"), num(ext, "tz")])
    R = _tsai_rotation(rx, ry, rz)
    try:
        return Camera(name=name or str(cam.attrib.get("name", p.stem)), K=K, size=(width, height),
                      dist=np.array([k1, 0.0, 0.0, 0.0, 0.0]), R=R, t=t)
    except ValueError as exc:
        raise CalibrationError(f"{p}: {exc}") from None


def _tsai_rotation(rx: float, ry: float, rz: float) -> np.ndarray:
    """Tsai's rotation from Euler angles (radians): ``R = Rz(rz) Ry(ry) Rx(rx)``."""
    sa, ca = math.sin(rx), math.cos(rx)
    sb, cb = math.sin(ry), math.cos(ry)
    sg, cg = math.sin(rz), math.cos(rz)
    return np.array([
        [cb * cg, cg * sa * sb - ca * sg, sa * sg + ca * cg * sb],
        [cb * sg, sa * sb * sg + ca * cg, ca * sb * sg - cg * sa],
        [-sb, cb * sa, ca * cb],
    ])
