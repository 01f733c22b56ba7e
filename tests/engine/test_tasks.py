"""The app's jobs as worker tasks: training from corrected clips in the store."""

import sys
from pathlib import Path

import numpy as np

from partlab.engine import tasks
from partlab.labelling.store import Store
from partlab.labelling.video import write_video
from partlab.models.bundle import load_bundle
from partlab.tracking.core.box import Box

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "models"))
from walkers import walking_truth  # noqa: E402


def test_train_bundle_task_trains_saves_and_registers(tmp_path):
    store = Store()
    project = store.create_project("p")
    ids = []
    for k in (1, 2):
        video = write_video(tmp_path / f"c{k}.mp4", (np.full((96, 128, 3), 90 + k, np.uint8) for _ in range(30)), 25)
        clip = store.add_clip(project.id, video)
        truth = walking_truth(2, 30, seed=k)
        store.save_tracker_run(clip.id, truth)
        for f in range(30):  # the user corrected every frame; at frame 20 flagged a torso as failed
            r = truth[(truth.frame == f) & (truth.track_id == 1) & (truth.part == "head")].iloc[0]
            store.edit_box(clip.id, f, 1, "head", Box(r.x, r.y, r.w, r.h), expected_revision=0)
        r = truth[(truth.frame == 20) & (truth.track_id == 1) & (truth.part == "torso")].iloc[0]
        store.edit_box(clip.id, 20, 1, "torso", Box(r.x + 80, r.y, r.w, r.h), failure=True, expected_revision=0)
        ids.append(clip.id)
    seen = []
    out = tmp_path / "bundle"
    result = tasks.train_bundle(lambda d, t: seen.append((d, t)), url=store.url, project_id=project.id, clip_ids=ids,
                                name="b1", out=str(out), seed=3, make_default=True, with_tracker=False)
    b = load_bundle(out)
    assert b.summary["samples"]["human_flags"] == 2 and b.summary["samples"]["tracker"] == 0
    assert [r.name for r in store.bundles(project.id)] == ["b1"]
    assert store.project(project.id).default_bundle_id == result["bundle_id"]
    assert seen[0][0] == 0 and seen[-1][0] == seen[-1][1] > 1  # the bar counts every step to the end
