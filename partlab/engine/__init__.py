"""Work that runs outside the process that asked for it, on Dask: ``partlab batch`` over many clips
(:mod:`partlab.engine.batch`), the cluster it runs on (:mod:`partlab.engine.cluster`) and the app's
jobs (:mod:`partlab.engine.jobs`). Tasks are plain functions of paths, URLs and numbers, so any
worker that has ``pip install partlab`` (and sees the files and the database) can run them."""

#: ``partlab batch`` cuts clips into chunks of this many frames by default (2 min at 25 fps): long
#: enough that the overlap's warm-up costs under 3 %, short enough that a 1-hour clip spreads over
#: 30 tasks. Here (not in batch.py) so that ``partlab --help`` need not import pandas.
DEFAULT_CHUNK = 3000
#: frames each chunk starts early: the background model learns from its first frames and the body
#: tracker's detection needs a person seen moving for some frames (2 s at 25 fps)
DEFAULT_OVERLAP = 50
