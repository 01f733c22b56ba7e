"""End to end against a real Label Studio server started here on 127.0.0.1 (``label-studio`` from PyPI
in its own venv, ``.venv-peers/labelstudio``, with a data directory ``make peers`` initialised): a video
project gets partlab's predictions from ``serve-ml``, a user's corrected annotation goes back, the
backend retrains a bundle, and the next predictions come from it."""

from __future__ import annotations

import json
import os
import shutil
import socket
import sqlite3
import subprocess
import threading
import time
import urllib.error
import urllib.request

import numpy as np
import pandas as pd
import pytest

from partlab.labelling.formats import labelstudio
from partlab.labelling.mlbackend import PartlabBackend, make_server
from partlab.labelling.video import probe, write_video
from tests.labelling.formats.test_peers_venv import PEERS, _python
from tests.tracking.walkers import background, draw_walker

TOKEN = "abcdef0123456789abcdef0123456789"  # the test user's token (make peers: label-studio init)
TEMPLATE = PEERS / "labelstudio-data"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    exe = _python("labelstudio").parent / "label-studio"
    if not (TEMPLATE / "label_studio.sqlite3").is_file():
        pytest.skip(f"{TEMPLATE}: no initialised Label Studio data: run `make peers`")
    data = tmp_path_factory.mktemp("ls") / "data"
    shutil.copytree(TEMPLATE, data)
    with sqlite3.connect(data / "label_studio.sqlite3") as db:  # the test token works as a legacy API token
        db.execute("update jwt_auth_jwtsettings set legacy_api_tokens_enabled = 1")
    port = _free_port()
    env = dict(os.environ, LABEL_STUDIO_BASE_DATA_DIR=str(data), LABEL_STUDIO_ENABLE_LEGACY_API_TOKEN="true",
               LABEL_STUDIO_LOCAL_FILES_SERVING_ENABLED="true", DJANGO_DB="sqlite")
    log = open(data.parent / "server.log", "w")
    proc = subprocess.Popen([str(exe), "start", "--no-browser", "--internal-host", "127.0.0.1", "--port", str(port),
                             ], env=env, stdout=log, stderr=subprocess.STDOUT)
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.time() + 300
        while True:
            try:
                with urllib.request.urlopen(url + "/health", timeout=5) as resp:
                    if json.loads(resp.read()).get("status") == "UP":
                        break
            except (urllib.error.URLError, ConnectionError, TimeoutError):
                pass
            if proc.poll() is not None or time.time() > deadline:
                raise AssertionError(f"Label Studio did not start: {(data.parent / 'server.log').read_text()[-2000:]}")
            time.sleep(2)
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(30)
        except subprocess.TimeoutExpired:
            proc.kill()
        log.close()


def _api(base, method, path, body=None):
    req = urllib.request.Request(base + path, data=None if body is None else json.dumps(body).encode(), method=method,
                                 headers={"Authorization": f"Token {TOKEN}", "Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=300) as resp:
        text = resp.read()
        return json.loads(text) if text else None


def test_predictions_annotation_fit_and_the_next_predictions(server, tmp_path):
    rng = np.random.default_rng(2)
    bg = background(rng, 320, 200)
    frames, truths = [], []
    for t in range(20):
        f = bg.copy()
        truths.append(draw_walker(f, 60 + 3 * t, 50, 110, (40, 40, 160), (120, 60, 30), phase=t / 3))
        frames.append(f)
    path = write_video(tmp_path / "walk.avi", frames, 25)
    info = probe(path)
    backend = PartlabBackend(tmp_path / "models", document_root=tmp_path)
    ml_server = make_server(backend, "127.0.0.1", 0)
    threading.Thread(target=ml_server.serve_forever, daemon=True).start()
    try:
        project = _api(server, "POST", "/api/projects", {"title": "partlab", "label_config":
                                                          labelstudio.labeling_config(info.fps)})
        pid = project["id"]
        _api(server, "POST", f"/api/projects/{pid}/import", [{"data": {"video": "/data/local-files/?d=walk.avi"}}])
        (task,) = _api(server, "GET", f"/api/tasks?project={pid}")["tasks"]
        ml = _api(server, "POST", "/api/ml", {"url": f"http://127.0.0.1:{ml_server.server_address[1]}",
                                              "project": pid, "title": "partlab", "is_interactive": False})
        assert ml["state"] == "CO" and ml["model_version"] == "partlab-0"  # Label Studio reached /health, /setup
        got = _api(server, "POST", f"/api/dm/actions?id=retrieve_tasks_predictions&project={pid}",
                   {"selectedItems": {"all": True, "excluded": []}})
        assert got["processed_items"] == 1
        (pred,) = _api(server, "GET", f"/api/predictions?task={task['id']}")
        assert pred["model_version"] == "partlab-0"
        assert {r["value"]["labels"][0] for r in pred["result"]} == {"person", "head", "torso", "hipleg"}
        # the user corrects the track and submits it: Label Studio's webhook makes the backend retrain
        truth = pd.DataFrame([dict(frame=t, track_id=0, part=p, x=b.x, y=b.y, w=b.w, h=b.h, score=np.nan,
                                   source="manual") for t, parts in enumerate(truths) for p, b in parts.items()
                              if p in ("person", "head", "torso", "hipleg")])
        _api(server, "POST", f"/api/tasks/{task['id']}/annotations", {"result": labelstudio.regions(truth, info)})
        deadline = time.time() + 600
        while backend.version < 1 and time.time() < deadline:
            time.sleep(1)
        backend.wait(600)
        assert backend.version >= 1 and backend.last_fit.get("status") == "ok", backend.last_fit
        assert backend.last_fit["annotations"] == 1 and (backend.bundle_path() / "bundle.json").is_file()
        stored = json.loads((backend.model_dir / "annotations" / f"{task['id']}.json").read_text())
        assert len(stored["annotations"][0]["result"]) == 4  # what Label Studio sent is the user's annotation
        _api(server, "POST", f"/api/dm/actions?id=retrieve_tasks_predictions&project={pid}",
             {"selectedItems": {"all": True, "excluded": []}})
        versions = {p["model_version"] for p in _api(server, "GET", f"/api/predictions?task={task['id']}")}
        assert backend.model_version in versions and backend.model_version != "partlab-0"
    finally:
        backend.wait(600)
        ml_server.shutdown()
        ml_server.server_close()
