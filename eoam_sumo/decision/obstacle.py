"""The in-path obstacle's own braking, estimated from the radar's range rate.

The paper's phase boundaries are functions of the closing speed as if the obstacle held it
(sec. 5-6). An obstacle that brakes to a stop ends further ahead than that model says only
when it brakes gently; when it brakes hard the closing speed grows faster than the model
assumes and the warning and braking come late (on the baseline at 100 km/h a 3 m/s^2 stop
ended worse than an 8 m/s^2 one). The decision therefore also places the obstacle where it
will stop: a standing obstacle at range + v_obj^2 / (2 a_obj), approached at the ego's own
speed, and takes the more urgent of the two sectors. An obstacle braking more gently than the
ego can is still moving when the speeds match, and the gap is least then, not where it stands:
the ego needs v_rel^2 / (2 (a_ego - a_obj)) instead of v_rel^2 / (2 a_ego) (relative motion
under constant decelerations), ``speed_match_factor`` times the paper's stopping distance.

The obstacle's speed is the ego's speed plus the range rate; its deceleration the derivative
of that speed through a first-order low-pass filter (``time_constant_s``), as an ACC estimates
a lead vehicle's acceleration (Winner et al., Handbook of Driver Assistance Systems, 2016,
ch. 46). A speed step no car can make (beyond ``plausible_mps2``) is another object or a new
track: the estimate starts again from it.
"""

from __future__ import annotations

import math
from typing import NamedTuple


class ObstacleDecel:
    """Low-pass estimate of the in-path obstacle's deceleration [m/s^2, braking positive]."""

    __slots__ = ("_raw", "_speed", "_t", "decel_mps2", "plausible_mps2", "time_constant_s")

    def __init__(self, time_constant_s: float = 0.1, plausible_mps2: float = 15.0):
        if not (math.isfinite(time_constant_s) and time_constant_s > 0.0):
            raise ValueError(f"time_constant_s={time_constant_s!r} must be finite and > 0")
        self.time_constant_s = time_constant_s
        self.plausible_mps2 = plausible_mps2
        self.reset()

    def reset(self) -> None:
        """Forget the track (a new obstacle, or none)."""
        self._t = math.nan
        self._speed = 0.0
        self._raw = math.inf  # the last unfiltered derivative (inf: none yet)
        self.decel_mps2 = 0.0

    def update(self, time_s: float, obstacle_speed_mps: float) -> float:
        """Add one measurement of the obstacle's speed; the filtered deceleration."""
        dt = time_s - self._t
        if dt > 0.0:  # false for the first sample (nan)
            raw = (self._speed - obstacle_speed_mps) / dt
            if -self.plausible_mps2 <= raw <= self.plausible_mps2:
                self.decel_mps2 += dt / (self.time_constant_s + dt) * (raw - self.decel_mps2)
                self._raw = raw
            else:
                self.decel_mps2 = 0.0
                self._raw = math.inf
        self._t, self._speed = time_s, obstacle_speed_mps
        return self.decel_mps2

    def settled(self, tolerance_mps2: float = 0.5) -> bool:
        """The estimate follows the last measured derivative within ``tolerance_mps2``: not
        lagging a change of the obstacle's braking (its onset: the filter still rising)."""
        return abs(self._raw - self.decel_mps2) <= tolerance_mps2


def stopping_range_m(range_m: float, obstacle_speed_mps: float, decel_mps2: float) -> float:
    """Range to where a braking obstacle will stand: range + v_obj^2 / (2 a_obj); infinite
    when it does not brake or drives backwards."""
    if decel_mps2 <= 0.0 or obstacle_speed_mps <= 0.0:
        return math.inf if obstacle_speed_mps > 0.0 else range_m
    return range_m + obstacle_speed_mps * obstacle_speed_mps / (2.0 * decel_mps2)


def speed_match_factor(
    closing_mps: float, obstacle_speed_mps: float, decel_mps2: float, ego_decel_mps2: float
) -> float:
    """The stopping distance's factor a_ego / (a_ego - a_obj) when an obstacle braking at
    ``decel_mps2`` is still moving as the ego, braking at ``ego_decel_mps2``, matches its
    speed (the gap least then); 1.0 otherwise (it holds its speed, stops first, or brakes at
    least as hard as the ego: the standing placement or the paper's rule)."""
    rel_decel = ego_decel_mps2 - decel_mps2
    if decel_mps2 <= 0.0 or rel_decel <= 0.0 or closing_mps <= 0.0:
        return 1.0
    if obstacle_speed_mps * rel_decel <= closing_mps * decel_mps2:  # stops before the match
        return 1.0
    return ego_decel_mps2 / rel_decel


def travel_m(speed_mps: float, decel_mps2: float, dt_s: float) -> float:
    """Distance a body covers in ``dt_s`` from ``speed_mps`` braking at ``decel_mps2`` (to
    its stop)."""
    if decel_mps2 > 0.0 and dt_s * decel_mps2 > speed_mps:
        return 0.5 * speed_mps * speed_mps / decel_mps2
    return dt_s * (speed_mps - 0.5 * decel_mps2 * dt_s)


class ObstacleTrack(NamedTuple):
    """The in-path obstacle as last sensed, road frame of the ego's lane."""

    time_s: float
    front_s_m: float  # station of its front
    speed_mps: float
    left_edge_m: float  # offset of its left side
    decel_mps2: float  # its braking (0: holds its speed)
    length_m: float

    @classmethod
    def sensed(
        cls,
        meas,
        front_offset_m: float,
        range_m: float,
        closing_mps: float,
        obj,
        unknown_length_m: float,
        decel_mps2: float,
    ) -> ObstacleTrack:
        """From an ``EgoMeasurement`` and the sensor: the object track ``obj`` (an
        ``ObjectState``) when it gives one; else the range from the ego's front bumper
        (``front_offset_m`` ahead of its centre of gravity), an assumed length and a width
        filling the ego's lane."""
        if obj is not None:
            return cls(
                meas.time_s,
                obj.s_m + 0.5 * obj.length_m,
                max(obj.speed_mps, 0.0),
                obj.d_m + 0.5 * obj.width_m,
                decel_mps2,
                obj.length_m,
            )
        return cls(
            meas.time_s,
            meas.s_m + front_offset_m + range_m + unknown_length_m,
            max(meas.vx_mps - closing_mps, 0.0),
            0.5 * meas.lane_width_m,
            decel_mps2,
            unknown_length_m,
        )

    def at(self, time_s: float) -> tuple[float, float]:
        """(front station, speed) predicted at ``time_s`` from its speed and braking."""
        dt = time_s - self.time_s
        return (
            self.front_s_m + travel_m(self.speed_mps, self.decel_mps2, dt),
            max(self.speed_mps - self.decel_mps2 * dt, 0.0),
        )
