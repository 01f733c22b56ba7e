"""The built-in demo project: synthetic scenes rendered once into the data directory.

``make run`` calls this before starting the app, and the app calls it on start, so a
new user finds a project "demo" with the ``single`` and ``pair_cross`` scenes (exact
truth and init boxes in ``PARTLAB_DATA/demo/<scene>/``). Nothing happens when the
scene generator (``partlab.labelling.synth``) is not installed.
"""

from __future__ import annotations

import threading
from pathlib import Path

from partlab.labelling.config import data_dir

DEMO_PROJECT = "demo"
DEMO_SCENES: tuple[str, ...] = ("single", "pair_cross")
#: small enough to render in a few seconds on a shared machine, big enough to label
DEMO_SIZE = dict(n_frames=100, width=480, height=320)
_LOCK = threading.Lock()


def demo_files(clip_name: str) -> dict[str, Path]:
    """The synthetic truth/init CSVs of a demo clip (empty for other clips)."""
    scene = Path(clip_name).stem
    folder = data_dir() / "demo" / scene
    if scene not in DEMO_SCENES or not folder.is_dir():
        return {}
    return {k: folder / f"{k}.csv" for k in ("truth", "init") if (folder / f"{k}.csv").exists()}


def ensure_demo(store=None) -> bool:
    """Create the demo project with its clips if missing; True when it exists afterwards."""
    from partlab.labelling import synth
    from partlab.labelling.store import Store, StoreError

    with _LOCK:
        store = store or Store()
        project = store.project_by_name(DEMO_PROJECT)
        if project is None:
            try:
                project = store.create_project(DEMO_PROJECT)
            except StoreError:  # another process made it meanwhile
                project = store.project_by_name(DEMO_PROJECT)
        have = {c.name for c in store.clips(project.id)}
        for scene in DEMO_SCENES:
            name = f"{scene}.mp4"
            if name in have:
                continue
            target = data_dir() / "demo" / scene
            if not (target / "clip.mp4").exists():
                print(f"partlab: rendering the demo scene {scene!r} into {target}", flush=True)
                synth.render_scenario(scene, target, seed=0, **DEMO_SIZE)
            clip = store.add_clip(project.id, target / "clip.mp4", name=name)
            if (target / "occluders.csv").exists():
                import pandas as pd

                from partlab.tracking.core.box import Box

                regions = pd.read_csv(target / "occluders.csv")
                store.set_occluders(clip.id, [Box(r.x, r.y, r.w, r.h) for r in regions.itertuples()])
    return True


if __name__ == "__main__":
    ensure_demo()


def track_demo(store=None) -> list:
    """Start tracking every demo clip that has no tracker run yet (from its scene's init
    boxes, in the background), so a first-time user sees boxes on Correct at once; returns
    the jobs started."""
    from partlab.app import jobs
    from partlab.app.runs import start_tracking
    from partlab.labelling.store import Store
    from partlab.tracking.tracks import read_tracks_csv

    store = store or Store()
    project = store.project_by_name(DEMO_PROJECT)
    if project is None:
        return []
    started = []
    for clip in store.clips(project.id):
        files = demo_files(clip.name)
        if len(store.runs(clip.id)) or "init" not in files or jobs.active("track", clip_id=clip.id):
            continue
        init = read_tracks_csv(files["init"])
        started.append(start_tracking(store, clip, tracker="body", init=init,
                                      start=int(init.frame.min()) if len(init) else 0))
    return started
