"""Every tunable number of the body-part tracker (Zhao & Lee), grouped by what it tunes.

``BodyParams`` is what ``partlab track`` uses, what retraining fits (the fields marked
**fitted**: ``dynamics.noise``, ``output.extent`` and, from person boxes alone, ``output.person`` and
the detector's and track ending's thresholds, by :mod:`partlab.models`) and what a model
bundle stores under the key ``"body"``. The tracker reads numbers only from here. Groups, in the
paper's order:

- ``appearance`` (sec. 3.1): the colour model, its 8-bin equalized histograms and its update;
- ``particles`` (sec. 3.2): the entropy-adaptive particle count of eq. (2);
- ``dynamics`` (sec. 3): process noise (fitted), how particles start and what holds the parts together;
- ``decomposition`` (sec. 4.1): cutting a person into head, torso and hip-leg;
- ``background`` (sec. 4): OpenCV's MOG2 adaptive Gaussian mixture, the foreground masks;
- ``detection`` (sec. 4, 5): where new people start and when a track ends;
- ``detector`` (not in the paper): a people detector as a cue for starting, re-acquiring, re-sizing
  and ending tracks (Breitenstein et al. 2009);
- ``occlusion`` (sec. 4.3.1-4.3.2): between people and behind fixed occluders;
- ``adjustment`` (sec. 4.3): rebuilding failed parts and the failure detector's input;
- ``output``: how the tracked inner rectangles are reported (fitted).

docs/parameters.md lists every field with its default and why.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import ClassVar

from partlab.tracking.core.params import (
    COUNT,
    FRACTION,
    POSITIVE,
    POSITIVE_COUNT,
    Parameters,
    Rule,
    flag,
    group_field,
    mapping,
    number,
    pair,
)

UNIT = Rule(lo=0, hi=1, lo_open=True)  # (0, 1]


@dataclass(frozen=True)
class PartNoise:
    """Process-noise standard deviations of the constant-velocity state ``[X, Y, W, H, dX, dY]``
    of one part, in pixels (per frame), and the sharpness ``lam`` of the colour likelihood
    ``exp(-lam * d^2)`` (Nummiaro et al.: weights from the Bhattacharyya distance ``d``).
    **Fitted** from corrected trajectories (:mod:`partlab.models.variance`; ``lam`` by
    :mod:`partlab.models.sharpness`)."""

    x: float = number(4.0)
    y: float = number(3.0)
    w: float = number(1.0)
    h: float = number(1.0)
    vx: float = number(1.0)
    vy: float = number(0.5)
    lam: float = number(20.0, POSITIVE)


def _default_part_noise() -> dict[str, PartNoise]:
    # The head moves least relative to its size; the hip-leg swings most sideways.
    return {
        "head": PartNoise(x=3.0, y=2.0, w=0.5, h=0.5, vx=1.0, vy=0.5, lam=20.0),
        "torso": PartNoise(x=4.0, y=3.0, w=1.0, h=1.0, vx=1.0, vy=0.5, lam=20.0),
        "hipleg": PartNoise(x=5.0, y=3.0, w=1.0, h=1.0, vx=1.5, vy=0.5, lam=20.0),
        "person": PartNoise(x=5.0, y=4.0, w=1.5, h=1.5, vx=1.5, vy=0.5, lam=20.0),
    }


def _default_output_extent() -> dict[str, tuple[float, float, float, float]]:
    # The filters track inner rectangles (mass centre +- one standard deviation, Zhao & Lee
    # sec. 4.1), which keep the colour model clean but cover only the middle of a part: for an
    # evenly filled region the full extent is 2*sqrt(3) ~ 3.5 standard deviations, i.e. about
    # 1.7x the inner rectangle. The hip-leg's inner rectangle is the upper half of the legs, so its
    # extent reaches further down and, with legs swinging, wider. Medians measured on the
    # synthetic suite (tracked vs truth, seed 7). The hip-leg's median (4.3 x 1.73, shifted 0.38
    # down) would cost a bending walker's hip-leg its tracking rate (averaged 0.77 -> 0.63);
    # 1.8 x 1.5 shifted 0.25 keeps every rate of the suite and still raises the hip-leg's mean IoU
    # from 0.16 to 0.39. Refitted from corrections by partlab.models.extent.
    return {
        "head": (1.65, 1.6, 0.0, -0.12),
        "torso": (1.6, 1.6, 0.0, -0.05),
        "hipleg": (1.8, 1.5, 0.0, 0.25),
        # the whole-body baseline tracks the full person box: reported as it is
        "person": (1.0, 1.0, 0.0, 0.0),
    }


@dataclass(frozen=True)
class BodyAppearance:
    """The colour model of a part (sec. 3.1)."""

    # 8 bins per YCbCr channel and the model update H_t = 0.9 H_{t-1} + 0.1 Q_t (eq. (1)).
    bins_per_channel: int = number(8, POSITIVE_COUNT)
    model_update: float = number(0.1, FRACTION)
    # The model is updated only when the estimate matches it at least this well (a part that
    # slid onto background should not learn the background).
    update_min_similarity: float = number(0.3, FRACTION)
    # Equalization: the reference is smoothed (Gaussian, in levels) and mixed with a uniform
    # share before its quantiles become bin edges, so that colours next to a narrow peak (a
    # plain shirt) still fall into distinct bins instead of all into one.
    equalization_smoothing: float = number(2.0)
    equalization_floor: float = number(0.05, FRACTION)
    # Parts at least this many pixels wide and tall are histogrammed on every second pixel of
    # every second row (4x less work). Off by default (0 counts every pixel): at 24 px it cut the
    # PETS09 person rate from 0.62 to 0.54 for about 10% less tracker time.
    histogram_stride_min: float = number(0.0)
    # Background-weighted target while the camera moves (Comaniciu, Ramesh & Meer 2003; Ning et
    # al. 2012's corrected version: the target alone is weighted, not the candidates): a part's
    # binned target is multiplied by v_u = max(min(o* / o_u, 1), surround_floor), o the histogram
    # (same bins) of a ring around the person's start box, ``surround`` of its width and height
    # wide on each side, o* its smallest non-zero bin: colours common around the person count
    # less. Only while ``background.camera_motion`` finds the camera moving, when no foreground
    # mask tells the person from the background: a thin walker in a loose box then has part
    # models that are mostly background, and the parts follow the background's colours as the
    # camera pans (OTB Human3 from the first box, seeds 1-2: person rate 0.095 -> 0.261). With a
    # static camera it cost more than it gave (PETS09 seed 1 from the first boxes: edits/100
    # 18.4 -> 32.1, tracks lost; OTB Crossing: the floor is needed, else the hip-leg of a dark
    # walker on a dark road collapses, MOTA 0.78 -> -0.10). 0: off.
    surround: float = number(0.3)
    surround_floor: float = number(0.25, FRACTION)


@dataclass(frozen=True)
class BodyParticles:
    """The entropy-adaptive particle count of eq. (2) (sec. 3.2): C = 1.2, bounded to 200..1000."""

    initial: int = number(500, POSITIVE_COUNT)
    min: int = number(200, POSITIVE_COUNT)
    max: int = number(1000, POSITIVE_COUNT)
    c: float = number(1.2, POSITIVE)

    def check(self, path: str) -> None:
        if self.min > self.max:
            raise ValueError(f"{path}.min: must be <= {path}.max ({self.max}), got {self.min}")


@dataclass(frozen=True)
class BodyDynamics:
    """How particles move and start, and what holds a person's parts together."""

    # Per-part process noise and colour sharpness (fitted).
    noise: dict[str, PartNoise] = mapping(_default_part_noise, cls=PartNoise)
    # New particles are spread by this many process-noise sigmas around the start box.
    init_spread: float = number(1.5)
    # A part's width and height stay within these factors of its size at (re)initialisation:
    # colour likelihoods hardly constrain size, so wider bounds let boxes grow onto background
    # (PETS09 person rate 0.62 with these, 0.48 with 0.7..1.6, 0.46 with 0.6..2.0).
    size_range: tuple[float, float] = pair((0.75, 1.35))
    # Shared motion (not in the paper): after the torso is measured, the head's and hip-leg's
    # predicted particles move by this share of the torso's displacement instead of their own
    # velocity. A small part (a head of 15 px) cannot learn a sudden turn or speed-up from its
    # own few pixels quickly enough; the torso can. 0 gives the paper's independent dynamics.
    shared_motion: float = number(0.7, FRACTION)
    # Body coherence (not in the paper, which leaves this to the failure detector): head and
    # hip-leg particle weights are multiplied by a Gaussian of their horizontal distance to the
    # torso's centre, sigma = coherence x torso width, so that a head does not follow another
    # person's head of the same skin colour. 0 turns it off (the paper's independent filters).
    coherence: float = number(0.5)
    # Likewise vertically: head and hip-leg stay near their starting height relative to the
    # torso (in torso heights), sigma = coherence_y x torso height (bending changes it slowly).
    coherence_y: float = number(0.5)
    # Start velocity (not in Zhao & Lee): for this many frames after a track starts, every part's
    # velocity goes ``start_velocity_gain`` of the way, each measured frame, to the median of the
    # torso estimate's last three displacements (the second-order dynamics of Xu, Deng & Jia
    # sec. 3, x_t - x_{t-1} = x_{t-1} - x_{t-2}). A track starts standing (velocity 0) and its
    # particles learn a walker's speed only through their velocity noise: on PETS09 a track given at
    # frame 528 moved at -2.4 px a frame three frames later while its estimate moved at -10, lagged
    # onto the slower person behind and swapped with them. Not while the camera moves (a panning
    # camera follows its walker: OTB Human3 rate 0.51 -> 0.27 with it). 0 frames: off. 12 (2026-12-06): PETS09
    # from the first boxes, seeds 1-8, person rate 0.759 -> 0.830, MOTA 0.730 -> 0.740, IDF1
    # 0.844 -> 0.851, edits/100 16.58 -> 15.17; automatic, seeds 1-4, MOTA 0.773 -> 0.782, IDF1
    # 0.803 -> 0.824, but randomized scenes 100-101 automatic MOTA 0.458 -> 0.435
    # (docs/measurements/annotation_effort.md).
    start_velocity_frames: int = number(12, COUNT)
    start_velocity_gain: float = number(0.5, FRACTION)
    # A track the detection cue re-acquires is put on its detection standing (its velocity was a
    # coasting guess, or ran ahead of its walker); with ``relearn_velocity`` it then learns its
    # velocity again as a new track does (``start_velocity_frames``, ``start_velocity_gain``) rather
    # than through its velocity noise only: on PETS09 person 17's track was re-acquired at the end
    # of its start, stood there while he walked on at 9 px a frame and lost him for 130 frames.
    # True (2026-12-06): PETS09 from the first boxes, seeds 1-8, edits/100 15.33 -> 13.82 (lower on
    # 6 of 8), MOTA 0.743 -> 0.764, IDF1 0.852 -> 0.861, person rate 0.826 -> 0.843 (up on 3 seeds,
    # down on 5: who of persons 9 and 15 keeps which id decides it; docs/measurements/annotation_effort.md).
    relearn_velocity: bool = flag(True)

    def check(self, path: str) -> None:
        lo, hi = self.size_range
        if lo > hi:
            raise ValueError(f"{path}.size_range: must be (low, high) with low <= high, got {self.size_range}")


@dataclass(frozen=True)
class BodyDecomposition:
    """Cutting a person's foreground into head, torso and hip-leg (sec. 4.1)."""

    # The paper gives no height ratios; head : torso : hip-leg of an adult standing figure is
    # about 1 : 2.5 : 4 (head ~ 1/7.5 of the height, crotch at ~ 1/2).
    height_ratios: tuple[float, float, float] = pair((0.15, 0.33, 0.52), n=3)
    # How far a separation line may move (fraction of person height).
    separation_search: float = number(0.06, FRACTION)
    # Part boxes given in an init table are shrunk to their inner rectangles (the shrinking of
    # sec. 4.1 applied to the given box) before tracking: a tight box around legs is half floor,
    # and a histogram that is half floor slides onto the floor. False tracks them as given.
    shrink_given_parts: bool = flag(True)


@dataclass(frozen=True)
class BodyBackground:
    """OpenCV MOG2, the adaptive Gaussian mixture of sec. 4 [15]: history (frames), variance
    threshold, shadows dropped, computed at ``scale`` of the frame size (the mask is only used for
    blobs and decomposition), then opened and closed with elliptic kernels (pixels at full size)."""

    history: int = number(300, POSITIVE_COUNT)
    var_threshold: float = number(16.0, POSITIVE)
    scale: float = number(0.5, UNIT)
    # MOG2's own schedule learns at 1/(2n) in the first frames, which absorbs a walker into the
    # background within a few frames; the rate is held at most 1/warmup instead, and a colour
    # must take more than 1 - ratio of a pixel's weight before it is background.
    warmup: int = number(60, POSITIVE_COUNT)
    ratio: float = number(0.7, FRACTION)
    morph_open: int = number(3, COUNT)
    morph_close: int = number(9, COUNT)
    # A moving camera (pan, tilt; partlab.tracking.core.camera_motion: median Lucas-Kanade shift of
    # a grid of points) makes the background model report the whole scene: while the camera's
    # frame-to-frame shift reached ``camera_motion`` pixels in the last ``camera_hold`` frames, the
    # mask is not used (no blob starts; support from ``camera_residual`` below; tracks follow colour
    # and the detector). Static
    # clips measure at most 0.14 px (PETS09, OTB Crossing), a panning one 2.1 (OTB Human3).
    # 0 turns it off (a static camera assumed, as Zhao & Lee do).
    camera_motion: float = number(0.5, Rule())
    camera_hold: int = number(60, COUNT)
    # While the camera moves, foreground support (tracks going lost, found again, ending) comes
    # from the frame against the previous one shifted by the camera's shift: pixels changing by
    # more than ``camera_residual`` grey levels move in the scene (CameraMotion.moving_mask). A
    # track that takes a still object for its walker (OTB Human3: a litter bin past a sign, which
    # the colour models match as well) loses its support, coasts and is looked for again.
    # 0: no support while the camera moves (tracks follow colour alone).
    camera_residual: float = number(10.0)
    # While the camera moves, a person going lost coasts on from where it was when its support
    # went, at the velocity it had up to then, and is looked for only where something moves (not
    # from wherever the frames without support took it: a still object of its colours). OTB Human3
    # from the first box, seeds 1-4: person rate 0.26 -> 0.51. (On a static camera it cost PETS09:
    # edits/100 17.0 -> 21.2.)
    camera_rewind: bool = flag(True)
    # While the camera moves, a measurement that leaves a person where less moves in the scene (the
    # share of its box in ``camera_residual``'s mask) than where its own motion in the scene (its
    # image motion less the camera's shift, over its last clean frames) and the camera's shift put
    # it, by more than ``camera_keep_motion``, is not taken: the person coasts that frame. Where
    # two walkers pass each other the other way (OTB Human3, frames 99-101), the colour models slid
    # off the tracked one across the still ground towards the other. OTB Human3 from the first
    # box, seeds 1-4: person rate 0.649 -> 0.798 (seeds 1 and 3 keep the walker past the crosser);
    # held-out OTB Couple 0.604 -> 0.684. Static cameras never use it. 0: off.
    camera_keep_motion: float = number(0.2, FRACTION)


@dataclass(frozen=True)
class BodyDetection:
    """Where new people start (automatic detection) and when a track ends."""

    # Foreground blobs smaller than this are not people (sec. 5: people > 100 x 30 px; smaller
    # here so that distant walkers in 720x480 scenes still count).
    min_person_height: float = number(40.0)
    min_person_width: float = number(12.0)
    max_person_aspect: float = number(1.2, POSITIVE)
    # A person-size blob must be seen this many frames running, ...
    start_frames: int = number(3, POSITIVE_COUNT)
    # ... and both its side edges (or its top and bottom) must have moved the same way by this
    # fraction of its height since it was first seen: a walker present in the first frames is
    # learnt into the background model and leaves a "ghost" blob where it stood, which never
    # moves, and while the walker separates from it their joint blob has one edge held still.
    # (People who stand still from the first frame on are background anyway.)
    start_min_motion: float = number(0.05)
    # ... and its outline must lie on image edges: gradient magnitude around the outline over
    # that of the background just outside (partlab.tracking.body.detection.edge_contrast; ghosts
    # of people who stood in the first frames measure about 1.0-1.2, people 1.6-3).
    ghost_edge_contrast: float = number(1.4)
    # ... overlap no tracked person by more than ``overlap`` of its area and have ``fill_min`` of
    # foreground inside its box.
    overlap: float = number(0.2, FRACTION)
    fill_min: float = number(0.25, FRACTION)
    # Blobs are looked for in the foreground left after blanking every tracked person's reported
    # box, widened by this fraction of its size on each side: a tracked walker merging with a
    # ghost or a newcomer no longer makes a blob that is mostly an already tracked person.
    margin: float = number(0.25, Rule())
    # Blobs touching the frame border (people still entering) do not start tracks: their box
    # would be cut and the decomposition wrong.
    border: int = number(2, COUNT)
    # A track ends after ``lost_frames`` frames without foreground support (fraction below
    # ``support_min``) or when less than ``leave_fraction`` of its box is inside the frame.
    lost_frames: int = number(10, POSITIVE_COUNT)
    support_min: float = number(0.1, FRACTION)
    leave_fraction: float = number(0.5, FRACTION)
    # ... unless the person moves along the border that cuts its box, or back into the frame, and
    # at least half of ``leave_fraction`` of it is still inside (``leave_along``): the tracker's
    # person box is wider than the person and jitters, so a walker going sideways along the bottom
    # edge with the feet cut off has a fifth of it outside. PETS09 trained on frames 0-199 (fitted
    # ``leave_fraction`` 0.8): person 4, entering bottom right and walking left along the bottom
    # edge at 14 px a frame, was ended 16 frames after his first box and drawn again (281 boxes on
    # seed 3). False: end on the fraction alone.
    leave_along: bool = flag(True)
    # (Automatically started tracks end at once; the rest of this applies to --init tracks.)
    # Tracks started from --init are judged by the same foreground support once the background
    # model has learnt the scene (after ``background.warmup`` frames). A person without support
    # for ``lost_frames`` frames is *lost*: all parts coast on the person's recent velocity (an
    # obstacle nobody listed with --occluders may hide them) while the torso's model looks for
    # them near the prediction (``occlusion.release_search``, ``release_similarity``) on
    # foreground. Found again: tracking goes on and the coasted rows stay; still lost after
    # ``coast_frames`` frames (1.6 s at 25 fps: a walker crosses a pillar or a parked car in
    # about that), the track ends and the rows written while it was lost are withdrawn
    # (it had left, or the tracker had lost it: either way those boxes are on background).
    coast_frames: int = number(40, COUNT)
    end_init_tracks: bool = flag(True)
    # A track that goes lost (or, lost, coasts) with its reported person box within ``exit_margin``
    # of its width from the frame's left or right border (or of its height from the top or bottom)
    # and not moving away from that border has walked out of the frame: it ends at once and the rows
    # written since it lost its support are withdrawn, instead of coasting pinned at the edge (the
    # colour likelihood sees only the part of a box inside the frame, so a box does not follow its
    # walker out) where a newcomer's detection may re-acquire it. 0: off. PETS09 from the first
    # boxes (seeds 1-4, with ``bridge`` and ``head_sets_sides`` False): edits/100 18.76 -> 16.75,
    # MOTA 0.684 -> 0.716. (A person standing still at the border with no foreground support ends too.)
    exit_margin: float = number(0.25, FRACTION)
    # ... or that was so (within ``exit_margin`` of a border, not moving away) on a frame with
    # foreground support at most ``exit_window`` frames before its support went: at the border the
    # box loses its walker's colours and bounces back into the frame (PETS09: a walker leaving on
    # the right, the box 3 px from the border, then 2 px a frame back inwards, where the coasting
    # track re-acquired the next passer-by). 0: the border is judged on the current frame only.
    # Off (2026-12-03): 10 helps PETS09 from the first boxes with ``detector.steer`` 0.7 and
    # ``steer_velocity`` 0.5 (edits/100 17.01 -> 14.10, seed 2 24.22 -> 12.93), but alone it costs
    # them (16.75 -> 18.51: tracks of people still in view at the border end); OTB Crossing and two
    # synthetic scenes are unchanged by it.
    exit_window: int = number(0, COUNT)


@dataclass(frozen=True)
class BodyDetector:
    """People detection as a cue for starting, re-acquiring, re-sizing and ending tracks
    (Breitenstein et al. 2009 guide their particle filters by a detector's confidence; here the
    colour part filters stay, and OpenCV's HOG people detector, Dalal & Triggs, run only around
    foreground blobs and tracks (:mod:`partlab.tracking.core.people`), starts, corrects and ends
    them). Not in Zhao & Lee."""

    # Off: the paper's tracker (tracks start from foreground blobs only).
    enabled: bool = flag(True)
    # Automatic mode: foreground blobs still start tracks too (``body.detection``), for people
    # the detector does not see (small, seen from above, unusual clothing: on the synthetic
    # figures HOG finds 5-60% of the people). False: tracks start from detections only.
    blob_starts: bool = flag(True)
    # The detector runs on every ``every``-th frame: a walker moves a few pixels a frame, and one
    # scan costs several times the part filters of a frame (PETS09, 2 cores: ~150-300 ms a scan).
    every: int = number(3, POSITIVE_COUNT)
    # Scanned regions: foreground blobs at least this tall (pixels) and every track's box.
    min_region_height: float = number(25.0)
    # How a region is scanned (partlab.tracking.core.people.RegionScan). fill 1.2: people down to
    # ~0.8 of the region's height are found (PETS09 frames 60-300 every 5th, blobs as regions:
    # recall 0.83, precision 0.91 at IoU 0.5; fill 0.95: recall 0.75; fill 0.8: 0.36).
    fill: float = number(1.2, POSITIVE)
    margin: float = number(0.25)
    # Pyramid step: 1.05 gains ~0.07 recall at ~2.5x the time.
    scale_step: float = number(1.1, Rule(lo=1, lo_open=True))
    # The SVM margin a window needs (OpenCV's detectMultiScale weights) and the IoU of the
    # non-maximum suppression.
    min_score: float = number(0.3, Rule())
    nms: float = number(0.4, FRACTION)
    # The 64 x 128 window's person is about 0.6 x 0.75 of it (body box = window shrunk by this).
    shrink: tuple[float, float] = pair((0.6, 0.75), rule=UNIT)
    max_upscale: float = number(3.0, POSITIVE)
    # Windows found at a scan's smallest scale may hold a person smaller than any window the scan
    # tried (a walker going away inside a track's box grown with them): each is scanned again around
    # itself ``finer`` times smaller (people down to ~0.8 x finer of the region), and a smaller
    # window found there competes with it in the non-maximum suppression. 1: off. OTB Crossing
    # (walker 50 -> 32 px tall): detections that fit the walker instead of the smallest window.
    finer: float = number(0.7, UNIT)
    # A detection belongs to a track when their boxes overlap at IoU >= match_iou (Hungarian
    # assignment over all pairs).
    match_iou: float = number(0.3, FRACTION)
    # ... and when the detection's torso region (where it puts the track's torso) matches the
    # torso's colour model at least ``match_similarity`` (Bhattacharyya coefficient; 0: IoU
    # alone): a walker's box overlaps the neighbour beside it as much as its own person, and a
    # detection of the neighbour steers the track onto them. The assignment maximises IoU +
    # ``similarity_weight`` x similarity.
    match_similarity: float = number(0.0, FRACTION)
    similarity_weight: float = number(0.0, Rule())
    # A track coasting on its dynamics (behind another person, or lost) that a detection matches
    # is moved this share of the way to it and coasts on with the per-frame motion of its last
    # detections (at most ``velocity_frames`` apart): people walking in groups stop and turn
    # behind each other. 0: coasting tracks are steered like the others and keep their velocity.
    steer_coasting: float = number(0.0, FRACTION)
    velocity_frames: int = number(9, POSITIVE_COUNT)
    # A matched detection moves and re-sizes the track's parts this share of the way to where it
    # puts them (the part boxes keep their places inside the person box): colour likelihoods hardly
    # constrain a box's size, a detector's window does. 0.7 (what retraining fitted on PETS09
    # frames 0-199) with ``steer_velocity`` 0.5 does better on PETS09 (automatic MOTA 0.722 -> 0.783,
    # seeds 1-4), OTB Crossing and two synthetic scenes, but loses the synthetic bending walker's
    # torso (scene ``bend`` seeds 0-9: right on 0.94 -> 0.89 of the frames, hip-leg 0.77 -> 0.74), so
    # it stays 0.5 (2026-12-03).
    steer: float = number(0.5, FRACTION)
    # ... and brings the parts' velocity this share of the way to the per-frame motion of the track's
    # last two detections (at most ``velocity_frames`` apart; 0: off): the colour filters' velocity
    # lags a walker (PETS09 automatic: 63-70 % of the boxes off by IoU 0.3-0.5 trail their walker).
    # Off (2026-12-03, PETS09 seeds 1-4, OTB Crossing seeds 1-4, synthetic scenes 100-101 seeds 1-2,
    # docs/measurements/annotation_effort.md): 0.25 raises PETS09's automatic MOTA 0.722 -> 0.749 and
    # helps Crossing (edits/100 10.21 -> 7.71) but costs the synthetic scenes (edits/100 from the
    # first boxes 26.9 -> 29.0, automatic 38.6 -> 40.0); 0.5 gives PETS09 0.759 and costs Crossing
    # (10.21 -> 13.33); 0.5 with ``steer`` 0.7 gives PETS09 0.783, Crossing 4.79 and the synthetic
    # scenes 26.0 / 37.7, but the bending walker's torso (above).
    steer_velocity: float = number(0.0, FRACTION)
    # ... the same in runs that find people themselves (no ``--init``, no keyframes), where every
    # track was started from a detector's window rather than a drawn box, and its colour models'
    # velocity lags the more. 0.5 (2026-12-03, docs/measurements/annotation_effort.md): PETS09
    # automatic MOTA 0.722 -> 0.757 (seeds 1-4, each >= 0.752), edits/100 17.00 -> 15.37; OTB Human3
    # automatic, walker covered 0.805 +- 0.045 -> 0.844 +- 0.004; randomized scenes 100-107 automatic:
    # see the measurement.
    steer_velocity_auto: float = number(0.5, FRACTION)
    # Swap guard: a matched detection that overlaps another track at least ``swap_guard`` times as
    # much as its own (IoU, and at least ``match_iou``) does not steer: where two walkers cross, the
    # detector's window (or the assignment) may be the other person's, and steering would carry
    # the track onto them. The match still counts (no re-acquisition). 0: off.
    swap_guard: float = number(0.0, FRACTION)
    # A steered part's width and height stay within ``layout_tolerance`` times those it would have
    # in the detection's box laid out as the track's parts were when a detection first matched it
    # (a person's proportions do not change as they walk; the first match, not the start, as a
    # track started on a person partly in view has a partial layout). 0: off. Without it the
    # layout drifts: a hip-leg box grown over the dark road below the feet grows with every
    # detection (whose steer also re-bases its size bounds), so steering ratchets it up (OTB
    # Crossing person rate 0.65 off, 0.98 at 1.25).
    layout_tolerance: float = number(1.25)
    # ... only when the two overlap at IoU below ``steer_below`` (1: every match). Steering only
    # tracks below IoU 0.5 (wrong by the MOT rule) cost PETS09 (frames 0-300, seed 1) MOTA 0.63 ->
    # 0.33 automatic, 0.57 -> 0.27 from the first boxes.
    steer_below: float = number(1.0, FRACTION)
    # The head is steered like the other parts (True) or moved with the torso's correction only,
    # keeping its size and place on the torso (False): a detector's window is only roughly a
    # person's box, and a few pixels are a head's whole height (synthetic walkers, head rate:
    # 0.59 without detection, 0.12 with the head steered, 0.66 with it following the torso).
    steer_head: bool = flag(False)
    # Automatic mode: a detection no track explains starts a track once seen again
    # (``confirm_distance``) in ``confirm_hits`` of the last ``confirm_window`` scans (a single false
    # window does not).
    confirm_hits: int = number(2, POSITIVE_COUNT)
    confirm_window: int = number(3, POSITIVE_COUNT)
    # A detection continues a candidate of an earlier scan when their centres lie within this
    # many detection heights (and their heights within 1.5x): a walker moves ~0.1-0.3 heights
    # between scans, and a fast one's boxes three frames apart need not overlap.
    confirm_distance: float = number(0.5)
    # A lost track (or one no detection has matched for ``reacquire_after`` frames) is re-acquired by
    # an unmatched detection whose centre lies within ``reacquire_distance`` of its height from the
    # track's prediction and whose torso region matches the torso's model at least
    # ``reacquire_similarity`` (Bhattacharyya coefficient): behind a pillar, out of a group.
    reacquire_after: int = number(12, COUNT)
    reacquire_distance: float = number(1.0)
    reacquire_similarity: float = number(0.6, FRACTION)
    # Motion continuity of a re-acquisition: a track measured up to now on its walker (not lost,
    # not behind someone, no coasting stretch open, its torso matching at least
    # ``occlusion.release_similarity``) and walking is not re-acquired by a detection lying behind it
    # against its walking direction (the jump's component along its velocity) by more than
    # ``reacquire_against`` of the detection's width and no further than it walked in the last
    # ``reacquire_after`` frames: that detection is on the path its walker took while the track went
    # on measuring them, where the walker following them is now. Where two walkers in one coat walk
    # one behind the other (PETS09 persons 3 and 4 from frame 528), HOG sees the pair as one and
    # the front one's track, measured on its walker but unmatched for ``reacquire_after`` frames,
    # jumped back onto the first detection of the one behind (seed 6 frame 543: 55 px back,
    # walking at -12 px a frame) and the other track then took the front walker: the swap. A track
    # lost, coasting, touching another track (two tracks on one walker: either may be the wrong
    # one) or matching its model less clearly is re-acquired as before. 0: off. 0.5 (2026-12-06):
    # PETS09 from the first boxes, seeds 1-8, persons 3 and 4 keep their ids on every seed, person
    # rate 0.916 -> 0.922, MOTA 0.759 -> 0.766, edits/100 14.53 -> 13.88 (seed 6, the one the coin
    # fell on: 0.870 -> 0.925, edits 17.51 -> 13.51; seed 8 0.947 -> 0.944, edits -1.14; the others
    # identical), automatic mode and the randomized suite unchanged, OTB Human3 (panning camera)
    # seeds 1-4 rate 0.514 -> 0.649, edits/100 53.0 -> 42.5 (seed 3 worse: 36.2 -> 44.7)
    # (docs/measurements/annotation_effort.md).
    reacquire_against: float = number(0.5)
    # Which of two touching tracks (two tracks on one walker) due for re-acquisition takes a
    # detection near them: not the one placed on that walker more recently (its box given there,
    # ``--init`` or a keyframe, or its last measurement clear of every other track; a given box
    # before a measurement of the same frame), while the other is due too and the detection lies
    # within its ``reacquire_distance``: that one reached the shared walker later, from the walker
    # the detection now shows. Without it the first in id order takes the detection (PETS09 seed 2
    # with ``released_behind``, frame 540: track 3, given on person 3 at frame 528 where track 4
    # had run ahead onto him, took person 4's detection behind the pair and the two swapped
    # walkers). False: off.
    reacquire_owner: bool = flag(False)
    # A track re-acquired onto a detection forgets its clean centres from before the jump
    # (``Person.velocity``, the median motion of the person box): kept, they mix the positions on
    # the walker it left with those on the one it jumped to, and the jump reads as motion (PETS09
    # seed 8: track 4, re-acquired at frame 552 and put behind at 556, coasted at -13.6 px a frame
    # while its walker walked at -4). Off: alone not measured; with ``released_behind`` (see there)
    # PETS09 seeds 1-8 rate 0.922 -> 0.919, MOTA 0.766 -> 0.771, edits/100 13.88 -> 13.40 (with
    # ``released_behind`` alone 0.912 / 0.759 / 13.97), held-out seeds 9-14 0.858 -> 0.902, but the
    # bundle retrained on frames 0-199 does worse on the rest (seeds 1-4: 9.12 -> 11.13 edits/100)
    # and automatic mode's IDF1 0.824 -> 0.816 (seed 4). True: on.
    reacquire_forgets: bool = flag(False)
    # Re-identification of tracks given by the user (``--init``) that ended (lost and withdrawn, or
    # walked out): a free detection (no track takes it, none covers it) where such a track's person
    # could be by now (its height within ``reid_size`` times the track's last box's, its centre
    # within ``reid_distance`` + ``reid_speed`` x frames since, in detection heights, of where the
    # track was last measured clear of everyone, not lost), whose torso and hip-leg regions match the models of
    # the boxes the track was started from at least ``reid_similarity`` (mean Bhattacharyya
    # coefficient) and better by ``reid_margin`` than every other such ended track's, in
    # ``reid_hits`` scans running (a single window does not), brings it back there with its id (a
    # user expects the same person to keep their id). Colour alone cannot tell people apart here:
    # on PETS09 a live track's models match a passer-by at 0.74-0.91, the ended track's first
    # models its own person at 0.72-0.88, so where and when decide. A track that walked out is only
    # looked for within ``reid_border`` detection heights of the border it left through. A person
    # given later (their first box) on whom a re-identified track stands at IoU >= ``reid_undo_iou``
    # was taken for the ended one: that re-identification is undone (0: never). ``reid_hits`` 0: off.
    reid_hits: int = number(3, COUNT)
    reid_similarity: float = number(0.7, FRACTION)
    reid_margin: float = number(0.05, FRACTION)
    reid_size: float = number(1.5, Rule(lo=1))
    reid_distance: float = number(1.0, Rule(lo=0))
    reid_speed: float = number(0.05, Rule(lo=0))
    reid_border: float = number(1.0, Rule())
    reid_undo_iou: float = number(0.5, FRACTION)
    # Two tracks whose person boxes overlap at IoU >= duplicate_iou (neither marked behind the
    # other) are one person twice: the one a detection matched less recently (then the younger)
    # ends; a track given with --init is not ended but goes lost (coasts, may be re-acquired).
    # 1 turns it off.
    duplicate_iou: float = number(0.5, FRACTION)
    # Which of two duplicates goes (tracks given with --init): the one whose first models (torso
    # and hip-leg of the boxes it was started from) match the region the two share worse, by at
    # least ``duplicate_margin`` (mean Bhattacharyya coefficient); closer than that, the rule above.
    # Where two walkers meet and one track is carried onto the other person, the detection
    # recency says nothing about whose person it is (both tracks sit on one person and take its
    # detections in turn), while the started models do: on PETS09 two walkers in dark jackets,
    # blue jeans against dark trousers, standing side by side for 100 frames, match their own
    # first models at 0.85-0.93 and each other's at 0.45-0.65. 0: off (recency alone).
    duplicate_margin: float = number(0.1, FRACTION)
    # A track the first models sent lost (a duplicate or a claim above: it sat on someone else's
    # person) yields to the others while that loss lasts: it is not paired with a detection that
    # another track overlaps at ``match_iou`` or more (those are assigned first), and its torso
    # probe does not bring it back where it would sit on a live track (IoU of the person boxes at
    # least ``duplicate_iou``): the exclusion principle (MacCormick & Blake 1999, which Migniot &
    # Ababsa apply to several people), one observation for one target. Without it the duplicate
    # that went lost comes back onto the same person at the next detection or probe. A track lost
    # by the recency rule (two walkers the first models cannot tell apart) does not yield: two
    # walkers in one coat starting side by side must both keep their detections. False: off.
    lost_yields: bool = flag(True)
    # A track due for re-acquisition (lost, or unmatched for ``reacquire_after`` frames) may also
    # claim a detection another track holds, when its first models match that detection better
    # than the holder's by ``duplicate_margin`` (both given with --init): it jumps there as on a free
    # detection, and the holder, on someone else's person, goes lost. Where one track was carried
    # onto the other's person at a meeting while that one coasted past (PETS09's persons 9 and 15
    # stop to talk), the detection goes on matching the wrong track by overlap and no duplicate
    # ever forms. False: only free detections are re-acquired.
    reacquire_claims: bool = flag(True)
    # A yielding track (``lost_yields``) whose torso probe ends its loss in this frame, touching a
    # track measured in this frame, is the one behind (sec. 4.3.1), whatever the scores: it was
    # not measured, its scores are those of its last measured frame, on the person it was sent
    # off. Without it those stale scores, higher than those of the track that has just claimed its
    # person back, put that one behind: it coasts off its person on its old velocity and the
    # released track keeps that person (PETS09 seed 1, frames 42-43). Off by default: alone it
    # raised seed 1 (0.826 -> 0.919) but not the 8-seed mean (0.911 -> 0.898: the 3 <-> 4 coin
    # moved onto other seeds); with ``reacquire_forgets`` (2026-12-06) PETS09 from the first boxes
    # seeds 1-8 rate 0.922 -> 0.919 with every seed >= 0.85 (seed 1 0.825 -> 0.918), edits/100
    # 13.88 -> 13.40, held-out seeds 9-14 rate 0.858 -> 0.902, but retraining on frames 0-199
    # then lowers the edits on 200-794 less (trained bundle seeds 1-4: 9.12 -> 11.13 edits/100).
    # Putting a yielding track behind for all of its loss gave 0.901, hiding nobody in that frame
    # seed 3 0.755. True: on.
    released_behind: bool = flag(False)
    # Automatic mode: a track no detection has matched for ``undetected_frames`` frames ends (a ghost
    # of the background model, a shadow). 0: never for this reason (foreground support still ends
    # tracks).
    undetected_frames: int = number(0, COUNT)

    def check(self, path: str) -> None:
        if 0 < self.layout_tolerance < 1:
            raise ValueError(f"{path}.layout_tolerance: must be 0 (off) or >= 1, got {self.layout_tolerance}")
        if self.confirm_hits > self.confirm_window:
            raise ValueError(f"{path}.confirm_hits: must be <= {path}.confirm_window ({self.confirm_window}), "
                             f"got {self.confirm_hits}")

    def scan(self):
        """The region scan these numbers describe."""
        from partlab.tracking.core.people import RegionScan

        return RegionScan(self.fill, self.margin, self.scale_step, self.min_score, self.nms, self.shrink,
                          self.max_upscale, self.finer)


@dataclass(frozen=True)
class BodyOcclusion:
    """Occlusion between people and behind fixed occluders (sec. 4.3.1-4.3.2)."""

    # Two persons occlude each other when parts of theirs overlap by more than ``overlap`` of the
    # smaller part and the touching parts' similarities to their models differ by at least
    # ``margin`` (the lower one is behind). The occluded one is tracked by dynamics, model frozen.
    overlap: float = number(0.1, FRACTION)
    # A part's similarity to its own model moves by itself from frame to frame (PETS09 from the first
    # boxes, seeds 1-8: by 0.01 at the median, 0.022 at the 75th percentile, 0.073 at the 95th), so
    # the difference must exceed that jitter to say who is in front; below it both stay measured.
    # 0.02 put people who stop behind a neighbour onto dynamics on a difference that meant nothing,
    # and they coasted on at walking speed. 0.08 (2026-12-06): PETS09 from the first boxes, seeds
    # 1-8, person rate 0.730 -> 0.759, MOTA 0.718 -> 0.730, IDF1 0.824 -> 0.844, edits/100
    # 16.76 -> 16.58; automatic, seeds 1-4, MOTA 0.757 -> 0.773 (IDF1 0.828 -> 0.803).
    margin: float = number(0.08, FRACTION)
    # Part boxes are widened by this share of their width on each side for the touching test:
    # an inner rectangle (mean +- one std) covers about 60% of its part's width.
    pad: float = number(0.35)
    # An occluded person is measured again when its parts no longer touch the front person's,
    # or after this many frames at most (two walkers moving together would otherwise keep the
    # one behind on dynamics forever).
    max_frames: int = number(50, COUNT)
    # While occluded, the torso is looked for within release_search x its width of the
    # prediction; a match of at least release_similarity off the front person ends the occlusion.
    release_similarity: float = number(0.9, FRACTION)
    release_search: float = number(1.5)
    # A part is behind a fixed occluder region (--occluders) when this fraction of it is covered.
    occluder_overlap: float = number(0.1, FRACTION)
    # A person that coasted on its dynamics (lost, or behind another person) and is found again
    # has the boxes written while it coasted replaced by a straight line from its last measured
    # boxes to the ones where it was found (what linear interpolation between the two would give):
    # the coasting velocity cannot foresee a stop or a turn in the dark, the place it is found
    # again shows where it went. Only the written rows change, when the run ends. PETS09 from the
    # first boxes (seeds 1-4, the other two options on): edits/100 17.61 -> 16.75, MOTA 0.697 -> 0.716.
    bridge: bool = flag(True)


@dataclass(frozen=True)
class BodyAdjustment:
    """Rebuilding failed parts (sec. 4.3) and what the failure detector sees (sec. 4.2)."""

    # A lost head or hip-leg: besides the paper's rebuild above/below the torso, the part's own
    # model searches the foreground around the torso's centre (candidates spread by this many
    # torso heights) and wins if it matches better; that finds the head of a person bending
    # forward, where the paper's upright geometry cannot. 0: the paper's rebuild only.
    search: float = number(0.6)
    # Failure detector input: how many past frames of part states are kept per person.
    history_frames: int = number(30, POSITIVE_COUNT)


@dataclass(frozen=True)
class BodyOutput:
    """How a tracked inner rectangle is reported as the part's box (fitted)."""

    # (scale_w, scale_h, shift_x, shift_y): scales about the centre, shifts in fractions of the
    # tracked size. Only the output changes; the filters keep tracking the inner rectangles.
    # (1, 1, 0, 0) reports them as they are, as the paper does; a part not listed likewise.
    extent: dict[str, tuple[float, float, float, float]] = mapping(_default_output_extent, rule=Rule(), n=4)
    # The person box written with the part boxes (sec. 5.3: the minimum bounding rectangle of the
    # three parts) is that rectangle scaled and shifted by (scale_w, scale_h, shift_x, shift_y), in
    # fractions of its size: the box people draw around a whole person need not be the union of
    # the part boxes (a walker's swinging arms and feet reach beyond them; far-away people are
    # cut into parts that leave gaps). (1, 1, 0, 0), the MBR itself, is the paper's. Fitted from
    # corrected person boxes, which need no part boxes (partlab.models.person). Only the output
    # changes, as for ``extent``: automatic starts and the detection cue go on with the MBR.
    person: tuple[float, float, float, float] = pair((1.0, 1.0, 0.0, 0.0), rule=Rule(), n=4)
    # The head box takes part in the person box's left and right sides (True, the paper's MBR of
    # the three parts) or only in its top (False: the sides come from torso and hip-leg). The
    # head's box is the decomposition's strip widened by ``extent`` and a few pixels of error
    # make it stick out sideways beyond the body. Only the output changes, as for ``person``. PETS09
    # from the first boxes (seeds 1-4, the other two options on): edits/100 18.77 -> 16.75, MOTA
    # 0.676 -> 0.716.
    head_sets_sides: bool = flag(False)

    def check(self, path: str) -> None:
        for part, (sw, sh, _dx, _dy) in self.extent.items():
            if sw <= 0 or sh <= 0:
                raise ValueError(f"{path}.extent.{part}: scales must be > 0, got {(sw, sh)}")
        if self.person[0] <= 0 or self.person[1] <= 0:
            raise ValueError(f"{path}.person: scales must be > 0, got {self.person[:2]}")


@dataclass(frozen=True)
class BodyParams(Parameters):
    """Parameters of the three-part body tracker (Zhao & Lee), by what they tune."""

    KEY: ClassVar[str] = "body"

    appearance: BodyAppearance = group_field(BodyAppearance)
    particles: BodyParticles = group_field(BodyParticles)
    dynamics: BodyDynamics = group_field(BodyDynamics)
    decomposition: BodyDecomposition = group_field(BodyDecomposition)
    background: BodyBackground = group_field(BodyBackground)
    detection: BodyDetection = group_field(BodyDetection)
    detector: BodyDetector = group_field(BodyDetector)
    occlusion: BodyOcclusion = group_field(BodyOcclusion)
    adjustment: BodyAdjustment = group_field(BodyAdjustment)
    output: BodyOutput = group_field(BodyOutput)

    #: fields added after partlab 0.2 (no flat name)
    ADDED: ClassVar[tuple[str, ...]] = (*(f"detector.{f.name}" for f in fields(BodyDetector)), "output.person",
                                        "background.camera_motion", "background.camera_hold",
                                        "background.camera_residual", "background.camera_rewind",
                                        "background.camera_keep_motion",
                                        "detection.exit_margin", "detection.exit_window", "occlusion.bridge",
                                        "output.head_sets_sides", "appearance.surround", "appearance.surround_floor",
                                        "dynamics.start_velocity_frames", "dynamics.start_velocity_gain",
                                        "dynamics.relearn_velocity", "detection.leave_along")

    #: partlab 0.2's flat names (the shipped bundle and users' bundles) -> where they live now
    FLAT: ClassVar[dict[str, str | None]] = {
        "bins_per_channel": "appearance.bins_per_channel",
        "model_update": "appearance.model_update",
        "update_min_similarity": "appearance.update_min_similarity",
        "equalization_smoothing": "appearance.equalization_smoothing",
        "equalization_floor": "appearance.equalization_floor",
        "histogram_stride_min": "appearance.histogram_stride_min",
        "particles_initial": "particles.initial",
        "particles_min": "particles.min",
        "particles_max": "particles.max",
        "particles_c": "particles.c",
        "part_noise": "dynamics.noise",
        "init_spread": "dynamics.init_spread",
        "size_range": "dynamics.size_range",
        "shared_motion": "dynamics.shared_motion",
        "coherence": "dynamics.coherence",
        "coherence_y": "dynamics.coherence_y",
        "height_ratios": "decomposition.height_ratios",
        "separation_search": "decomposition.separation_search",
        "shrink_given_parts": "decomposition.shrink_given_parts",
        "background_history": "background.history",
        "background_var_threshold": "background.var_threshold",
        "background_scale": "background.scale",
        "background_warmup": "background.warmup",
        "background_ratio": "background.ratio",
        "morph_open": "background.morph_open",
        "morph_close": "background.morph_close",
        "min_person_height": "detection.min_person_height",
        "min_person_width": "detection.min_person_width",
        "max_person_aspect": "detection.max_person_aspect",
        "start_frames": "detection.start_frames",
        "start_min_motion": "detection.start_min_motion",
        "ghost_edge_contrast": "detection.ghost_edge_contrast",
        "detection_overlap": "detection.overlap",
        "blob_fill_min": "detection.fill_min",
        "detection_margin": "detection.margin",
        "detection_border": "detection.border",
        "lost_frames": "detection.lost_frames",
        "support_min": "detection.support_min",
        "leave_fraction": "detection.leave_fraction",
        "coast_frames": "detection.coast_frames",
        "end_init_tracks": "detection.end_init_tracks",
        "occlusion_overlap": "occlusion.overlap",
        "occlusion_margin": "occlusion.margin",
        "occlusion_pad": "occlusion.pad",
        "occlusion_max_frames": "occlusion.max_frames",
        "release_similarity": "occlusion.release_similarity",
        "release_search": "occlusion.release_search",
        "occluder_overlap": "occlusion.occluder_overlap",
        "adjust_search": "adjustment.search",
        "history_frames": "adjustment.history_frames",
        "output_extent": "output.extent",
    }
