"""partlab as a Label Studio ML backend, over HTTP on 127.0.0.1: predict proposes part boxes for a video
task, a submitted annotation retrains a bundle, and the next predict tracks with it."""

from __future__ import annotations

import json
import threading
import urllib.request

import numpy as np
import pandas as pd
import pytest

from partlab.labelling.formats import labelstudio
from partlab.labelling.mlbackend import PartlabBackend, make_server
from partlab.labelling.video import probe, write_video
from partlab.tracking.core.box import Box
from tests.tracking.walkers import background, correct, draw_walker


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    rng = np.random.default_rng(2)
    d = tmp_path_factory.mktemp("ml")
    bg = background(rng, 320, 200)
    frames, truths = [], []
    for t in range(20):
        f = bg.copy()
        truths.append(draw_walker(f, 60 + 3 * t, 50, 110, (40, 40, 160), (120, 60, 30), phase=t / 3))
        frames.append(f)
    return write_video(d / "walk.avi", frames, 25), truths


@pytest.fixture()
def server(tmp_path):
    backend = PartlabBackend(tmp_path / "models")
    srv = make_server(backend, "127.0.0.1", 0)
    thread = threading.Thread(target=srv.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{srv.server_address[1]}", backend
    srv.shutdown()
    srv.server_close()


def _post(url, body):
    req = urllib.request.Request(url, data=json.dumps(body).encode(), headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=300) as resp:
        return resp.status, json.loads(resp.read())


def _truth_table(truths):
    return pd.DataFrame([dict(frame=t, track_id=0, part=p, x=b.x, y=b.y, w=b.w, h=b.h)
                         for t, parts in enumerate(truths) for p, b in parts.items()
                         if p in ("person", "head", "torso", "hipleg")])


def test_predict_fit_predict(server, walk):
    url, backend = server
    path, truths = walk
    info = probe(path)
    with urllib.request.urlopen(url + "/health", timeout=10) as resp:
        assert json.loads(resp.read()) == {"status": "UP", "model_class": "partlab", "model_version": "partlab-0"}
    # the user drew the person on frame 0 (1-based frame 1 in Label Studio): predict tracks the rest
    b = truths[0]["person"]
    start = pd.DataFrame([dict(frame=0, track_id=0, part="person", x=b.x, y=b.y, w=b.w, h=b.h, score=np.nan,
                               source="manual")])
    task = {"id": 3, "data": {"video": str(path)},
            "annotations": [{"id": 1, "result": labelstudio.regions(start, info)}]}
    code, got = _post(url + "/predict", {"tasks": [task]})
    assert code == 200 and got["model_version"] == "partlab-0"
    (pred,) = got["results"]
    regions = {r["id"]: r for r in pred["result"]}
    assert set(regions) == {"t0-person", "t0-head", "t0-torso", "t0-hipleg"}
    boxes = labelstudio.tracks_from_results(pred["result"], (info.width, info.height), "predict")
    torso = boxes[boxes.part == "torso"]
    assert len(torso) == 20
    assert np.mean([correct(Box(r.x, r.y, r.w, r.h), truths[r.frame]["torso"]) for r in torso.itertuples()]) >= 0.8
    # the user submits the corrected track: fit retrains and the next predict uses the new bundle
    corrected = {"id": 2, "result": labelstudio.regions(_truth_table(truths).assign(score=np.nan, source="manual"),
                                                          info)}
    code, fit = _post(url + "/webhook", {"action": "ANNOTATION_CREATED", "task": {"id": 3, "data": task["data"]},
                                         "annotation": corrected, "project": {"id": 1}})
    assert code == 201 and fit == {"status": "training", "model_version": "partlab-0"}
    backend.wait(600)
    with urllib.request.urlopen(url + "/health", timeout=10) as resp:
        health = json.loads(resp.read())
    assert health["model_version"] == "partlab-1" and health["last_fit"]["annotations"] == 1
    assert (backend.model_dir / "bundle-1" / "bundle.json").is_file()
    code, got = _post(url + "/predict", {"tasks": [task]})
    assert got["model_version"] == "partlab-1" and got["results"][0]["model_version"] == "partlab-1"
    assert backend.model().summary.get("samples")  # the bundle predict loads is the one fit wrote


def test_bad_task_is_a_400_naming_it(server):
    url, _ = server
    with pytest.raises(urllib.error.HTTPError) as err:
        _post(url + "/predict", {"tasks": [{"id": 9, "data": {"video": "/data/upload/1/none.mp4"}}]})
    assert err.value.code == 400
    assert "task 9: cannot find its video '/data/upload/1/none.mp4'" in json.loads(err.value.read())["error"]
