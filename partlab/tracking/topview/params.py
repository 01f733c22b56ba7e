"""Every tunable number of the top-view tracker (Migniot & Ababsa), grouped by what it tunes.

The paper gives the model, the likelihoods and the resampling but almost no numbers; each default
here says where it comes from. Distances are millimetres, angles radians, per frame at 25 fps.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from partlab.tracking.core.params import (
    FRACTION,
    NONNEG,
    POSITIVE,
    POSITIVE_COUNT,
    Parameters,
    flag,
    group_field,
    mapping,
    number,
    pair,
)


@dataclass(frozen=True)
class RoiParams:
    """Sec. 2.1: the region of interest is the depth pixels high enough above the floor to be a
    torso, arm or head. Hands hang at about 0.45 of a person's height (720 mm for 1.6 m), a low
    basket or shelf board stays below 650 mm; the sensor measures 0.8..3.5 m (sec. 3)."""

    min_height_mm: float = number(650.0)
    max_height_mm: float = number(2400.0)
    min_depth_mm: float = number(800.0)
    max_depth_mm: float = number(3500.0)
    #: points per person given to the likelihood each frame, drawn at random from its ROI pixels
    #: (a person covers 3-6 thousand pixels at 320x240; 500 keep eq. 1's mean within ~2 mm of
    #: all of them and the frame within budget)
    max_points: int = number(500, POSITIVE_COUNT)


@dataclass(frozen=True)
class DynamicsParams:
    """Random-walk propagation (sec. 2.2): per-frame standard deviations of each group of degrees
    of freedom. Arms move fastest (a reaching hand about 50 mm a frame), the pelvis slowest."""

    position_mm: float = number(12.0)
    yaw: float = number(0.04)
    bend: float = number(0.03)
    neck: float = number(0.06)
    shoulder: tuple[float, float, float] = pair((0.10, 0.08, 0.10), n=3)  # flexion, abduction, twist
    elbow: tuple[float, float] = pair((0.12, 0.10))               # flexion, twist
    #: partlab's: a forearm and hand the camera above does not see (under the upper arm, the
    #: head or a bent torso) are held by nothing in eq. 1, so the degrees of freedom only they
    #: show (the shoulder's twist, the elbow's flexion and twist) random-walk at full speed and
    #: carry the hidden hand 100-300 mm off in 10-20 frames. Their noise is scaled down to
    #: ``hidden_scale`` while fewer than ``hidden_points`` of the person's points (of the
    #: ``roi.max_points`` drawn) lie on the estimate's forearm and hand or are left unexplained
    #: (farther than ``unexplained_mm`` from the model) beside that arm, and back up as they show
    #: again (re-acquisition): 1 = the paper's plain random walk
    hidden_scale: float = number(0.25, FRACTION)
    hidden_points: float = number(8.0, POSITIVE)
    unexplained_mm: float = number(40.0, POSITIVE)


@dataclass(frozen=True)
class LikelihoodParams:
    """Eq. (1)-(2): ``omega = exp(-(d_ch / distance_scale_mm + colour_weight * d_bh))``.

    The text writes ``exp(d)`` (the minus sign was lost) and gives no scale: 10 mm is the size of
    the differences between good and poor particles (a depth point on a misplaced forearm is
    30-80 mm off), so weights spread over about one e-fold per centimetre."""

    distance_scale_mm: float = number(5.0, POSITIVE)
    #: pseudo-points of the whole model's mean distance added to each part's mean (eq. 3): a
    #: part with 20 points of its own is judged half by them, one with 200 almost only by them
    prior_points: float = number(20.0)
    use_colour: bool = flag(True)
    #: weight of the summed Bhattacharyya distances; a distance of 0.1 (a clearly different
    #: histogram) then costs as much as 5 mm of eq. 1
    colour_weight: float = number(0.5)
    #: partlab's free-space check (:func:`partlab.tracking.topview.likelihood.free_space`): the
    #: weight of a part's mean violation in the cost (0: the paper's eq. 1-2 alone) and its cap
    #: (a misplaced arm over the floor costs ``cap`` at most, as much as a point 100 mm off)
    free_space_weight: float = number(0.5)
    free_space_cap_mm: float = number(100.0)
    #: partlab's self-intersection check (:func:`partlab.tracking.topview.likelihood.self_intersection`):
    #: the weight of how deep a forearm or hand goes into its own torso or head (mean over the
    #: segments' axis points, capped), in the arm's cost; 0 = off. A hand pushed 30 mm into the
    #: torso then costs as much as its points lying 15 mm off at the weight 0.5
    self_weight: float = number(0.5)
    self_cap_mm: float = number(100.0, POSITIVE)
    #: colour histogram: levels per BGR channel (4 -> 64 bins: enough for clothes vs skin vs hair)
    colour_levels: int = number(4, POSITIVE_COUNT)


@dataclass(frozen=True)
class ResamplingParams:
    """Sec. 2.4: ``part`` weighs and resamples each of Table 1's five parts on its own and
    shuffles them (eq. 3-4); ``global`` resamples whole particles by one weight (the "3D model")."""

    mode: str = "part"
    n_particles: int = number(200, POSITIVE_COUNT)

    def check(self, path: str) -> None:
        if self.mode not in ("part", "global"):
            raise ValueError(f"{path}.mode: must be 'part' or 'global', got {self.mode!r}")
        if self.n_particles < 2:
            raise ValueError(f"{path}.n_particles: must be at least 2, got {self.n_particles}")


@dataclass(frozen=True)
class ExclusionParams:
    """Eq. (5): each ROI point goes to the person whose predicted model is nearest; points
    farther than this from every model belong to nobody (a newcomer, an object)."""

    max_assign_mm: float = number(250.0)
    #: the prediction ``x^_k`` of eq. 5 comes from the last estimate "and the dynamic of the
    #: system": ``x_{k-1} + velocity * (x_{k-1} - x_{k-2})``. 0 is the random walk's own
    #: prediction (the last estimate); 1, constant velocity, keeps a forearm that moves 30-50 mm a
    #: frame on its own pixels where two people's forearms cross
    velocity: float = number(1.0)
    #: partlab's second pass: after every person's filter has run, each point goes again to the
    #: nearest *fitted* model, and a person whose points changed by at least
    #: ``second_pass_points`` is weighed again with the new ones (only with two people or more;
    #: :meth:`partlab.tracking.topview.tracker.TopViewTracker.step`)
    second_pass: bool = flag(True)
    second_pass_points: int = number(20, POSITIVE_COUNT)
    #: partlab's colour term in eq. 5 (eq. 2's colour cue used for the assignment too; only with
    #: two people or more and a colour stream): a point's cost for a person is its distance to
    #: the person's model minus ``colour_mm`` times the log of how common its colour bin was, the
    #: frame before, on that person's primitive nearest the point (``1 - colour_person_share``)
    #: and on the whole person (``colour_person_share``), plus ``colour_floor``. A hand lying on
    #: the other person's shoulders is 20-30 mm from their shirt and 40-90 mm from its own
    #: model when that is off; a skin colour the shirt never showed costs the shirt
    #: ``colour_mm * ln(1 / colour_floor)`` = 78 mm more. 0 = the paper's eq. 5 (distance only)
    colour_mm: float = number(20.0, NONNEG)
    colour_floor: float = number(0.02, POSITIVE)
    colour_person_share: float = number(0.2, FRACTION)


@dataclass(frozen=True)
class StartParams:
    """Automatic start from the ROI and dropping lost people.

    A blob of unassigned ROI pixels covering at least ``min_person_fraction`` of the image starts
    a person (one person at 2.9 m covers 3-6 % of a Kinect picture); its highest point is the top
    of the head. A person with fewer than ``min_points`` points for ``lost_after`` frames is dropped."""

    min_person_fraction: float = number(0.012, FRACTION)
    head_band_mm: float = number(120.0)
    #: a blob's highest point starts a person only this high (1.2 m: a child's head, above any
    #: arm a grown-up holds at the side); the person is what lies this close to it, seen from
    #: above (a torso's half diagonal plus a bent arm)
    min_head_height_mm: float = number(1200.0)
    person_radius_mm: float = number(450.0)
    #: height from the top of a head down to the lowest point around it: at least the head and
    #: neck (about 270 mm) plus the shoulders' slope; a forearm held level spans less
    min_person_span_mm: float = number(350.0)
    min_points: int = number(80, POSITIVE_COUNT)
    lost_after: int = number(10, POSITIVE_COUNT)
    # -- fitting the model to given joints and the frame's points (:mod:`.start`) --
    #: depth points used by the fit (spread evenly over the person's; 300 keep the fit ~0.2 s)
    fit_points: int = number(300, POSITIVE_COUNT)
    #: the points' share of the fit against the joints': 1 = all points together count as much
    #: as the joints (the joints are given, the points say what they leave open)
    points_weight: float = number(1.0, POSITIVE)
    #: how exactly the given joints are known (mm) and how far a standing person's pelvis is from
    #: its standing height (hips sink about 30 mm per radian of bend, knees bend a little)
    joint_sd_mm: float = number(10.0, POSITIVE)
    stand_sd_mm: float = number(40.0, POSITIVE)
    bend_sink_mm: float = number(30.0)
    #: the stature may differ from the head-to-shoulders estimate by this factor (people's
    #: proportions vary by about 10 %)
    stature_range: tuple[float, float] = pair((0.85, 1.2))
    #: soft-L1 loss scale (mm): points farther off than this (another person, noise) count less
    fit_scale_mm: float = number(20.0, POSITIVE)
    #: least-squares evaluations per start (the fit converges in 10-30)
    fit_evaluations: int = number(60, POSITIVE_COUNT)


@dataclass(frozen=True)
class OutputParams:
    """The joints' image boxes: a square this many mm across at the joint's depth."""

    joint_box_mm: dict[str, float] = mapping(lambda: {
        "head": 190.0, "right_shoulder": 120.0, "left_shoulder": 120.0, "right_elbow": 110.0,
        "left_elbow": 110.0, "right_hand": 160.0, "left_hand": 160.0}, rule=POSITIVE)


@dataclass(frozen=True)
class TopViewParams(Parameters):
    """All of the top-view tracker's parameters (registry key ``topview``)."""

    KEY: ClassVar[str] = "topview"

    roi: RoiParams = group_field(RoiParams)
    dynamics: DynamicsParams = group_field(DynamicsParams)
    likelihood: LikelihoodParams = group_field(LikelihoodParams)
    resampling: ResamplingParams = group_field(ResamplingParams)
    exclusion: ExclusionParams = group_field(ExclusionParams)
    start: StartParams = group_field(StartParams)
    output: OutputParams = group_field(OutputParams)
