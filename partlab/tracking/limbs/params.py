"""Every tunable number of the head-and-hands tracker, grouped by what it tunes.

From *3D tracking of the hands and head of interacting people from several cameras* (parallel
filters over skin blobs, sec. 3-5; state machine, sec. 5.2; labelling, sec. 7.1) and Xu, Deng &
Jia (hue histograms and mean shift, sec. 3). The paper gives no state-machine thresholds; they are
parameters here. ``LimbParams`` is stored by model bundles under the key ``"limbs"``. Groups:

- ``dynamics``: particle count and the second-order dynamics of each filter;
- ``appearance``: the hue histogram, its likelihood and the mean-shift refinement;
- ``priors``: the candidate terms of eq. 17, 19, 25-27 (the ``sigma_*`` are **fitted**);
- ``skin``: the skin-colour model and its mask;
- ``blobs``: which skin blobs become candidates, and the arm ends hands see;
- ``states``: the five-state machine (sec. 5.2);
- ``labels``: which target is a head, a left or a right hand (sec. 7.1);
- ``adjustment``: re-acquiring a lost head with the face detector (Xu, Deng & Jia sec. 3);
- ``people``: where people are, for trackers started without ``--init`` (issue 13).

docs/parameters.md lists every field with its default and why.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from partlab.tracking.core.params import (
    COUNT,
    FRACTION,
    POSITIVE,
    POSITIVE_COUNT,
    Parameters,
    flag,
    group_field,
    number,
)


@dataclass(frozen=True)
class LimbDynamics:
    """One filter per target: ``particles`` of ``[cx, cy, vx, vy]`` (pixels)."""

    particles: int = number(300, POSITIVE_COUNT)
    # position noise (pixels, std per frame)
    noise_xy: float = number(6.0)
    # velocity noise of the second-order dynamics x_t - x_{t-1} = x_{t-1} - x_{t-2} + w_t
    # (Xu, Deng & Jia sec. 3); the decay < 1 damps the velocity so a stopped hand does not overshoot.
    noise_v: float = number(2.0)
    velocity_decay: float = number(0.8, FRACTION)
    # a combined filter spreads its particles this much wider so it sees both modes.
    combined_noise_scale: float = number(1.5, POSITIVE)
    # a lost target's particles are spread this wide (pixels, std) around where it is looked
    # for: about a swinging hand's excursion from where the body carried it.
    lost_search: float = number(20.0)


@dataclass(frozen=True)
class LimbAppearance:
    """The hue histogram of a target (Xu, Deng & Jia sec. 3)."""

    hue_bins: int = number(16, POSITIVE_COUNT)
    model_update: float = number(0.1, FRACTION)
    # eq. (1): pi = exp(-lam D^2). The reference holds only skin pixels while a candidate box
    # also holds ~20% background at its corners (D^2 ~ 0.1 when on target): lam = 4 keeps that
    # near 0.65 and a box on background (D^2 ~ 1) near 0.02; the paper's lam = 1 is too flat to
    # tell them apart, the body tracker's 20 rejects even the target.
    lam: float = number(4.0, POSITIVE)
    # hue is undefined for grey pixels: only pixels with S and V at least these count.
    hue_min_saturation: int = number(30, COUNT)
    hue_min_value: int = number(40, COUNT)
    # mean shift on the back-projection refines the PF mean.
    mean_shift_iterations: int = number(10, COUNT)
    mean_shift_eps: float = number(1.0, POSITIVE)


@dataclass(frozen=True)
class LimbPriors:
    """The candidate prior p(Z) (eq. 19, a product of named terms) and p(x | Z) (eq. 17).

    ``sigma_v`` and ``sigma_d`` (eq. 25-26) compare two cameras: they are **fitted** and saved by
    training, but the one-camera tracker does not read them yet (the multi-camera work wires them).
    One camera uses ``sigma_s`` (eq. 27, distance of a blob to the silhouette, **fitted**) and
    ``sigma_xy``."""

    sigma_v: float = number(12.0, POSITIVE)
    sigma_d: float = number(20.0, POSITIVE)
    sigma_s: float = number(8.0, POSITIVE)
    # spread of p(x | Z_c), the particle-to-candidate term of eq. 17 (pixels): about a hand's
    # radius, so a particle on the blob scores near 1 and one beside it little.
    sigma_xy: float = number(8.0, POSITIVE)
    # weight every particle keeps (added to blob x hue, which is ~0.8 on target), so a filter
    # whose blob is missed (shadow, occlusion) diffuses around its last place.
    blob_floor: float = number(0.01)


@dataclass(frozen=True)
class LimbSkin:
    """The skin-colour model (partlab.tracking.core.skin) and its mask."""

    # skin probability above which a pixel is skin
    threshold: float = number(0.5, FRACTION)
    # with --init, refit the skin model on the init frame's head/hand boxes
    adapt: bool = flag(True)
    # luma bins of the refitted model: coarse, so lighting drift stays within a bin or two
    ybins: int = number(8, POSITIVE_COUNT)
    # ... and where the refit sees under keep_recall of an init box as skin, keep as skin the
    # colour bins holding keep_mass of that box's pixels (skin.train_skin_model). On desk seeds 2
    # and 9 the plain refit sees under 6% of each hand (short sleeves: the forearms share the
    # hands' bins); kept, hands and forearms show, and hands see the arm's end (blobs.tip_span),
    # not the blob centre: desk 720x480 (12 seeds) right hand 1.00 vs 0.83 off. Only where the
    # refit sees almost nothing of the box (recall < 0.1): through the mp4 codec (what
    # `partlab track` decodes) the refit sees 10-50% of those hands, and keeping their bins there
    # turned the forearms and desk into skin (hands 0.75 at 0.5; 0.92 at 0.1, as with none).
    keep_mass: float = number(0.8, FRACTION)
    keep_recall: float = number(0.1, FRACTION)
    # ... for boxes with both sides at least this (pixels): the walker's 8 px hands have too few
    # pixels of their own (walker left hand 0.75 at frame 105 with them kept, 1.00 without), and
    # at 320x240 (desk hands 13-16 px) it went with blobs.tip_min_side.
    keep_min_side: float = number(17.0)
    # ... and, for smaller boxes, the colour bins holding at least 1/keep_spread of the bin's
    # pixels in the frame (0: none kept): a 14-15 px hand of a person standing with bare forearms
    # (one-camera activity scenes, 720x480) shares its colour with its forearm (the bin's pixels
    # 3-30 times the box's: kept; otherwise lost at frame 4, the refit seeing under 5% of it), not
    # with the floor or the sleeve at its edge (600-9000 times: not kept, or the floor turned
    # skin). On since 2026-12-06 (with blobs.tip_kept, tip_person, cut_ends and
    # states.people_mode_search, activities decision.clap_found_frames): activity scenes seeds
    # 0-9 clap recall 0.80 -> 1.00, handshake 0.90 / 0.90 -> 1.00 / 1.00, exchange 0.83 / 0.50 ->
    # 0.78 / 0.70, place recall 0.90 -> 1.00; held out (10-19) no kind's precision or recall lower
    # (handshake 0.64 / 0.70 -> 0.90 / 0.90, place 0.90 / 0.90 -> 1.00 / 1.00); desk 320x240 left
    # hand 0.917 -> 1.000 at frame 105, right the same (docs/measurements/activities.md).
    keep_spread: float = number(50.0)
    # keep the colours of init boxes the init table marks hidden (occluded >= 0.5)? A hand
    # behind its body has a box of clothes (the exchange scenes' far hands: the shirt's bins
    # pass keep_spread). They stay skin samples: left out altogether, the walker's hidden left
    # hand's box cost seed 3's hands (left mean rate 0.517 -> 0.416).
    keep_hidden: bool = flag(False)
    # opening kernel (pixels) applied to the skin mask before blobs; 1 = none
    open: int = number(3, POSITIVE_COUNT)


@dataclass(frozen=True)
class LimbBlobs:
    """Which skin blobs become candidates, and the arm ends hands see."""

    # keep ceil(3 * alpha * people) largest blobs (sec. 6.2: alpha > 1), drop tiny ones
    alpha: float = number(1.5, POSITIVE)
    min_area: float = number(30.0)
    # a tracked target keeps a box this many times its size around it observable even where the
    # adaptive background model has absorbed a person who sits still.
    support_scale: float = number(2.0)
    # hands see the ends of elongated blobs, not their centres (limbs.filter.blob_tips): a blob
    # whose farthest pixels are tip_span hand sides apart gives its two ends, plus any pixel
    # tip_far sides from every end found; an end's point is the centroid of the blob within
    # tip_radius sides. tip_span = 0: blob centres only.
    tip_span: float = number(1.6)
    tip_far: float = number(2.5)
    tip_radius: float = number(0.8, POSITIVE)
    # ... for hands with a box side at least this (pixels); smaller hands see blob centres: a
    # distant walker's 8 px hand end is mostly noise (walker 640x480 left hand 0.25 at frame 105
    # with ends, 1.00 without), and a 15 px desk hand's blob at 320x240 is cut square by the
    # support box around it, whose corners become "ends" (desk seed 7 lost both hands; at 14 px
    # the 12-seed 320x240 rates stayed 0.92 / 0.75, other seeds failing).
    tip_min_side: float = number(17.0)
    # ... and smaller hands whose init box's colours the skin refit had to keep
    # (skin.keep_spread): their colour is their bare forearm's, so their blob is hand and
    # forearm and the hand its end. Without: a clap's kept hands sat mid-forearm and met too
    # briefly (one-camera clap seed 3: 49-64 against 30-80; with: 28-62); desk 320x240 seed 2's
    # left hand (kept) mean rate 0.14 with blob centres, 0.95 with ends.
    tip_kept: bool = flag(True)
    # ... and, while not lost, every small hand of a person one of whose hands was kept: the
    # kept colour is the person's skin, so their other bare forearm shows too (with keep_spread
    # 50, held-out handshake 18: person 2's right hand, hidden at the start, was tracked 10-14 px
    # up its forearm and missed the handshake; with: found). A lost hand keeps blob centres: with
    # arm ends it took the elbow end of the other forearm (exchange seeds 2, 6 lost).
    tip_person: bool = flag(True)
    # a blob that goes on as skin beyond the observed region (the foreground and the support
    # boxes) is cut there: its end at the cut is no hand, and its centre lies towards the cut
    # (limbs.filter.blob_tips). A still person whom the adaptive background absorbed is seen only
    # in the support box round each hand, which cuts a kept hand's forearm square: the cut was an
    # end, or pulled the blob's centre up the arm, and the estimate ratcheted up the forearm with
    # its box (one-camera clap seed 6: 419 -> 384 px in 5 frames; exchange seed 13 with
    # skin.keep_spread 50: 30 px up in 3 frames, a false place). For hands under tip_min_side
    # (those that see arm ends because their colours were kept): for the desk's larger hands
    # (720x480, 12 seeds) it lost right hands (0.917 at frame 105, mean 0.777, against 1.00 and
    # 0.886), as a first try of dropping cut ends there had.
    cut_ends: bool = flag(True)
    # ... also for hands that see blob centres (a cut blob's end away from the cut instead of its
    # centre). Off: with skin.keep_spread 50 it kept exchange seed 13's person 2 left hand (not
    # kept) from creeping 25 px up its forearm, but where the cut blob held both hands of a clap
    # the end away from the cut was the other hand (clap seed 1 lost).
    cut_centres: bool = flag(False)
    # a tracked hand ignores arm ends farther than tip_gate sides from where it is predicted
    tip_gate: float = number(1.0)


@dataclass(frozen=True)
class LimbStates:
    """Thresholds of the five-state machine (sec. 5.2; the paper gives none)."""

    # prior p(Z) a candidate needs for start_frames frames to start a tracker.
    start_prior: float = number(0.5, FRACTION)
    start_frames: int = number(3, POSITIVE_COUNT)
    # pixels, used when no size is known (the tracker always knows it) ...
    combine_distance: float = number(20.0)
    split_distance: float = number(30.0)
    # ... and the same in units of the targets' box side, so the thresholds hold at any
    # resolution: hands combine when about touching (1.3 sides between centres) and split once a
    # gap of most of a hand shows (1.8 sides).
    combine_size: float = number(1.3)
    split_size: float = number(1.8)
    # a combined pair's posterior modes are sought among its own blobs (those no other target
    # sits on) within this many split distances of the filter: one mode stays under the filter,
    # the other may already be a swing away when the pair is seen to part (a walker's hands ~50 px
    # a step; a desk clap's hands back at rest within two frames). 4 gave desk 720x480 right-hand
    # rate 0.83 vs 0.75 at 2, and walker left hand 1.00 vs 0.75.
    mode_search: float = number(4.0)
    # ... and for a pair of two people's hands (a handshake, an exchange), within this many (0:
    # mode_search): their hands part slowly, and far modes were the people's own arms (one-camera
    # handshake seeds 10, 17, 18 with skin.keep_spread 50: the pair split at once, one hand onto its
    # own elbow 37 px away or its person's other forearm 75 px away).
    people_mode_search: float = number(1.2)
    # ... and not on the blob where a lost target is looked for (its last place, moved with its
    # head): two people's hands meeting in a handshake or an exchange split at once onto a lost
    # hand's blob 70 px away (the refit skin model barely sees that 14 px hand, so its own filter
    # stays lost on it), and one of them then tracked the wrong hand (synthetic exchange seed 3).
    # Desk 320x240 and 720x480 (12 seeds) and walker (4 seeds) rates: unchanged.
    pair_lost_claims: bool = flag(True)
    # a combined pair of two people's hands seen as one mode that has moved more than split_size
    # sides from where the hands met, along the direction between them before the join, has parted
    # with one hand unseen
    # (one camera: the taker's hand back behind its own body after an exchange): the mode goes to
    # the member on its side, the other is lost (sec. 5.2) and looked for as far back the other
    # way. Off: the pair stayed combined on the seen hand, both labels on it (exchange seed 3: the
    # giver's hand, from the handover to the end of the clip). Not for one person's two hands: a
    # walker's hands cross as they swing and the pair moves with the walker (synthetic walker seed
    # 1: right-hand mean rate 0.725 -> 0.671 when it applied to them).
    split_unseen: bool = flag(True)
    # a combined pair owns the candidates within a split distance of its estimate (its two hands,
    # apart but not yet split) and, for a lost hand looking for its blob, every part of a blob it
    # sits on (two hands already). Off: only those within half a box plus sigma_xy, as a single
    # hand. Exchange seed 3 (renderer of 2026-12-06): person 2's left hand, lost from frame 6 (a
    # faint blob) and found again at 52, jumped 60 px onto the meeting hands' second blob, 20 px
    # from the pair's estimate; person 1's lost left hand did the same at 57. The pair then saw
    # its blob only every other frame and was lost at 72, both hands held at the meeting point.
    pair_span: bool = flag(True)
    lost_likelihood: float = number(0.15, FRACTION)
    # hysteresis: a lost target comes back only above this confidence.
    recover_likelihood: float = number(0.3, FRACTION)
    lost_frames: int = number(5, POSITIVE_COUNT)
    # frames of estimates kept to read the direction between two targets before they join.
    history_frames: int = number(10, COUNT)


@dataclass(frozen=True)
class LimbLabels:
    """Which target is whose head or hand (sec. 7.1)."""

    # a hand belongs to the nearest head within this many head heights; a person facing the
    # camera has the left hand on the image's right.
    person_radius: float = number(5.0, POSITIVE)
    facing_camera: bool = flag(True)
    # frames an unlabelled tracker with no head nearby waits before it is taken as a head.
    head_guess_frames: int = number(5, COUNT)


@dataclass(frozen=True)
class LimbAdjustment:
    """Re-acquiring a head with the face detector (Xu, Deng & Jia sec. 3): after ``reacquire_frames``
    frames below ``reacquire_confidence``."""

    reacquire_frames: int = number(5, POSITIVE_COUNT)
    reacquire_confidence: float = number(0.3, FRACTION)


@dataclass(frozen=True)
class LimbPeople:
    """Where people are, for trackers started without ``--init`` (``partlab.tracking.limbs.people``):
    limbs start, are labelled, are written and live only on person regions."""

    # a foreground component at least this fraction of the frame tall is a person region: PETS09's
    # farthest walkers are ~0.09 of the frame, a seated person at a desk ~0.5; road cones,
    # flickering wall patches and grass tufts are under 0.04
    min_height: float = number(0.06, FRACTION)
    # closing kernel (fraction of the frame height) joining a walker's legs, body and head into one
    # component: ~9 px on 576 lines, about a walker's leg gap
    close: float = number(0.015, FRACTION)
    # ... on the foreground shrunk by this factor (a region's box needs no finer grain)
    shrink: int = number(4, POSITIVE_COUNT)
    # a head is labelled and written only in the top quarter of a person region: a standing
    # person's head centre lies at about a fourteenth of their height from the top (PETS09 truth:
    # 0.06-0.1), a seated one's lower; the top third also let through red sleeves at mid-chest
    # (PETS frames 0-199, --seed 1: limb heads on a truth person's top third 0.74 at 1/3, 0.80 at 0.2)
    head_top: float = number(0.25, FRACTION)
    # frames off every person region after which an automatically started tracker ends; ~2 s at
    # PETS09's 7 fps: a walker's silhouette breaks up behind a pillar for about that long
    end_frames: int = number(15, POSITIVE_COUNT)


@dataclass(frozen=True)
class LimbParams(Parameters):
    """Parameters of the head-and-hands tracker, by what they tune."""

    KEY: ClassVar[str] = "limbs"

    dynamics: LimbDynamics = group_field(LimbDynamics)
    appearance: LimbAppearance = group_field(LimbAppearance)
    priors: LimbPriors = group_field(LimbPriors)
    skin: LimbSkin = group_field(LimbSkin)
    blobs: LimbBlobs = group_field(LimbBlobs)
    states: LimbStates = group_field(LimbStates)
    labels: LimbLabels = group_field(LimbLabels)
    adjustment: LimbAdjustment = group_field(LimbAdjustment)
    people: LimbPeople = group_field(LimbPeople)

    #: partlab 0.2's flat names (the shipped bundle and users' bundles) -> where they live now
    FLAT: ClassVar[dict[str, str | None]] = {
        "particles": "dynamics.particles",
        "noise_xy": "dynamics.noise_xy",
        "noise_v": "dynamics.noise_v",
        "velocity_decay": "dynamics.velocity_decay",
        "combined_noise_scale": "dynamics.combined_noise_scale",
        "lost_search": "dynamics.lost_search",
        "hue_bins": "appearance.hue_bins",
        "model_update": "appearance.model_update",
        "lam": "appearance.lam",
        "hue_min_saturation": "appearance.hue_min_saturation",
        "hue_min_value": "appearance.hue_min_value",
        "mean_shift_iterations": "appearance.mean_shift_iterations",
        "mean_shift_eps": "appearance.mean_shift_eps",
        "sigma_v": "priors.sigma_v",
        "sigma_d": "priors.sigma_d",
        "sigma_s": "priors.sigma_s",
        "sigma_xy": "priors.sigma_xy",
        "blob_floor": "priors.blob_floor",
        "skin_threshold": "skin.threshold",
        "skin_adapt": "skin.adapt",
        "skin_ybins": "skin.ybins",
        "skin_keep_mass": "skin.keep_mass",
        "skin_keep_recall": "skin.keep_recall",
        "skin_keep_min_side": "skin.keep_min_side",
        "skin_keep_spread": "skin.keep_spread",
        "skin_keep_hidden": "skin.keep_hidden",
        "skin_open": "skin.open",
        "blob_alpha": "blobs.alpha",
        "min_blob_area": "blobs.min_area",
        "support_scale": "blobs.support_scale",
        "tip_span": "blobs.tip_span",
        "tip_far": "blobs.tip_far",
        "tip_radius": "blobs.tip_radius",
        "tip_min_side": "blobs.tip_min_side",
        "tip_kept": "blobs.tip_kept",
        "tip_person": "blobs.tip_person",
        "tip_gate": "blobs.tip_gate",
        "start_prior": "states.start_prior",
        "start_frames": "states.start_frames",
        "combine_distance": "states.combine_distance",
        "split_distance": "states.split_distance",
        "combine_size": "states.combine_size",
        "split_size": "states.split_size",
        "mode_search": "states.mode_search",
        "lost_likelihood": "states.lost_likelihood",
        "recover_likelihood": "states.recover_likelihood",
        "lost_frames": "states.lost_frames",
        "history_frames": "states.history_frames",
        "person_radius": "labels.person_radius",
        "facing_camera": "labels.facing_camera",
        "head_guess_frames": "labels.head_guess_frames",
        "reacquire_frames": "adjustment.reacquire_frames",
        "reacquire_confidence": "adjustment.reacquire_confidence",
        "people_min_height": "people.min_height",
        "people_close": "people.close",
        "people_shrink": "people.shrink",
        "people_head_top": "people.head_top",
        "people_end_frames": "people.end_frames",
    }
    #: fields added after partlab 0.2 (no flat name)
    ADDED: ClassVar[tuple[str, ...]] = ("states.pair_lost_claims", "states.split_unseen",
                                            "states.pair_span", "blobs.cut_ends", "blobs.cut_centres",
                                            "states.people_mode_search")
