"""The DMM stage: the in-path obstacle's phase-diagram sector (paper sec. 5-6) and the action
the EOAM takes on it, with the next lane's state (a ``Decision`` for the mode machine)."""

from __future__ import annotations

from eoam_sumo.decision.dmm import BRAKE, LIMIT_BRAKE, NONE, STEER, Action, Sector
from eoam_sumo.decision.modes import NORMAL, RETURN, UPDATE_BRAKE, UPDATE_STEER_BRAKE
from eoam_sumo.eoam.parts import Parts
from eoam_sumo.eoam.shifts import lane_change_height_m
from eoam_sumo.eoam.state import ControllerState, Decision, Situation
from eoam_sumo.eoam_messages import EgoMeasurement, Perception

_COMMITTING = (NORMAL, UPDATE_BRAKE)  # a STEER here begins a lane change (policy gate)
_WATCHING = (UPDATE_STEER_BRAKE, RETURN)  # the policy watches the next lane


def decide(
    parts: Parts,
    state: ControllerState,
    meas: EgoMeasurement,
    perception: Perception,
    situation: Situation,
) -> Decision:
    """The sector, the action (a coasted object within the stopping distance brakes) and
    whether the next lane is closed (oncoming traffic, or the decision policy's checks)."""
    sector, action = sector_action(parts, state, meas, situation)
    if situation.coasted_near and action is NONE:
        action = BRAKE
    mode = state.mode
    committing = action is STEER and mode in _COMMITTING
    blocked = parts.gate.blocks(
        meas, perception, committing, mode in _WATCHING, situation.obstacle_decel_mps2
    )
    return Decision(sector, action, situation.oncoming or blocked)


def sector_action(
    parts: Parts, state: ControllerState, meas: EgoMeasurement, situation: Situation
) -> tuple[Sector | None, Action]:
    """The sector where ``parts.placement`` puts the obstacle (None: nothing in the path) and
    its action, a STEER turned into braking where a lane change is not wanted: too slow for
    one (``min_steer_speed_mps``), braking already stopping short of the obstacle (mode 1), no
    lane to change into, or steering inhibited (``steering_inhibited``: an AEB)."""
    rng = situation.range_m
    if rng is None:
        return None, NONE
    st = parts.settings
    friction = state.friction_now()
    curve = friction.curve
    v, closing = meas.vx_mps, situation.closing_mps
    # the speed-match rule trusts a settled estimate only (not the filter rising at an onset)
    ego_decel = friction.brake_decel_mps2 if state.obstacle_decel.settled() else 0.0
    sector, stop_range = parts.placement.place(
        curve, rng, closing, v, situation.obstacle_decel_mps2, ego_decel
    )
    action = sector.action
    if action is STEER:
        if v < st.min_steer_speed_mps:
            action = BRAKE  # too slow for a lane change: braking needs less room
        elif (
            state.mode is UPDATE_BRAKE
            and rng > curve.at(closing).stop_m
            and stop_range > curve.at(v).stop_m
        ):
            action = BRAKE  # braking already stops short of it: no lane change
        elif not meas.left_lane_available or st.steering_inhibited:
            action = LIMIT_BRAKE  # no lane to change into, or braking only: brake in lane
        elif (
            lane_change_height_m(parts.params, st, state.obstacle, meas, state.target_offset_m)
            is None
        ):
            action = LIMIT_BRAKE  # no offset within the target lane clears the obstacle
    return sector, action
