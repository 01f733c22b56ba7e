"""Parameters of the multi-camera head-and-hands tracker (3D tracking of the hands and head of
interacting people from several cameras, sec. 4-6). Lengths are millimetres in the take's world
frame unless they say pixels.

The three prior variances ``sigma_v``, ``sigma_d``, ``sigma_s`` (eq. 25-27) are what training
fits from corrected takes (sec. 6.4, :mod:`partlab.models.limbs3d`); the state machine's thresholds
are not given in the paper and are parameters here (the names are those of
:class:`partlab.tracking.params.LimbParams`, whose state machine this tracker reuses).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Limbs3DParams:
    # -- observations (sec. 6.2) --------------------------------------------------------
    # keep the ceil(3 * alpha * people) largest skin blobs per view (alpha > 1: spares)
    blob_alpha: float = 1.5
    # blobs smaller than this many pixels are noise (a hand 3 m away at 640x480 is ~200 px)
    blob_min_area: float = 12.0
    skin_threshold: float = 0.5
    # silhouettes (sec. 6.1, background subtraction): with an empty-scene plate per view (a take's
    # ``<stream>_background.png``), a pixel is a person's where a channel differs from the plate by
    # more than this (after a 5 x 5 blur; sensor noise is ~3 levels); without one, the run loop's
    # adaptive foreground mask is used
    plate_threshold: float = 28.0
    # without an empty-scene plate: around each tracked target's projection, skin counts even where
    # the adaptive background model has absorbed a person who sits still (radius in target sizes,
    # see head_size_mm); with a plate the silhouette is trusted (the seated scene's wooden table is
    # skin-coloured and lies right under the hands)
    support_scale: float = 2.5
    # -- candidate priors p(Z) = p_o p_t p_b (eq. 19, 25-27); fitted by training ------------
    # eq. 25: spread of the difference of the two blobs' relative heights within their silhouettes
    sigma_v: float = 0.08
    # eq. 26: spread of the distance between the two lines of sight (mm); true pairs lie within a
    # few cm (blob centroids are not projections of one 3D point: the head's hair, sec. 6.3)
    sigma_d: float = 30.0
    # eq. 27: spread of the distance (pixels) of the candidate's projection to each view's silhouette
    sigma_s: float = 6.0
    # candidates below this prior are pruned (the paper's Fig. 4 threshold, 0.1)
    prior_threshold: float = 0.1
    # candidates must lie in the room: above the floor and below this height (mm)
    max_height: float = 2400.0
    # close candidates merge: the weaker is eliminated and boosts the stronger by this fraction of
    # its prior (sec. 6.4). 45 mm: the three pairs of a hand seen by three cameras lie within ~3 cm,
    # while two touching hands stay ~50 mm apart (centre to centre)
    merge_distance: float = 45.0
    merge_boost: float = 0.5
    # the kept candidate moves to the prior-weighted mean of those it absorbs (the paper keeps the
    # stronger point; the mean of the pairs of 3-4 cameras is a better estimate of the centre)
    merge_average: bool = True
    # -- particle filter (sec. 4.2, eq. 17) -----------------------------------------------
    particles: int = 200
    # p(x | Z_c): Gaussian of this spread (mm) around each candidate, about a hand's radius
    sigma_x: float = 45.0
    # weight every particle keeps, so a filter whose candidates vanish diffuses around its place
    weight_floor: float = 1e-3
    # dynamics x_t = x_{t-1} + decay v_{t-1} + noise (mm per frame; a gesturing hand moves up to
    # ~60 mm a frame at 25 fps)
    noise_xyz: float = 25.0
    noise_v: float = 10.0
    velocity_decay: float = 0.85
    # sec. 4.2 allows "further steps" on top of SIR: this fraction of the particles is drawn around
    # the candidates within candidate_gate mm of the prediction (by prior), so a hand that moves
    # faster than the dynamics expect (~60 mm a frame when gesturing) is not left behind; their
    # weights are eq. 17's like any other particle's
    candidate_mix: float = 0.3
    candidate_gate: float = 250.0
    # a candidate nearer another target's prediction (by this factor) is left to that target
    exclusive_ratio: float = 1.0
    # -- state machine (sec. 5.2; names as LimbParams, used by LimbStateMachine) -----------
    combine_distance: float = 80.0  # mm between estimates: two hands about touching
    split_distance: float = 120.0  # mm between the combined posterior's modes
    combine_size: float = 0.0  # (no size-relative thresholds in 3D: millimetres are absolute)
    split_size: float = 0.0
    lost_likelihood: float = 0.1
    recover_likelihood: float = 0.25
    lost_frames: int = 5
    start_frames: int = 3
    start_prior: float = 0.5
    history_frames: int = 10
    # a lost target's particles spread this wide (mm) around where it is looked for
    lost_search: float = 120.0
    combined_noise_scale: float = 1.3
    # modes of a combined pair are sought among candidates within this many split distances
    mode_search: float = 2.5
    # -- output -----------------------------------------------------------------------------
    # back-projected boxes: a part's size in mm (the synthetic heads' boxes are ~230 mm, hands ~95)
    head_size_mm: float = 230.0
    hand_size_mm: float = 100.0
    # automatic start (no --init): a head is the highest of a person's candidates, hands within
    # this horizontal radius of it; persons are assumed to face the cameras' centroid
    person_radius: float = 900.0

    @property
    def states(self) -> Limbs3DParams:
        """Where :class:`~partlab.tracking.limbs.state_machine.LimbStateMachine` reads its thresholds
        (``params.states.lost_frames``, the grouped style of ``LimbParams``); here they are fields of
        this object (the state-machine block above)."""
        return self
