"""The lateral stage: the active mode's reference (the lane centre unless a path is active)
and the steering command, feedforward + lookahead feedback + yaw damping (paper eq. 38)."""

from __future__ import annotations

import math
from typing import NamedTuple

from eoam_sumo.decision.modes import ONCOMING_BRAKE
from eoam_sumo.eoam.longitudinal import shares_ellipse
from eoam_sumo.eoam.parts import Parts
from eoam_sumo.eoam.state import ControllerState, LateralOutput
from eoam_sumo.eoam_messages import EgoMeasurement
from eoam_sumo.manoeuvre.angles import wrap_angle
from eoam_sumo.manoeuvre.path_reference import PathReference, retimed
from eoam_sumo.params import G_MPS2


class Reference(NamedTuple):
    """The path's reference at the ego's dx, relative to the road."""

    y_m: float
    yaw_rad: float
    curvature_1pm: float
    preview_curvature_1pm: float  # a preview ahead (0 with planned steering)
    ax_mps2: float
    speed_mps: float
    steer_ff_rad: float  # the plan's own road-wheel angle (planned steering)
    sideslip_rad: float | None  # the plan's body sideslip (None: steady-state)
    in_path: bool  # before the path's end
    planned: bool  # steered with the plan's road-wheel angle


_LANE_CENTRE = Reference(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, None, False, False)


def lateral_control(parts: Parts, state: ControllerState, meas: EgoMeasurement) -> LateralOutput:
    """The reference at the distance travelled on the active path and the steering command;
    while mode 3 arrests a lateral motion, the envelope's edge against it (no reference)."""
    path = state.path
    dx, rate = state.path_progress(meas)
    ref = reference(parts, path, meas, dx, rate)
    steer = parts.planned_steering if ref.planned else parts.steering
    v, d, mu = meas.vx_mps, meas.d_m, meas.mu
    if state.arrest:  # against the motion: the envelope's edge, or a turn the tyres sustain
        if parts.settings.arrest_lateral_g is None:
            delta = steer.envelope_edge(v, meas.yaw_rate_radps, meas.vy_mps, mu, -state.arrest)
        else:
            delta = arrest_steer(parts, meas, state.arrest, parts.settings.arrest_lateral_g)
        return LateralOutput(
            delta, d, dx, 0.0, 0.0, delta, 0.0, 0.0, ref.in_path, ref.ax_mps2, ref.speed_mps
        )
    road_kappa = meas.road_curvature_1pm
    e_lat = d - ref.y_m
    delta, ff, fb, yd, e_la = steer.command(
        v,
        meas.yaw_rate_radps,
        meas.vy_mps,
        e_lat,
        wrap_angle(meas.e_yaw_rad - ref.yaw_rad),
        ref.curvature_1pm + road_kappa,
        ref.preview_curvature_1pm + road_kappa,
        mu,
        ref.steer_ff_rad,
        ref.sideslip_rad,
    )
    if state.mode is ONCOMING_BRAKE and shares_ellipse(parts, state, meas):
        delta = steering_share(parts, steer, meas, delta)
    return LateralOutput(
        delta, ref.y_m, dx, e_lat, e_la, ff, fb, yd, ref.in_path, ref.ax_mps2, ref.speed_mps
    )


def arrest_steer(parts: Parts, meas: EgoMeasurement, arrest: float, lateral_g: float) -> float:
    """Mode 3's arrest of a lateral motion (``arrest``: its sign) along a turn against it at
    ``lateral_g`` mu g: the steady-state steer for that lateral acceleration plus the steering
    law's yaw-rate gain (eq. 38's k_r) on the error to its yaw rate a_y / v (<= mu g / v, what
    the tyres sustain at this speed), never past the front slip envelope's edge; the brake
    takes the friction ellipse's rest (``longitudinal.force_limits``)."""
    v = max(meas.vx_mps, parts.settings.limit_brake_floor_speed_mps)
    ay = -arrest * lateral_g * meas.mu * G_MPS2
    steer = parts.steering
    k_r = steer.gains_at(v, meas.mu)[1]
    r_target = ay / v + v * meas.road_curvature_1pm
    delta = steer.steer_for_lateral_accel(v, ay) - k_r * (meas.yaw_rate_radps - r_target)
    edge = steer.envelope_edge(v, meas.yaw_rate_radps, meas.vy_mps, meas.mu, -arrest)
    return max(delta, edge) if arrest > 0.0 else min(delta, edge)


def steering_share(parts: Parts, steer, meas: EgoMeasurement, delta_rad: float) -> float:
    """``delta_rad`` within the lateral share of the friction ellipse the brake's floor
    leaves, sqrt(1 - floor^2) of mu Fz over the ellipse margin (eqs. 25, 28), as the front
    tyres' slip about the body's own motion (``share_edges``): a sliding body is steered
    against its slide, not held at a steady-state angle that may push it further."""
    st = parts.settings
    share = math.sqrt(max(1.0 - st.limit_brake_floor * st.limit_brake_floor, 0.0))
    right, left = steer.share_edges(
        meas.vx_mps,
        meas.yaw_rate_radps,
        meas.vy_mps,
        meas.mu,
        share / st.longitudinal.ellipse_margin,
    )
    return max(right, min(left, delta_rad))


def reference(
    parts: Parts, path: PathReference | None, meas: EgoMeasurement, dx_m: float, rate: float = 1.0
) -> Reference:
    """The path at ``dx_m``: past its end its offset and profile, straight along the road; a
    planned lane change with its own steering taken the actuator's lag ahead, else the
    curvature ``preview_time_s`` ahead for the feedforward; a path laid out in time re-timed
    to the ego's speed (``rate``: ``PathReference.progress``)."""
    if path is None:
        return _LANE_CENTRE
    st = parts.settings
    v = meas.vx_mps
    y_ref, yaw_ref, kappa_ref, ax_ref, v_plan, _, beta_plan = retimed(path.at(dx_m), rate)
    if not dx_m < path.length_m:
        return Reference(y_ref, 0.0, 0.0, 0.0, ax_ref, v_plan, 0.0, None, False, False)
    if path.planned_steering:  # planned with the plant's tyre
        ahead = max(0.0, st.planned_preview_time_s - st.planned_preview_slope_s2pm * v)
        steer_ff = path.at(dx_m + v * ahead).steer_rad
        beta_ref = beta_plan + parts.steering.steady_sideslip(v, meas.road_curvature_1pm)
        return Reference(
            y_ref, yaw_ref, kappa_ref, 0.0, ax_ref, v_plan, steer_ff, beta_ref, True, True
        )
    kappa_ff = retimed(path.at(dx_m + rate * v * st.preview_time_s), rate).curvature_1pm
    return Reference(y_ref, yaw_ref, kappa_ref, kappa_ff, ax_ref, v_plan, 0.0, None, True, False)
