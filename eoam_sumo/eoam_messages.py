"""The per-step messages into and out of the EOAM module (``eoam.EoamController.step``),
as named tuples (immutable)."""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

if TYPE_CHECKING:
    from eoam_sumo.decision.policy import NextLaneView


class EgoMeasurement(NamedTuple):
    """Ego state in the road frame of its original lane (s along, d left of its centre)."""

    time_s: float
    vx_mps: float
    vy_mps: float
    yaw_rate_radps: float
    ax_mps2: float
    ay_mps2: float
    s_m: float
    d_m: float
    e_yaw_rad: float
    road_curvature_1pm: float
    mu: float
    lane_width_m: float
    left_lane_available: bool = True  # map: a lane (either direction) left of the ego's lane


class ObjectState(NamedTuple):
    """A tracked object in the road frame of the ego's original lane (a sensor's object list)."""

    s_m: float  # station of its centre
    d_m: float  # lateral offset of its centre, left positive
    speed_mps: float  # along the road
    length_m: float
    width_m: float


class Perception(NamedTuple):
    """Radar-derived view: the in-path obstacle (None when nothing) and oncoming traffic."""

    aro_range_m: float | None = None
    aro_range_rate_mps: float | None = None
    oncoming_detected: bool = False
    aro_object: ObjectState | None = None  # the in-path obstacle as an object, when tracked
    next_lane_obstacle_range_m: float | None = None  # nearest standing object in the next lane
    next_lane: NextLaneView | None = None  # what is known of the next lane (safe policy)
    # an in-path object the radar lost from view at close range, predicted at its last
    # velocity (a coasted track): its range and range rate now, or None
    coasted_range_m: float | None = None
    coasted_range_rate_mps: float = 0.0
    oncoming_object: ObjectState | None = None  # the nearest oncoming road user, when tracked


class Command(NamedTuple):
    """Actuator commands for the next step plus what the controller decided, for logging."""

    steer_cmd_rad: float
    drive_force_cmd_n: float
    brake_force_cmd_n: float
    mode: int
    fcw: bool
    sector: str
    ax_target_mps2: float
    y_target_m: float
    dx_m: float
    lateral_error_m: float
    lookahead_error_m: float
    steer_ff_rad: float
    steer_fb_rad: float
    steer_yd_rad: float
    speed_target_mps: float
