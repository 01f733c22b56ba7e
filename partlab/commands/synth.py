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
                   help="single, pair_cross, pillar, distractors, crowd, bend or desk; with depth and a stereo "
                        "pair: desk_depth or standing_depth (default: single)")
    p.add_argument("--seed", type=seed, default=0, help="random seed; the same seed gives the same scene")
    p.add_argument("--frames", type=int, default=150, help="number of frames (default: 150, 6 s at 25 fps)")
    p.add_argument("--size", default=None,
                   help="frame size WIDTHxHEIGHT (default: 720x480; 320x240 for the depth scenarios)")


def _size(text: str) -> tuple[int, int]:
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m:
        raise CommandError(f"--size must look like 720x480, got {text!r}")
    return int(m.group(1)), int(m.group(2))


def run(args) -> int:
    from partlab.labelling.synth import SCENARIOS, render_scenario
    from partlab.labelling.synth.depth_scene import DEPTH_SCENARIOS, render_depth_scenario

    if args.scenario not in SCENARIOS + DEPTH_SCENARIOS:
        raise CommandError(f"unknown scenario {args.scenario!r}; choose one of {', '.join(SCENARIOS + DEPTH_SCENARIOS)}")
    depth = args.scenario in DEPTH_SCENARIOS
    width, height = _size(args.size or ("320x240" if depth else "720x480"))
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
            out = render_scenario(args.scenario, args.outdir, seed=args.seed, n_frames=args.frames,
                                  width=width, height=height, progress=True)
    except (ValueError, OSError) as exc:  # e.g. OUTDIR is a file, or the disk is full
        raise CommandError(f"cannot write the scene to {args.outdir}: {exc}") from exc
    print(f"partlab synth: wrote {args.scenario} (seed {args.seed}, {args.frames} frames, {width}x{height}) to {out}")
    return 0
