"""``partlab serve-ml --model-dir DIR [--port 9090]``: partlab as a Label Studio ML backend.

Add it in Label Studio under Project settings > Model with the URL ``http://127.0.0.1:9090``; see
:mod:`partlab.labelling.mlbackend` for what ``predict`` and ``fit`` do.
"""

from __future__ import annotations

from pathlib import Path

from partlab.cli import CommandError, seed


def add_arguments(p) -> None:
    p.add_argument("--model-dir", metavar="DIR", required=True,
                   help="where retrained bundles (bundle-<version>/) and submitted annotations are kept")
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--port", type=int, default=9090)
    p.add_argument("--tracker", default="body", help="the tracker predict runs (see partlab track --help)")
    p.add_argument("--data-root", metavar="DIR", help="Label Studio's data directory (its uploads are there)")
    p.add_argument("--document-root", metavar="DIR", help="the root of Label Studio's local-files storage")
    p.add_argument("--ls-url", metavar="URL", help="Label Studio's URL, to download task videos from")
    p.add_argument("--api-key", metavar="TOKEN", help="a Label Studio access token (with --ls-url)")
    p.add_argument("--seed", type=seed, default=0)
    p.add_argument("--train-with-tracker", action="store_true",
                   help="validate retraining with tracker runs on the annotated clips (minutes per fit)")


def run(args) -> int:
    from partlab.labelling.mlbackend import PartlabBackend, make_server

    if not 0 <= args.port < 65536:
        raise CommandError(f"--port {args.port} is outside 0..65535")
    backend = PartlabBackend(Path(args.model_dir), tracker=args.tracker,
                             data_root=Path(args.data_root) if args.data_root else None,
                             document_root=Path(args.document_root) if args.document_root else None,
                             ls_url=args.ls_url, api_key=args.api_key, seed=args.seed,
                             train_with_tracker=args.train_with_tracker)
    try:
        server = make_server(backend, args.host, args.port)
    except OSError as exc:
        raise CommandError(f"cannot listen on {args.host}:{args.port}: {exc}") from None
    print(f"partlab ML backend on http://{args.host}:{server.server_address[1]} "
          f"(model {backend.model_version}, bundles in {args.model_dir})", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return 0
