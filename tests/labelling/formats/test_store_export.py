import pandas as pd

from partlab.labelling.formats import export_project, import_dataset
from partlab.labelling.store import Store

CORE = ["frame", "track_id", "part", "x", "y", "w", "h", "failure", "occluded"]


def test_export_a_project_from_the_store(tmp_path, truth, clip):
    path, _ = clip
    store = Store(f"sqlite:///{tmp_path / 'db.sqlite'}", clips_dir=tmp_path / "clips")
    project = store.create_project("walk")
    c = store.add_clip(project.id, path, name="walk clip.avi")
    store.save_tracker_run(c.id, truth)
    (out,) = export_project(store, project.id, "cvat", tmp_path / "out", frames=False)
    assert out.name == f"{c.id:04d}_walk_clip"
    back = import_dataset(out, "cvat")
    pd.testing.assert_frame_equal(back[CORE], truth[CORE])
    assert store.clip(c.id).exported
