"""Every tunable number of the depth face-and-hands tracker (Xu, Deng & Jia), grouped by what it
tunes. Defaults say why they are what they are; the paper gives few numbers (200 samples, q = 0.5,
lambda > 3), the rest were chosen by hand while looking at synthetic depth scenes of seeds 0-3 (which
are also among the benchmark's 0-9) and are named here so that retraining or a user can change them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

from partlab.tracking.core.params import FRACTION, POSITIVE_COUNT, Parameters, flag, group_field, number, pair


@dataclass(frozen=True)
class Appearance:
    """Sec. 3, eq. 1-2: hue histograms of the H channel of HSV."""

    # 32 bins of OpenCV's 0-180 hue (5.6 each): with 16, skin (hue ~10) and a red shirt (0-2) fell
    # in one bin and the hands slid up red sleeves in front of the face (unseen desk seed 14)
    hue_bins: int = number(32, POSITIVE_COUNT)
    # hue is undefined for grey or dark pixels: only pixels with S and V at least these count
    min_saturation: int = number(30, POSITIVE_COUNT)
    min_value: int = number(40, POSITIVE_COUNT)
    # eq. 1 is pi = exp(-D^2); a candidate box also holds background at its corners (D^2 ~ 0.15
    # on target) while skin-free boxes reach D^2 ~ 0.9: lam = 6 makes them 0.4 against 0.005, the
    # paper's lam = 1 (0.86 against 0.41) hardly tells them apart.
    lam: float = number(6.0)
    # the hands' reference is the face's colour (sec. 4): the inner part of the face box, which
    # leaves out the hair at its top and the background at its sides
    face_inner: tuple[float, float] = pair((0.6, 0.6))
    # the share of a hand's box that the hand covers: the reference is the face's skin hue times
    # this plus the "other" bin (no hue, or not in front of the face) times the rest, so that the
    # window whose skin share matches it scores best and the scale alpha is observed (a pure-skin
    # reference prefers any window inside the hand, the smallest alpha). pi/4 (a disc in its
    # square; a fist is about that, an open hand with spread fingers less)
    hand_fill: float = number(0.785, FRACTION)


@dataclass(frozen=True)
class Dynamics:
    """Sec. 3: x_t - x_{t-1} = x_{t-1} - x_{t-2} + w_t on (x, y, alpha), reference size fixed."""

    # the paper's Fig. 4 runs 200 samples
    particles: int = number(200, POSITIVE_COUNT)
    # velocity kept per frame (1 = the paper's pure second-order model); below 1 damps the
    # overshoot when a hand stops or turns suddenly
    velocity_decay: float = number(0.7)
    # position noise (pixels per frame, in units of the target's reference width): the face moves
    # little, the hands turn suddenly (a hand at 3 m/s crosses a hand's width per frame)
    face_noise: float = number(0.15)
    hand_noise: float = number(0.45)
    # scale noise per frame and the range alpha may take (sec. 3's alpha)
    alpha_noise: float = number(0.02)
    alpha_range: tuple[float, float] = pair((0.7, 1.4))


@dataclass(frozen=True)
class DepthCue:
    """Sec. 2 (depth foreground) and sec. 4, Table 1 (hand candidate regions) and eq. 3."""

    # sec. 2: foreground = pixels nearer than the face's depth plus this margin, in face widths
    # (about 0.9 m for a 160 mm face: the torso and arms, never the wall behind)
    foreground_margin: float = number(3.0)
    # Table 1 step 2: lambda (> 3 in the paper). In millimetres the inequality is d < d_f - lambda sd_f
    # (the paper's d > ... is for disparity, which grows as things come nearer).
    lam: float = number(3.5)
    # ... but never less than this gap in face widths: a smooth face can have sd_f ~ 10 mm, and the
    # forearms resting against the torso would then pass the test
    min_gap: float = number(0.6)
    # Table 1 step 3: a component of "proper size", in face areas (a hand is about 0.3; a hand with
    # its forearm up to about 2.5; a desk top in front of the person is far larger)
    min_area: float = number(0.08)
    max_area: float = number(3.0)
    # ... and, after step 4, no longer than this in face widths either way (a hand with its
    # forearm pointing sideways is about 2; a stereo pair's streak of noise along a desk's edge, 4)
    max_extent: float = number(2.5)
    # Table 1 step 4 c): epsilon and epsilon' in pixels
    eps: float = number(0.5)
    eps_size: float = number(4.0)
    max_iterations: int = number(20, POSITIVE_COUNT)
    # eq. 3's covariance is diag((w/2)^2, (h/2)^2); never narrower than this, in hand widths
    min_sigma: float = number(0.25)
    # support surfaces (regions.support_surfaces, our addition): a plane among the pixels in front
    # of the face covering this many face areas (a desk top; a hand is ~0.3 and not flat) is not a
    # hand; its points lie within surface_tol face widths of it (~20 mm: the stereo pair's error on
    # the desk top is ~7 mm median, a resting hand's centre lies a hand radius, ~45 mm, above it)
    surfaces: bool = flag(True)
    surface_area: float = number(3.0)
    surface_tol: float = number(0.12)
    # RANSAC: planes tried per search, up to surface_planes planes (a desk's top and its front),
    # fitted on every surface_step-th pixel each way (1/16 of the pixels at 4: a few ms a frame)
    surface_hypotheses: int = number(48, POSITIVE_COUNT)
    surface_planes: int = number(2, POSITIVE_COUNT)
    surface_step: int = number(4, POSITIVE_COUNT)
    # sec. 4: weights for importance and standard sampling are q and 1 - q (Fig. 4: q = 0.5)
    q: float = number(0.5, FRACTION)
    # ICONDENSATION's three kinds of sample: of the q drawn from g, this share are its
    # "initialisation" samples (weight 1, as if the prior were g: a lost hand can come back) and the
    # rest its importance samples (weight f/g); standard samples weigh 1
    reinit_share: float = number(0.4, FRACTION)
    # hands are observed only on pixels nearer than the face by this gap (face widths): by sec. 4's
    # constraint 1 the hands are in front of the torso, and the face, the neck and a bare forearm at
    # the torso's depth share the hands' (face's) colour
    hand_gap: float = number(0.25)
    # a candidate region farther than this from a hand's prediction (in hand widths) is not its
    # region (it is the other hand, or a stray arm)
    gate: float = number(6.0)
    # the prior f of the f/g weight (ICONDENSATION) has a uniform part for sudden motion, so an
    # importance sample far from every prediction keeps a small weight instead of none
    prior_floor: float = number(0.05, FRACTION)
    # switches of the paper's ablation (Table 2): colour only uses no depth at all
    importance_sampling: bool = flag(True)
    depth_foreground: bool = flag(True)


@dataclass(frozen=True)
class Refinement:
    """Sec. 3: mean shift on the back-projection refines the sample mean."""

    mean_shift: bool = flag(True)
    iterations: int = number(10, POSITIVE_COUNT)
    eps: float = number(0.5)


@dataclass(frozen=True)
class Reacquisition:
    """Sec. 3-4: the face re-acquired by detection, the hands' initialisation success test."""

    # "when the maximum confidence of all samples is less than a threshold in few consecutive frames"
    face_confidence: float = number(0.15)
    face_frames: int = number(3, POSITIVE_COUNT)
    # OpenCV's Haar cascade: scale step and neighbours, smallest face in pixels
    scale_factor: float = number(1.1)
    min_neighbors: int = number(4, POSITIVE_COUNT)
    min_face: int = number(16, POSITIVE_COUNT)
    # "if average confidence of samples exceeds the threshold ... initialisation is successful".
    # Both hand thresholds sit above what a window with no hand pixel at all scores against the
    # hands' reference, exp(-lam (1 - sqrt(1 - hand_fill))) = 0.04 at the defaults; a window a
    # fifth of whose pixels are the hand's skin scores about 0.3, the hand's own window 1
    hand_confidence: float = number(0.2)
    # a hand whose best sample stays under this for hand_frames frames is re-initialised
    hand_lost: float = number(0.1)
    hand_frames: int = number(5, POSITIVE_COUNT)
    # a hand's reference size from the face box when no hand box is given (hand : face width)
    hand_size: float = number(0.7)


@dataclass(frozen=True)
class Posture:
    """Sec. 5: sizes in proportion to the head (ratios of the head width, adult proportions)."""

    # the depth map sees surfaces: a part's centre lies this far behind (head and hand radii)
    head_depth: float = number(0.55)
    hand_depth: float = number(0.3)
    # shoulders: below the head centre, each side of it, and behind the face surface
    shoulder_drop: float = number(1.2)
    shoulder_half: float = number(1.2)
    shoulder_depth: float = number(0.65)
    # torso rectangle below the head (width, height in head widths)
    torso_size: tuple[float, float] = pair((2.2, 3.2))
    # arm segments (head widths): upper arm 1.7, forearm 1.5 (about 0.17 and 0.15 of the height)
    upper_arm: float = number(1.7)
    forearm: float = number(1.5)
    arm_depth: float = number(0.25)
    # the elbow search: candidates on the circle of possible elbows, and the depth error (head
    # widths) under which a candidate "matches its corresponding point in the depth map"
    elbow_candidates: int = number(72, POSITIVE_COUNT)
    elbow_tolerance: float = number(0.6)
    # the arm model: points sampled along each of the upper arm and forearm of a candidate
    arm_samples: int = number(8, POSITIVE_COUNT)
    # the factors tried on the arms' proportions (each person's arms fitted to the depth over the
    # clip, posture.ArmFit): adults' arm-to-head ratios spread by several per cent
    arm_scales: tuple[float, ...] = pair((0.88, 0.94, 1.0, 1.06, 1.12), n=5)
    # sec. 5's "rough range of elbow ... according to human kinetics": an elbow is not more than this
    # above its shoulder, nor more than this nearer the body's midline than its shoulder (head widths);
    # without it, candidates in front of the chest match the chest's depth as well as the arm's
    elbow_above: float = number(0.5)
    elbow_medial: float = number(0.5)
    # joint rows' box side (head widths)
    joint_box: float = number(0.4)


@dataclass(frozen=True)
class DepthParams(Parameters):
    """Parameters of ``--tracker limbs-depth`` (Xu, Deng & Jia); stored by bundles under ``"depth"``."""

    KEY: ClassVar[str] = "depth"
    FLAT: ClassVar[dict[str, str | None]] = {}

    appearance: Appearance = group_field(Appearance)
    dynamics: Dynamics = group_field(Dynamics)
    depth: DepthCue = group_field(DepthCue)
    refinement: Refinement = group_field(Refinement)
    reacquisition: Reacquisition = group_field(Reacquisition)
    posture: Posture = group_field(Posture)

    @classmethod
    def ablation(cls, variant: str) -> DepthParams:
        """Table 2's rows: ``color_ms`` (Color-PF + MS), ``color_is`` (Color-PF + Depth-IS), ``all``."""
        p = cls()
        if variant == "color_ms":
            return replace(p, depth=replace(p.depth, importance_sampling=False, depth_foreground=False))
        if variant == "color_is":
            return replace(p, refinement=replace(p.refinement, mean_shift=False))
        if variant == "all":
            return p
        raise ValueError(f"unknown ablation variant {variant!r}; expected color_ms, color_is or all")
