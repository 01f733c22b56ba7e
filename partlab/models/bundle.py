"""Model bundles: a versioned directory of everything retraining fits.

Layout (format ``partlab-model-bundle``, version 2)::

    BUNDLE_DIR/
      bundle.json      format, version, created, params {key: nested parameters} (by the
                       registry's parameter key: "body", "limbs", ...),
                       detector (dt, normalise, persist, per-SVM kernel/intercept/gamma/threshold),
                       summary (clips, sample counts, CV scores, thresholds, fitted variances),
                       files {name: sha256}, manifest_sha256
      svm_head.npz     scaler mean/scale, support vectors, dual coefficients (float64)
      svm_torso.npz, svm_hipleg.npz, svm_multi.npz

Loading never runs code from the bundle: the SVMs are plain float arrays read with
``np.load(allow_pickle=False)`` and evaluated in numpy (:class:`partlab.models.failure_svm.SVMModel`),
parameters are JSON. Before anything is read, every file is checked against the
SHA-256 in the manifest (and the manifest against its own hash); a file that is
missing, changed, not listed, or a directory without ``bundle.json`` is refused
with a message saying which. The hashes catch corruption and edits; the safety
comes from the formats, which cannot carry code.

Version 1 (partlab 0.2, and the shipped bundle) stored ``body_params`` and ``limb_params`` as
flat dicts; they are read as they are (:meth:`partlab.tracking.core.params.Parameters.from_dict`
reads the flat form).
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import re
import zipfile
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib import resources
from os import PathLike
from pathlib import Path

import numpy as np

from partlab.limits import max_bundle_array_bytes
from partlab.models.failure_svm import SVMFailureDetector, SVMModel
from partlab.models.features import DEFAULT_DT
from partlab.models.labels import SVM_NAMES
from partlab.tracking.params import BodyParams, LimbParams

FORMAT_NAME = "partlab-model-bundle"
FORMAT_VERSION = 2
MANIFEST = "bundle.json"
_ARRAY_NAMES = ("mean", "scale", "support_vectors", "dual_coef")
_SAFE_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.-]*\.npz$")


class BundleError(ValueError):
    """A directory that is not a usable model bundle; the message says why."""


@dataclass(frozen=True, eq=False)
class Bundle:
    """What ``partlab track --model`` uses: tracker parameters and the failure detector."""

    body_params: BodyParams = field(default_factory=BodyParams)
    limb_params: LimbParams = field(default_factory=LimbParams)
    failure_detector: SVMFailureDetector | None = None
    summary: dict = field(default_factory=dict)
    created: str = ""
    #: parameters of other registry keys (trackers added after body and limbs), by key
    more_params: dict = field(default_factory=dict)

    @property
    def params(self) -> dict:
        """Every parameters object by the registry's key (what :func:`partlab.tracking.run.track` reads)."""
        return {"body": self.body_params, "limbs": self.limb_params, **self.more_params}


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _write_npz(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """An ``.npz`` (deflated zip of ``.npy``) with fixed timestamps, so the same arrays
    give the same bytes and the shipped bundle rebuilds identically."""
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name, arr in arrays.items():
            buf = io.BytesIO()
            np.lib.format.write_array(buf, np.ascontiguousarray(arr), allow_pickle=False)
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, buf.getvalue())


def _json_safe(obj):
    """NaN/inf -> None, numpy scalars -> Python, tuples -> lists (strict JSON)."""
    if isinstance(obj, dict):
        return {str(k): _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_safe(v) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _canonical(manifest: dict) -> bytes:
    body = {k: v for k, v in manifest.items() if k != "manifest_sha256"}
    return json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=False).encode("utf-8")


def save_bundle(bundle: Bundle, path: str | PathLike) -> Path:
    """Write ``bundle`` to the directory ``path`` (created; an existing bundle there is
    replaced, any other non-empty directory is refused so nothing of the user's is lost)."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise BundleError(f"{out}: exists and is not a directory")
    if out.is_dir() and any(out.iterdir()) and not (out / MANIFEST).is_file():
        raise BundleError(f"{out}: a non-empty directory that is not a model bundle; choose another output")
    out.mkdir(parents=True, exist_ok=True)
    if (out / MANIFEST).is_file():
        for old in out.glob("*.npz"):
            old.unlink()
    files: dict[str, str] = {}
    detector = None
    if bundle.failure_detector is not None:
        det = bundle.failure_detector
        svms = {}
        for name, model in det.models.items():
            fname = f"svm_{name}.npz"
            _write_npz(out / fname, {k: np.asarray(v, dtype=np.float64) for k, v in model.arrays().items()})
            files[fname] = _sha256(out / fname)
            svms[name] = {**model.meta(), "file": fname}
        detector = {"dt": det.dt, "normalise": det.normalise, "persist": det.persist, "svms": svms}
    manifest = _json_safe({
        "format": FORMAT_NAME,
        "version": FORMAT_VERSION,
        "created": bundle.created or datetime.now(UTC).isoformat(timespec="seconds"),
        "params": {key: p.to_dict() for key, p in bundle.params.items()},
        "detector": detector,
        "summary": bundle.summary,
        "files": files,
    })
    manifest["manifest_sha256"] = hashlib.sha256(_canonical(manifest)).hexdigest()
    (out / MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True, allow_nan=False) + "\n",
                                encoding="utf-8")
    return out


def _read_manifest(root: Path) -> dict:
    if not root.exists():
        raise BundleError(f"{root}: no such bundle directory")
    if not root.is_dir():
        raise BundleError(f"{root}: a model bundle is a directory, this is a file")
    mpath = root / MANIFEST
    if not mpath.is_file():
        raise BundleError(f"{root}: not a partlab model bundle (no {MANIFEST})")
    try:
        manifest = json.loads(mpath.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise BundleError(f"{mpath}: not valid JSON ({exc})") from None
    except RecursionError:
        raise BundleError(f"{mpath}: JSON nested too deeply") from None
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT_NAME:
        raise BundleError(f"{root}: not a partlab model bundle ({MANIFEST} does not say format {FORMAT_NAME!r})")
    version = manifest.get("version")
    if not isinstance(version, int) or version < 1:
        raise BundleError(f"{mpath}: invalid format version {version!r}")
    if version > FORMAT_VERSION:
        raise BundleError(f"{root}: bundle format version {version} is newer than this partlab reads "
                          f"({FORMAT_VERSION}); upgrade partlab")
    expected = manifest.get("manifest_sha256")
    try:
        actual = hashlib.sha256(_canonical(manifest)).hexdigest()
    except ValueError:
        actual = None
    if expected != actual:
        raise BundleError(f"{mpath}: the manifest was modified after the bundle was written (hash mismatch); "
                          "refusing to load it")
    return manifest


def _verify_files(root: Path, manifest: dict) -> dict[str, str]:
    files = manifest.get("files")
    if not isinstance(files, dict):
        raise BundleError(f"{root / MANIFEST}: 'files' must map file names to SHA-256 hashes")
    for name in files:
        if not isinstance(name, str) or not _SAFE_NAME.match(name) or "/" in name or "\\" in name:
            raise BundleError(f"{root / MANIFEST}: file name {name!r} is not allowed (plain *.npz names only)")
    present = {p.name for p in root.iterdir()}
    unexpected = sorted(present - set(files) - {MANIFEST})
    if unexpected:
        raise BundleError(f"{root}: file(s) not in the bundle manifest: {', '.join(unexpected)}; "
                          "a bundle holds only what it lists (refusing to load it)")
    for name, digest in files.items():
        p = root / name
        if not p.is_file():
            raise BundleError(f"{root}: {name} listed in the manifest is missing")
        if _sha256(p) != digest:
            raise BundleError(f"{p}: contents changed since the bundle was written (SHA-256 mismatch); "
                              "refusing to load it")
    return files


def _check_array_sizes(path: Path) -> None:
    """Refuse an ``.npz`` any of whose arrays (or members) is larger than
    ``PARTLAB_MAX_BUNDLE_ARRAY_BYTES``, from the zip directory and each ``.npy`` header, before
    any array is read (a small deflated file can hold a huge array of zeros)."""
    limit = max_bundle_array_bytes()
    try:
        with zipfile.ZipFile(path) as zf:
            for info in zf.infolist():
                if info.file_size > limit + 4096:
                    raise BundleError(f"{path}: member {info.filename} is {info.file_size} bytes uncompressed, over "
                                      f"the limit of {limit} (set PARTLAB_MAX_BUNDLE_ARRAY_BYTES to change it)")
                with zf.open(info) as f:
                    version = np.lib.format.read_magic(f)
                    if version == (1, 0):
                        shape, _, dtype = np.lib.format.read_array_header_1_0(f)
                    else:
                        shape, _, dtype = np.lib.format.read_array_header_2_0(f)
                nbytes = math.prod(int(n) for n in shape) * dtype.itemsize
                if nbytes > limit:
                    raise BundleError(f"{path}: array {info.filename} of shape {tuple(shape)} is {nbytes} bytes, over "
                                      f"the limit of {limit} (set PARTLAB_MAX_BUNDLE_ARRAY_BYTES to change it)")
    except BundleError:
        raise
    except Exception as exc:  # zip errors, truncated files, headers that are not .npy
        raise BundleError(f"{path}: not a readable .npz file of plain arrays ({exc})") from None


def _load_arrays(path: Path) -> dict[str, np.ndarray]:
    _check_array_sizes(path)
    try:
        with np.load(path, allow_pickle=False) as npz:
            arrays = {k: npz[k] for k in npz.files}
    except ValueError as exc:
        raise BundleError(f"{path}: holds something other than plain numeric arrays ({exc})") from None
    except Exception as exc:  # zip errors, truncated files
        raise BundleError(f"{path}: not a readable .npz file ({exc})") from None
    missing = [k for k in _ARRAY_NAMES if k not in arrays]
    if missing:
        raise BundleError(f"{path}: missing array(s) {', '.join(missing)}")
    for k, a in arrays.items():
        if a.dtype.kind != "f":
            raise BundleError(f"{path}: array {k!r} has dtype {a.dtype}, expected floats")
        if not np.isfinite(a).all():
            raise BundleError(f"{path}: array {k!r} holds NaN or infinite values")
    return arrays


#: What training fits; a loaded bundle applies these over the installed defaults. The
#: manifest records every parameter as it was at training time (for the record), but the
#: hand-set tunables follow the installed partlab, so improving a default never needs every
#: bundle to be retrained.
LEARNED_BODY_FIELDS: tuple[str, ...] = ("dynamics.noise", "output.extent")
LEARNED_LIMB_FIELDS: tuple[str, ...] = ("priors.sigma_v", "priors.sigma_d", "priors.sigma_s")
#: What training may fit from person boxes (:mod:`partlab.models.person`): applied only where the
#: bundle's summary lists them as learnt (``summary["person"]["fields"]``), so a bundle that did
#: not learn them follows the installed defaults like every other hand-set tunable.
PERSON_BODY_FIELDS: tuple[str, ...] = ("output.person", "detector.min_score", "detector.shrink",
                                       "detector.steer", "detector.steer_velocity", "detector.undetected_frames",
                                       "detection.leave_fraction")


def learned_body_params(saved: BodyParams, person_fields=()) -> BodyParams:
    fields = (*LEARNED_BODY_FIELDS, *(f for f in PERSON_BODY_FIELDS if f in set(person_fields)))
    return BodyParams().updated({k: saved.get(k) for k in fields})


def person_fields(summary) -> list[str]:
    """The person-box fields a bundle's summary says training learnt (others are ignored)."""
    person = summary.get("person") if isinstance(summary, dict) else None
    listed = person.get("fields", []) if isinstance(person, dict) else []
    return [f for f in PERSON_BODY_FIELDS if isinstance(listed, list) and f in listed]


def learned_limb_params(saved: LimbParams) -> LimbParams:
    return LimbParams().updated({k: saved.get(k) for k in LEARNED_LIMB_FIELDS})


def _read_params(manifest: dict) -> tuple[BodyParams, LimbParams, dict]:
    """The parameters of a manifest: version 2's ``params`` by key, or version 1's flat
    ``body_params`` / ``limb_params``; the fitted fields over the installed defaults."""
    from partlab.tracking import registry

    if manifest["version"] == 1:
        saved = {"body": manifest["body_params"], "limbs": manifest["limb_params"]}
    else:
        saved = manifest["params"]
        if not isinstance(saved, dict):
            raise ValueError("'params' must map parameter keys to parameters")
    unknown = sorted(set(saved) - set(registry.PARAMETERS))
    if unknown:
        raise ValueError(f"parameters of unknown kind(s) {', '.join(unknown)} (a newer partlab's trackers?)")
    learnt = person_fields(manifest.get("summary"))
    body = learned_body_params(BodyParams.from_dict(saved["body"]), learnt) if "body" in saved else BodyParams()
    limb = learned_limb_params(LimbParams.from_dict(saved["limbs"])) if "limbs" in saved else LimbParams()
    more = {k: registry.params_class(k).from_dict(v) for k, v in saved.items() if k not in ("body", "limbs")}
    return body, limb, more


def load_bundle(path: str | PathLike) -> Bundle:
    """Read and verify a bundle written by :func:`save_bundle`."""
    root = Path(path)
    manifest = _read_manifest(root)
    _verify_files(root, manifest)
    try:
        body, limb, more = _read_params(manifest)
    except (KeyError, TypeError, ValueError, AttributeError, OverflowError, RecursionError) as exc:
        raise BundleError(f"{root / MANIFEST}: bad parameters ({type(exc).__name__}: {str(exc)[:160]})") from None
    detector = None
    det = manifest.get("detector")
    if det is not None:
        models = {}
        try:
            for name, meta in det["svms"].items():
                if name not in SVM_NAMES:
                    raise BundleError(f"{root / MANIFEST}: unknown SVM {name!r}")
                if meta["file"] not in manifest["files"]:
                    raise BundleError(f"{root / MANIFEST}: SVM {name!r} file {meta['file']!r} is not in 'files'")
                numbers = {k: float(meta[k] or 0.0) if k == "gamma" else float(meta[k])
                           for k in ("intercept", "gamma", "threshold")}
                bad = [k for k, v in numbers.items() if not math.isfinite(v)]
                if bad:
                    raise BundleError(f"{root / MANIFEST}: SVM {name!r} {bad[0]} is {meta[bad[0]]!r}, "
                                      "not a finite number")
                arrays = _load_arrays(root / meta["file"])
                models[name] = SVMModel(
                    kernel=str(meta["kernel"]), intercept=float(meta["intercept"]),
                    gamma=float(meta["gamma"] or 0.0), threshold=float(meta["threshold"]),
                    **{k: arrays[k] for k in _ARRAY_NAMES},
                )
            detector = SVMFailureDetector(models, dt=float(det.get("dt", DEFAULT_DT)),
                                          normalise=bool(det.get("normalise", True)),
                                          persist=int(det.get("persist", 1)))
        except (KeyError, TypeError, AttributeError, OverflowError) as exc:
            raise BundleError(f"{root / MANIFEST}: bad detector description ({type(exc).__name__}: "
                              f"{str(exc)[:160]})") from None
        except ValueError as exc:
            if isinstance(exc, BundleError):
                raise
            raise BundleError(f"{root}: bad SVM arrays ({exc})") from None
    summary = manifest.get("summary") or {}
    if not isinstance(summary, dict):
        raise BundleError(f"{root / MANIFEST}: 'summary' must be an object, got {type(summary).__name__}")
    return Bundle(body, limb, detector, dict(summary), str(manifest.get("created", "")), more)


def default_bundle_path() -> Path:
    """Directory of the bundle shipped in the package (``models/default_bundle``)."""
    return Path(str(resources.files("partlab.models") / "default_bundle"))


def default_bundle() -> Bundle:
    """The bundle shipped with partlab, built by ``scripts/train_default_bundle.py``."""
    path = default_bundle_path()
    if not (path / MANIFEST).is_file():
        raise BundleError(f"the default bundle is missing from the package ({path}); "
                          "build it with scripts/train_default_bundle.py")
    return load_bundle(path)
