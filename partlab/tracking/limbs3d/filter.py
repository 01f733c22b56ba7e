"""One particle filter per 3D target (sec. 4.2, SIR; weights by eq. 17).

``particles: (N, 6) float64 [X, Y, Z, vX, vY, vZ]`` (mm, mm per frame). Each frame the filter
predicts with damped constant velocity plus Gaussian noise, weights every particle by

    w_i = sum_c p(x_i | Z_c) p(Z_c)                                    (eq. 17)

over the candidates it may use (``p(x | Z)`` a Gaussian of spread ``sigma_x``), takes the weighted
mean as its estimate, and resamples systematically (every frame, as SIR does, eq. 12). Its
confidence is the best candidate's ``p(x | Z) p(Z)`` at the estimate: near the prior of the
candidate it sits on, near 0 when no candidate is near (what the state machine thresholds).
"""

from __future__ import annotations

import numpy as np

from partlab.tracking.core.resampling import systematic_resample
from partlab.tracking.limbs3d.params import Limbs3DDynamics


class TargetFilter:
    def __init__(self, position, params: Limbs3DDynamics, rng: np.random.Generator, spread: float | None = None):
        self.params = params
        self.rng = rng
        self.particles = np.zeros((params.particles, 6))
        self.reset(position, spread)
        self.confidence = 1.0

    def reset(self, position, spread: float | None = None, keep_velocity: bool = False) -> None:
        """Put the particles around ``position`` (``spread`` mm, default ``noise_xyz``)."""
        s = self.params.noise_xyz if spread is None else spread
        n = self.params.particles
        v = self.particles[:, 3:].copy() if keep_velocity else np.zeros((n, 3))
        self.particles = np.hstack([np.asarray(position, float)[None] + self.rng.normal(0, s, (n, 3)), v])

    @property
    def estimate(self) -> np.ndarray:
        return self.particles[:, :3].mean(axis=0)

    def predict(self, scale: float = 1.0) -> None:
        p = self.params
        n = len(self.particles)
        v = p.velocity_decay * self.particles[:, 3:] + self.rng.normal(0, p.noise_v * scale, (n, 3))
        self.particles[:, :3] += v + self.rng.normal(0, p.noise_xyz * scale, (n, 3))
        self.particles[:, 3:] = v

    def propose(self, candidates: np.ndarray, prior: np.ndarray, gate: float | None = None) -> np.ndarray:
        """Redraw ``candidate_mix`` of the particles around the gated candidates (sec. 4.2's
        "further steps"); the others keep their predicted state. Returns every particle's
        importance factor ``f / q`` (ICONDENSATION, Isard & Blake): ``f`` the dynamics' density
        (a Gaussian of the predicted cloud's mean and spread), ``q`` the mixture the particles
        were drawn from, ``(1 - mix) f + mix g`` with ``g`` the candidates' Gaussians. Without it a
        strong false candidate within the gate captures the filter in one frame, whatever the
        motion says (a hand's candidate 3 mm off with prior 0.5 lost to one 200 mm off with 1.0)."""
        p = self.params
        n = len(self.particles)
        ones = np.ones(n)
        if len(candidates) == 0 or p.candidate_mix <= 0:
            return ones
        mean = self.particles[:, :3].mean(axis=0)
        near = np.linalg.norm(candidates - mean, axis=1) < (p.candidate_gate if gate is None else gate)
        if not near.any():
            return ones
        c, w = candidates[near], prior[near] / prior[near].sum()
        k = int(round(p.candidate_mix * n))
        spread = np.sqrt(self.particles[:, :3].var(axis=0) + p.noise_xyz**2)  # (3,)
        pick = self.rng.choice(len(c), size=k, p=w)
        rows = self.rng.choice(n, size=k, replace=False)
        self.particles[rows, :3] = c[pick] + self.rng.normal(0, p.noise_xyz, (k, 3))
        x = self.particles[:, :3]
        f = np.exp(-0.5 * (((x - mean) / spread) ** 2).sum(-1)) / np.prod(spread)
        if p.jump_mix > 0:  # heavier tail: a hand can start a fast move (a clap) in any frame
            wide = spread * p.jump_scale
            f = (1 - p.jump_mix) * f + p.jump_mix * np.exp(-0.5 * (((x - mean) / wide) ** 2).sum(-1)) / np.prod(wide)
        d2 = ((x[:, None] - c[None]) ** 2).sum(-1)
        g = np.exp(-d2 / (2 * p.noise_xyz**2)) @ w / p.noise_xyz**3
        q = (1 - p.candidate_mix) * f + p.candidate_mix * g
        return f / np.maximum(q, 1e-300)

    def weigh(self, candidates: np.ndarray, prior: np.ndarray) -> np.ndarray:
        """Eq. 17 for every particle (``(N,)``, not normalised)."""
        p = self.params
        if len(candidates) == 0:
            return np.full(len(self.particles), p.weight_floor)
        d2 = ((self.particles[:, None, :3] - candidates[None]) ** 2).sum(-1)
        return np.exp(-d2 / (2 * p.sigma_x**2)) @ prior + p.weight_floor

    def update(self, candidates: np.ndarray, prior: np.ndarray, gate: float | None = None) -> np.ndarray:
        """Propose (within ``gate`` mm, default ``candidate_gate``), weigh, estimate, resample;
        returns the estimate (mm)."""
        w = self.propose(candidates, prior, gate) * self.weigh(candidates, prior)
        w = w / w.sum()
        est = (self.particles[:, :3] * w[:, None]).sum(0)
        idx = systematic_resample(w, len(w), self.rng)
        self.particles = self.particles[idx]
        if len(candidates):
            d2 = ((candidates - est) ** 2).sum(-1)
            self.confidence = float(np.max(np.exp(-d2 / (2 * self.params.sigma_x**2)) * prior))
        else:
            self.confidence = 0.0
        self._estimate = est
        return est
