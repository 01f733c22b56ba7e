"""The bundle loader on malformed but correctly hashed manifests and oversized arrays: a Bundle or a
BundleError naming the file, never another exception; an array over the limit is refused before it is read."""

import hashlib
import io
import json
import shutil
import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from partlab.models.bundle import MANIFEST, Bundle, BundleError, _canonical, load_bundle, save_bundle
from partlab.models.failure_svm import SVMFailureDetector


@pytest.fixture(scope="module")
def saved(trained_svms, tmp_path_factory):
    root = tmp_path_factory.mktemp("bundle") / "b"
    save_bundle(Bundle(failure_detector=SVMFailureDetector(trained_svms[2])), root)
    return root


def _rehash(root, manifest):
    manifest["manifest_sha256"] = hashlib.sha256(_canonical(manifest)).hexdigest()
    (root / MANIFEST).write_text(json.dumps(manifest))


LEAF = st.one_of(st.none(), st.booleans(), st.integers(-3, 2**70), st.floats(allow_nan=False, allow_infinity=False),
                 st.text(max_size=6), st.just("svm_head.npz"))
JSON = st.recursive(LEAF, lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=6), c, max_size=3),
                    max_leaves=6)
#: paths into the manifest worth breaking
PATHS = st.sampled_from([("params",), ("params", "body"), ("params", "body", "dynamics"), ("detector",),
                         ("detector", "svms"), ("detector", "svms", "head"), ("detector", "svms", "head", "file"),
                         ("detector", "svms", "head", "intercept"), ("detector", "svms", "head", "gamma"),
                         ("detector", "dt"), ("detector", "persist"), ("summary",), ("files",), ("created",)])


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(PATHS, JSON)
def test_hashed_but_malformed_manifests(saved, tmp_path_factory, path, value):
    root = tmp_path_factory.mktemp("m") / "b"
    shutil.copytree(saved, root)
    manifest = json.loads((root / MANIFEST).read_text())
    node = manifest
    for key in path[:-1]:
        node = node.get(key) if isinstance(node, dict) else None
    if not isinstance(node, dict):
        return
    node[path[-1]] = value
    _rehash(root, manifest)
    try:
        bundle = load_bundle(root)
    except BundleError as exc:
        assert str(root) in str(exc)
    else:
        assert isinstance(bundle.summary, dict)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def _zeros_npz(path, shape):
    """An .npz whose head array is ``shape`` of zeros: deflated to a few kB, huge when loaded."""
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name in ("mean", "scale", "support_vectors", "dual_coef"):
            header = io.BytesIO()
            dtype = np.dtype(np.float64)
            size = int(np.prod(shape)) * dtype.itemsize if name == "support_vectors" else 8
            np.lib.format.write_array_header_1_0(header, {"descr": dtype.str, "fortran_order": False,
                                                          "shape": shape if name == "support_vectors" else (1,)})
            with zf.open(f"{name}.npy", "w", force_zip64=True) as f:
                f.write(header.getvalue())
                chunk = b"\0" * (1 << 20)
                for _ in range(size // len(chunk)):
                    f.write(chunk)
                f.write(b"\0" * (size % len(chunk)))


def test_an_oversized_array_is_refused_before_it_is_read(saved, tmp_path, monkeypatch):
    root = tmp_path / "b"
    shutil.copytree(saved, root)
    f = root / "svm_head.npz"
    _zeros_npz(f, (4096, 2048))  # 64 MiB when loaded, about 64 kB on disk
    assert f.stat().st_size < 1 << 20
    manifest = json.loads((root / MANIFEST).read_text())
    manifest["files"]["svm_head.npz"] = hashlib.sha256(f.read_bytes()).hexdigest()
    _rehash(root, manifest)
    monkeypatch.setenv("PARTLAB_MAX_BUNDLE_ARRAY_BYTES", str(8 * 2**20))
    with pytest.raises(BundleError, match=r"svm_head.npz: member support_vectors.npy is 67108992 bytes uncompressed, "
                                          r"over the limit of 8388608 \(set PARTLAB_MAX_BUNDLE_ARRAY_BYTES"):
        load_bundle(root)


def test_a_header_claiming_a_huge_array_is_refused(saved, tmp_path):
    """A .npy header stating 2**40 floats in a tiny member: refused from the header, nothing allocated."""
    root = tmp_path / "b"
    shutil.copytree(saved, root)
    f = root / "svm_head.npz"
    with zipfile.ZipFile(f, "w") as zf:
        for name in ("mean", "scale", "support_vectors", "dual_coef"):
            header = io.BytesIO()
            np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False,
                                                          "shape": (2**20, 2**20)})
            zf.writestr(f"{name}.npy", header.getvalue())
    manifest = json.loads((root / MANIFEST).read_text())
    manifest["files"]["svm_head.npz"] = hashlib.sha256(f.read_bytes()).hexdigest()
    _rehash(root, manifest)
    with pytest.raises(BundleError, match=r"array mean.npy of shape \(1048576, 1048576\) is 8796093022208 bytes"):
        load_bundle(root)


def test_nan_in_a_hashed_bundle_is_refused(saved, tmp_path):
    root = tmp_path / "b"
    shutil.copytree(saved, root)
    manifest = json.loads((root / MANIFEST).read_text())
    manifest["detector"]["svms"]["head"]["intercept"] = "nan"
    _rehash(root, manifest)
    with pytest.raises(BundleError, match="SVM 'head' intercept is 'nan', not a finite number"):
        load_bundle(root)
