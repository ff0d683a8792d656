"""Time-optimal lateral escapes within the friction budget (jerk-limited bang-bang).

An evasive shift (away from oncoming traffic, back into the own lane) is quickest when the
lateral acceleration is at the budget A = k mu g the whole time: towards the target, then
against it so that the lateral motion stops exactly there (the time-optimal control of a
double integrator, Pontryagin's bang-bang). The tyres and the steering cannot jump from one
side of the budget to the other, so the acceleration changes at a bounded jerk J = A / ramp
(``ramp_s``: the time from no lateral acceleration to the full budget). A ``MinTimeShift`` is
that profile from the ego's lateral state (offset, lateral speed, lateral acceleration), at
constant forward speed, in the ``at(dx) -> TrajectoryPoint`` form of the other paths
(``PathReference(..., height_m=None)``).

The profile is a chain of constant-jerk segments: ramp towards +A (towards the target), hold,
at the switching time ramp to -A, hold until the lateral speed is what the last ramp back to
zero acceleration removes, then that ramp. The switching time is found by bisection so that
the motion ends at the target; when even switching at once passes the target (the ego moves
towards it too fast to stop there) the path switches at once and ends beyond it.
"""

from __future__ import annotations

import math

from eoam_sumo.manoeuvre.points import TrajectoryPoint

_BISECTIONS = 48


def _advance(y: float, v: float, a: float, jerk: float, t: float) -> tuple[float, float, float]:
    """State after ``t`` seconds of constant jerk."""
    return (
        y + t * (v + t * (0.5 * a + t * jerk / 6.0)),
        v + t * (a + 0.5 * t * jerk),
        a + jerk * t,
    )


def _speed_zeros(v: float, a: float, jerk: float, dur: float) -> list[float]:
    """Times in [0, dur] at which a constant-jerk segment's speed v + a t + j t^2 / 2 is 0."""
    if jerk != 0.0:
        disc = a * a - 2.0 * jerk * v
        if disc < 0.0:
            return []
        roots = [(-a + r) / jerk for r in (math.sqrt(disc), -math.sqrt(disc))]
    elif a != 0.0:
        roots = [-v / a]
    else:
        return []
    return [t for t in roots if 0.0 <= t <= dur]


class MinTimeShift:
    """Jerk-limited time-optimal lateral shift to ``y1_m`` (module doc)."""

    __slots__ = ("_segs", "duration_s", "length_m", "speed_mps", "y1_m", "y_end_m")

    def __init__(
        self,
        y0_m: float,
        v0_mps: float,
        a0_mps2: float,
        y1_m: float,
        speed_mps: float,
        accel_mps2: float,
        ramp_s: float,
    ):
        if not (accel_mps2 > 0.0 and ramp_s > 0.0 and speed_mps > 0.0):
            raise ValueError("accel_mps2, ramp_s and speed_mps must be > 0")
        if not all(math.isfinite(x) for x in (y0_m, v0_mps, a0_mps2, y1_m)):
            raise ValueError(
                f"escape y0={y0_m!r}, v0={v0_mps!r}, a0={a0_mps2!r}, y1={y1_m!r} not all finite"
            )
        self.speed_mps = float(speed_mps)
        self.y1_m = float(y1_m)
        big_a, jerk = accel_mps2, accel_mps2 / ramp_s
        # in the sign (+1 or -1) in which the motion first goes towards the target; both
        # are tried where the target is reachable without passing it, the quicker kept
        best = None
        for sign in (1.0, -1.0):
            found = self._solve(
                (sign * y0_m, sign * v0_mps, sign * a0_mps2), sign * y1_m, big_a, jerk
            )
            if found is not None and (best is None or found[0] < best[1][0]):
                best = (sign, found)
        if best is None:  # too fast towards the target to stop there: brake at once
            sign = 1.0 if v0_mps >= 0.0 else -1.0
            segs: list[tuple[float, float]] = []
            state = (sign * y0_m, sign * v0_mps, sign * a0_mps2)
            self._profile(state, 0.0, big_a, jerk, segs)
        else:
            sign, (_, segs) = best
            state = (sign * y0_m, sign * v0_mps, sign * a0_mps2)
        self._segs: list[tuple[float, float, float, float, float, float]] = []
        t0, (y, v, a) = 0.0, state
        for dur, j in segs:  # absolute segment starts, in the real sign
            self._segs.append((t0, dur, sign * y, sign * v, sign * a, sign * j))
            y, v, a = _advance(y, v, a, j, dur)
            t0 += dur
        self.duration_s = t0
        self.length_m = max(t0 * speed_mps, 1e-3)
        self.y_end_m = sign * y

    @classmethod
    def _solve(cls, state, target: float, big_a: float, jerk: float) -> tuple[float, list] | None:
        """(duration, segments) of the profile towards + that ends at ``target``, or None
        when no switching time ends there."""

        def final(t_switch: float) -> float:
            return cls._profile(state, t_switch, big_a, jerk, None)[0]

        lo, hi = 0.0, 1.0
        if final(lo) > target + 1e-9:
            return None
        while final(hi) < target and hi < 1e3:
            lo, hi = hi, 2.0 * hi
        for _ in range(_BISECTIONS):
            mid = 0.5 * (lo + hi)
            if final(mid) < target:
                lo = mid
            else:
                hi = mid
        segs: list[tuple[float, float]] = []
        if abs(cls._profile(state, hi, big_a, jerk, segs)[0] - target) > 1e-6:
            return None  # the ends jump past the target (the motion away is not arrested)
        return sum(dur for dur, _ in segs), segs

    @staticmethod
    def _profile(
        state, t_switch: float, big_a: float, jerk: float, segs: list | None
    ) -> tuple[float, float, float]:
        """End state of the profile switching at ``t_switch`` (appending its segments)."""
        y, v, a = state

        def seg(dur: float, j: float) -> None:
            nonlocal y, v, a
            if dur > 0.0:
                y, v, a = _advance(y, v, a, j, dur)
                if segs is not None:
                    segs.append((dur, j))

        # towards the target: to +A at the jerk limit, then hold, until t_switch
        j1 = jerk if a < big_a else -jerk
        ramp = min(abs(big_a - a) / jerk, t_switch)
        seg(ramp, j1)
        seg(t_switch - ramp, 0.0)
        # against it: jerk -J until the last ramp (+J back to a = 0) ends at v = 0
        disc = 0.5 * a * a + jerk * v
        if disc < 0.0:  # still moving away from the target: switching this early never stops
            return -math.inf, v, a
        t_last = (a + math.sqrt(disc)) / jerk
        t_full = (a + big_a) / jerk
        if t_last <= t_full:
            seg(max(t_last, 0.0), -jerk)
        else:
            seg(t_full, -jerk)
            seg(max((v - 0.5 * big_a * big_a / jerk) / big_a, 0.0), 0.0)
        seg(max(-a / jerk, 0.0), jerk)
        return y, v, a

    def state_at(self, t_s: float) -> tuple[float, float, float]:
        """(offset, lateral speed, lateral acceleration) ``t_s`` after the start (held at the
        end)."""
        segs = self._segs
        if not segs:
            return self.y_end_m, 0.0, 0.0
        for t0, dur, y, v, a, j in segs:
            if t_s < t0 + dur:
                return _advance(y, v, a, j, max(t_s - t0, 0.0))
        t0, dur, y, v, a, j = segs[-1]
        y, _, _ = _advance(y, v, a, j, dur)
        return y, 0.0, 0.0

    def max_offset_m(self) -> float:
        """The largest offset along the path (at the segment ends and where the lateral
        speed is zero within a segment)."""
        best = self.state_at(0.0)[0]
        for _, dur, y, v, a, j in self._segs:
            for t in [dur, *_speed_zeros(v, a, j, dur)]:
                best = max(best, _advance(y, v, a, j, t)[0])
        return best

    def turn_s(self) -> float:
        """When the lateral speed first falls to zero from its initial sign (0 when the motion
        starts towards the target or at rest): where an arrest of the motion ends."""
        v0 = self.state_at(0.0)[1]
        if v0 * (self.y1_m - self.state_at(0.0)[0]) >= 0.0:
            return 0.0
        for t0, dur, _, v, a, j in self._segs:
            zeros = _speed_zeros(v, a, j, dur)
            if zeros:
                return t0 + min(zeros)
        return self.duration_s

    def time_within_s(self, line_m: float, below: bool = True) -> float:
        """First time from which the offset stays at or below ``line_m`` (above it when not
        ``below``) to the end of the path; inf when it ends beyond the line."""
        s = 1.0 if below else -1.0
        if s * self.y_end_m > s * line_m:
            return math.inf
        t_hi = self.duration_s
        # the last time beyond the line: scan the segments backwards, then bisect
        samples = [t0 + f * dur for t0, dur, *_ in self._segs for f in (0.0, 0.25, 0.5, 0.75)]
        samples.append(t_hi)
        beyond = [t for t in samples if s * self.state_at(t)[0] > s * line_m]
        if not beyond:
            return 0.0
        lo = max(beyond)
        hi = min((t for t in samples if t > lo), default=t_hi)
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            if s * self.state_at(mid)[0] > s * line_m:
                lo = mid
            else:
                hi = mid
        return hi

    def at(self, dx_m: float) -> TrajectoryPoint:
        v = self.speed_mps
        y, vy, ay = self.state_at(dx_m / v)
        slope = vy / v
        return TrajectoryPoint(
            y, 0.0, math.atan(slope), ay / (v * v) / (1.0 + slope * slope) ** 1.5, 0.0
        )
