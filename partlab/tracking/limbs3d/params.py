"""Every tunable number of the multi-camera head-and-hands tracker (*3D tracking of the hands and
head of interacting people from several cameras*, sec. 4-6), grouped by what it tunes. Lengths are
millimetres in the take's world frame unless they say pixels. ``Limbs3DParams`` is stored by model
bundles under the key ``"limbs3d"``. Groups:

- ``observations``: silhouettes and the skin blobs of each view (sec. 6.1-6.2);
- ``priors``: the candidate prior p(Z) = p_o p_t p_b (eq. 19, 25-27; the ``sigma_*`` are
  **fitted** from corrected takes, sec. 6.4, :mod:`partlab.models.limbs3d`), pruning and merging;
- ``dynamics``: one particle filter per 3D target (sec. 4.2, eq. 17);
- ``states``: the five-state machine of sec. 5.2 (the paper gives no thresholds; the names are
  those of :class:`partlab.tracking.limbs.params.LimbStates`, whose machine this tracker reuses);
- ``output``: back-projected boxes and how new targets are labelled.
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
class Limbs3DObservations:
    """Silhouettes and skin blobs per view (sec. 6.1-6.2)."""

    # keep the ceil(3 * alpha * people) largest skin blobs per view (alpha > 1: spares)
    blob_alpha: float = number(1.5, POSITIVE)
    # blobs smaller than this many pixels are noise (a hand 3 m away at 640x480 is ~200 px)
    blob_min_area: float = number(12.0)
    skin_threshold: float = number(0.5, FRACTION)
    # opening kernel (pixels, elliptic) on the skin mask before blobs, 1 = none: the anti-aliased
    # rim of a yellow or orange shirt against a grey wall mixes to skin chroma, a 1-2 px line that
    # joins head and hands into one blob through the torso's outline; a 5 px opening removes it
    # while a hand 3 m away (~15 px across at 640x480) stays
    skin_open: int = number(5, POSITIVE_COUNT)
    # with --init: refit the skin model (core.skin.train_skin_model, a Bayes ratio over coarse luma
    # bins shrunk to the rule) on the init targets' back-projected boxes in every view. A shaded
    # olive or orange sleeve shares the rule's chroma with skin but not its brightness; its
    # speckle otherwise joins the hand's blob and drags its centre ~100 mm up the arm
    skin_adapt: bool = flag(True)
    skin_ybins: int = number(8, POSITIVE_COUNT)
    # silhouettes (sec. 6.1, background subtraction): with an empty-scene plate per view (a take's
    # ``<stream>_background.png``), a pixel is a person's where a channel differs from the plate by
    # more than this (after a 2 x 2 area average; sensor noise is ~3 levels); without one, the run
    # loop's adaptive foreground mask is used
    plate_threshold: float = number(28.0, POSITIVE)
    # without an empty-scene plate: around each tracked target's projection, skin counts even where
    # the adaptive background model has absorbed a person who sits still (radius in target sizes,
    # see output.head_size_mm); with a plate the silhouette is trusted
    support_scale: float = number(2.5)
    # a view whose plate silhouette covers more than this fraction of it sees no people (a dark,
    # covered or moved camera: a black frame differs from its plate everywhere, and the adapted skin
    # model found a blob in one, standing seed 5 at 3 cameras): its blobs are dropped, and it counts
    # as not seeing (dynamics.gate_growth_dark, hold_unseen). 1 = never (2026-12-03)
    blind_fill: float = number(0.9, FRACTION)


@dataclass(frozen=True)
class Limbs3DPriors:
    """The candidate prior p(Z) = p_o p_t p_b (eq. 19, 25-27), pruning and merging (sec. 6.4)."""

    # eq. 25 (fitted): spread (mm) of the difference of the two blobs' depths below the top of
    # their silhouettes (priors.py: the paper's relative rows, turned into mm at the candidate's
    # depth because a table hides the legs from some views). True pairs differ by 30-45 mm
    # (median) and 120-150 (90th percentile) on the seated takes, and by ~200 where two people's
    # silhouettes merge in one view and not the other (the handshake); false head-hand pairs by
    # ~400. 150 mm: 100 gave the 3-camera handshake (seeds 0-2) 105/49/114 mm, 150 gave 90/70/101
    sigma_v: float = number(150.0, POSITIVE)
    # p_o's reference (our addition): a blob whose silhouette component is smaller than this
    # fraction of the view's largest is measured from the top of the nearest larger component
    # (priors.observe_view). Seated 2-camera seed 6: the right hand reaching across the table is
    # an 89-pixel component of its own in cam0, so its Dv was ~0 there and ~590 mm in cam1, and
    # its true pair got p_o 0 for 30 frames. 0 = off. 0.25 with fragment_either (2026-12-02,
    # docs/trackers/limbs3d.md, seeds 0-9 at 2 and 3 cameras and held-out 20-24): standing 3
    # cameras all parts 24 -> 21 mm, every seed under 50; seated 2 cameras 19 -> 16, seed 6 96 -> 33
    fragment: float = number(0.25, FRACTION)
    # with fragment > 0: p_o takes the better of the two references (every blob from its own
    # component's top, and a fragment's from its person's), so a pair that agreed from their own
    # components' tops is not lost (standing 3 cameras seed 8 with fragment alone: right hand 184 mm,
    # 40 with both)
    fragment_either: bool = flag(True)
    # with fragment > 0: a fragment's person is the highest of the larger components whose columns
    # overlap those of the nearest one (priors.observe_view; our addition). A person whose clothes
    # match the background breaks into head, chest and belly components stacked in one view, and the
    # nearest to a hand at the hip was the belly's (standing seed 5, 2 cameras, camera 0: the right
    # hand's true pair had Dv -640..-800 mm, p_o 0, for 50 frames; the hand was lost and held
    # 277-419 mm off). Two people side by side do not overlap; the highest larger component within
    # 40 px instead (tried) took the other person's and cost handshake seed 4 ~20 mm at 2 and 4
    # cameras. 2026-12-06 (docs/measurements/limbs3d.md, seeds 0-9): standing 2 cameras 39.9 -> 34.5
    # mm (seed 5 85.7 -> 32.3), every other take of standing, seated and handshake at 2-4 cameras
    # within 0.5 mm. False = the nearest one (before)
    fragment_stack: bool = flag(True)
    # eq. 26 (fitted): spread of the distance between the two lines of sight (mm). Blob centroids
    # are not projections of one 3D point (the head's hair, sec. 6.3), yet on the synthetic seated
    # takes 90 % of true pairs lie within 3-10 mm, while a tenth of false pairs lie within 22-38 mm;
    # 20 mm keeps the true ones (>= 0.75 at 15 mm) and halves those false ones
    sigma_d: float = number(20.0, POSITIVE)
    # eq. 27 (fitted): spread of the distance (pixels) of the candidate's projection to each view's
    # silhouette
    sigma_s: float = number(6.0, POSITIVE)
    # candidates below this prior are pruned (the paper's Fig. 4 threshold, 0.1)
    prior_threshold: float = number(0.1, FRACTION)
    # candidates must lie in the room: above the floor and below this height (mm)
    max_height: float = number(2400.0, POSITIVE)
    # close candidates merge: the weaker is eliminated and boosts the stronger by this fraction of
    # its prior (sec. 6.4). 45 mm: the three pairs of a hand seen by three cameras lie within ~3 cm,
    # while two touching hands stay ~50 mm apart (centre to centre)
    merge_distance: float = number(45.0)
    merge_boost: float = number(0.5)
    # a merged candidate whose blobs are all used by stronger candidates is a ghost (the crossing
    # of the lines of sight of two different limbs, priors.suppress_ghosts; our addition): its
    # prior is scaled by this (0 drops it, 1 = off)
    ghost_factor: float = number(0.0, FRACTION)
    # which of the candidates sharing blobs is the ghost (our addition): they claim their blobs in
    # order of the number of views their pairs span, then of prior * (1 - w + w exp(-d^2 / 2
    # ghost_anchor^2)), w = ghost_anchor_weight, d the distance (mm) to the nearest tracked
    # target's prediction: with two views the true pairs and the ghosts of two hands often all have
    # prior ~1, and the pair the dynamics expect should own its blobs (standing, camera 0 of 3
    # hidden, seed 0: hands 150-220 mm off on ghosts -> 34 mm). A small weight, a tie-breaker: with
    # 1 a false pair the filter sat on kept out-ranking the true one that came back 250 mm away
    # (standing seed 5, 3 cameras: left hand 22 -> 56 mm). 0 = by prior alone (before 2026-12-03)
    ghost_anchor: float = number(150.0)
    ghost_anchor_weight: float = number(0.1, FRACTION)
    # the kept candidate moves to the prior-weighted mean of those it absorbs (the paper keeps the
    # stronger point; the mean of the pairs of 3-4 cameras is a better estimate of the centre)
    merge_average: bool = flag(True)


@dataclass(frozen=True)
class Limbs3DDynamics:
    """One SIR filter per target, ``particles`` of ``[X, Y, Z, vX, vY, vZ]`` (sec. 4.2, eq. 17)."""

    particles: int = number(200, POSITIVE_COUNT)
    # p(x | Z_c): Gaussian of this spread (mm) around each candidate, about a hand's radius
    sigma_x: float = number(45.0, POSITIVE)
    # weight every particle keeps, so a filter whose candidates vanish diffuses around its place;
    # 1e-3 was above what the jump mixture gives a particle on a candidate 200 mm off (~1e-3), so
    # the cloud stayed behind whatever the candidate's prior
    weight_floor: float = number(1e-4, POSITIVE)
    # x_t = x_{t-1} + decay v_{t-1} + noise (mm per frame; a gesturing hand moves up to ~60 mm a
    # frame at 25 fps)
    noise_xyz: float = number(25.0)
    noise_v: float = number(10.0)
    velocity_decay: float = number(0.85, FRACTION)
    # sec. 4.2 allows "further steps" on top of SIR: this fraction of the particles is drawn around
    # the candidates within candidate_gate mm of the prediction (by prior), so a hand that moves
    # faster than the dynamics expect is not left behind; their weights are eq. 17's like any other
    candidate_mix: float = number(0.3, FRACTION)
    candidate_gate: float = number(250.0, POSITIVE)
    # the gate grows by this fraction of itself per frame in a row the target had no confidence
    # (up to states.lost_frames; our addition): a clapping hand whose candidates vanished for one
    # frame is ~270 mm from its next one (standing seed 5, camera 0 of 3 hidden: lost at 69). Off
    # (0): 0.5 (2026-12-03, seeds 0-9) loses no target with a camera hidden at 3 cameras (standing
    # 1 -> 0 lost) and moves the 3-camera handshake 78.8 -> 76.7 mm, but the 4-camera one 69.9 ->
    # 71.5 and the 2-camera one 91.4 -> 91.7 mm with one more swap
    gate_growth: float = number(0.0)
    # gate_growth added while some view sees no skin blob at all (a dark or covered camera, our
    # addition): the hands it helped triangulate have pair candidates only now and then. 2026-12-03,
    # seeds 0-9, camera 0 hidden for 30 frames, with blind_fill: standing 3 cameras lost 1 -> 0
    # (seed 5); unhidden takes unchanged (it never applies there); 3-camera handshake hidden
    # stretch 80.2 -> 78.7 mm but the 20 frames after it 124.6 -> 132.6. 0 = off
    gate_growth_dark: float = number(0.5)
    # with fewer than two views seeing skin blobs nothing can be triangulated: such a frame is no
    # evidence against a target and does not count towards states.lost_frames (our addition,
    # Observation.unseen). 2026-12-03, seeds 0-9, 2 cameras, camera 0 hidden for 30 frames: lost
    # standing 2 -> 1 (seed 5 loses it unhidden too), handshake 27 -> 16 (unhidden 18), seated 0 -> 0;
    # the 20 frames after the stretch: standing 47.9 -> 50.4 mm, handshake 105.3 -> 133.5 (hands
    # kept on single-view candidates instead of held where lost). False = off
    hold_unseen: bool = flag(True)
    # the dynamics' density in the importance weights f / q is a mixture: (1 - jump_mix) the
    # predicted cloud's Gaussian, jump_mix one jump_scale times wider (our addition). A clap starts
    # in 2-3 frames (a hand at ~3 m/s, 120 mm a frame): with the Gaussian alone the filter fell
    # 200-300 mm behind its own strong candidate and was lost (standing seed 3: hands 285 and
    # 162 mm at 3 cameras; with the mixture 52 and 18, and the ghosts below dropped)
    jump_mix: float = number(0.2, FRACTION)
    jump_scale: float = number(4.0, POSITIVE)
    # a candidate nearer another target's prediction (by this factor) is left to that target
    exclusive_ratio: float = number(1.0, POSITIVE)
    # a hand uses only candidates within this distance (mm) of its own person's head estimate, 0 =
    # no limit (our addition, not the paper's): shoulder to head ~250 mm plus an arm ~650-700 mm,
    # and a hand hanging at the side of a 1.9 m person is ~880 mm from the head. Two people who
    # shake hands stand ~1 m apart, so when the hands part, the other person's hand going back to
    # its side (~1.2-1.4 m from this head) cannot carry this hand away with it
    hand_reach: float = number(1000.0)
    # single-view candidates (our addition, the "next step" of docs/trackers/limbs3d.md): a normal
    # target with no candidate from a pair of views within candidate_gate of its prediction (a hand
    # hidden by a body in all views but one, or a camera that went dark) takes, in each view, the
    # blob nearest its predicted projection within single_view_gate mm (projected at its depth) that
    # no other target's projection is nearer to, at the point of that blob's line of sight nearest
    # the prediction. Their prior is below states.recover_likelihood, so they keep a tracked target
    # tracked but never bring a lost one back (one view cannot tell its depth). 0 = off
    single_view_prior: float = number(0.2, FRACTION)
    single_view_gate: float = number(100.0, POSITIVE)
    # the gate when only one view sees skin blobs at all (a camera of two hidden): nothing can be
    # triangulated, every target is single-view and a hand that starts a clap (~150 mm a frame)
    # leaves the 100 mm gate in one frame, is lost and held there (2026-12-03: camera 0 of 2
    # hidden for 30 frames, seeds 0-9, targets lost standing 14 -> 2, seated 8 -> 0). Wider for
    # every frame was worse with two views left (seated 3 cameras, camera 0 hidden: lost 0 -> 2
    # with 150 or 250 mm): a hand whose pair merged with the other's for a frame took a wrong blob
    single_view_gate_alone: float = number(250.0, POSITIVE)
    # a single-view candidate's depth (our addition): a hand that no other view sees as a blob is
    # hidden there, so it lies where its line of sight projects onto a silhouette (within this
    # many pixels) in every other view that sees people; of those points of the line (within
    # single_view_depth mm of the prediction's), the one nearest the prediction, so the hand hidden
    # behind its own body is not pushed off it along the line. 0 = the point nearest the prediction
    single_view_support: float = number(0.0)
    # a hand seen by one view has the depth another view tells (our addition; the paper calls such
    # a target lost, sec. 5.2, and finds it again from "prior information of the target position",
    # here its line of sight; with three views or more): a hand with no pair candidate in its gate
    # for more than states.lost_frames frames takes, once one has been there states.start_frames
    # frames in a row, a candidate of prior >= states.start_prior made from the blob it follows in
    # one view and another view's blob, none of whose blobs is another target's image (a blob is
    # shared only with another person's hand near the candidate, and not by a lost hand), wherever
    # it lies along the line. A combined pair with one mode from pairs takes as its second a blob of
    # one view beside it once that has moved away for start_frames frames (sec. 5.2, the modes
    # parting); the member given it, and any member of a split pair while seen by one view or lost,
    # is put on its line of sight (or held) where it was, relative to its head, when last tracked
    # alone from pairs (hands go back after a handshake). 2026-12-03, docs/measurements/limbs3d.md,
    # seeds 0-9: handshake 3 cameras 78.8 -> 72.6 mm, hands meet in 0.20 -> 0.63 of the handshake;
    # 4 cameras 69.9 -> 69.4 mm (0.34 -> 0.46); standing and seated unchanged. False = main before
    line_of_sight: bool = flag(True)
    single_view_depth: float = number(600.0, POSITIVE)
    # (line_of_sight) a hand seen by one view takes no candidate where two other tracked hands
    # already are, both estimates within states.split_distance of it (our addition): two hands
    # meeting make one blob, and a third hand's line of sight through that blob in one view is not
    # where the third hand is. Held-out 3-camera handshake seed 14: person 2's left hand, hidden,
    # was put on the exchange of person 1's left and person 2's right hand 540 mm from its own, and
    # two hands ended on another hand (107.8 -> 35.6 mm, none with it). 2026-12-06
    # (docs/measurements/limbs3d.md, session hs3d5): handshake seeds 0-9 at 2-4 cameras the same to
    # 0.1 mm, held-out 10-19 only seed 14 at 3 cameras changes; one person: never applies (one other
    # hand). False = main before
    sight_meeting: bool = flag(True)
    # a hand uses no candidate lying more than this many mm on the other side of its head (along its
    # person's left-right axis at the init frame, the horizontal line from its other hand to it;
    # our addition): a person's two hands keep their sides but for a reach across the body. Tried
    # 2026-12-06 at 150 (held-out handshake 3 cameras 60.8 -> 63.1 mm: seed 16 +35, hands on another
    # hand 2 -> 2); 0 = off
    hand_side: float = number(0.0)
    # a head uses no candidate that shares a blob with the candidate of more views another person's
    # tracked target claims (the one nearest its prediction within candidate_gate; our addition,
    # sec. 6.4's ghosts for heads): in a view where two heads lie on one line of sight the nearer
    # hides the farther, and the nearer's blob paired with the farther head's blob in a second view
    # makes a ghost beside the farther head, inside every silhouette (p_b ~1); a head seen by one
    # view slid 200 mm down onto one and stayed there (handshake seed 8, 3 cameras: 170-217 ->
    # 77-92 mm). A no-op with two cameras (every candidate is a pair) and for one person. Off by
    # default: seeds 0-9, 3 cameras, heads 50.4 -> 44.6 mm but all parts 49.5 -> 52.8 (seed 9's
    # right hand, lost in the reach either way, held elsewhere: 96 -> 240 mm), 4 cameras 54.8 ->
    # 54.4; held-out seeds 10-14 no better (3 cameras 80.2 -> 81.5, swaps 4 -> 5): a head freed
    # from the ghost drifts along its one view's line of sight, and the hands' homes, relative to
    # it, drift with it (docs/measurements/limbs3d.md, 2026-12-06, branch hs3d)
    head_own_blobs: bool = flag(False)
    # a hand uses no candidate that shares a blob with the candidate another tracked hand or head of
    # its person claims (the one nearest its prediction, within candidate_gate; of as many views or
    # more) and lies more than this many mm from that claim, when it is farther from this hand's
    # prediction than the claim is from its claimant's (tracker._ghost_of_claim; our addition, sec.
    # 6.4's ghosts): with two views a hand hidden in one of them sat on the ghost made of the other
    # hand's blob there and its own blob in the other view (standing 2 cameras seeds 3, 5, 7: 250-460
    # mm off); p_b cannot reject it with two views. Only for takes of at most
    # hand_own_blobs_cameras views: with three, two hands on one line of sight in one view share a
    # blob truly, and the 3-camera handshake lost 28-88 mm a take (2026-12-06, session hs3d). Off by
    # default: 2026-12-06 (docs/measurements/limbs3d.md, session hs3d2), with fragment_stack, standing
    # 2 cameras seeds 3 and 5 -18 and -7 mm but seed 9 +12 (a clap's two hands on one line of sight in
    # camera 0: the lagging hand's true pair shares the other's blob and is dropped). 0 = off
    hand_own_blobs: float = number(0.0)
    hand_own_blobs_cameras: int = number(2, POSITIVE_COUNT)
    # a lost target (held where it was lost) does not take candidates from a tracked one by being
    # nearer to them (our addition): a hand lost during a fast clap is held where it fell behind,
    # often nearer the other hand's candidates than that hand's own lagging prediction
    lost_yield: bool = flag(True)
    # a normal hand with no candidate it may use within candidate_gate of its prediction is put on
    # the nearest one of prior >= states.start_prior within this distance (mm) that is nearer to it
    # than to every other target (a lost one where it is held included), with fewer than three
    # views (tracker._refind; our addition; with three or more, line_of_sight re-finds a hand and
    # this made the 3-camera handshake worse, seeds 2 and 4 +18 and +23 mm): a hand leaving a clap at
    # ~140 mm a frame is 300-400 mm from its lagging estimate when next seen by two views (standing
    # 2 cameras seed 3: left hand frame 90, 220 -> 23 mm off). Off by default (2026-12-06,
    # docs/measurements/limbs3d.md, 2 cameras, seeds 0-9, with fragment_stack): standing 34.5 -> 34.7
    # mm (seed 3 -2.8, 4 -3.7, 0 and 8 +3), seated 15.9 -> 16.7 (seed 4 +12: a hand put on a candidate
    # of the other hand's; with hand_own_blobs as well +144 mm and a hand on another hand), handshake
    # within 3.4 mm a take. 0 = off
    refind_gate: float = number(0.0)
    # a combined filter spreads its particles this much wider so it sees both modes
    combined_noise_scale: float = number(1.3, POSITIVE)
    # a lost target's particles spread this wide (mm) around where it is looked for
    lost_search: float = number(120.0)


@dataclass(frozen=True)
class Limbs3DStates:
    """Thresholds of the five-state machine (sec. 5.2, on 3D targets; the paper gives none)."""

    combine_distance: float = number(80.0)  # mm between estimates: two hands about touching
    split_distance: float = number(120.0)  # mm between the combined posterior's modes
    # (no size-relative thresholds in 3D: millimetres are absolute)
    combine_size: float = number(0.0)
    split_size: float = number(0.0)
    lost_likelihood: float = number(0.1, FRACTION)
    # hysteresis: a lost target comes back only above this confidence
    recover_likelihood: float = number(0.25, FRACTION)
    lost_frames: int = number(5, POSITIVE_COUNT)
    start_frames: int = number(3, POSITIVE_COUNT)
    start_prior: float = number(0.5, FRACTION)
    # frames of estimates kept to read the direction between two targets before they join
    history_frames: int = number(10, COUNT)
    # a lost hand is held (and looked for) where it was relative to its person's head when last
    # tracked alone from pairs of views (its home), not where it was lost (our addition; the lost
    # state "uses prior information of the target position to retrieve the track", sec. 5.2): a
    # hand lost after falling behind or drifting was held where nothing is, between two people
    # (handshake 3 cameras seed 4: 355-440 mm off). Before 2026-12-06 only a hand that had left a
    # combined pair was. Seeds 0-9: swaps handshake 3/3/5 -> 1/1/5 at 2/3/4 cameras, standing 2
    # cameras 3 -> 2, mean errors within 0.5 mm; the tracked hands meet in less of the handshake
    # (3 cameras 0.63 -> 0.54); held-out seeds 10-14: swaps 7 -> 9, 4 cameras 42 -> 52 mm, 2-3 cameras
    # better (a small gain, not robust; 3-camera activities: exchange precision 1.00 -> 0.50, false
    # picks 1 -> 4), so it stays off: False = before
    lost_home: bool = flag(False)
    # a hand of a combined pair that is lost with it (the state machine's "combined -> lost": the
    # pair's modes never parted) is held and looked for at its home, relative to its head, as a
    # hand that left the pair by a split is with three views or more (our addition; sec. 5.2's lost
    # state retrieves the track from prior information of its position, and after an exchange each
    # hand goes back to its own person, sec. 7.1). Handshake seed 7, 2 cameras: person 1's left hand,
    # lost with person 2's right at the end of the exchange, was held where the pair was, 379-424 mm
    # off and within 135 mm of person 2's right hand (a swap); at its home 279-323 mm (that home is
    # where it was last tracked alone, already reaching). 2026-12-06, seeds 0-9: 2-camera handshake
    # seeds 6 and 7 only (83.0 -> 72.7, 68.7 -> 64.6 mm, each loses its swap); held-out seeds 10-19:
    # 2-camera handshake seed 15 only (73.3 -> 60.4 mm); every other take (standing and handshake
    # 0-19, seated 0-9, at 2-4 cameras) the same to 0.1 mm: no pair is lost combined there. False =
    # main before
    combined_lost_home: bool = flag(True)
    # a combined pair of two people's hands nearer one person's head than the other's by more than
    # foreign_margin mm for this many frames in a row splits, the farther person's hand going back to
    # its home, which is not taken from frames in which the hand is nearer another person's head than
    # its own (tracker._foreign_pair; our addition: after a handshake each hand goes back to its own
    # person, sec. 7.1). Handshake 4 cameras seed 7: person 2's right hand took person 1's when the
    # hands parted (person 1's tracker lagged 230-360 mm off), followed it to person 1 and was
    # combined with it for 56 frames, 930-1040 mm from person 2's head and ~230 mm nearer person 1's.
    # On since 2026-12-06 (session hs3d4, docs/measurements/limbs3d.md, with lost_claim_frames and
    # foreign_home_margin 150): handshake seeds 0-9, 4 cameras seed 7 106.6 -> 94.4 mm (no longer on
    # another hand), every other take at 2-4 cameras the same; held-out seeds 10-19 at 3 and 4
    # cameras the same but 4-camera seed 16 +0.3 mm; one person: never applies. 0 = off
    foreign_pair_frames: int = number(5, COUNT)
    foreign_margin: float = number(200.0, POSITIVE)
    # with foreign_pair_frames: a hand's home is not taken from a frame in which its estimate is nearer
    # another person's head than its own by more than this (mm; our addition). With 0 (session hs3d3)
    # held-out handshake 4 cameras seed 16 went 72.4 -> 90.0 mm with one more swap: person 1's head ~300
    # mm off, person 2's right hand reaching for the exchange was a little nearer it, kept a stale home
    # and was sent back there when the pair split (frame 97: 284 mm off, lost); 150: 72.7, and seed 7
    # (4 cameras) still leaves person 1's hand (106.6 -> 94.4 mm; 92.8 with 0; with 300 it stays on it)
    foreign_home_margin: float = number(150.0)
    # with foreign_pair_frames: the distances from a hand to the heads are measured horizontally (our
    # addition): a hand hanging at the hip is ~700-800 mm below either head, which hides how far it is
    # to the side of each. Held-out 3-camera handshake seed 15: both right hands combined at person
    # 1's hip, 780 / 910 mm from the heads in 3D (within foreign_margin), ~330 / ~700 across; person
    # 2's hand stayed on person 1's for 70 frames (86.4 -> 67.0 mm, no longer on it). 2026-12-06
    # (docs/measurements/limbs3d.md, session hs3d5): handshake seeds 0-9 at 2-4 cameras the same to
    # 0.1 mm, held-out 10-19 seed 15 at 3 cameras and seed 16 at 4 (72.7 -> 72.4) only; one person:
    # never applies. False = in 3D (main before)
    foreign_horizontal: bool = flag(True)
    # a hand uses no candidate nearer another person's head than its own by more than this (mm,
    # measured as foreign_horizontal says; our addition): two people's hands meet between them, and
    # a hand past that by this much is the other person's. Tried 2026-12-06 at 150: held-out
    # handshake 3 cameras 60.8 -> 61.8 mm (seeds 15 and 18 fixed, seed 16 +54 with a hand on another
    # hand: a head estimate ~300 mm off makes a hand's own candidates "foreign"), 4 cameras 45.3 ->
    # 44.2 (seed 10 -39, 13 +24, 17 +7); at 300, 3 cameras 60.8 -> 59.3 but seed 16 +35.5 with a hand
    # on another hand. 0 = off
    foreign_use: float = number(0.0)
    # a lost hand takes, once one has been there this many frames in a row, a candidate of prior >=
    # start_prior spanning lost_claim_views views or more, within dynamics.hand_reach of its head,
    # nearer it than every other person's head by lost_claim_margin mm, at least lost_claim_side mm on
    # the hand's side of its head (along the horizontal line from its person's other hand to it at
    # their init frame), that no tracked target's prediction is within dynamics.candidate_gate of
    # (tracker._orphan; our addition: the lost state retrieves the track, sec. 5.2). Handshake 4
    # cameras seed 4: person 2's right hand was lost at frame 68 and held ~600 mm off while its true
    # candidate lay 30-40 mm from its hand from frame 113, until its left hand took it (a hand on
    # another hand). Without the side, the 3-camera seed 2's lost right hand took its left hand's
    # candidate, ~245 mm on the left of the head (the right hand's own lay ~250 mm on the right).
    # 2026-12-06 (docs/measurements/limbs3d.md, session hs3d4), seeds 0-9: handshake 4 cameras 54.7 ->
    # 51.1 mm (seed 4 92.6 -> 55.8, no longer on another hand), 3 cameras 49.5 -> 48.9 (seed 7 50.2
    # -> 44.6), every other take the same (2 cameras: every candidate spans two views); standing and
    # seated at 3 and 4 cameras the same; held-out handshake seeds 10-19 at 3 and 4 cameras the same.
    # 0 = off
    lost_claim_frames: int = number(3, COUNT)
    lost_claim_views: int = number(3, POSITIVE_COUNT)
    lost_claim_margin: float = number(200.0)
    lost_claim_side: float = number(100.0)
    # modes of a combined pair are sought among candidates within this many split distances
    mode_search: float = number(2.5, POSITIVE)
    # a combined pair of two people's hands with one mode also takes for its second a candidate of
    # prior >= mode_heads_prior beyond mode_search but within mode_search_heads split distances of
    # the first, nearer one of the two heads than the first and within dynamics.hand_reach of it
    # (tracker._mode_towards_head; our addition). Handshake seed 8, 4 cameras: the right hand left
    # the handshake while hidden (frames 60-62, its only candidate a ghost of two shared blobs) and
    # came back 390 mm from the pair, out of mode_search: the pair stayed on the other hand and
    # split onto a false mode (swap, 143 -> 52 mm). The prior: a false candidate of 0.67 399 mm
    # from every part split a pair during seed 6's exchange (39 -> 64 mm); 2.5 = off
    mode_search_heads: float = number(4.0, POSITIVE)
    mode_heads_prior: float = number(0.8, FRACTION)
    # two hands of different people that split take their modes by the direction cue unless that puts
    # each on the other's side: the modes' difference against their heads' by more than this cosine
    # (tracker._split_sides; our addition). Handshake seed 3, 3 cameras: a lost hand and one drifting
    # on single-view candidates met at the exchange, the direction from their wrong estimates gave
    # each the other's mode (a swap). 2026-12-03, handshake seeds 0-9: 3 cameras 61.8 -> 49.6 mm,
    # swaps 7 -> 3; 4 cameras 69.4 -> 63.8, 10 -> 7; 2 cameras unchanged; one person: never applies.
    # 1 = off
    split_heads: float = number(0.5, FRACTION)


@dataclass(frozen=True)
class Limbs3DOutput:
    """Back-projected boxes and the labels of new targets."""

    # a part's size in mm (the synthetic heads' boxes are ~230 mm, hands ~95)
    head_size_mm: float = number(230.0, POSITIVE)
    hand_size_mm: float = number(100.0, POSITIVE)
    # automatic start (no --init): hands within this horizontal radius of a head are its person's
    person_radius: float = number(900.0, POSITIVE)


@dataclass(frozen=True)
class Limbs3DParams(Parameters):
    """Parameters of the multi-camera head-and-hands tracker, by what they tune."""

    KEY: ClassVar[str] = "limbs3d"

    observations: Limbs3DObservations = group_field(Limbs3DObservations)
    priors: Limbs3DPriors = group_field(Limbs3DPriors)
    dynamics: Limbs3DDynamics = group_field(Limbs3DDynamics)
    states: Limbs3DStates = group_field(Limbs3DStates)
    output: Limbs3DOutput = group_field(Limbs3DOutput)
