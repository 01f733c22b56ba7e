import hashlib
import json
import pickle

import numpy as np
import pytest

from partlab.models.bundle import MANIFEST, Bundle, BundleError, load_bundle, save_bundle
from partlab.models.failure_svm import SVMFailureDetector
from partlab.tracking.params import BodyParams, LimbParams, PartNoise


@pytest.fixture
def bundle(trained_svms):
    _x, _y, models, reports = trained_svms
    body = BodyParams()
    noise = dict(body.dynamics.noise, head=PartNoise(x=1.5, y=1.25, w=1.0, h=1.0, vx=0.3, vy=0.2, lam=20.0))
    return Bundle(body.updated({"dynamics.noise": noise}), LimbParams().updated({"priors.sigma_d": 7.5}),
                  SVMFailureDetector(models),
                  {"svms": {n: r.to_dict() for n, r in reports.items()}, "nan": float("nan")})


def test_round_trip_gives_identical_decisions(bundle, trained_svms, tmp_path):
    x = trained_svms[0][:300]
    save_bundle(bundle, tmp_path / "b")
    loaded = load_bundle(tmp_path / "b")
    assert loaded.body_params == bundle.body_params and loaded.limb_params.priors.sigma_d == 7.5
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
    m["params"]["body"]["particles"]["max"] = 5000
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
        assert b.body_params.dynamics.noise == BodyParams().dynamics.noise
        assert scores["+noise"]["mean"] <= scores["builtin"]["mean"]
    if not sel["kept"]["extent"]:
        assert b.body_params.output.extent == BodyParams().output.extent
    assert (b.failure_detector is not None) == sel["kept"]["detector"]
    if b.failure_detector is not None:
        assert set(b.failure_detector.models) == {"head", "torso", "hipleg", "multi"}


def test_a_bundle_applies_what_was_learned_over_the_installed_defaults(tmp_path):
    """Hand-set tunables follow the installed partlab; fitted ones come from the bundle."""

    from partlab.models.bundle import Bundle, load_bundle, save_bundle
    from partlab.tracking.params import BodyParams, LimbParams, PartNoise

    noise = dict(BodyParams().dynamics.noise, head=PartNoise(x=9.0, y=8.0, w=1.0, h=1.0, vx=1.0, vy=1.0, lam=7.0))
    body = BodyParams().updated({"dynamics.noise": noise, "output.extent": {"head": (2.0, 2.0, 0.0, 0.0)},
                                 "particles.initial": 321})
    limb = LimbParams().updated({"priors.sigma_d": 33.0, "dynamics.particles": 77})
    save_bundle(Bundle(body, limb, None, {}), tmp_path / "b")
    loaded = load_bundle(tmp_path / "b")
    assert loaded.body_params.dynamics.noise["head"].x == 9.0 and loaded.body_params.dynamics.noise["head"].lam == 7.0
    assert loaded.body_params.output.extent == {"head": (2.0, 2.0, 0.0, 0.0)}
    assert loaded.limb_params.priors.sigma_d == 33.0
    assert loaded.body_params.particles.initial == BodyParams().particles.initial  # not learned
    assert loaded.limb_params.dynamics.particles == LimbParams().dynamics.particles


def test_parameters_are_saved_by_registry_key_and_version_1_bundles_still_load(tmp_path):
    """Version 2 writes ``params`` by the registry's parameter key, nested by group; a version-1
    bundle (partlab 0.2: flat ``body_params`` / ``limb_params``, like the shipped one) loads the same."""
    import hashlib

    from partlab.models.bundle import FORMAT_VERSION, Bundle, _canonical, load_bundle, save_bundle
    from partlab.tracking.params import BodyParams, LimbParams, PartNoise

    noise = dict(BodyParams().dynamics.noise, torso=PartNoise(x=7.0, y=6.0, w=2.0, h=2.0, vx=1.0, vy=1.0, lam=11.0))
    body = BodyParams().updated({"dynamics.noise": noise})
    limb = LimbParams().updated({"priors.sigma_s": 3.5})
    root = save_bundle(Bundle(body, limb, None, {}), tmp_path / "v2")
    m = json.loads((root / MANIFEST).read_text())
    assert m["version"] == FORMAT_VERSION == 2 and set(m["params"]) == {"body", "limbs"}
    assert m["params"]["body"]["dynamics"]["noise"]["torso"]["lam"] == 11.0
    assert m["params"]["limbs"]["priors"]["sigma_s"] == 3.5
    new = load_bundle(root)
    # the same bundle as partlab 0.2 wrote it
    flat_body = {old: body.get(new_) for old, new_ in BodyParams.FLAT.items()}
    flat_body["part_noise"] = {k: vars(v) | {} for k, v in noise.items()}
    flat_limb = {old: limb.get(new_) for old, new_ in LimbParams.FLAT.items()}
    v1 = {k: v for k, v in m.items() if k not in ("params", "manifest_sha256")}
    v1.update(version=1, body_params=json.loads(json.dumps(flat_body)), limb_params=flat_limb)
    v1["manifest_sha256"] = hashlib.sha256(_canonical(v1)).hexdigest()
    (tmp_path / "v1").mkdir()
    (tmp_path / "v1" / MANIFEST).write_text(json.dumps(v1))
    old = load_bundle(tmp_path / "v1")
    assert old.body_params == new.body_params == body
    assert old.limb_params == new.limb_params == limb
    assert old.params["body"].dynamics.noise["torso"].x == 7.0
