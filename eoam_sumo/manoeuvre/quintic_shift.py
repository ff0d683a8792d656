"""The shortest quintic lateral shift within a lateral-acceleration budget (paper sec. 4.2,
eqs. 7-13), from the ego's lateral state (offset, slope and curvature of its course)."""

from __future__ import annotations

import math

import numpy as np

from eoam_sumo.manoeuvre.points import TrajectoryPoint

PEAK_SAMPLES = 200  # intervals over which a shift's peak curvature is checked
SEARCH_SAMPLES = 50  # intervals of the coarser check while searching the length
LENGTH_STEP = 1.02  # the scan that brackets the shortest length within the budget (2 %)
LENGTH_TOL_M = 1e-6  # how closely the root-finding places that length [m]
STOP_TOL_M = 1e-4  # how closely a lateral stop's end is placed [m]
STOP_BISECTIONS = 24  # at most, halving the stop's bracket down to STOP_TOL_M
OVERSHOOT_TOL_M = 1e-3  # a shift may pass its target by this much (rounding) [m]
_PASSES = 1e30  # the peak given to a shift that passes y1 while minimising the peak [1/m]
_PEAK_U = [i / PEAK_SAMPLES for i in range(PEAK_SAMPLES + 1)]
_SEARCH_U = [i / SEARCH_SAMPLES for i in range(SEARCH_SAMPLES + 1)]


class QuinticShift:
    """Quintic from the ego's lateral state to offset ``y1`` (paper sec. 4.2, eqs. 7-13).

    y(u) = y0 + P u + c2 u^2 + c3 u^3 + c4 u^4 + c5 u^5 with u = dx / X: the start has the
    ego's offset, the slope of its course relative to the road (P = slope0 X) and the
    curvature of its path (c2 = kappa0 X^2 / 2), so that neither the lateral speed nor the
    lateral acceleration the reference asks for jumps; the end is y = y1 with y' = y'' = 0.
    From rest (slope0 = kappa0 = 0) it is the paper's lane change
    y0 + (y1 - y0) (10u^3 - 15u^4 + 6u^5). Given at constant speed (ax = 0) in the tables'
    ``at(dx) -> TrajectoryPoint`` form, in absolute lateral positions
    (``PathReference(..., height_m=None)``).
    """

    __slots__ = ("_c", "length_m", "y1_m")

    def __init__(
        self, y0_m: float, slope0: float, y1_m: float, length_m: float, curvature0_1pm: float = 0.0
    ):
        if not (math.isfinite(length_m) and length_m > 0.0):
            raise ValueError(f"quintic length_m={length_m!r} must be finite and > 0")
        if not all(math.isfinite(v) for v in (y0_m, slope0, y1_m, curvature0_1pm)):
            raise ValueError(
                f"quintic y0={y0_m!r}, slope0={slope0!r}, y1={y1_m!r}, "
                f"curvature0={curvature0_1pm!r} not all finite"
            )
        p = slope0 * length_m
        c2 = 0.5 * curvature0_1pm * length_m * length_m
        # what the u^3..u^5 terms must add to y, dy/du and d2y/du2 at u = 1
        e, f, g = y1_m - y0_m - p - c2, -p - 2.0 * c2, -2.0 * c2
        self._c = (
            y0_m,
            p,
            c2,
            10.0 * e - 4.0 * f + 0.5 * g,
            -15.0 * e + 7.0 * f - g,
            6.0 * e - 3.0 * f + 0.5 * g,
        )
        self.length_m = float(length_m)
        self.y1_m = float(y1_m)

    def _check(self, grid) -> tuple[float, float]:
        """(largest |y''| [1/m], largest passing of y1 away from y0 [m]): at the grid points
        for the coarse grid; exactly for the full one, whose points add the stationary points
        of y and of y'' (the extremes lie there or at the ends)."""
        y0, p, c2, c3, c4, c5 = self._c
        big2 = self.length_m * self.length_m
        side = 1.0 if self.y1_m >= y0 else -1.0
        peak = past = 0.0
        points = list(grid)
        if grid is _PEAK_U:  # the stationary points of y and of y'' in (0, 1): exact extremes
            roots = [*np.roots([5.0 * c5, 4.0 * c4, 3.0 * c3, 2.0 * c2, p])]
            roots += [*np.roots([10.0 * c5, 4.0 * c4, c3])]
            points += [float(r.real) for r in roots if abs(r.imag) < 1e-9 and 0.0 < r.real < 1.0]
        for u in points:
            k = abs(2.0 * c2 + u * (6.0 * c3 + u * (12.0 * c4 + 20.0 * u * c5))) / big2
            peak = max(peak, k)
            beyond = side * (y0 + u * (p + u * (c2 + u * (c3 + u * (c4 + u * c5)))) - self.y1_m)
            past = max(past, beyond)
        return peak, past

    def peak_curvature_1pm(self) -> float:
        """Largest |y''| along the path (sampled), the lateral acceleration per v^2."""
        return self._check(_PEAK_U)[0]

    def overshoot_m(self) -> float:
        """How far the path passes its target offset y1 (sampled), 0 when it does not."""
        return self._check(_PEAK_U)[1]

    def _margin(self, limit_1pm: float) -> float:
        """How far the shift misses its budget: > 0 when its peak |y''| exceeds ``limit_1pm``
        or it passes y1 by more than ``OVERSHOOT_TOL_M`` (relative peak excess or overshoot
        per metre of shift, whichever is larger); <= 0 when it is within both. Continuous in
        the length between appearances of stationary points."""
        peak, past = self._check(_PEAK_U)
        scale = max(abs(self.y1_m - self._c[0]), 0.01)
        return max(peak / limit_1pm - 1.0, (past - OVERSHOOT_TOL_M) / scale)

    @classmethod
    def for_lateral_accel(
        cls,
        y0_m: float,
        slope0: float,
        y1_m: float,
        speed_mps: float,
        lateral_accel_mps2: float,
        min_length_m: float,
        curvature0_1pm: float = 0.0,
    ) -> QuinticShift:
        """The shortest shift (not below ``min_length_m``) that does not pass y1 and whose peak
        lateral acceleration v^2 |y''| is within ``lateral_accel_mps2`` (time-optimal within
        that friction budget, for a quintic). Lengths are scanned 2 % apart to bracket the
        shortest one within the budget, which is then found by root-finding to
        ``LENGTH_TOL_M``, so the length is a continuous function of the ego's state (no
        last-bit change of the state can jump it to a neighbouring grid length).

        Where no length meets the budget (the ego already moves away from y1 too fast, or its
        lateral acceleration exceeds the budget), the shift without overshoot of least peak.
        """
        if not (lateral_accel_mps2 > 0.0 and min_length_m > 0.0):
            raise ValueError("lateral_accel_mps2 and min_length_m must be > 0")
        limit = lateral_accel_mps2 / max(speed_mps * speed_mps, 1e-9)
        rest = math.sqrt(10.0 * math.sqrt(3.0) / 3.0 * max(abs(y1_m - y0_m), 1e-3) / limit)
        # from the shortest allowed: short shifts pass the target least
        length = max(min_length_m, 0.3 * rest) if slope0 == 0.0 else min_length_m
        # far enough to turn a lateral motion away from y1 round and come back
        top = 4.0 * min_length_m + 8.0 * (
            rest + abs(slope0) * speed_mps * speed_mps / lateral_accel_mps2
        )
        state = (y0_m, slope0, y1_m, curvature0_1pm)
        failed, lengths = None, []
        while length <= top:
            traj = cls(y0_m, slope0, y1_m, length, curvature0_1pm)
            # the full check's points include the coarse grid's, so its peak is at least the
            # coarse one: a coarse peak over the budget misses it without the full check
            coarse_peak, coarse_past = traj._check(_SEARCH_U)
            if (
                coarse_past <= OVERSHOOT_TOL_M
                and coarse_peak / limit - 1.0 <= 0.0
                and traj._margin(limit) <= 0.0
            ):
                return traj if failed is None else _first_within(cls, state, limit, failed, length)
            failed = length
            lengths.append(length)
            length *= LENGTH_STEP
        return _least_peak(cls, state, lengths, min_length_m)

    def within(self, speed_mps: float, lateral_accel_mps2: float) -> bool:
        """Peak lateral acceleration within the budget and no overshoot of y1."""
        peak, past = self._check(_PEAK_U)
        return peak * speed_mps * speed_mps <= lateral_accel_mps2 and past <= OVERSHOOT_TOL_M

    @classmethod
    def stopping(
        cls,
        y0_m: float,
        slope0: float,
        speed_mps: float,
        lateral_accel_mps2: float,
        min_length_m: float,
        curvature0_1pm: float = 0.0,
        reaction_s: float = 0.0,
    ) -> QuinticShift:
        """The shift that arrests the lateral motion soonest: to the nearest offset ahead of
        the motion it can stop at within the budget without passing it (bisection between
        the constant-deceleration stop v_lat^2 / (2 a) and four times it or more, to 0.1 mm),
        moved on
        by what the motion covers in ``reaction_s`` (steering and yaw lag) at its present
        lateral speed and acceleration: d + v_lat tau + a tau^2 / 2 + D."""
        v_lat = slope0 * speed_mps
        a_lat = curvature0_1pm * speed_mps * speed_mps
        ahead = v_lat * reaction_s + 0.5 * a_lat * reaction_s * reaction_s
        side = 1.0 if v_lat + a_lat * max(reaction_s, 0.1) >= 0.0 else -1.0
        lo = v_lat * v_lat / (2.0 * lateral_accel_mps2)
        hi = max(4.0 * lo, 0.05)

        def shift(dist: float) -> QuinticShift:
            return cls.for_lateral_accel(
                y0_m,
                slope0,
                y0_m + side * dist,
                speed_mps,
                lateral_accel_mps2,
                min_length_m,
                curvature0_1pm,
            )

        best = shift(hi)
        while not best.within(speed_mps, lateral_accel_mps2) and hi < 50.0:
            lo, hi = hi, 2.0 * hi  # the shortest length (min_length_m) asks for more room
            best = shift(hi)
        for _ in range(STOP_BISECTIONS):
            if hi - lo <= STOP_TOL_M:
                break
            mid = 0.5 * (lo + hi)
            traj = shift(mid)
            if traj.within(speed_mps, lateral_accel_mps2):
                best, hi = traj, mid
            else:
                lo = mid
        if side * ahead <= 0.0:
            return best
        return shift(best.y1_m * side - y0_m * side + side * ahead)

    def at(self, dx_m: float) -> TrajectoryPoint:
        big = self.length_m
        u = min(max(dx_m / big, 0.0), 1.0)
        y0, p, c2, c3, c4, c5 = self._c
        y = y0 + u * (p + u * (c2 + u * (c3 + u * (c4 + u * c5))))
        dy = (p + u * (2.0 * c2 + u * (3.0 * c3 + u * (4.0 * c4 + 5.0 * u * c5)))) / big
        ddy = (2.0 * c2 + u * (6.0 * c3 + u * (12.0 * c4 + 20.0 * u * c5))) / (big * big)
        return TrajectoryPoint(y, 0.0, math.atan(dy), ddy / (1.0 + dy * dy) ** 1.5, 0.0)


def _first_within(cls, state: tuple, limit: float, lo: float, hi: float) -> QuinticShift:
    """The shortest length in (lo, hi] within the budget (``_margin`` <= 0), by Brent's method
    on the margin (lo misses the budget, hi meets it), to ``LENGTH_TOL_M``; the bracket's upper
    end where the root itself misses by its last bits."""
    from scipy.optimize import brentq  # at first use: a command that plans no shift skips it

    y0, slope0, y1, kappa0 = state

    def margin(length: float) -> float:
        return cls(y0, slope0, y1, length, kappa0)._margin(limit)

    root, result = brentq(margin, lo, hi, xtol=LENGTH_TOL_M, full_output=True, disp=False)
    for length in (root, root + LENGTH_TOL_M, hi):
        traj = cls(y0, slope0, y1, min(length, hi), kappa0)
        if result.converged and traj._margin(limit) <= 0.0:
            return traj
    return cls(y0, slope0, y1, hi, kappa0)


def _least_peak(cls, state: tuple, lengths: list[float], min_length_m: float) -> QuinticShift:
    """No scanned length meets the budget: the shift without overshoot of least peak |y''|,
    its length refined between the scanned neighbours (bounded Brent minimisation), or, where
    every allowed length passes y1, the longest shorter one that does not."""
    y0, slope0, y1, kappa0 = state
    peaks = []
    for length in lengths:
        peak, past = cls(y0, slope0, y1, length, kappa0)._check(_PEAK_U)
        peaks.append(peak if past <= OVERSHOOT_TOL_M else math.inf)
    if peaks and math.isfinite(min(peaks)):
        return _refined_least_peak(cls, state, lengths, peaks)
    length = min_length_m
    while True:  # every allowed length passes y1: shorter ones, until one does not
        length /= LENGTH_STEP
        traj = cls(y0, slope0, y1, length, kappa0)
        if length < 0.01 or traj._check(_PEAK_U)[1] <= OVERSHOOT_TOL_M:
            return traj


def _refined_least_peak(cls, state: tuple, lengths: list, peaks: list) -> QuinticShift:
    """The least-peak length between the scanned neighbours of the scan's best (ties within
    1e-9 relative go to the shorter length, so rounding noise on a plateau does not choose)."""
    y0, slope0, y1, kappa0 = state
    least = min(peaks)
    k = next(i for i, p in enumerate(peaks) if p <= least * (1.0 + 1e-9))
    lo, hi = lengths[max(k - 1, 0)], lengths[min(k + 1, len(lengths) - 1)]
    best = cls(y0, slope0, y1, lengths[k], kappa0)

    def peak_of(length: float) -> float:
        peak, past = cls(y0, slope0, y1, length, kappa0)._check(_PEAK_U)
        return peak if past <= OVERSHOOT_TOL_M else _PASSES

    if hi > lo:
        from scipy.optimize import minimize_scalar

        found = minimize_scalar(
            peak_of, bounds=(lo, hi), method="bounded", options={"xatol": LENGTH_TOL_M}
        )
        if found.fun < least * (1.0 - 1e-9):
            best = cls(y0, slope0, y1, float(found.x), kappa0)
    return best
