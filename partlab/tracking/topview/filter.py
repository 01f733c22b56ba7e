"""One person's particle filter (Migniot & Ababsa sec. 2.2-2.4).

Each frame runs the paper's four steps in its order: resampling, propagation, weighting,
estimation. With ``mode="part"`` every particle carries one weight per weighting part (eq. 3);
each part's degrees of freedom are resampled by that part's weights and then shuffled by a
random permutation ``f_p`` (eq. 4), so that a good arm of one particle meets a good torso of
another. With ``mode="global"`` a particle has one weight and is resampled whole.

Shapes: ``particles (N, 17) float64`` (:data:`partlab.tracking.topview.model.DOF` order);
``weights (N, 5)`` normalised per part (every column the same in global mode).

*Survival rate* (sec. 3, Fig. 7), which the paper does not define: the number of distinct
particles a part's resampling keeps, divided by ``N`` (1 = every particle survives: flat weights;
low = a few particles win: a sharp likelihood). In global mode all parts share one rate.
"""

from __future__ import annotations

import numpy as np

from partlab.tracking.core.resampling import systematic_resample
from partlab.tracking.topview.likelihood import (
    bhattacharyya,
    free_space,
    nearest,
    nearest_primitive,
    self_intersection,
    weigh,
)
from partlab.tracking.topview.model import (
    JOINT_LIMITS,
    N_DOF,
    N_PARTS,
    PART_DOFS,
    WEIGHT_PARTS,
    Body,
    kinematics,
    primitives,
)
from partlab.tracking.topview.params import TopViewParams

_PART_SLICES = [np.array(PART_DOFS[p]) for p in WEIGHT_PARTS]
_YAW = 3
#: per arm (right, left): its forearm and hand primitives and the degrees of freedom only they show
#: (shoulder twist, elbow flexion and twist: the upper arm's own position does not depend on them)
_FOREARM_PRIMS = ((4, 5), (7, 8))
_FOREARM_DOFS = ((9, 10, 11), (14, 15, 16))


def noise_scales(p: TopViewParams) -> np.ndarray:
    """``(17,)`` per-frame propagation standard deviation of each degree of freedom."""
    d = p.dynamics
    arm = [*d.shoulder, *d.elbow]
    return np.array([d.position_mm] * 3 + [d.yaw, d.bend, d.neck, d.neck] + arm + arm)


class PersonFilter:
    """The particle filter of one person, started around ``state`` (``(17,)``, or ``(S, 17)``
    hypotheses split evenly among the particles)."""

    def __init__(self, params: TopViewParams, rng: np.random.Generator, body: Body, state: np.ndarray,
                 spread: float = 1.0):
        self.params = params
        self.rng = rng
        self.body = body
        n = params.resampling.n_particles
        starts = np.atleast_2d(np.asarray(state, np.float64))
        self.scales = noise_scales(params)
        self.particles = starts[np.arange(n) % len(starts)] + spread * self.scales * rng.standard_normal((n, N_DOF))
        self._clip()
        self.weights = np.full((n, N_PARTS), 1.0 / n)
        self.estimate = starts[0].copy()
        self.previous = self.estimate.copy()  # the estimate before the last, for the prediction
        self.survival = np.ones(N_PARTS)
        #: per arm, how much of the forearm and hand the last frame's points showed (``(2,)``
        #: counts, :meth:`observe_forearms`; the propagation slows down what is hidden)
        self.seen = np.full(2, np.inf)
        self.reference: np.ndarray | None = None  # (5, bins) colour histograms of the estimate

    @property
    def n(self) -> int:
        return len(self.particles)

    def _clip(self) -> None:
        np.clip(self.particles, JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1], out=self.particles)

    # -- 1. resampling (eq. 4) ----------------------------------------------------------------
    def resample(self) -> None:
        n = self.n
        if self.params.resampling.mode == "global":
            idx = systematic_resample(self.weights[:, 0], n, self.rng)
            self.particles = self.particles[idx]
            self.survival[:] = len(np.unique(idx)) / n
            return
        new = np.empty_like(self.particles)
        for p, dofs in enumerate(_PART_SLICES):
            idx = systematic_resample(self.weights[:, p], n, self.rng)
            self.survival[p] = len(np.unique(idx)) / n
            idx = idx[self.rng.permutation(n)]  # f_p: recombine parts across particles
            new[:, dofs] = self.particles[idx][:, dofs]
        self.particles = new

    # -- 2. propagation -----------------------------------------------------------------------
    def propagate(self) -> None:
        self.particles += self.step_scales() * self.rng.standard_normal(self.particles.shape)
        self._clip()

    def step_scales(self) -> np.ndarray:
        """``(17,)`` this frame's noise: :func:`noise_scales` with a hidden forearm's degrees of
        freedom slowed down to ``dynamics.hidden_scale`` (partlab's, :meth:`observe_forearms`)."""
        d = self.params.dynamics
        scales = self.scales.copy()
        for arm, dofs in enumerate(_FOREARM_DOFS):
            shown = min(self.seen[arm] / d.hidden_points, 1.0)
            scales[list(dofs)] *= d.hidden_scale + (1.0 - d.hidden_scale) * shown
        return scales

    def observe_forearms(self, points: np.ndarray) -> None:
        """How much of each forearm and hand the points show: those nearest (and near) the
        estimate's forearm and hand, plus those the estimate leaves unexplained (farther than
        ``dynamics.unexplained_mm``) nearer that arm's shoulder than the other's (a hand seen
        again where the model does not have it)."""
        if not len(points):
            self.seen[:] = 0.0
            return
        dist, prim = nearest_primitive(points, primitives(self.estimate[None], self.body)[0])
        pose = kinematics(self.estimate[None], self.body)
        right = (np.linalg.norm(points - pose.shoulders[0], axis=1)
                 < np.linalg.norm(points - pose.shoulders[1], axis=1))
        loose = dist > self.params.dynamics.unexplained_mm
        for arm, prims in enumerate(_FOREARM_PRIMS):
            side = right if arm == 0 else ~right
            self.seen[arm] = (np.isin(prim, prims) & ~loose).sum() + (loose & side).sum()

    # -- 3. weighting (eq. 1-3) ----------------------------------------------------------------
    def weigh(self, points: np.ndarray, bins: np.ndarray | None, n_bins: int, depth: np.ndarray | None = None,
              camera=None) -> None:
        lk = self.params.likelihood
        use_colour = bins is not None and self.reference is not None
        prims = primitives(self.particles, self.body)
        sums, counts, hist = weigh(points, prims, bins if use_colour else None, n_bins)
        bh = bhattacharyya(hist, self.reference[None]) if use_colour else np.zeros_like(sums)
        free = np.zeros_like(sums)
        if lk.free_space_weight > 0 and depth is not None and camera is not None:
            free = free_space(prims, depth, camera, lk.free_space_cap_mm)
        # both of partlab's checks, in mm: free space and the body's own volume
        extra = lk.free_space_weight * free
        if lk.self_weight > 0:
            extra = extra + lk.self_weight * self_intersection(prims, lk.self_cap_mm)
        if self.params.resampling.mode == "global":
            d = sums.sum(1) / np.maximum(counts.sum(1), 1.0)
            cost = (d + extra.mean(1)) / lk.distance_scale_mm + lk.colour_weight * bh.sum(1)
            cost = np.repeat(cost[:, None], N_PARTS, 1)
        else:
            # a part's mean over the points nearest it (eq. 3), shrunk towards the whole model's
            # mean by ``prior_points`` pseudo-points: a part few points are nearest to (the torso
            # under the shoulders, an arm in the air) is judged by the whole model, not by chance
            whole = sums.sum(1, keepdims=True) / np.maximum(counts.sum(1, keepdims=True), 1.0)
            d = (sums + lk.prior_points * whole) / (counts + lk.prior_points)
            cost = (d + extra) / lk.distance_scale_mm + lk.colour_weight * bh
        w = np.exp(-(cost - cost.min(0)))
        self.weights = w / w.sum(0)

    # -- 4. estimation -------------------------------------------------------------------------
    def estimate_state(self) -> np.ndarray:
        est = np.empty(N_DOF)
        for p, dofs in enumerate(_PART_SLICES):
            w = self.weights[:, p]
            est[dofs] = w @ self.particles[:, dofs]
        w = self.weights[:, WEIGHT_PARTS.index("torso")]
        yaw = self.particles[:, _YAW]
        est[_YAW] = np.arctan2(w @ np.sin(yaw), w @ np.cos(yaw))  # a circular mean
        self.previous, self.estimate = self.estimate, est
        return est

    def _last_step(self) -> np.ndarray:
        """``(17,)`` the estimate's last step ``x_{k-1} - x_{k-2}`` (the yaw's the short way round)."""
        step = self.estimate - self.previous
        step[_YAW] = (step[_YAW] + np.pi) % (2 * np.pi) - np.pi
        return step

    def predicted(self, velocity: float) -> np.ndarray:
        """``(17,)`` the next state predicted from the last two estimates (eq. 5's ``x^_k``):
        ``velocity`` 0 is the last estimate, 1 constant velocity (within the joint limits)."""
        return np.clip(self.estimate + velocity * self._last_step(), JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1])

    def step(self, points: np.ndarray, bins: np.ndarray | None = None, n_bins: int = 0,
             depth: np.ndarray | None = None, camera=None) -> np.ndarray:
        """One frame with this person's ROI points ``(M, 3)`` (and their colour bins ``(M,)``;
        ``depth``/``camera``: the frame's depth image and calibration for the free-space check)."""
        self.resample()
        self.propagate()
        return self.measure(points, bins, n_bins, depth, camera)

    def measure(self, points: np.ndarray, bins: np.ndarray | None = None, n_bins: int = 0,
                depth: np.ndarray | None = None, camera=None, again: bool = False) -> np.ndarray:
        """Steps 3 and 4 (weighting, estimation) of this frame's particles. ``again``: the same
        particles weighed once more with other points (eq. 5's second pass,
        :meth:`TopViewTracker.step`): compared with the colour reference and the estimate of the
        frame before, as the first pass was."""
        if again:
            self.reference, self.estimate = self._before
        else:
            self._before = (self.reference, self.estimate)
        self.weigh(points, bins, n_bins, depth, camera)
        est = self.estimate_state()
        if self.params.dynamics.hidden_scale < 1.0:
            self.observe_forearms(points)
        if bins is not None:
            self.update_reference(points, bins, n_bins)
        return est

    def update_reference(self, points: np.ndarray, bins: np.ndarray, n_bins: int) -> None:
        """Sec. 2.3.2: each part's histogram of the estimate, compared with at the next frame."""
        if not len(points):
            return
        _, part = nearest(points, primitives(self.estimate[None], self.body)[0])
        ref = np.zeros((N_PARTS, n_bins))
        np.add.at(ref, (part, bins), 1.0)
        self.reference = ref
