"""``partlab batch SOURCE -o OUT``: track every clip of a folder, a manifest CSV or a project in the
store on Dask (a local cluster by default, ``--scheduler`` for an existing one). See docs/batch.md."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from partlab.cli import CommandError, seed


def add_arguments(p) -> None:
    from partlab.engine import DEFAULT_CHUNK, DEFAULT_OVERLAP
    from partlab.tracking import registry

    p.add_argument("source", metavar="DIR|MANIFEST.csv", nargs="?",
                   help="a folder of videos and take folders, or a manifest CSV (path[,name,init]); "
                        "leave out with --project to track the project's clips")
    p.add_argument("-o", "--output", metavar="OUT", help="folder for OUT/<clip>.csv (and the resume markers)")
    p.add_argument("--project", metavar="NAME",
                   help="write the results to this project in the store (PARTLAB_DATABASE_URL); with a "
                        "SOURCE its clips are added to the project first (created if needed)")
    p.add_argument("--tracker", choices=registry.names(), default="body")
    p.add_argument("--model", metavar="BUNDLE_DIR", help="model bundle, or 'default' for the shipped one")
    p.add_argument("--seed", type=seed, default=0, help="random seed of every clip (as partlab track --seed)")
    p.add_argument("--chunk-frames", type=int, default=DEFAULT_CHUNK, metavar="N",
                   help=f"split clips longer than N + overlap frames into chunks of N (0: never; "
                        f"default {DEFAULT_CHUNK})")
    p.add_argument("--overlap", type=int, default=DEFAULT_OVERLAP, metavar="N",
                   help=f"frames a chunk starts early, to warm up and to join identities (default {DEFAULT_OVERLAP})")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="local worker processes (default: one per core)")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="use a running Dask scheduler")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=True)


def _jobs(args, store):
    from partlab.engine import batch

    if args.source is None:
        if not args.project:
            raise CommandError("give a folder or manifest, or --project NAME to track a project's clips")
        return batch.project_clips(store, args.project)
    jobs = batch.discover(args.source)
    if not args.project:
        return jobs
    project = store.project_by_name(args.project) or store.create_project(args.project)
    out = []
    for j in jobs:
        if not Path(j.path).is_file():
            raise CommandError(f"{j.path}: the store keeps videos; add take folders with the app or "
                               "Store.import_take, or write to a folder with -o")
        clip = store.add_clip(project.id, j.path, name=Path(j.path).name)
        out.append(batch.ClipJob(j.name, str(clip.path), j.init, clip.id))
    return out


def run(args) -> int:
    from tqdm import tqdm

    from partlab.engine import batch, cluster

    if not args.output and not args.project:
        raise CommandError("give -o OUT (a folder) or --project NAME (the store) for the results")
    if args.workers is not None and args.workers < 1:
        raise CommandError(f"--workers must be at least 1, got {args.workers}")
    settings = batch.Settings(args.tracker, args.model, args.seed, args.chunk_frames, args.overlap)
    settings.check()
    if args.model and args.model != "default" and not Path(args.model).is_dir():
        raise CommandError(f"--model {args.model}: no such bundle directory")
    if args.model and args.model != "default":
        settings = batch.Settings(args.tracker, str(Path(args.model).resolve()), args.seed, args.chunk_frames,
                                  args.overlap)
    store = None
    if args.project:
        from partlab.labelling.store import Store

        store = Store()
    jobs = _jobs(args, store)
    sink = batch.StoreSink(store.url) if args.project else batch.FolderSink(args.output)
    with cluster.client(args.scheduler, args.workers) as client:
        link = cluster.dashboard_link(client)
        n_workers = len(client.scheduler_info().get("workers", {}))
        print(f"partlab batch: {len(jobs)} clip(s) on {n_workers} worker(s)"
              + (f"; dashboard {link}" if link else ""), file=sys.stderr)
        bar = tqdm(total=len(jobs), unit="clip", desc="batch", disable=not args.progress)
        failed_names = []

        def on_result(summary: dict) -> None:
            bar.update(1)
            if summary["status"] != "done":
                failed_names.append(summary["name"])
                tqdm.write(f"partlab batch: {summary['name']} failed: {summary['error']}", file=sys.stderr)
            bar.set_postfix(failed=len(failed_names))

        try:
            todo = [j for j in jobs if not sink.done(j, settings)]
            bar.update(len(jobs) - len(todo))
            report = batch.run_batch(client, todo, settings, sink, on_result=on_result)
        finally:
            bar.close()
    if args.output:
        Path(args.output).mkdir(parents=True, exist_ok=True)
        report.table().to_csv(Path(args.output) / "batch.csv", index=False)
    skipped = len(jobs) - len(report.done) - len(report.failed)
    print(f"{len(report.done)} clip(s) tracked, {skipped} already done, {len(report.failed)} failed "
          f"in {report.seconds:.1f} s" + (f"; results in {args.output}" if args.output else
                                           f"; results in project {args.project!r}"))
    return 1 if report.failed else 0
