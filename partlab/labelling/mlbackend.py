"""partlab as a Label Studio ML backend (``partlab serve-ml``): ``predict`` proposes part boxes for video
tasks with partlab's trackers, ``fit`` retrains a model bundle from the annotations users submit, and the
next ``predict`` tracks with it.

The protocol is Label Studio's ML backend HTTP API (what the ``label-studio-ml`` package serves), spoken
here with the standard library so that no conflicting pins come in:

- ``GET /health`` (and ``GET /``): ``{"status": "UP", "model_class": "partlab", "model_version": ...}``;
- ``POST /setup``: ``{"model_version": ...}``;
- ``POST /predict`` ``{"tasks": [...], ...}``: ``{"results": [{"result": [videorectangle regions], "score",
  "model_version"}], "model_version"}``, one prediction per task, in the format of
  :mod:`partlab.labelling.formats.labelstudio`;
- ``POST /webhook`` (and ``/train``) with Label Studio's webhook body: ``ANNOTATION_CREATED`` and
  ``ANNOTATION_UPDATED`` keep the task's annotation (``MODEL_DIR/annotations/<task>.json``) and retrain;
  ``START_TRAINING`` retrains on every annotation kept. Retraining runs in a thread (the answer is
  ``{"status": "training"}`` at once); ``/health`` reports the new ``model_version`` when it is done.

A task's video is ``data.video``: a local path, a Label Studio upload (``/data/upload/...``, found under
``--data-root``, Label Studio's data directory, or downloaded from ``--ls-url`` with ``--api-key``) or
``/data/local-files/?d=...`` (under ``--document-root``). A task that already has an annotation is
tracked from its first annotated frame's boxes (the user's initial boxes); one without is tracked with
automatic initialisation. Retraining starts from the current bundle (the shipped one at first) and
writes ``MODEL_DIR/bundle-<version>``; the model version counts retrainings.
"""

from __future__ import annotations

import json
import shutil
import tempfile
import threading
import urllib.parse
import urllib.request
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pandas as pd

from partlab.errors import UserError
from partlab.labelling.formats import labelstudio
from partlab.labelling.video import VideoClip, probe
from partlab.tracking.parts import BOX_PARTS

TRAIN_ACTIONS = ("ANNOTATION_CREATED", "ANNOTATION_UPDATED")


class BackendError(UserError):
    """A request the backend cannot serve; sent back as HTTP 400 with the message."""


@dataclass
class PartlabBackend:
    """The backend's state: where bundles and annotations live, and how to find task videos."""

    model_dir: Path
    tracker: str = "body"
    data_root: Path | None = None
    document_root: Path | None = None
    ls_url: str | None = None
    api_key: str | None = None
    seed: int = 0
    train_with_tracker: bool = False  # validation runs of the tracker make fit minutes long; opt in
    version: int = 0
    last_fit: dict = field(default_factory=dict)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    _fits: list = field(default_factory=list, repr=False)

    def __post_init__(self):
        self.model_dir = Path(self.model_dir)
        (self.model_dir / "annotations").mkdir(parents=True, exist_ok=True)
        done = sorted(int(p.name.split("-")[1]) for p in self.model_dir.glob("bundle-*") if p.name[7:].isdigit())
        self.version = done[-1] if done else 0

    # -- models -----------------------------------------------------------------
    @property
    def model_version(self) -> str:
        return f"partlab-{self.version}"

    def bundle_path(self) -> Path | None:
        return self.model_dir / f"bundle-{self.version}" if self.version else None

    def model(self):
        from partlab.models import bundle

        path = self.bundle_path()
        return bundle.load_bundle(path) if path is not None else bundle.default_bundle()

    # -- videos -----------------------------------------------------------------
    def video(self, task: dict) -> Path:
        url = str((task.get("data") or {}).get("video") or "")
        if not url:
            raise BackendError(f"task {task.get('id')}: no data.video (expected a video task)")
        local = Path(url)
        if local.is_absolute() and local.exists():
            return local
        parsed = urllib.parse.urlparse(url)
        if parsed.path.startswith("/data/local-files/") and self.document_root is not None:
            rel = urllib.parse.parse_qs(parsed.query).get("d", [""])[0]
            cand = (self.document_root / rel).resolve()
            if cand.is_file() and self.document_root.resolve() in cand.parents:
                return cand
        if parsed.path.startswith("/data/") and self.data_root is not None:
            cand = (self.data_root / "media" / parsed.path[len("/data/"):]).resolve()
            if cand.is_file() and self.data_root.resolve() in cand.parents:
                return cand
        if self.ls_url:
            cache = self.model_dir / "videos"
            cache.mkdir(exist_ok=True)
            dest = cache / (Path(parsed.path).name or f"task-{task.get('id')}.mp4")
            if not dest.exists():
                full = url if parsed.scheme else self.ls_url.rstrip("/") + url
                req = urllib.request.Request(full, headers={"Authorization": f"Token {self.api_key}"}
                                             if self.api_key else {})
                with urllib.request.urlopen(req, timeout=60) as resp, open(dest, "wb") as f:
                    shutil.copyfileobj(resp, f)
            return dest
        raise BackendError(f"task {task.get('id')}: cannot find its video {url!r} (give --data-root, "
                           "--document-root or --ls-url)")

    # -- predict ----------------------------------------------------------------
    def predict(self, tasks: list[dict]) -> list[dict]:
        from partlab.app.pipeline import track_video

        model = self.model()
        out = []
        for task in tasks:
            path = self.video(task)
            info = probe(path)
            init = self._initial_boxes(task, info)
            start = int(init["frame"].min()) if init is not None else 0
            tracks = track_video(path, self.tracker, init=init, model=model, seed=self.seed, start=start)
            tracks = tracks[tracks["part"].isin(BOX_PARTS)]
            regions = labelstudio.regions(tracks, info)
            scores = tracks["score"].dropna()
            out.append({"result": regions, "score": float(scores.mean()) if len(scores) else 0.0,
                        "model_version": self.model_version})
        return out

    def _initial_boxes(self, task: dict, info) -> pd.DataFrame | None:
        results = labelstudio.results_of(task)
        if not results:
            return None
        df = labelstudio.tracks_from_results(results, (info.width, info.height), f"task {task.get('id')}")
        first = df[df["frame"] == df["frame"].min()]
        return first[["frame", "track_id", "part", "x", "y", "w", "h"]].reset_index(drop=True)

    # -- fit --------------------------------------------------------------------
    def webhook(self, body: dict) -> dict:
        action = str(body.get("action", ""))
        if action in TRAIN_ACTIONS:
            task, annotation = body.get("task") or {}, body.get("annotation") or {}
            if not task or not annotation.get("result"):
                return {"status": "ignored", "reason": "no task or empty annotation",
                        "model_version": self.model_version}
            task = dict(task, annotations=[annotation])
            (self.model_dir / "annotations" / f"{int(task.get('id') or 0)}.json").write_text(
                json.dumps(task), encoding="utf-8")
            return self.fit_in_background()
        if action == "START_TRAINING":
            return self.fit_in_background()
        return {"status": "ignored", "reason": f"action {action!r}", "model_version": self.model_version}

    def fit_in_background(self) -> dict:
        """Start :meth:`fit` in a thread and answer at once (Label Studio does not wait minutes for a
        webhook); fits run one after another, and ``predict`` uses the newest finished bundle."""
        def run():
            try:
                self.last_fit = self.fit()
            except Exception as exc:  # noqa: BLE001 - reported on /health, the server keeps serving
                self.last_fit = {"status": "failed", "error": f"{type(exc).__name__}: {exc}"}
        thread = threading.Thread(target=run, name="partlab-fit", daemon=True)
        self._fits.append(thread)
        thread.start()
        return {"status": "training", "model_version": self.model_version}

    def wait(self, timeout: float | None = None) -> None:
        """Wait for the fits started so far (for tests and a clean shutdown)."""
        for thread in list(self._fits):
            thread.join(timeout)

    def fit(self) -> dict:
        """Retrain from every kept annotation, starting from the current bundle."""
        from partlab.models.bundle import save_bundle
        from partlab.models.training import train_bundle

        with self._lock:
            clips = []
            for f in sorted((self.model_dir / "annotations").glob("*.json")):
                task = json.loads(f.read_text(encoding="utf-8"))
                path = self.video(task)
                info = probe(path)
                truth = labelstudio.tracks_from_results(labelstudio.results_of(task), (info.width, info.height),
                                                        f"task {task.get('id')}")
                clip = VideoClip(path, info)
                clips.append((clip.frames, info.fps, truth))
            if not clips:
                return {"status": "ignored", "reason": "no annotations yet", "model_version": self.model_version}
            runner = None
            if self.train_with_tracker:
                from partlab.models.runner import body_tracker_runner as runner
            bundle = train_bundle(clips, seed=self.seed, tracker_runner=runner, start=self.model())
            with tempfile.TemporaryDirectory(dir=self.model_dir) as tmp:
                save_bundle(bundle, Path(tmp) / "b")
                (Path(tmp) / "b").rename(self.model_dir / f"bundle-{self.version + 1}")
            self.version += 1
            return {"status": "ok", "model_version": self.model_version, "annotations": len(clips),
                    "samples": bundle.summary.get("samples")}


def make_server(backend: PartlabBackend, host: str = "127.0.0.1", port: int = 9090) -> ThreadingHTTPServer:
    """An HTTP server speaking Label Studio's ML backend API for ``backend`` (not started)."""

    class Handler(BaseHTTPRequestHandler):
        def log_message(self, fmt, *args):  # quiet; the command prints one line per request
            pass

        def _send(self, code: int, payload: dict) -> None:
            data = json.dumps(payload).encode()
            self.send_response(code)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(data)))
            self.end_headers()
            self.wfile.write(data)

        def do_GET(self):
            if self.path.split("?")[0] in ("/", "/health"):
                self._send(200, {"status": "UP", "model_class": "partlab", "model_version": backend.model_version,
                                 **({"last_fit": backend.last_fit} if backend.last_fit else {})})
            else:
                self._send(404, {"error": f"no route {self.path}"})

        def do_POST(self):
            try:
                length = int(self.headers.get("Content-Length") or 0)
                body = json.loads(self.rfile.read(length) or b"{}")
                route = self.path.split("?")[0]
                if route == "/setup":
                    self._send(200, {"model_version": backend.model_version})
                elif route == "/predict":
                    results = backend.predict(list(body.get("tasks") or []))
                    self._send(200, {"results": results, "model_version": backend.model_version})
                elif route in ("/webhook", "/train"):
                    self._send(201, backend.webhook(body))
                else:
                    self._send(404, {"error": f"no route {self.path}"})
            except (UserError, ValueError) as exc:
                self._send(400, {"error": str(exc)})

    return ThreadingHTTPServer((host, port), Handler)
