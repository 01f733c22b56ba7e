"""The high-level layer of seed 000 (sec. 5.2, Fig. 1): one finite state machine per tracker.

States: ``uninitialized`` (no filter yet), ``unlabelled`` (tracked, type unknown),
``normal`` (tracked and labelled), ``combined`` (two targets tracked by one filter)
and ``lost``. Transitions, each driven by what the low layer reports per frame
(:class:`Observation`):

- uninitialized -> unlabelled: a candidate's prior p(Z) stays above ``start_prior``
  for ``start_frames`` frames;
- unlabelled -> normal: a labelling cue gave the tracker its type;
- normal -> combined (both trackers): their estimates come closer than
  ``combine_size`` target sizes (``combine_distance`` pixels when no size is given) while both are
  confident (likelihood at least
  ``lost_likelihood``); the vector between them before joining is kept;
- combined -> unlabelled (both): the combined posterior's two strongest modes lie
  more than ``split_size`` target sizes (or ``split_distance`` pixels) apart; each tracker receives
  the mode that keeps the
  direction between them from before the join (sec. 7.1), which labels them again;
- combined -> unlabelled (the member on the side its mode went) and lost (the other): a pair of
  two people's hands (``Observation.two_people``) with one mode only whose estimate has moved
  more than ``split_size`` target sizes from where the hands met along the direction between
  them before the join (``states.split_unseen``): the
  hands have parted and one of them is no longer seen (in one camera, a hand taken back behind
  its own body); the seen mode is the member's on whose side it went (sec. 7.1's direction cue),
  and the other, with no mode to receive, is lost (sec. 5.2's lost state: no candidate represents
  it) rather than riding on the other's hand; it is looked for where it would be had it moved
  back as far the other way;
- normal / unlabelled / combined -> lost: the likelihood stays below
  ``lost_likelihood`` for ``lost_frames`` frames (sec. 5.2: "test the posterior
  probabilities against a threshold");
- lost -> normal (or unlabelled if it never had a type): the likelihood around the
  last position rises above ``recover_likelihood``.

Each join and separation pair is kept as an event (sec. 7.1's basis for activities).
The machine is pure bookkeeping: the tracker (:mod:`partlab.tracking.limbs.tracker`) acts on the
returned transitions.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from partlab.tracking.params import LimbParams


class LimbState(str, Enum):
    UNINITIALIZED = "uninitialized"
    UNLABELLED = "unlabelled"
    NORMAL = "normal"
    COMBINED = "combined"
    LOST = "lost"


@dataclass(frozen=True)
class Observation:
    """What the low layer reports for one tracker at one frame.

    ``position``: the filter's estimate (or, uninitialized, the candidate it would start
    from); ``likelihood``: the filter's confidence in [0, 1]; ``prior``: p(Z) of the
    candidate an uninitialized tracker would start from; ``labelled``: a labelling cue
    decided the tracker's type this frame; ``modes``: posterior modes ``(x, y)``,
    strongest first (read only for the first tracker of a combined pair).
    """

    position: tuple[float, float] | None = None
    likelihood: float = 0.0
    prior: float = 0.0
    labelled: bool = False
    modes: tuple[tuple[float, float], ...] = ()
    #: the target's box side (pixels); with it the combine/split distances scale with the target
    size: float = 0.0
    #: the frame could not have seen the target (e.g. too few views left to triangulate anything):
    #: it counts as a confident frame for ``lost_frames`` (the count starts again after it)
    unseen: bool = False
    #: a combined pair's leader: its two members are two people's (each hand goes back to its own
    #: person's side after they part, which ``split_unseen`` relies on)
    two_people: bool = False


@dataclass(frozen=True)
class Transition:
    tracker: int
    frame: int
    old: LimbState
    new: LimbState
    reason: str
    partner: int | None = None
    #: on a split, the mode this tracker receives
    position: tuple[float, float] | None = None


@dataclass(frozen=True)
class JoinEvent:
    """Two trackers combined at ``start_frame`` and separated (or were lost) at ``end_frame``."""

    start_frame: int
    end_frame: int
    tracker_a: int
    tracker_b: int
    ended_by: str  # "split" or "lost"


@dataclass
class _Status:
    state: LimbState
    low: int = 0
    strong: int = 0
    partner: int | None = None
    joined_at: int = -1
    before: np.ndarray | None = None  # this tracker's position minus its partner's, before the join
    met: np.ndarray | None = None  # combined: where the pair's estimate was when the two joined
    history: deque = field(default_factory=deque)


def assign_by_direction(before: np.ndarray, modes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Give tracker a and b one mode each so that the vector a - b after separation makes
    an angle below 90 degrees with the vector before joining (seed 000 sec. 7.1).

    ``before``: ``(2,)`` position of a minus position of b before the join; ``modes``: ``(2, 2)``.
    Returns (mode of a, mode of b).
    """
    m = np.asarray(modes, float).reshape(2, -1)
    if float(np.dot(m[0] - m[1], np.asarray(before, float))) >= 0:
        return m[0], m[1]
    return m[1], m[0]


def _length(vector) -> float:
    """Length of a 2D vector (``np.hypot``, as the one-camera tracker always measured) or of a
    3D one (the multi-camera tracker's targets, :mod:`partlab.tracking.limbs3d`)."""
    v = np.asarray(vector, float).ravel()
    return float(np.hypot(*v)) if v.size == 2 else float(np.linalg.norm(v))


def distance_threshold(pixels: float, per_size: float, size: float) -> float:
    """``per_size`` target sizes when the size is known and ``per_size > 0``, else ``pixels``."""
    return per_size * size if per_size > 0 and size > 0 else pixels


class LimbStateMachine:
    """Per-tracker states and the pairwise combine/split logic of seed 000 sec. 5.2."""

    def __init__(self, params: LimbParams | None = None):
        self.params = params or LimbParams()
        self._status: dict[int, _Status] = {}
        self._sizes: dict[int, float] = {}
        self.events: list[JoinEvent] = []

    # -- queries ---------------------------------------------------------------------------
    def add(self, tracker: int, state: LimbState = LimbState.UNINITIALIZED) -> None:
        if tracker in self._status:
            raise ValueError(f"tracker {tracker} already exists")
        history = deque(maxlen=max(self.params.states.history_frames, 1))
        self._status[tracker] = _Status(LimbState(state), history=history)

    def state(self, tracker: int) -> LimbState:
        return self._status[tracker].state

    def partner(self, tracker: int) -> int | None:
        return self._status[tracker].partner

    def joined_at(self, tracker: int) -> int:
        """Frame at which a combined tracker joined its partner (-1 if not combined)."""
        return self._status[tracker].joined_at

    def direction_before(self, tracker: int) -> np.ndarray | None:
        """This combined tracker's position minus its partner's before they joined."""
        b = self._status[tracker].before
        return None if b is None else b.copy()

    def remove(self, tracker: int) -> None:
        """Forget an uninitialized tracker whose candidate vanished."""
        if self._status[tracker].state != LimbState.UNINITIALIZED:
            raise ValueError(f"only uninitialized trackers can be removed, tracker {tracker} is "
                             f"{self._status[tracker].state.value}")
        del self._status[tracker]

    def end(self, tracker: int) -> None:
        """Forget a tracker that is not combined (its track ended); its past events stay."""
        if self._status[tracker].state == LimbState.COMBINED:
            raise ValueError(f"tracker {tracker} is combined: end its pair first")
        del self._status[tracker]
        self._sizes.pop(tracker, None)

    def trackers(self) -> list[int]:
        return list(self._status)

    def is_leader(self, tracker: int) -> bool:
        """A combined pair is tracked by one filter: the lower tracker id's."""
        s = self._status[tracker]
        return s.state != LimbState.COMBINED or s.partner is None or tracker < s.partner

    # -- one frame -------------------------------------------------------------------------
    def update(self, frame: int, observations: dict[int, Observation]) -> list[Transition]:
        """Apply this frame's observations; returns the transitions made, in order."""
        p = self.params
        out: list[Transition] = []

        moved: set[int] = set()  # one transition per tracker per frame

        def move(t: int, new: LimbState, reason: str, partner=None, position=None) -> None:
            s = self._status[t]
            moved.add(t)
            out.append(Transition(t, frame, s.state, new, reason, partner, position))
            s.state = new
            s.low = 0
            s.strong = 0

        for t, s in self._status.items():
            obs = observations.get(t, Observation())
            # likelihood counters
            s.low = s.low + 1 if obs.likelihood < p.states.lost_likelihood and not obs.unseen else 0

        for t, s in list(self._status.items()):
            if t in moved:
                continue
            obs = observations.get(t, Observation())
            if s.state == LimbState.COMBINED:
                if self.is_leader(t):
                    self._combined_step(frame, t, s, obs, move)
            else:
                self._single_step(t, s, obs, move)

        self._combine(frame, observations, move)
        for t, s in self._status.items():
            obs = observations.get(t, Observation())
            if obs.position is not None and s.state not in (LimbState.UNINITIALIZED,):
                s.history.append(np.asarray(obs.position, float))
            if obs.size > 0:
                self._sizes[t] = obs.size
        return out

    def _single_step(self, t: int, s: _Status, obs: Observation, move) -> None:
        """uninitialized -> unlabelled (a strong candidate), normal/unlabelled -> lost (low
        likelihood), unlabelled -> normal (labelled), lost -> normal/unlabelled (recovered)."""
        p = self.params.states
        if s.state == LimbState.UNINITIALIZED:
            s.strong = s.strong + 1 if obs.prior >= p.start_prior else 0
            if s.strong >= p.start_frames:
                move(t, LimbState.UNLABELLED, "strong candidate")
        elif s.state in (LimbState.NORMAL, LimbState.UNLABELLED):
            if s.low >= p.lost_frames:
                move(t, LimbState.LOST, "low likelihood")
            elif s.state == LimbState.UNLABELLED and obs.labelled:
                move(t, LimbState.NORMAL, "labelled")
        elif s.state == LimbState.LOST and obs.likelihood >= p.recover_likelihood:
            move(t, LimbState.NORMAL if obs.labelled else LimbState.UNLABELLED, "recovered")

    def _combined_step(self, frame: int, t: int, s: _Status, obs: Observation, move) -> None:
        """A combined pair (seen by its leader ``t``) is lost together, or splits into two
        unlabelled trackers once its two modes are ``split_size`` sides apart."""
        p = self.params.states
        b = s.partner
        modes = np.asarray(obs.modes, float).reshape(len(obs.modes), -1) if len(obs.modes) else np.zeros((0, 2))
        if s.low >= p.lost_frames:
            self._end_join(frame, t, b, "lost")
            move(t, LimbState.LOST, "combined target lost", b)
            move(b, LimbState.LOST, "combined target lost", t)
        elif len(modes) >= 2 and _length(modes[0] - modes[1]) > distance_threshold(
                p.split_distance, p.split_size, obs.size):
            pos_a, pos_b = assign_by_direction(s.before, modes[:2])
            self._end_join(frame, t, b, "split")
            move(t, LimbState.UNLABELLED, "split", b, tuple(map(float, pos_a)))
            move(b, LimbState.UNLABELLED, "split", t, tuple(map(float, pos_b)))
        elif (getattr(p, "split_unseen", False)  # the one-camera tracker's rule; limbs3d has no such field
              and obs.two_people and len(modes) < 2 and obs.position is not None and s.met is not None):
            self._split_one_unseen(frame, t, b, s, np.asarray(obs.position, float), obs.size, move)

    def _split_one_unseen(self, frame: int, a: int, b: int, s: _Status, at: np.ndarray, size: float,
                          move) -> None:
        """The pair's one mode ``at`` has left the meeting point by more than the split distance
        along the direction between the two before the join: the member on that side receives it,
        the other is lost, looked for as far back the other way from the meeting point."""
        before = np.asarray(s.before, float)
        norm = _length(before)
        if norm <= 0:
            return
        u = before / norm  # from b towards a, before the join
        along = float(np.dot(at - s.met, u))
        if abs(along) <= distance_threshold(self.params.states.split_distance, self.params.states.split_size,
                                            size):
            return
        seen, unseen = (a, b) if along > 0 else (b, a)
        guess = s.met - along * u  # the unseen hand, gone back as far the other way
        self._end_join(frame, a, b, "split")
        move(seen, LimbState.UNLABELLED, "split", unseen, tuple(map(float, at)))
        move(unseen, LimbState.LOST, "split unseen", seen, tuple(map(float, guess)))

    def _end_join(self, frame: int, a: int, b: int, how: str) -> None:
        sa, sb = self._status[a], self._status[b]
        self.events.append(JoinEvent(sa.joined_at, frame, min(a, b), max(a, b), how))
        for s in (sa, sb):
            s.partner, s.joined_at, s.before, s.met = None, -1, None, None

    def _combine(self, frame: int, observations: dict[int, Observation], move) -> None:
        """Pair normal trackers whose estimates are closer than ``combine_distance``, closest first."""
        p = self.params
        # a filter below the lost threshold has no meaningful maximum-likelihood point: it is
        # drifting (its blob vanished), and must not be combined with the target it drifts onto
        ids = [t for t, s in self._status.items() if s.state == LimbState.NORMAL
               and observations.get(t, Observation()).position is not None
               and observations[t].likelihood >= p.states.lost_likelihood]
        pairs = []
        for i, a in enumerate(ids):
            for b in ids[i + 1:]:
                d = _length(np.subtract(observations[a].position, observations[b].position))
                size = (observations[a].size + observations[b].size) / 2 if (
                    observations[a].size > 0 and observations[b].size > 0) else 0.0
                if d < distance_threshold(p.states.combine_distance, p.states.combine_size, size):
                    pairs.append((d, a, b))
        used: set[int] = set()
        for _, a, b in sorted(pairs):
            if a in used or b in used:
                continue
            used |= {a, b}
            before = self._direction_before(a, b, observations)
            met = (np.asarray(observations[a].position, float) + np.asarray(observations[b].position, float)) / 2
            for t, other, vec in ((a, b, before), (b, a, -before)):
                s = self._status[t]
                move(t, LimbState.COMBINED, "estimates joined", other)
                s.partner, s.joined_at, s.before, s.met = other, frame, vec, met.copy()

    def _direction_before(self, a: int, b: int, observations: dict[int, Observation]) -> np.ndarray:
        """Position of a minus b at the latest remembered frame when they were still apart."""
        ha, hb = list(self._status[a].history), list(self._status[b].history)
        n = min(len(ha), len(hb))
        pairs = list(zip(ha[len(ha) - n:], hb[len(hb) - n:]))
        for pa, pb in reversed(pairs):
            states = self.params.states
            if _length(pa - pb) >= distance_threshold(states.combine_distance, states.combine_size,
                                                       self._sizes.get(a, 0.0)):
                return pa - pb
        if pairs:
            return pairs[0][0] - pairs[0][1]
        return np.subtract(observations[a].position, observations[b].position).astype(float)
