"""Decision-making module (DMM): the phase-diagram sectors A-G and the action each asks for.

The phase diagram (paper sec. 5-6, Figures 11, 14, 15) places the ego-obstacle pair by its
relative distance d and relative closing speed v. Its boundaries at v, from the offline
tables, are the minimum clearing distance with the optimised acceleration profile S (eq. 32),
its buffered version Sb, the stopping distance B0 (eq. 33), its buffered version Bb, and the
time-to-collision line T = TTC * v (eq. 34). The warning line W = max(T, max(Sb, Bb) +
``FCW_LEAD_S`` v) is T, moved out where T would warn less than ``FCW_LEAD_S`` before the
braking or steering begins (at a steady closing speed). The sectors are:

====== ================================ ============ =========================================
sector region                           action       meaning
====== ================================ ============ =========================================
A      d <= S and d <= B0               LIMIT_BRAKE  imminent: neither steer nor brake avoids
C      d <= S and d > B0, or d <= Sb    BRAKE        braking alone still stops in time
       where B0 <= S
F      S < d <= Sb and d <= Bb          STEER        steer (braking would need its buffer)
B      S < d <= Sb and d > Bb           STEER        steer with the steering buffer
D      d > Sb and d <= Bb               BRAKE        brake to soften the steer to come
E      d > Sb, d > Bb and d <= W        FCW          forward-collision warning only
G      otherwise (or v <= 0)            NONE         nothing to do
====== ================================ ============ =========================================

For any fixed v the sectors follow each other in the order A, C, F, B, D, E, G as d grows
(some may be empty), so the urgency never increases with distance.

Where stopping is shorter than clearing (B0 <= S: low closing speeds), the steering sectors F
and B are braking sector C: a lane change begun there would clear the obstacle later than
limit braking stops the ego short of it, so it never is the last resort. The paper draws its
phase diagrams for highway speeds, where B0 > S, and leaves this range open.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from enum import Enum
from typing import NamedTuple


class Action(Enum):
    """What a DMM sector asks the ego to do."""

    NONE = "none"
    FCW = "fcw"
    BRAKE = "brake"
    STEER = "steer"
    LIMIT_BRAKE = "limit_brake"


class Sector(Enum):
    """DMM phase-diagram sector (paper Figure 14): value the letter, ``action`` what it asks
    for, ``letter`` the value and ``warns`` whether it raises the forward-collision warning
    (A-F). These are set after the class: mypyc does not compile an enum's own ``__new__``."""

    action: Action
    letter: str
    warns: bool

    A = "A"
    B = "B"
    C = "C"
    D = "D"
    E = "E"
    F = "F"
    G = "G"


_ACTIONS = {
    "A": Action.LIMIT_BRAKE,
    "B": Action.STEER,
    "C": Action.BRAKE,
    "D": Action.BRAKE,
    "E": Action.FCW,
    "F": Action.STEER,
    "G": Action.NONE,
}
for _sector in Sector:
    _sector.action = _ACTIONS[_sector.value]
    _sector.letter = _sector.value
    _sector.warns = _sector.value != "G"


# The members as module names, as the step's code reads them (as the modes in
# ``decision.modes``)
NONE, FCW, BRAKE, STEER, LIMIT_BRAKE = Action
A, B, C, D, E, F, G = Sector

#: The forward-collision warning's least lead over the braking or steering that follows at a
#: steady closing speed [s]: UN R152 para. 5.2.1.1, the collision warning at the latest 0.8 s
#: before the start of emergency braking (as secondary sources quote it: docs/protocols.md),
#: and 0.05 s (5 DMM steps) so that the warning's and the braking's first steps, each
#: quantised to the step, keep 0.8 s between them. The paper's T = TTC v (eq. 34) alone gives
#: 0.56-0.74 s at 10-25 km/h of closing speed, where the constant buffers c_s, c_b dominate.
FCW_LEAD_S = 0.85

#: Sectors in order of increasing distance for a fixed closing speed (A most urgent, G least).
SECTOR_ORDER = (Sector.A, Sector.C, Sector.F, Sector.B, Sector.D, Sector.E, Sector.G)


def warning_line_m(
    rel_speed_mps: float,
    clear_buffered_m: float,
    stop_buffered_m: float,
    ttc_s: float,
    lead_s: float = FCW_LEAD_S,
) -> float:
    """The warning line W = max(T, max(Sb, Bb) + ``lead_s`` v) at a closing speed."""
    v = rel_speed_mps
    return max(ttc_s * v, max(clear_buffered_m, stop_buffered_m) + lead_s * v)


def classify(
    range_m: float,
    rel_speed_mps: float,
    clear_m: float,
    clear_buffered_m: float,
    stop_m: float,
    stop_buffered_m: float,
    ttc_s: float,
    warn_lead_s: float = FCW_LEAD_S,
) -> Sector:
    """Sector of the phase point (range, closing speed) given the boundaries at that speed;
    the warning line is ``warning_line_m`` with the lead ``warn_lead_s``.

    A non-finite range or closing speed, or one that is not closing (v <= 0), is sector G.
    """
    d, v = range_m, rel_speed_mps
    if not (v > 0.0 and math.isfinite(v) and math.isfinite(d)):
        return G
    if d <= clear_m:
        return A if d <= stop_m else C
    if d <= clear_buffered_m:
        if stop_m <= clear_m:  # stopping is shorter than clearing: braking stops first
            return C
        return F if d <= stop_buffered_m else B
    if d <= stop_buffered_m:
        return D
    if d <= warning_line_m(v, clear_buffered_m, stop_buffered_m, ttc_s, warn_lead_s):
        return E
    return G


def dmm_sector(boundary, range_m: float, rel_speed_mps: float) -> Sector:
    """Sector for a ``Boundary`` (offline tables) evaluated at the current closing speed."""
    return classify(
        range_m,
        rel_speed_mps,
        boundary.clear_opt_m,
        boundary.clear_buffered_m,
        boundary.stop_m,
        boundary.stop_buffered_m,
        boundary.ttc_s,
    )


class BoundaryRow(NamedTuple):
    """The DMM boundaries at one friction and closing speed (m; the TTC in s)."""

    clear_m: float  # S, minimum clearing distance with the optimised profile (eq. 32)
    clear_buffered_m: float  # Sb
    stop_m: float  # B0, stopping distance (eq. 33)
    stop_buffered_m: float  # Bb
    ttc_s: float  # T / v (eq. 34)


#: Samples of the boundary curve between 0 and the lowest table speed (see ``BoundaryCurve``).
LOW_SPEED_SAMPLES = 24


class BoundaryCurve:
    """The DMM boundaries at one friction as plain floats at fixed closing speeds.

    Built once per friction value from ``boundaries.at(mu, v)`` at the given speeds (the
    tables' own speed grid, between which ``at`` is linear in v, so the curve is exact) and at
    ``LOW_SPEED_SAMPLES`` speeds from 0 to the lowest of them, where the stopping distance is
    quadratic in v (eq. 33; linear blending between samples 1/24 of the lowest speed apart
    overestimates it by at most 1/4608 of B0 there); ``at`` and ``sector`` then cost a
    bisection and a linear blend. A row is looked up at its first use (an estimated friction
    changes the curve every few steps, which then reads two or three of its rows). Above the
    last speed the last row is used. ``stop_scale``
    (>= 1) lengthens the stopping distance B0 (and Bb by as much) where limit braking
    delivers less than the tables' deceleration (eq. 33: B0 = v^2 / 2a scales with 1 / a).
    ``lateral_stop_factor`` (>= 1, set at each step) lengthens B0 (and Bb by as much) further
    where a curve's lateral acceleration takes part of the friction ellipse.
    """

    __slots__ = ("_boundaries", "_rows", "_speeds", "_stop_scale", "lateral_stop_factor", "mu")

    def __init__(self, boundaries, mu: float, speeds_mps, stop_scale: float = 1.0):
        given = sorted({0.0, *(float(v) for v in speeds_mps)})
        if len(given) < 2 or given[0] < 0.0 or not math.isfinite(given[-1]):
            raise ValueError(f"bad boundary speeds: {speeds_mps!r}")
        if not (math.isfinite(stop_scale) and stop_scale >= 1.0):
            raise ValueError(f"stop_scale={stop_scale!r} must be finite and >= 1")
        n = LOW_SPEED_SAMPLES
        speeds = sorted({*given, *(given[1] * k / n for k in range(n))})
        self.mu = mu
        self._boundaries, self._stop_scale = boundaries, stop_scale
        self._speeds = speeds
        self._rows: list[tuple[float, float, float, float, float] | None] = [None] * len(speeds)
        self.lateral_stop_factor = 1.0

    def _row(self, i: int) -> tuple[float, float, float, float, float]:
        """The boundaries at ``self._speeds[i]`` (looked up once, at the first use)."""
        row = self._rows[i]
        if row is not None:
            return row
        mu, v = self.mu, self._speeds[i]
        b = self._boundaries.at(mu, v)
        longer = float(b.stop_m) * (self._stop_scale - 1.0)
        row = (  # plain tuples: indexing a tuple subclass is slower
            float(b.clear_opt_m),
            float(b.clear_buffered_m),
            float(b.stop_m) + longer,
            float(b.stop_buffered_m) + longer,
            float(b.ttc_s),
        )
        if not all(math.isfinite(x) for x in row):
            raise ValueError(f"non-finite DMM boundary at mu={mu}, v={v}")
        self._rows[i] = row
        return row

    def at(self, rel_speed_mps: float) -> BoundaryRow:
        """The boundaries at a closing speed (held at the ends of the speed range)."""
        return BoundaryRow._make(self._blend(rel_speed_mps))

    def _blend(self, rel_speed_mps: float) -> tuple[float, float, float, float, float]:
        """``at`` as a plain tuple (for ``sector``, at every step with an obstacle in range),
        B0 and Bb lengthened by ``lateral_stop_factor``."""
        row = self._straight(rel_speed_mps)
        k = self.lateral_stop_factor
        if k == 1.0:
            return row
        longer = row[2] * (k - 1.0)
        return (row[0], row[1], row[2] + longer, row[3] + longer, row[4])

    def _straight(self, rel_speed_mps: float) -> tuple[float, float, float, float, float]:
        """The boundaries on a straight road at a closing speed (blended between samples)."""
        speeds = self._speeds
        j = bisect_right(speeds, rel_speed_mps)
        if j <= 0:
            return self._row(0)
        if j >= len(speeds):
            return self._row(len(speeds) - 1)
        v0 = speeds[j - 1]
        w = (rel_speed_mps - v0) / (speeds[j] - v0)
        a, b = self._row(j - 1), self._row(j)
        return (
            a[0] + w * (b[0] - a[0]),
            a[1] + w * (b[1] - a[1]),
            a[2] + w * (b[2] - a[2]),
            a[3] + w * (b[3] - a[3]),
            a[4] + w * (b[4] - a[4]),
        )

    def sector(self, range_m: float, rel_speed_mps: float) -> Sector:
        """Sector of (range, closing speed); G when not closing or not finite."""
        if not (rel_speed_mps > 0.0 and math.isfinite(rel_speed_mps)):
            return G
        s, sb, b0, bb, ttc = self._blend(rel_speed_mps)
        return classify(range_m, rel_speed_mps, s, sb, b0, bb, ttc)
