"""What the reference drivers share: the lead as the forward radar reports it, and the
braking response after a reaction time (a delay at a fixed acceleration, then a
jerk-limited ramp to a full deceleration, held to standstill)."""

from __future__ import annotations

import math
from collections import deque
from typing import NamedTuple

from eoam_sumo.eoam_messages import Perception

#: A range this far off the previous step's prediction is another object [m] (a cut-in, a
#: vehicle revealed by a cut-out): the project's assumption.
FRESH_JUMP_M = 2.0
#: Below this speed the ego counts as stopped and the brake is held [m/s].
STOPPED_MPS = 0.05
#: The lead is no longer closing when it is at most this much slower [m/s].
MATCHED_MPS = 0.05
#: The lead's acceleration is its speed's slope over this window [s] (shorter while the
#: object is newer): a radar's range rate is noisy and arrives once per scan, and a one-step
#: difference of it would be noise (the project's choice).
ACCEL_WINDOW_S = 0.5


class Lead(NamedTuple):
    """The in-path object: gap from the ego's front bumper, its speed and acceleration along
    the road (the ego's speed plus the range rate; its slope over ``ACCEL_WINDOW_S``),
    whether it was first seen at this step (not at the first step of a run) and whether it
    then came from the side (its centre outside the ego's lane: a cut-in; else a vehicle
    revealed, or first seen, ahead)."""

    gap_m: float
    speed_mps: float
    accel_mps2: float
    fresh: bool
    from_side: bool = False


class LeadTracker:
    """The lead from the step's ``Perception`` (range and range rate of the in-path object)."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self._prev: tuple[float, float, float] | None = None  # gap, range rate, lead speed
        self._started = False
        self._speeds: deque[float] = deque()  # the lead's speeds, one a step, newest last

    def update(
        self, v_mps: float, perception: Perception, dt_s: float, lane_width_m: float = 3.5
    ) -> Lead | None:
        gap, rate = perception.aro_range_m, perception.aro_range_rate_mps
        first, self._started = not self._started, True
        prev = self._prev
        if gap is None or rate is None:
            self._prev = None
            return None
        speed = v_mps + rate
        self._prev = (gap, rate, speed)
        speeds = self._speeds
        if prev is None or abs(gap - (prev[0] + prev[1] * dt_s)) > FRESH_JUMP_M:
            speeds.clear()
            speeds.append(speed)
            obj = perception.aro_object
            side = obj is not None and abs(obj.d_m) > 0.5 * lane_width_m
            return Lead(gap, speed, 0.0, not first, side)
        speeds.append(speed)
        if dt_s > 0.0 and len(speeds) > round(ACCEL_WINDOW_S / dt_s) + 1:
            speeds.popleft()
        accel = (speed - speeds[0]) / ((len(speeds) - 1) * dt_s) if dt_s > 0.0 else 0.0
        return Lead(gap, speed, accel, False)


def time_to_collision_s(lead: Lead, v_mps: float) -> float:
    """Gap over closing speed (inf when not closing)."""
    closing = v_mps - lead.speed_mps
    return lead.gap_m / closing if closing > 0.0 else math.inf


def released(lead: Lead | None, v_mps: float, braking_mps2: float) -> bool:
    """The danger is over: nothing ahead, or a lead no slower than the ego and not braking
    harder than ``braking_mps2``."""
    if lead is None:
        return True
    return lead.speed_mps >= v_mps - MATCHED_MPS and lead.accel_mps2 > -braking_mps2


class Response:
    """A reaction of ``delay_s`` at ``delay_accel_mps2``, then the deceleration rising from
    the reaction's at ``jerk_mps3`` to ``decel_mps2`` (as JRC-FSM ``CC_react``; each step's
    value at its middle, so that a step held constant integrates the ramp exactly), capped
    per step (the FSM's demand)."""

    def __init__(
        self, delay_s: float, delay_accel_mps2: float, jerk_mps3: float, decel_mps2: float
    ):
        self.delay_s, self.delay_accel = delay_s, delay_accel_mps2
        self.jerk, self.decel_max = jerk_mps3, decel_mps2
        self.start_s: float | None = None
        self.decel = 0.0
        self.cap = math.inf  # the last step's cap

    @property
    def active(self) -> bool:
        return self.start_s is not None

    def start(self, t_s: float) -> None:
        self.start_s, self.decel, self.cap = t_s, math.nan, math.inf

    def stop(self) -> None:
        self.start_s = None

    def preview(self, t_s: float, dt_s: float, ahead_s: float) -> float | None:
        """The acceleration ``ahead_s`` after this step's (``accel`` called first), the cap
        held; None when not responding. An actuator lagging by ``ahead_s`` commanded with it
        gives the car the profile itself (a first-order lag follows a ramp ``ahead_s`` late)."""
        if self.start_s is None:
            return None
        elapsed = t_s + ahead_s - self.start_s
        if elapsed < self.delay_s - 1e-9:
            return self.delay_accel
        if math.isnan(self.decel) or t_s - self.start_s < self.delay_s - 1e-9:
            into = elapsed - self.delay_s + 0.5 * dt_s  # the ramp's time at that step's middle
            decel = max(-self.delay_accel, 0.0) + self.jerk * into
        else:
            decel = self.decel + self.jerk * ahead_s
        return -min(decel, self.decel_max, self.cap)

    def accel(self, t_s: float, dt_s: float, cap_mps2: float = math.inf) -> float:
        """The acceleration over the step from ``t_s`` (negative: braking)."""
        assert self.start_s is not None
        if t_s - self.start_s < self.delay_s - 1e-9:
            return self.delay_accel
        step = self.jerk * dt_s
        if math.isnan(self.decel):  # the ramp's first step: from the reaction's deceleration
            rise = max(-self.delay_accel, 0.0) + 0.5 * step
        else:
            rise = self.decel + step
        self.cap = cap_mps2
        self.decel = min(rise, self.decel_max, cap_mps2)
        return -self.decel


def gate_response(
    resp: Response, t_s: float, unsafe: bool, lead: Lead | None, v_mps: float, braking_mps2: float
) -> str:
    """A safety-distance driver's response switched by its danger test (FSM, RSS): ``"off"``
    (no intervention; the response ends once ``released``), ``"hold"`` (stopped: hold the
    brake) or ``"on"`` (the response runs; started at the first unsafe step)."""
    if not resp.active:
        if not unsafe:
            return "off"
        resp.start(t_s)
    if v_mps < STOPPED_MPS:
        return "hold"
    if not unsafe and released(lead, v_mps, braking_mps2):
        resp.stop()
        return "off"
    return "on"
