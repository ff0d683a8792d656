"""The lateral shifts the EOAM begins from the ego's lateral state (paper sec. 4.2, eqs. 7-13).

Each is a trajectory (``.at(dx)``, ``.length_m``) that ``transitions.start_path`` samples into
the active ``PathReference``.
"""

from __future__ import annotations

import math

from eoam_sumo.decision.obstacle import ObstacleTrack
from eoam_sumo.eoam_messages import EgoMeasurement
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.manoeuvre.lateral_state import course_state, lateral_state
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift
from eoam_sumo.params import G_MPS2, LANE_CHANGE_HEIGHT_M, WIDE_LANE_M, VehicleParams


def quintic_shift(
    settings: EoamSettings, target_m: float, meas: EgoMeasurement, lateral_g: float
) -> QuinticShift:
    """The shortest quintic from the ego's lateral state (offset, course, path curvature) to
    ``target_m`` within ``lateral_g`` mu g that does not pass it."""
    slope, kappa, speed = course_state(meas)
    return QuinticShift.for_lateral_accel(
        meas.d_m,
        slope,
        target_m,
        speed,
        lateral_g * meas.mu * G_MPS2,
        settings.return_min_length_m,
        kappa,
    )


def min_time_shift(
    settings: EoamSettings, target_m: float, meas: EgoMeasurement, lateral_g: float
) -> MinTimeShift:
    """The jerk-limited time-optimal shift to ``target_m`` within ``lateral_g`` mu g."""
    v_lat, a_lat, speed = lateral_state(meas)
    accel = lateral_g * meas.mu * G_MPS2
    return MinTimeShift(meas.d_m, v_lat, a_lat, target_m, speed, accel, settings.escape_ramp_s)


def lateral_stop(settings: EoamSettings, meas: EgoMeasurement) -> QuinticShift:
    """The quintic that arrests the ego's lateral motion soonest within ``evasive_lateral_g``
    mu g; it ends where the lateral motion stops."""
    slope, kappa, speed = course_state(meas)
    return QuinticShift.stopping(
        meas.d_m,
        slope,
        speed,
        settings.evasive_lateral_g * meas.mu * G_MPS2,
        settings.return_min_length_m,
        kappa,
        settings.lateral_reaction_s,
    )


def passing_offset_m(
    params: VehicleParams,
    settings: EoamSettings,
    obstacle: ObstacleTrack | None,
    meas: EgoMeasurement,
    target_offset_m: float = 0.0,
) -> float:
    """Mode 4's target: just far enough left to pass the obstacle with ``side_clearance_m``
    (less exposure to the oncoming vehicle than a whole lane), at most to the target lane's
    centre (``target_offset_m``; 0: a lane width), and never back towards the obstacle from
    where the ego already is."""
    need = clearing_offset_m(params, settings, obstacle, meas)
    return max(min(need, target_offset_m or meas.lane_width_m), meas.d_m)


def clearing_offset_m(
    params: VehicleParams,
    settings: EoamSettings,
    obstacle: ObstacleTrack | None,
    meas: EgoMeasurement,
) -> float:
    """The ego's offset that clears the obstacle's box (its left side, or the ego's lane's
    edge without a track) by ``side_clearance_m``."""
    left_edge = obstacle.left_edge_m if obstacle is not None else 0.5 * meas.lane_width_m
    return left_edge + 0.5 * params.width_m + settings.side_clearance_m


def yawed_body_reach_m(params: VehicleParams, meas: EgoMeasurement) -> float:
    """How much nearer than half its width a corner of the ego's body comes to a road user
    alongside when the body is yawed against its course: a lane change's course straightens
    before its body does, which is then yawed towards what it passes by up to the rear
    axle's slip angle. That is bounded by the slip at which the rear tyres' linear force
    reaches their friction, beta = mu g m l_f / (C_r L) (single-track, the rear axle's load
    m g l_f / L), the corner half a length from the centre: 0.5 L |sin beta|."""
    l_f, l_r = params.cg_to_front_m, params.cg_to_rear_m
    rear_load_n = params.mass_kg * G_MPS2 * l_f / (l_f + l_r)
    beta = meas.mu * rear_load_n / params.cornering_stiffness_rear_npr
    return 0.5 * params.length_m * abs(math.sin(beta))


def lane_change_height_m(
    params: VehicleParams,
    settings: EoamSettings,
    obstacle: ObstacleTrack | None,
    meas: EgoMeasurement,
    target_offset_m: float = 0.0,
) -> float | None:
    """Mode 2's lateral travel: to the target lane's centre (``target_offset_m``; 0: a lane
    width), or farther where the obstacle reaches so far into the target lane that its centre
    does not clear it (``clearing_offset_m``) by the side clearance from the body's corner,
    yawed as a lane change's body ends (``yawed_body_reach_m``), as long as the ego's body,
    its other corner as far out, stays inside the target lane; None: no offset within it
    clears the obstacle (brake in lane). Where either lane is wider than ``WIDE_LANE_M`` the
    travel is the tables' ``LANE_CHANGE_HEIGHT_M``, or what clears the obstacle's track if
    more, up to the target lane's centre (a 28 m lane: a swerve, not a 28 m lane change)."""
    centre = target_offset_m or meas.lane_width_m
    target_width = 2.0 * centre - meas.lane_width_m  # centre to centre = half of both widths
    far_edge = centre + 0.5 * target_width
    reach = yawed_body_reach_m(params, meas)  # a front corner in, the rear one out
    need = clearing_offset_m(params, settings, obstacle, meas) + reach
    if max(meas.lane_width_m, target_width) > WIDE_LANE_M:
        if obstacle is None:  # no track: a lane this wide gives no edge to clear
            need = LANE_CHANGE_HEIGHT_M
        centre = min(centre, max(need, LANE_CHANGE_HEIGHT_M))
    if need <= centre:
        return centre
    if need + 0.5 * params.width_m + reach <= far_edge + 1e-9:
        return need
    return None
