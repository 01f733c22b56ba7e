"""``partlab synth OUTDIR --scenario NAME --seed N [--frames N] [--size WxH]``.

The depth scenarios (``desk_depth``, ``standing_depth``) write a take folder: colour, rendered depth,
the right view of a stereo pair with its calibration, and ``stereo/take.json`` for depth from the
pair (:func:`partlab.labelling.synth.depth_scene.render_depth_scenario`).
"""

from __future__ import annotations

import re

from partlab.cli import CommandError, seed


def add_arguments(p) -> None:
    p.add_argument("outdir", metavar="OUTDIR", help="directory to write clip.mp4, truth.csv, init.csv, scene.json")
    p.add_argument("--scenario", default="single",
                   help="single, pair_cross, pillar, distractors, crowd, bend or desk (default: single); "
                        "activities with event truth: pick_place, exchange, handshake, clap; with depth and a "
                        "stereo pair: desk_depth or standing_depth; seen from the ceiling with depth: topview_s1, "
                        "topview_s2, topview_s3, topview_group (docs/synthetic.md)")
    p.add_argument("--seed", type=seed, default=0, help="random seed; the same seed gives the same scene")
    p.add_argument("--frames", type=int, default=150, help="number of frames (default: 150, 6 s at 25 fps)")
    p.add_argument("--size", default=None,
                   help="frame size WIDTHxHEIGHT (default: 720x480; 320x240 for the depth and top-view "
                        "scenarios; 640x480 with --cameras)")
    p.add_argument("--cameras", type=int, default=None,
                   help="render a multi-camera take from N calibrated cameras (scenarios standing, seated, "
                        "handshake): one clip per camera, calibration.json, truth.csv with a camera column, "
                        "truth3d.csv (mm) and chessboard/ clips for partlab calibrate")


def _size(text: str) -> tuple[int, int]:
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m:
        raise CommandError(f"--size must look like 720x480, got {text!r}")
    return int(m.group(1)), int(m.group(2))


def _run_multiview(args) -> int:
    from partlab.labelling.synth.multiview import SCENARIOS_3D, render_take

    scenario = "standing" if args.scenario == "single" else args.scenario
    if scenario not in SCENARIOS_3D:
        raise CommandError(f"unknown multi-camera scenario {args.scenario!r}; choose one of {', '.join(SCENARIOS_3D)}")
    if not 1 <= args.cameras <= 8:
        raise CommandError(f"--cameras must be between 1 and 8, got {args.cameras}")
    width, height = _size(args.size or "640x480")
    if width < 64 or height < 48 or width % 2 or height % 2 or args.frames < 1 or args.seed < 0:
        raise CommandError("--size must be even and at least 64x48, --frames >= 1 and --seed >= 0")
    try:
        out = render_take(scenario, args.outdir, args.cameras, seed=args.seed, n_frames=args.frames,
                          width=width, height=height)
    except (ValueError, OSError) as exc:
        raise CommandError(f"cannot write the take to {args.outdir}: {exc}") from exc
    print(f"partlab synth: wrote {scenario} from {args.cameras} cameras (seed {args.seed}, {args.frames} frames, "
          f"{width}x{height}) to {out}")
    return 0


def run(args) -> int:
    from partlab.labelling.synth import SCENARIOS, render_scenario
    from partlab.labelling.synth.depth_scene import DEPTH_SCENARIOS, render_depth_scenario
    from partlab.labelling.synth.topview import TOPVIEW_SCENARIOS, render_topview

    if args.cameras is not None:
        return _run_multiview(args)
    known = SCENARIOS + DEPTH_SCENARIOS + TOPVIEW_SCENARIOS
    if args.scenario not in known:
        raise CommandError(f"unknown scenario {args.scenario!r}; choose one of {', '.join(known)}")
    depth, topview = args.scenario in DEPTH_SCENARIOS, args.scenario in TOPVIEW_SCENARIOS
    width, height = _size(args.size or ("320x240" if depth or topview else "720x480"))
    if width < 64 or height < 48 or width % 2 or height % 2:
        raise CommandError(f"--size {width}x{height}: width and height must be even and at least 64x48")
    if args.frames < 1:
        raise CommandError(f"--frames must be at least 1, got {args.frames}")
    if args.seed < 0:
        raise CommandError(f"--seed must be a non-negative integer, got {args.seed}")
    try:
        if depth:
            out = render_depth_scenario(args.scenario, args.outdir, seed=args.seed, n_frames=args.frames,
                                        width=width, height=height)
        else:
            render = render_topview if topview else render_scenario
            out = render(args.scenario, args.outdir, seed=args.seed, n_frames=args.frames,
                         width=width, height=height, progress=True)
    except (ValueError, OSError) as exc:  # e.g. OUTDIR is a file, or the disk is full
        raise CommandError(f"cannot write the scene to {args.outdir}: {exc}") from exc
    print(f"partlab synth: wrote {args.scenario} (seed {args.seed}, {args.frames} frames, {width}x{height}) to {out}")
    return 0
