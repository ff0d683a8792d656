"""The longitudinal stage: the drive and brake force limits from the friction ellipse, then
the active mode's loop (speed PID, limit braking, or the manoeuvre's acceleration profile)."""

from __future__ import annotations

from eoam_sumo.decision.modes import (
    NORMAL,
    ONCOMING_BRAKE,
    ONCOMING_STEER_BRAKE,
    UPDATE_BRAKE,
    UPDATE_STEER_BRAKE,
)
from eoam_sumo.eoam.parts import Parts
from eoam_sumo.eoam.state import ControllerState, Friction, LateralOutput, LongitudinalOutput
from eoam_sumo.eoam_messages import EgoMeasurement
from eoam_sumo.params import G_MPS2

_STEERING = (UPDATE_STEER_BRAKE, ONCOMING_STEER_BRAKE)


def longitudinal_control(
    parts: Parts,
    state: ControllerState,
    meas: EgoMeasurement,
    lateral: LateralOutput,
    dt_s: float,
) -> LongitudinalOutput:
    """Mode 0 holds the set speed; 1 and 3 brake at the no-lock limit to standstill on the
    friction under the ego (``state.lane_friction``: a lane a lane change would take does not
    lower it); 2 and 4 follow the path's acceleration profile, then (like 5) hold the speed at
    its end."""
    mode, v, mu = state.mode, meas.vx_mps, meas.mu
    long = parts.longitudinal
    tracking = lateral.in_path and mode in _STEERING  # the table's ax already fits the ellipse
    braking = mode is UPDATE_BRAKE or mode is ONCOMING_BRAKE  # limit braking without locking
    lane = state.lane_friction if braking and state.lane_friction is not None else None
    drive_lim, brake_lim = force_limits(parts, state, meas, lateral.steer_rad, tracking, lane)
    if mode is NORMAL:
        target = following_speed_mps(parts, state, meas)
        drive, brake, ax_target = long.track_speed(target, v, mu, drive_lim, brake_lim, dt_s)
        return LongitudinalOutput(drive, brake, ax_target, target)
    if braking:
        if mode is ONCOMING_BRAKE and shares_ellipse(parts, state, meas):
            friction = lane or state.friction_now()
            floor = parts.settings.limit_brake_floor * friction.brake_limit_n
            # the brake has priority (the steering takes the ellipse's rest), below what
            # locks a wheel braking straight (only looked up when the floor would raise it)
            if not floor <= brake_lim:
                lock_n = long.wheel_lock_limit_n(v, friction.mu, 0.0)
                brake_lim = max(brake_lim, min(floor, lock_n))
        return LongitudinalOutput(0.0, brake_lim, -brake_lim / parts.params.mass_kg, 0.0)
    if tracking:
        drive, brake = long.track_accel(
            lateral.ax_ref_mps2, meas.ax_mps2, v, drive_lim, brake_lim, dt_s
        )
        return LongitudinalOutput(drive, brake, lateral.ax_ref_mps2, lateral.v_plan_mps)
    hold = state.hold_speed_mps
    if hold is None:  # the profile's end: hold the speed reached
        state.hold_speed_mps = hold = v
        long.reset()
    drive, brake, ax_target = long.track_speed(hold, v, mu, drive_lim, brake_lim, dt_s)
    return LongitudinalOutput(drive, brake, ax_target, hold)


#: Mode 0 after mode 3 let a moving obstacle go: the time gap kept behind it, and the time in
#: which a gap error is closed. The project's assumptions: 1.8 s is the "half the
#: speedometer" rule of thumb (a gap of half the speed in km/h, in metres).
FOLLOW_GAP_S = 1.8
FOLLOW_CLOSE_S = 3.0
#: How long a track not sensed again is still followed [s]: then the set speed (it left the
#: path or the sensor); the project's choice, 1 s of radar cycles.
FOLLOW_TRACK_AGE_S = 1.0


def following_speed_mps(parts: Parts, state: ControllerState, meas: EgoMeasurement) -> float:
    """Mode 0's speed target: the set speed, or after mode 1 or 3 let a moving obstacle go
    (``state.following``), while it is still sensed (``FOLLOW_TRACK_AGE_S``), at most the
    obstacle's speed plus the gap error beyond ``FOLLOW_GAP_S`` of its speed, closed in
    ``FOLLOW_CLOSE_S`` (car-following: the object ahead sets the speed, no stop-and-go
    behind a road user that drives on slower than the set speed)."""
    target = state.initial_speed_mps
    obstacle = state.obstacle
    if (
        not state.following
        or obstacle is None
        or meas.time_s - obstacle.time_s > FOLLOW_TRACK_AGE_S
    ):
        return target
    front_s, v_obs = obstacle.at(meas.time_s)
    gap = front_s - obstacle.length_m - meas.s_m - parts.params.cg_to_front_bumper_m
    return min(target, max(v_obs + (gap - FOLLOW_GAP_S * v_obs) / FOLLOW_CLOSE_S, 0.0))


def shares_ellipse(parts: Parts, state: ControllerState, meas: EgoMeasurement) -> bool:
    """Mode 3 above ``limit_brake_floor_speed_mps`` with the ego's body inside its own lane
    (a lateral correction, not an escape from the next lane, nor an arrest, nor the return
    mode 5 began, whose path keeps the ellipse's share it was laid out with): the brake keeps
    ``limit_brake_floor`` of the limit, the steering the rest of the friction ellipse (paper
    eqs. 25, 28: (Fx / mu Fz)^2 + (Fy / mu Fz)^2 <= 1)."""
    st = parts.settings
    return (
        st.limit_brake_floor > 0.0
        and not state.arrest
        and not state.braking_return
        and meas.vx_mps > st.limit_brake_floor_speed_mps
        and abs(meas.d_m) + 0.5 * parts.params.width_m <= 0.5 * meas.lane_width_m
    )


def force_limits(
    parts: Parts,
    state: ControllerState,
    meas: EgoMeasurement,
    steer_rad: float,
    tracking: bool,
    friction: Friction | None = None,
) -> tuple[float, float]:
    """(drive, brake) limits from the friction ellipse with the lateral acceleration in use:
    measured, and outside the table's profile also the one this steering command asks for,
    so that the brake yields before a turning axle locks; on ``friction`` (None: the
    believed one, ``meas.mu``)."""
    friction = friction or state.friction_now()
    ay_use = lateral_use_mps2(parts, meas, steer_rad, tracking)
    arrest_g = parts.settings.arrest_lateral_g
    if state.arrest and arrest_g is not None:  # the arrest's lateral share kept for it
        ay_use = max(ay_use, arrest_g * meas.mu * G_MPS2)
    return parts.longitudinal.limits(meas.vx_mps, friction.mu, ay_use, friction.brake_limit_n)


def lateral_use_mps2(parts: Parts, meas: EgoMeasurement, steer_rad: float, tracking: bool) -> float:
    """|a_y| the brake limits leave friction for: measured, and outside the table's profile
    also the one this steering command asks for."""
    ay_use = abs(meas.ay_mps2)
    if not tracking:
        ay_use = max(ay_use, abs(parts.steering.lateral_accel(meas.vx_mps, steer_rad)))
    return ay_use
