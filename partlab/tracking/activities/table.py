"""The decision table of sec. 7.3.1 (Table 1): what an activity is, from what the hands hold before
and after its climax point.

Table 1 of the paper, with 1 = the hand holds an object, 0 = it does not:

| first before | second before | first after | second after | activity |
|---|---|---|---|---|
| 0 | 0 | 0 | 0 | hand shake (two people) or clap (one person) |
| 0 | 1 | 1 | 0 | exchange |
| 1 | 0 | 0 | 1 | exchange |
| 0 | - | 1 | - | pick |
| 1 | - | 0 | - | place |

Read per colour, not per hand: a hand "holds colour c" at a decision point when c's share of its
fused distribution is at least ``min_mass``, and "does not" when it is below ``max_mass_absent``.
A sleeve or a shirt seen around both hands at both points then never decides anything, while an
object that leaves one hand for the other does: an exchange needs one colour that moves, and a
handshake is never called an exchange unless a colour changed hands.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from partlab.tracking.activities.objects import DEGREES_PER_BIN, HUE_BINS
from partlab.tracking.activities.params import ActivityParams


@dataclass(frozen=True)
class Verdict:
    kind: str
    colour: int | None  # hue bin of the object that decided it
    margin: float  # how far the deciding shares are from the thresholds (0..1)


def mass(held: Mapping[int, float], hue: int, params: ActivityParams) -> float:
    """The largest share ``held`` gives a hue within ``decision.same_colour`` of ``hue`` (0: none)."""
    reach = params.decision.same_colour / DEGREES_PER_BIN
    return max((m for h, m in held.items() if min((h - hue) % HUE_BINS, (hue - h) % HUE_BINS) <= reach),
               default=0.0)


def _margin(present: list[float], absent: list[float], params: ActivityParams) -> float:
    d = params.decision
    up = min((m - d.min_mass) / max(1e-9, 1 - d.min_mass) for m in present)
    down = min((1.0 - m / max(1e-9, max(d.max_mass_absent, d.absent_ratio * max(present))) for m in absent),
               default=1.0)
    return float(max(0.0, min(1.0, 0.5 * (up + down) + 0.5)))


def absent(m: float, present: float, params: ActivityParams) -> bool:
    """Not held: below ``max_mass_absent``, or a small fraction of what the other point holds."""
    return m <= max(params.decision.max_mass_absent, params.decision.absent_ratio * present)


def two_hands(a_before: dict, b_before: dict, a_after: dict, b_after: dict, same_person: bool,
              params: ActivityParams) -> Verdict:
    """Rows 1-3 of Table 1 for two hands that joined and separated."""
    d = params.decision
    for src_b, dst_b, src_a, dst_a in ((a_before, b_before, a_after, b_after), (b_before, a_before, b_after, a_after)):
        for hue in (set(src_b) | set(dst_a)) if d.exchange_band else set(src_b):
            m, gained = mass(src_b, hue, params), mass(dst_a, hue, params)
            if d.exchange_band:  # one side held, the other at least not absent (hysteresis)
                if max(m, gained) < d.min_mass or absent(min(m, gained), max(m, gained), params):
                    continue
            elif m < d.min_mass or gained < d.min_mass:
                continue
            if absent(mass(dst_b, hue, params), gained, params) and absent(mass(src_a, hue, params), m, params):
                return Verdict("exchange", hue, _margin([m, gained], [mass(dst_b, hue, params),
                                                                        mass(src_a, hue, params)], params))
    margin = 1.0 - _moved(a_before, b_before, a_after, b_after, params) / max(d.min_mass, 1e-9)
    return Verdict("clap" if same_person else "handshake", None, float(max(0.2, min(1.0, 0.6 + 0.4 * margin))))


def _moved(a_before: dict, b_before: dict, a_after: dict, b_after: dict, params: ActivityParams) -> float:
    """How much of one colour went from one hand to the other, at most over the colours and the two
    directions: the smaller of what the giving hand lost and what the receiving hand gained. A
    colour that stays around one hand (a sleeve, the trousers a hand rests by, a shirt behind
    both) moves nothing, however much of it there is: only a colour that half changed hands makes
    a clap or a handshake unsure."""
    out = 0.0
    for src_b, dst_b, src_a, dst_a in ((a_before, b_before, a_after, b_after), (b_before, a_before, b_after, a_after)):
        for hue in set(src_b) | set(dst_a):
            lost = mass(src_b, hue, params) - mass(src_a, hue, params)
            gained = mass(dst_a, hue, params) - mass(dst_b, hue, params)
            out = max(out, min(lost, gained))
    return out


def one_hand(before: dict, after: dict, params: ActivityParams, stays=None) -> Verdict | None:
    """Rows 4-5 of Table 1: a colour that appears in a hand at a still moment is picked up, one
    that disappears is placed; None when nothing changed.

    ``stays(hue)``: whether that colour stayed where the hand stood still while the hand moved on
    (True), moved with it (False) or cannot be told (None). An object put down stays, so a colour
    held before that stays behind is placed even when the hand, resting beside it, still shows some
    of it; a colour that appears around the hand but stays behind lay beside it, not picked up."""
    d = params.decision
    stays = stays or (lambda hue: None)
    best = None
    for hue, m in after.items():
        was = mass(before, hue, params)
        if m >= d.min_mass and absent(was, m, params) and stays(hue) is not True:
            v = Verdict("pick", hue, _margin([m], [was], params))
            best = v if best is None or v.margin > best.margin else best
    for hue, m in before.items():
        now = mass(after, hue, params)
        if m < d.min_mass:
            continue
        if absent(now, m, params):
            v = Verdict("place", hue, _margin([m], [now], params))
        elif stays(hue) is True:
            v = Verdict("place", hue, _margin([m], [], params))
        else:
            continue
        best = v if best is None or v.margin > best.margin else best
    return best
