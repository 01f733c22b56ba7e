import hashlib
import json
import pickle

import numpy as np
import pytest

from partlab.models.bundle import Bundle, BundleError, load_bundle, save_bundle, MANIFEST
from partlab.models.failure_svm import SVMFailureDetector
from partlab.tracking.params import BodyParams, LimbParams, PartNoise


@pytest.fixture
def bundle(trained_svms):
    _x, _y, models, reports = trained_svms
    body = BodyParams()
    noise = dict(body.part_noise, head=PartNoise(x=1.5, y=1.25, w=1.0, h=1.0, vx=0.3, vy=0.2, lam=20.0))
    from dataclasses import replace
    return Bundle(replace(body, part_noise=noise), replace(LimbParams(), sigma_d=7.5),
                  SVMFailureDetector(models),
                  {"svms": {n: r.to_dict() for n, r in reports.items()}, "nan": float("nan")})


def test_round_trip_gives_identical_decisions(bundle, trained_svms, tmp_path):
    x = trained_svms[0][:300]
    save_bundle(bundle, tmp_path / "b")
    loaded = load_bundle(tmp_path / "b")
    assert loaded.body_params == bundle.body_params and loaded.limb_params.sigma_d == 7.5
    assert loaded.summary["nan"] is None and loaded.summary["svms"]["head"]["trained"] is True
    for name, m in bundle.failure_detector.models.items():
        np.testing.assert_array_equal(loaded.failure_detector.models[name].decision(x), m.decision(x))
        assert loaded.failure_detector.models[name].threshold == m.threshold
    np.testing.assert_array_equal(loaded.failure_detector.part_scores(x), bundle.failure_detector.part_scores(x))
    # writing again over a bundle is allowed
    save_bundle(loaded, tmp_path / "b")
    assert load_bundle(tmp_path / "b").created == loaded.created


def test_tampered_file_is_refused(bundle, tmp_path):
    root = save_bundle(bundle, tmp_path / "b")
    f = root / "svm_torso.npz"
    data = bytearray(f.read_bytes())
    data[len(data) // 2] ^= 0x01
    f.write_bytes(bytes(data))
    with pytest.raises(BundleError, match="svm_torso.npz.*changed"):
        load_bundle(root)


def test_edited_manifest_is_refused(bundle, tmp_path):
    root = save_bundle(bundle, tmp_path / "b")
    m = json.loads((root / MANIFEST).read_text())
    m["body_params"]["particles_max"] = 5000
    (root / MANIFEST).write_text(json.dumps(m))
    with pytest.raises(BundleError, match="manifest was modified"):
        load_bundle(root)


def test_foreign_directories_are_refused(tmp_path):
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "a.jpg").write_bytes(b"\xff\xd8")
    with pytest.raises(BundleError, match="not a partlab model bundle"):
        load_bundle(tmp_path / "photos")
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / MANIFEST).write_text(json.dumps({"format": "something-else", "version": 1}))
    with pytest.raises(BundleError, match="not a partlab model bundle"):
        load_bundle(tmp_path / "other")
    with pytest.raises(BundleError, match="no such"):
        load_bundle(tmp_path / "missing")
    with pytest.raises(BundleError, match="non-empty directory"):
        save_bundle(Bundle(), tmp_path / "photos")


class _Payload:
    def __init__(self, path):
        self.path = path

    def __reduce__(self):
        return (open, (self.path, "w"))


def test_pickles_in_a_bundle_are_never_executed(bundle, tmp_path):
    marker = tmp_path / "pwned"
    root = save_bundle(bundle, tmp_path / "b")
    # 1. a pickle file dropped next to the bundle's files
    (root / "model.pkl").write_bytes(pickle.dumps(_Payload(str(marker))))
    with pytest.raises(BundleError, match="model.pkl"):
        load_bundle(root)
    assert not marker.exists()
    (root / "model.pkl").unlink()
    # 2. an npz holding a pickled object array, with the manifest's hashes forged to match
    f = root / "svm_head.npz"
    arr = np.empty(1, dtype=object)
    arr[0] = _Payload(str(marker))
    with open(f, "wb") as fh:
        np.savez(fh, mean=arr, scale=arr, support_vectors=arr, dual_coef=arr)
    m = json.loads((root / MANIFEST).read_text())
    m["files"]["svm_head.npz"] = hashlib.sha256(f.read_bytes()).hexdigest()
    from partlab.models.bundle import _canonical
    m["manifest_sha256"] = hashlib.sha256(_canonical(m)).hexdigest()
    (root / MANIFEST).write_text(json.dumps(m))
    with pytest.raises(BundleError, match="other than plain numeric arrays"):
        load_bundle(root)
    assert not marker.exists()


def test_bundle_without_detector(tmp_path):
    root = save_bundle(Bundle(), tmp_path / "empty")
    b = load_bundle(root)
    assert b.failure_detector is None and b.body_params == BodyParams()


def test_same_bundle_gives_the_same_bytes(bundle, tmp_path):
    import dataclasses
    fixed = dataclasses.replace(bundle, created="2026-01-01T00:00:00+00:00")
    a, b = save_bundle(fixed, tmp_path / "a"), save_bundle(fixed, tmp_path / "b")
    for f in sorted(p.name for p in a.iterdir()):
        assert (a / f).read_bytes() == (b / f).read_bytes(), f


def test_default_bundle_ships_and_keeps_only_what_validation_approved():
    from partlab.models.bundle import default_bundle
    from partlab.tracking.params import BodyParams

    b = default_bundle()
    r = b.summary["svms"]["torso"]
    assert r["tnr"] >= 0.95 or r["tpr"] >= 0.95
    assert {c["name"] for c in b.summary["clips"]} >= {"single-101", "crowd-104"}
    assert b.summary["samples"]["tracker"] > 0
    sel = b.summary["selection"]
    assert set(sel["kept"]) == {"noise", "extent", "detector"}
    scores = sel["scores"]
    assert 0.5 < scores["builtin"]["mean"] <= 1.0
    # every component it uses scored above the built-in parameters on the training clips
    if not sel["kept"]["noise"]:
        assert b.body_params.part_noise == BodyParams().part_noise
        assert scores["+noise"]["mean"] <= scores["builtin"]["mean"]
    if not sel["kept"]["extent"]:
        assert b.body_params.output_extent == BodyParams().output_extent
    assert (b.failure_detector is not None) == sel["kept"]["detector"]
    if b.failure_detector is not None:
        assert set(b.failure_detector.models) == {"head", "torso", "hipleg", "multi"}


def test_a_bundle_applies_what_was_learned_over_the_installed_defaults(tmp_path):
    """Hand-set tunables follow the installed partlab; fitted ones come from the bundle."""
    from dataclasses import replace

    from partlab.models.bundle import Bundle, load_bundle, save_bundle
    from partlab.tracking.params import BodyParams, LimbParams, PartNoise

    noise = dict(BodyParams().part_noise, head=PartNoise(x=9.0, y=8.0, w=1.0, h=1.0, vx=1.0, vy=1.0, lam=7.0))
    body = replace(BodyParams(), part_noise=noise, output_extent={"head": (2.0, 2.0, 0.0, 0.0)},
                   particles_initial=321)
    limb = replace(LimbParams(), sigma_d=33.0, particles=77)
    save_bundle(Bundle(body, limb, None, {}), tmp_path / "b")
    loaded = load_bundle(tmp_path / "b")
    assert loaded.body_params.part_noise["head"].x == 9.0 and loaded.body_params.part_noise["head"].lam == 7.0
    assert loaded.body_params.output_extent == {"head": (2.0, 2.0, 0.0, 0.0)}
    assert loaded.limb_params.sigma_d == 33.0
    assert loaded.body_params.particles_initial == BodyParams().particles_initial  # not learned
    assert loaded.limb_params.particles == LimbParams().particles
