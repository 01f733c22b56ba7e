"""Every tunable number of the trackers, in one place.

These objects are what retraining fits (``models/``) and what a model bundle
stores (as JSON through :func:`dataclasses.asdict`). Trackers read numbers only
from here: no magic constants in the tracking code. Defaults are documented with
why they are what they are.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields


def _refuse_unknown(cls, data: dict, what: str) -> None:
    """A saved parameter this version does not know is an error, not something to drop."""
    unknown = set(data) - {f.name for f in fields(cls)}
    if unknown:
        raise ValueError(f"unknown {what} parameter(s): {', '.join(sorted(unknown))}")


@dataclass(frozen=True)
class PartNoise:
    """Process-noise standard deviations of the constant-velocity state
    ``[X, Y, W, H, dX, dY]`` of one part, in pixels (per frame), and the sharpness
    ``lam`` of the colour likelihood ``exp(-lam * d^2)`` (Nummiaro et al.: weights
    from the Bhattacharyya distance ``d``). Fitted from corrected trajectories."""

    x: float = 4.0
    y: float = 3.0
    w: float = 1.0
    h: float = 1.0
    vx: float = 1.0
    vy: float = 0.5
    lam: float = 20.0


def _default_part_noise() -> dict[str, PartNoise]:
    # The head moves least relative to its size; the hip-leg swings most sideways.
    return {
        "head": PartNoise(x=3.0, y=2.0, w=0.5, h=0.5, vx=1.0, vy=0.5, lam=20.0),
        "torso": PartNoise(x=4.0, y=3.0, w=1.0, h=1.0, vx=1.0, vy=0.5, lam=20.0),
        "hipleg": PartNoise(x=5.0, y=3.0, w=1.0, h=1.0, vx=1.5, vy=0.5, lam=20.0),
        "person": PartNoise(x=5.0, y=4.0, w=1.5, h=1.5, vx=1.5, vy=0.5, lam=20.0),
    }


def _default_output_extent() -> dict[str, tuple[float, float, float, float]]:
    # The filters track inner rectangles (mass centre +- one standard deviation, seed 002
    # sec. 4.1), which keep the colour model clean but cover only the middle of a part: for an
    # evenly filled region the full extent is 2*sqrt(3) ~ 3.5 standard deviations, i.e. about
    # 1.7x the inner rectangle. The hip-leg's inner rectangle is the upper half of the legs, so its
    # extent reaches further down and, with legs swinging, wider. Medians measured on the
    # synthetic suite (tracked vs truth, seed 7). The hip-leg's median
    # (4.3 x 1.73, shifted 0.38 down) would cost a bending walker's hip-leg its tracking rate
    # (averaged 0.77 -> 0.63); 1.8 x 1.5 shifted 0.25 keeps every rate of the suite and still
    # raises the hip-leg's mean IoU from 0.16 to 0.39.; refitted from corrections by models/extent.py.
    return {
        "head": (1.65, 1.6, 0.0, -0.12),
        "torso": (1.6, 1.6, 0.0, -0.05),
        "hipleg": (1.8, 1.5, 0.0, 0.25),
        # the whole-body baseline tracks the full person box: reported as it is
        "person": (1.0, 1.0, 0.0, 0.0),
    }


@dataclass(frozen=True)
class BodyParams:
    """Parameters of the three-part body tracker (seed 002)."""

    # seed 002 sec. 3.1: 8 bins per YCbCr channel, model update H_t = 0.9 H_{t-1} + 0.1 Q_t.
    bins_per_channel: int = 8
    model_update: float = 0.1
    # seed 002 sec. 3.2, eq. (2): entropy-adaptive particle count, C = 1.2, bounded to 200..1000.
    particles_initial: int = 500
    particles_min: int = 200
    particles_max: int = 1000
    particles_c: float = 1.2
    # seed 002 sec. 4.1: the paper gives no height ratios; head : torso : hip-leg of an adult
    # standing figure is about 1 : 2.5 : 4 (head ~ 1/7.5 of the height, crotch at ~ 1/2).
    height_ratios: tuple[float, float, float] = (0.15, 0.33, 0.52)
    # seed 002 sec. 4.1: how far a separation line may move (fraction of person height).
    separation_search: float = 0.06
    # Foreground blobs smaller than this are not people (seed 002 sec. 5: people > 100 x 30 px;
    # smaller here so that distant walkers in 720x480 scenes still count).
    min_person_height: float = 40.0
    min_person_width: float = 12.0
    part_noise: dict[str, PartNoise] = field(default_factory=_default_part_noise)
    # How a tracked inner rectangle is reported as the part's box: (scale_w, scale_h, shift_x,
    # shift_y), scales about the centre and shifts in fractions of the tracked size. Only the
    # output changes; the filters keep tracking the inner rectangles. (1, 1, 0, 0) reports them as
    # they are, as the paper does.
    output_extent: dict[str, tuple[float, float, float, float]] = field(default_factory=_default_output_extent)
    # seed 002 sec. 3.1 equalization: the reference is smoothed (Gaussian, in levels) and mixed
    # with a uniform share before its quantiles become bin edges, so that colours next to a
    # narrow peak (a plain shirt) still fall into distinct bins instead of all into one.
    equalization_smoothing: float = 2.0
    equalization_floor: float = 0.05
    # New particles are spread by this many process-noise sigmas around the start box.
    init_spread: float = 1.5
    # A part's width and height stay within these factors of its size at (re)initialisation:
    # colour likelihoods hardly constrain size, so wider bounds let boxes grow onto background
    # (PETS09 person rate 0.62 with these, 0.48 with 0.7..1.6, 0.46 with 0.6..2.0).
    size_range: tuple[float, float] = (0.75, 1.35)
    # Background model (OpenCV MOG2, the adaptive Gaussian mixture of seed 002 sec. 4 [15]):
    # history (frames), variance threshold, shadows dropped, computed at ``background_scale``
    # of the frame size (the mask is only used for blobs and decomposition), then opened and
    # closed with elliptic kernels (pixels at full size).
    background_history: int = 300
    background_var_threshold: float = 16.0
    background_scale: float = 0.5
    # MOG2's own schedule learns at 1/(2n) in the first frames, which absorbs a walker into the
    # background within a few frames; the rate is held at most 1/background_warmup instead, and a
    # colour must take more than 1 - background_ratio of a pixel's weight before it is background.
    background_warmup: int = 60
    background_ratio: float = 0.7
    morph_open: int = 3
    morph_close: int = 9
    # Automatic detection: a person-size blob must be seen this many frames running, overlap no
    # tracked person by more than ``detection_overlap`` of its area, and have this fraction of
    # foreground inside its box; a track ends after ``lost_frames`` frames without foreground
    # support (fraction below ``support_min``) or when its box leaves the frame.
    start_frames: int = 3
    # ... and both its side edges (or its top and bottom) must have moved the same way by this
    # fraction of its height since it was first seen: a walker present in the first frames is
    # learnt into the background model and leaves a "ghost" blob where it stood, which never
    # moves, and while the walker separates from it their joint blob has one edge held still.
    # (People who stand still from the first frame on are background anyway.)
    start_min_motion: float = 0.05
    # ... and its outline must lie on image edges: gradient magnitude around the outline over
    # that of the background just outside (``partlab.tracking.body.detection.edge_contrast``; ghosts of
    # people who stood in the first frames measure about 1.0-1.2, people 1.6-3).
    ghost_edge_contrast: float = 1.4
    # Blobs are looked for in the foreground left after blanking every tracked person's reported
    # box, widened by this fraction of its size on each side: a tracked walker merging with a
    # ghost or a newcomer no longer makes a blob that is mostly an already tracked person.
    detection_margin: float = 0.25
    # blobs touching the frame border (people still entering) do not start tracks: their box
    # would be cut and the decomposition wrong.
    detection_border: int = 2
    detection_overlap: float = 0.2
    blob_fill_min: float = 0.25
    max_person_aspect: float = 1.2
    lost_frames: int = 10
    support_min: float = 0.1
    leave_fraction: float = 0.5
    # Occlusion (sec. 4.3.1-4.3.2): two persons occlude each other when parts of theirs overlap by
    # more than ``occlusion_overlap`` of the smaller part and the touching parts' similarities to
    # their models differ by at least ``occlusion_margin`` (the lower one is behind); a part is behind an occluder region when that
    # fraction of it is covered. The occluded one is tracked by dynamics, model frozen.
    occlusion_overlap: float = 0.1
    occlusion_margin: float = 0.02
    # Part boxes are widened by this share of their width on each side for the touching test:
    # an inner rectangle (mean +- one std) covers about 60% of its part's width.
    occlusion_pad: float = 0.35
    # An occluded person is measured again when its parts no longer touch the front person's,
    # or after this many frames at most (two walkers moving together would otherwise keep the
    # one behind on dynamics forever).
    occlusion_max_frames: int = 50
    # While occluded, the torso is looked for within release_search x its width of the
    # prediction; a match of at least release_similarity off the front person ends the occlusion.
    release_similarity: float = 0.9
    release_search: float = 1.5
    occluder_overlap: float = 0.1
    # The appearance model is updated (eq. (1)) only when the estimate matches it at least this well
    # (a part that slid onto background should not learn the background).
    update_min_similarity: float = 0.3
    # Body coherence (not in the paper, which leaves this to the failure detector): head and
    # hip-leg particle weights are multiplied by a Gaussian of their horizontal distance to the
    # torso's centre, sigma = coherence x torso width, so that a head does not follow another
    # person's head of the same skin colour. 0 turns it off (the paper's independent filters).
    coherence: float = 0.5
    # Likewise vertically: head and hip-leg stay near their starting height relative to the
    # torso (in torso heights), sigma = coherence_y x torso height (bending changes it slowly).
    coherence_y: float = 0.5
    # Adjustment (sec. 4.3) of a lost head or hip-leg: besides the paper's rebuild above/below the
    # torso, the part's own model searches the foreground around the torso's centre (candidates
    # spread by this many torso heights) and wins if it matches better; that finds the head of a
    # person bending forward, where the paper's upright geometry cannot. 0: the paper's rebuild only.
    adjust_search: float = 0.6
    # Part boxes given in an init table are shrunk to their inner rectangles (sec. 4.1's shrinking
    # applied to the given box) before tracking: a tight box around legs is half floor, and a
    # histogram that is half floor slides onto the floor. False tracks the boxes exactly as given.
    shrink_given_parts: bool = True
    # Shared motion (not in the paper): after the torso is measured, the head's and hip-leg's
    # predicted particles move by this share of the torso's displacement instead of their own
    # velocity. A small part (a head of 15 px) cannot learn a sudden turn or speed-up from its
    # own few pixels quickly enough; the torso can. 0 gives the paper's independent dynamics.
    shared_motion: float = 0.7
    # Parts at least this many pixels wide and tall are histogrammed on every second pixel of
    # every second row (4x less work). Off by default (0 counts every pixel): at 24 px it cut the
    # PETS09 person rate from 0.62 to 0.54 for about 10% less tracker time.
    histogram_stride_min: float = 0.0
    # Failure detector input: how many past frames of part states are kept per person.
    history_frames: int = 30

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> "BodyParams":
        _refuse_unknown(cls, data, "body")
        data = dict(data)
        if "part_noise" in data:
            data["part_noise"] = {k: PartNoise(**v) for k, v in data["part_noise"].items()}
        for name in ("height_ratios", "size_range"):
            if name in data:
                data[name] = tuple(data[name])
        if "output_extent" in data:
            data["output_extent"] = {k: tuple(float(x) for x in v) for k, v in data["output_extent"].items()}
        return cls(**data)


@dataclass(frozen=True)
class LimbParams:
    """Parameters of the head-and-hands tracker (seed 000 sec. 3-5, seed 003 sec. 3).

    The paper gives no state-machine thresholds; they are parameters here. The
    ``sigma_*`` terms are the 2D variances of the candidate priors (seed 000 eq. 25-27),
    fitted from training video by ``models/``. ``sigma_v`` and ``sigma_d`` compare two
    cameras (eq. 25-26) and are kept for multi-camera use; one camera uses ``sigma_s``
    (eq. 27, distance of a blob to the silhouette) and ``sigma_xy`` (p(x|Z), eq. 17).
    """

    particles: int = 300
    hue_bins: int = 16
    model_update: float = 0.1
    # one camera: silhouette term and its 2D analogues of seed 000 eq. 25-27 (pixels).
    sigma_v: float = 12.0
    sigma_d: float = 20.0
    sigma_s: float = 8.0
    # spread of p(x | Z_c), the particle-to-candidate term of seed 000 eq. 17 (pixels):
    # about a hand's radius, so a particle on the blob scores near 1 and one beside it little.
    sigma_xy: float = 8.0
    # weight every particle keeps (added to blob x hue, which is ~0.8 on target), so a filter
    # whose blob is missed (shadow, occlusion) diffuses around its last place.
    blob_floor: float = 0.01
    noise_xy: float = 6.0
    # velocity noise of the second-order dynamics x_t - x_{t-1} = x_{t-1} - x_{t-2} + w_t
    # (seed 003 sec. 3); the decay < 1 damps the velocity so a stopped hand does not overshoot.
    noise_v: float = 2.0
    velocity_decay: float = 0.8
    # seed 003 eq. (1): pi = exp(-lam D^2). The reference holds only skin pixels while a
    # candidate box also holds ~20% background at its corners (D^2 ~ 0.1 when on target):
    # lam = 4 keeps that near 0.65 and a box on background (D^2 ~ 1) near 0.02; the paper's
    # lam = 1 is too flat to tell them apart, the body tracker's 20 rejects even the target.
    lam: float = 4.0
    # hue is undefined for grey pixels: only pixels with S and V at least these count.
    hue_min_saturation: int = 30
    hue_min_value: int = 40
    # seed 003 sec. 3: mean shift on the back-projection refines the PF mean.
    mean_shift_iterations: int = 10
    mean_shift_eps: float = 1.0
    # state machine thresholds (seed 000 sec. 5.2)
    combine_distance: float = 20.0
    split_distance: float = 30.0
    # the same in units of the targets' box side, used when sizes are known (always in the
    # tracker) so the thresholds hold at any resolution: hands combine when about touching
    # (1.3 sides between centres) and split once a gap of most of a hand shows (1.8 sides).
    combine_size: float = 1.3
    split_size: float = 1.8
    lost_likelihood: float = 0.15
    # hysteresis: a lost target comes back only above this confidence.
    recover_likelihood: float = 0.3
    lost_frames: int = 5
    # a lost target's particles are spread this wide (pixels, std) around where it is looked
    # for: about a swinging hand's excursion from where the body carried it.
    lost_search: float = 20.0
    start_frames: int = 3
    # prior p(Z) a candidate needs for start_frames frames to start a tracker (sec. 5.2).
    start_prior: float = 0.5
    # frames of estimates kept to read the direction between two targets before they join.
    history_frames: int = 10
    # a combined filter spreads its particles this much wider so it sees both modes.
    combined_noise_scale: float = 1.5
    # a combined pair's posterior modes are sought among its own blobs (those no other target
    # sits on) within this many split distances of the filter: one mode stays under the filter,
    # the other may already be a swing away when the pair is seen to part (a walker's hands
    # ~50 px a step; a desk clap's hands back at rest within two frames). 4 gave desk 720x480
    # right-hand rate 0.83 vs 0.75 at 2, and walker left hand 1.00 vs 0.75.
    mode_search: float = 4.0
    # labelling (seed 000 sec. 7.1): a hand belongs to the nearest head within this many
    # head heights; a person facing the camera has the left hand on the image's right.
    person_radius: float = 5.0
    facing_camera: bool = True
    # frames an unlabelled tracker with no head nearby waits before it is taken as a head.
    head_guess_frames: int = 5
    # seed 003 sec. 3: re-acquire the head with the face detector after this many frames
    # below reacquire_confidence.
    reacquire_frames: int = 5
    reacquire_confidence: float = 0.3
    # a tracked target keeps a box this many times its size around it observable even where
    # the adaptive background model has absorbed a person who sits still (limbs._support).
    support_scale: float = 2.0
    # blobs: keep ceil(3 * alpha * people) largest (seed 000 sec. 6.2: alpha > 1), drop tiny ones
    blob_alpha: float = 1.5
    min_blob_area: float = 30.0
    # skin probability above which a pixel is skin (skin.SkinModel)
    skin_threshold: float = 0.5
    # with --init, refit the skin model on the init frame's head/hand boxes (limbs.LimbTracker)
    skin_adapt: bool = True
    # luma bins of the refitted model: coarse, so lighting drift stays within a bin or two
    skin_ybins: int = 8
    # ... and where the refit sees under skin_keep_recall of an init box as skin, keep as skin
    # the colour bins holding skin_keep_mass of that box's pixels (skin.train_skin_model).
    # On desk seeds 2 and 9 the plain refit sees under 6% of each hand (short sleeves: the
    # forearms share the hands' bins); kept, hands and forearms show, and hands see the arm's
    # end (tip_span), not the blob centre: desk 720x480 (12 seeds) right hand 1.00 vs 0.83 off.
    # Only where the refit sees almost nothing of the box (recall < 0.1): through the mp4 codec
    # (what `partlab track` decodes) the refit sees 10-50% of those hands, and keeping their bins
    # there turned the forearms and desk into skin (hands 0.75 at 0.5; 0.92 at 0.1, as with none).
    skin_keep_mass: float = 0.8
    skin_keep_recall: float = 0.1
    # ... for boxes with both sides at least this (pixels): the walker's 8 px hands have too
    # few pixels of their own (walker left hand 0.75 at frame 105 with them kept, 1.00 without),
    # and at 320x240 (desk hands 13-16 px) it went with tip_min_side (below).
    skin_keep_min_side: float = 17.0
    # opening kernel (pixels) applied to the skin mask before blobs; 1 = none
    skin_open: int = 3
    # hands see the ends of elongated blobs, not their centres (limb_filter.blob_tips): a blob
    # whose farthest pixels are tip_span hand sides apart gives its two ends, plus any pixel
    # tip_far sides from every end found; an end's point is the centroid of the blob within
    # tip_radius sides. tip_span = 0: blob centres only.
    tip_span: float = 1.6
    tip_far: float = 2.5
    tip_radius: float = 0.8
    # ... for hands with a box side at least this (pixels); smaller hands see blob centres: a
    # distant walker's 8 px hand end is mostly noise (walker 640x480 left hand 0.25 at frame
    # 105 with ends, 1.00 without), and a 15 px desk hand's blob at 320x240 is cut square by
    # the support box around it, whose corners become "ends" (desk seed 7 lost both hands;
    # at 14 px the 12-seed 320x240 rates stayed 0.92 / 0.75, other seeds failing).
    tip_min_side: float = 17.0
    # a tracked hand ignores arm ends farther than tip_gate sides from where it is predicted
    tip_gate: float = 1.0

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> "LimbParams":
        _refuse_unknown(cls, data, "limb")
        return cls(**data)
