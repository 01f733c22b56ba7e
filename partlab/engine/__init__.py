"""Work that runs outside the process that asked for it, on Dask: ``partlab batch`` over many clips
(:mod:`partlab.engine.batch`), the cluster it runs on (:mod:`partlab.engine.cluster`) and the app's
jobs (:mod:`partlab.engine.jobs`). Tasks are plain functions of paths, URLs and numbers, so any
worker that has ``pip install partlab`` (and sees the files and the database) can run them."""
