"""The perceive stage: the measurement checked, the friction's limits, the in-path obstacle
tracked, a coasted object and oncoming traffic (a ``Situation`` for the DMM stage)."""

from __future__ import annotations

import math

from eoam_sumo.control.longitudinal import equivalent_mass_kg
from eoam_sumo.decision.dmm import BoundaryCurve
from eoam_sumo.decision.modes import (
    NORMAL,
    ONCOMING_STEER_BRAKE,
    UPDATE_BRAKE,
    UPDATE_STEER_BRAKE,
)
from eoam_sumo.decision.obstacle import ObstacleTrack
from eoam_sumo.eoam.parts import Parts
from eoam_sumo.eoam.state import ControllerState, Friction, Situation
from eoam_sumo.eoam_messages import EgoMeasurement, ObjectState, Perception

_STEERING = (UPDATE_STEER_BRAKE, ONCOMING_STEER_BRAKE)  # a lane change follows one obstacle
_HOLDING = (NORMAL, UPDATE_BRAKE)  # a coasted object keeps these braking (track persistence)


def perceive(
    parts: Parts, state: ControllerState, meas: EgoMeasurement, perception: Perception
) -> Situation:
    """The step's view of the obstacle and the next lane (updates the friction record, the
    obstacle's braking estimate and its track)."""
    check_measurement(state, meas)
    if state.friction is None or meas.mu != state.friction.mu:
        state.friction = friction_at(parts, meas.mu)
    lane_mu = meas.mu_lane if meas.mu_lane > 0.0 else meas.mu
    if lane_mu == meas.mu:
        state.lane_friction = state.friction
    elif state.lane_friction is None or lane_mu != state.lane_friction.mu:
        state.lane_friction = friction_at(parts, lane_mu)
    state.friction.curve.lateral_stop_factor = curve_stop_factor(parts, state, meas)
    rng = perception.aro_range_m
    rate = perception.aro_range_rate_mps
    sensed: float | None = None
    closing = decel = 0.0
    threat_gone = True
    if rng is not None and math.isfinite(rng):
        sensed = rng
        closing = -rate if rate is not None and math.isfinite(rate) else 0.0
        decel = state.obstacle_decel.update(meas.time_s, meas.vx_mps - closing)
        threat_gone = closing < -parts.settings.release_opening_speed_mps
        track_obstacle(parts, state, meas, rng, closing, perception.aro_object, decel)
    else:
        state.obstacle_decel.reset()
    near, holds = coasted_object(parts, state, meas, perception)
    if holds:
        threat_gone = False
    return Situation(sensed, closing, decel, threat_gone, near, oncoming_seen(parts, perception))


def check_measurement(state: ControllerState, meas: EgoMeasurement) -> None:
    """Refuse a step before ``reset`` or with a non-finite measurement."""
    if math.isnan(state.initial_speed_mps):
        raise ValueError("EoamController.reset(initial_speed_mps) must be called first")
    if not math.isfinite(sum(meas)):  # a NaN or inf field (or finite fields overflowing)
        for name, value in zip(EgoMeasurement._fields, meas):
            if not math.isfinite(value):
                raise ValueError(f"ego measurement {name}={value!r} is not finite")
    if not meas.lane_width_m > 0.0:
        raise ValueError(f"lane_width_m={meas.lane_width_m!r} must be > 0")


#: The speed at which the DMM's stopping distance takes the no-lock cap (drag ~0) [m/s].
_SLOW_MPS = 1.0


def friction_at(parts: Parts, mu: float) -> Friction:
    """The limit braking force, the deceleration it delivers and the DMM boundaries at the
    sensed friction. The command is the tables' limit braking deceleration (whose stopping
    distance is their B0, eq. 33) times ``equivalent_mass_kg`` (the wheels spin down with the
    car), so B0 and Bb are the tables' own, lengthened only by as much as the wheel-lock cap
    (``wheel_lock_limit_n``, no ABS) takes off it on a straight road."""
    if not mu > 0.0:
        raise ValueError(f"friction mu={mu!r} must be > 0")
    m_eq = equivalent_mass_kg(parts.params)
    brake_limit = m_eq * float(parts.tables.limit_brake_decel_mps2(mu))
    # straight, slow (no drag): what the wheel-lock cap leaves of limit braking
    straight = min(brake_limit, parts.longitudinal.wheel_lock_limit_n(_SLOW_MPS, mu, 0.0))
    bounds = parts.tables.boundaries
    curve = BoundaryCurve(bounds, mu, bounds.speed_grid_mps, stop_scale=brake_limit / straight)
    return Friction(mu, brake_limit, brake_limit / m_eq, curve)


#: Below this lateral acceleration of the road's curve the boundaries stay a straight road's
#: [m/s^2] (a 6 km radius at 20 m/s; the ellipse then costs under 0.1 % of the braking).
_CURVE_MIN_MPS2 = 0.05
#: Midpoints in v^2 of the stopping integral on a curve; the factor's cap (a curve taking the
#: whole ellipse leaves no braking: the boundaries are then far beyond any range).
_CURVE_SAMPLES = 8
_CURVE_FACTOR_CAP = 10.0


def curve_stop_factor(parts: Parts, state: ControllerState, meas: EgoMeasurement) -> float:
    """How much longer limit braking stops on the road's curve than on a straight road, from
    the ego's speed V to a standstill following the curve (curvature k): the brake limit the
    longitudinal stage applies (``LongitudinalController.limits``: the friction ellipse at
    the lateral acceleration k v^2 and, without ABS, the wheel-lock cap) integrated as
    s = 1/2 int_0^{V^2} m_eq / F(v) d(v^2), against the same at k = 0 (paper eqs. 25, 28's
    ellipse; eq. 33 on a straight road). For a moving obstacle it is the same ratio (the ego
    slows less, so its lateral acceleration stays higher: a slight underestimate)."""
    kappa = abs(meas.road_curvature_1pm)
    v2 = meas.vx_mps * meas.vx_mps
    if kappa * v2 < _CURVE_MIN_MPS2:
        return 1.0
    limit_n = state.friction_now().brake_limit_n
    limits, mu = parts.longitudinal.limits, meas.mu
    curve_s = straight_s = 0.0
    for k in range(_CURVE_SAMPLES):
        u = (k + 0.5) / _CURVE_SAMPLES * v2
        speed = math.sqrt(u)
        brake_n = limits(speed, mu, kappa * u, limit_n)[1]
        if not brake_n > 0.0:
            return _CURVE_FACTOR_CAP
        curve_s += 1.0 / brake_n
        straight_s += 1.0 / limits(speed, mu, 0.0, limit_n)[1]
    return min(max(curve_s / straight_s, 1.0), _CURVE_FACTOR_CAP)


def track_obstacle(
    parts: Parts,
    state: ControllerState,
    meas: EgoMeasurement,
    range_m: float,
    closing_mps: float,
    obj: ObjectState | None,
    decel_mps2: float,
) -> None:
    """Remember the in-path obstacle's front station, speed and left edge (offset).

    From its object track when the sensor gives one; else from the range, an assumed
    length (``unknown_obstacle_length_m``) and a width filling its lane. During a lane
    change (modes 2, 4) only the obstacle being avoided is followed: one whose front is
    more than ``track_gate_m`` off the prediction is another object."""
    st = parts.settings
    track = ObstacleTrack.sensed(
        meas,
        parts.params.cg_to_front_bumper_m,
        range_m,
        closing_mps,
        obj,
        st.unknown_obstacle_length_m,
        parts.placement.track_decel_mps2(decel_mps2),
    )
    last = state.obstacle
    if (
        last is None
        or state.mode not in _STEERING
        or abs(track.front_s_m - last.at(meas.time_s)[0]) <= st.track_gate_m
    ):
        state.obstacle = track


def coasted_object(
    parts: Parts, state: ControllerState, meas: EgoMeasurement, perception: Perception
) -> tuple[bool, bool]:
    """(near, holds) for an object lost from view, predicted in the path, in modes 0 and 1:
    no hand-back while it does not pull away (holds); braking while it is within the
    stopping distance at the deceleration limit braking delivers, at the ego's speed or the
    closing speed (the larger), plus a margin (near)."""
    coasted_m = perception.coasted_range_m
    if coasted_m is None or state.mode not in _HOLDING:
        return False, False
    st = parts.settings
    closing = -perception.coasted_range_rate_mps
    vc = max(meas.vx_mps, closing)
    decel = state.friction_now().brake_decel_mps2
    near = coasted_m <= 0.5 * vc * vc / decel + st.coasted_margin_m
    return near, near or closing > -st.release_opening_speed_mps


def oncoming_seen(parts: Parts, perception: Perception) -> bool:
    """Oncoming traffic seen, or a standing car in the next lane within the obstacle's
    range plus ``next_lane_clear_m``: the lane change would end against it, as deadly."""
    block_m = perception.next_lane_obstacle_range_m
    rng = perception.aro_range_m
    if (
        block_m is not None
        and rng is not None
        and block_m <= rng + parts.settings.next_lane_clear_m
    ):
        return True
    return bool(perception.oncoming_detected)
