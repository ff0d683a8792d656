"""Evasion to either side: the lane the EOAM changes into, and the mirrored road
frame in which the step runs when that lane is the right one.

Every stage of the step (the DMM, the mode machine, the shifts, the point of no return, the
policy's checks) is written for a lane change to the left, d positive. Evading right, the step
sees the road mirrored about the ego's lane centre (d, course, yaw rate, lateral speed and
acceleration, road curvature and the obstacle's offset negated; the right lane's view as the
next lane) and its steering and lateral logs are mirrored back. The side is chosen while no
manoeuvre runs (modes 0 and 1) and held from the lane change until the hand-back.
"""

from __future__ import annotations

from eoam_sumo.decision.modes import NORMAL, UPDATE_BRAKE
from eoam_sumo.eoam.parts import Parts
from eoam_sumo.eoam.state import ControllerState
from eoam_sumo.eoam_messages import (
    ONCOMING,
    STANDING,
    Command,
    EgoMeasurement,
    NextLaneView,
    Perception,
    next_lane_motion,
)

LEFT = 1
RIGHT = -1
_CHOOSING = (NORMAL, UPDATE_BRAKE)  # no manoeuvre runs: the side may still change


def choose_side(
    parts: Parts, state: ControllerState, meas: EgoMeasurement, perception: Perception
) -> int:
    """The side of the lane change (held while a manoeuvre runs; module doc) and the lateral
    travel to the target lane's centre (``state.target_offset_m``, 0: a lane width)."""
    if state.mode not in _CHOOSING:
        return state.side
    side = LEFT
    right = perception.right_lane
    if right is not None and perception.aro_range_m is not None:
        side = open_side(parts, state, meas, perception, right)
    view = right if side == RIGHT else perception.next_lane
    state.side = side
    state.target_offset_m = lane_offset_m(meas.lane_width_m, view)
    return side


def open_side(
    parts: Parts,
    state: ControllerState,
    meas: EgoMeasurement,
    perception: Perception,
    right: NextLaneView,
) -> int:
    """The first side, left then right, whose lane the policy finds open for a lane change
    begun now (``SafePolicy.lane_reason``; the paper's policy judges the road users in it
    only, the safe policy the unseen road too); left when neither is open (the gate then
    refuses, the EOAM brakes in lane), right when there is no usable lane on the left."""
    judge = parts.side_judge
    decel = parts.placement.track_decel_mps2(state.obstacle_decel.decel_mps2)
    traffic_only = parts.settings.policy.name != "safe"
    options: list[tuple[int, NextLaneView | None]] = [(RIGHT, right)]
    if meas.left_lane_available:
        options.insert(0, (LEFT, perception.next_lane))
    for side, view in options:
        seen = meas if side == LEFT else right_friction(meas)
        _, reason = judge.lane_reason(seen, perception, view, decel, traffic_only)
        if not reason:
            return side
    return options[0][0]


def lane_offset_m(lane_width_m: float, view: NextLaneView | None) -> float:
    """Centre-to-centre distance from the ego's lane to the target lane (0: the same width,
    the lateral travel is one lane width)."""
    if view is None or not view.lane_width_m > 0.0 or view.lane_width_m == lane_width_m:
        return 0.0
    return 0.5 * (lane_width_m + view.lane_width_m)


def right_friction(meas: EgoMeasurement) -> EgoMeasurement:
    """``meas`` with the friction believed for a lane change to the right as ``mu`` (that to
    the left as ``mu_right``: swapped, so that doing it twice gives ``meas`` back)."""
    if not meas.mu_right > 0.0:  # none given: the same
        return meas
    return meas._replace(mu=meas.mu_right, mu_right=meas.mu)


def mirrored_measurement(meas: EgoMeasurement) -> EgoMeasurement:
    """The ego's state in the road frame mirrored about its lane centre (the right lane to
    its left, its friction the believed one: ``right_friction``)."""
    return right_friction(meas)._replace(
        vy_mps=-meas.vy_mps,
        yaw_rate_radps=-meas.yaw_rate_radps,
        ay_mps2=-meas.ay_mps2,
        d_m=-meas.d_m,
        e_yaw_rad=-meas.e_yaw_rad,
        road_curvature_1pm=-meas.road_curvature_1pm,
        left_lane_available=True,
    )


def mirrored_perception(perception: Perception) -> Perception:
    """The perception in the mirrored frame: the right lane's view as the next lane, its
    oncoming and standing road users (from that view: the whole lane, whatever its width; the
    classes of ``eoam_messages.next_lane_motion``, the radar's on the left), the obstacle's
    offset negated."""
    view = perception.right_lane
    obj = perception.aro_object
    oncoming, standing_m = False, None
    if view is not None:
        motions = [(gap, next_lane_motion(speed)) for gap, speed in view.users_ahead()]
        oncoming = any(motion == ONCOMING for _gap, motion in motions)
        standing = [gap for gap, motion in motions if motion == STANDING]
        standing_m = standing[0] if standing else None
    return perception._replace(
        aro_object=None if obj is None else obj._replace(d_m=-obj.d_m),
        oncoming_detected=oncoming,
        next_lane_obstacle_range_m=standing_m,
        next_lane=view,
        right_lane=perception.next_lane,
        oncoming_object=None,
    )


def mirrored_command(cmd: Command) -> Command:
    """The command of the mirrored step in the real frame (steering and lateral logs)."""
    return cmd._replace(
        steer_cmd_rad=-cmd.steer_cmd_rad,
        y_target_m=-cmd.y_target_m,
        lateral_error_m=-cmd.lateral_error_m,
        lookahead_error_m=-cmd.lookahead_error_m,
        steer_ff_rad=-cmd.steer_ff_rad,
        steer_fb_rad=-cmd.steer_fb_rad,
        steer_yd_rad=-cmd.steer_yd_rad,
    )
