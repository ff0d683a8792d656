"""The mode-machine stage: the events of this step, ``decision.modes.next_mode``, and the
entry actions of a new mode or the path restarts within one (paper sec. 3.1-3.2, 8.1)."""

from __future__ import annotations

from eoam_sumo.decision.modes import (
    NORMAL,
    ONCOMING_BRAKE,
    ONCOMING_STEER_BRAKE,
    RETURN,
    UPDATE_BRAKE,
    UPDATE_STEER_BRAKE,
    Mode,
    next_mode,
)
from eoam_sumo.eoam.parts import Parts
from eoam_sumo.eoam.shifts import lane_change_height_m, passing_offset_m, quintic_shift
from eoam_sumo.eoam.state import ControllerState, Decision
from eoam_sumo.eoam.strategies import beside_obstacle, heading_settled
from eoam_sumo.eoam_messages import EgoMeasurement, Perception
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift
from eoam_sumo.manoeuvre.path_reference import PathReference

_STEERING = (UPDATE_STEER_BRAKE, ONCOMING_STEER_BRAKE)


def advance_mode(
    parts: Parts,
    state: ControllerState,
    meas: EgoMeasurement,
    perception: Perception,
    decision: Decision,
    threat_gone: bool,
) -> None:
    """At most one transition; a new mode's entry actions, else the current mode's path
    restarts (an urgent return, mode 3's next shift)."""
    mode, path = state.mode, state.path
    dx = state.path_progress(meas)[0]
    settled = settled_in_lane(parts, state, meas, path, dx)
    clear = mode in _STEERING and clear_of_obstacle(parts, state, meas, path, dx)  # 2, 4
    stable = (
        clear and path is not None and parts.return_rule.stable_in_next_lane(state, meas, path, dx)
    )
    oncoming = decision.oncoming
    past_ponr = (
        oncoming and mode is UPDATE_STEER_BRAKE and passes_on(parts, state, meas, perception)
    )
    new = next_mode(
        mode,
        decision.action,
        oncoming=oncoming,
        past_ponr=past_ponr,
        timer_expired=meas.time_s - state.t_steer_s >= parts.settings.manoeuvre_time_s - 1e-9
        and not beside_obstacle(parts.settings, parts.params, state, meas),
        stable_in_next_lane=stable,
        clear_of_obstacle=clear,
        settled=settled,
        threat_gone=threat_gone and (mode is not ONCOMING_BRAKE or released(parts, meas, decision)),
        another_obstacle=mode is RETURN and another_obstacle(parts, state),
    )
    if new is not mode:
        enter(parts, state, new, meas)
    elif mode is RETURN or state.braking_return:
        if oncoming and not state.urgent_return:
            start_return(parts, state, meas, urgent=True)  # oncoming traffic seen meanwhile
    elif mode is ONCOMING_BRAKE:
        traj = parts.escapes.abort_next(state, meas, path, dx)
        if traj is not None:
            start_path(parts, state, meas, traj, None)


def released(parts: Parts, meas: EgoMeasurement, decision: Decision) -> bool:
    """Mode 3 may hand back (the obstacle pulls away): only with the obstacle still sensed
    in the path (not merely lost) and the ego in its lane and straight."""
    st = parts.settings
    return (
        decision.sector is not None
        and abs(meas.d_m) <= st.settle_offset_m
        and heading_settled(st, parts.steering, meas)
    )


def another_obstacle(parts: Parts, state: ControllerState) -> bool:
    """Mode 5: the obstacle sensed in the path is not the one modes 2 and 4 steered around
    (its front more than ``track_gate_m`` off that one's prediction, as the lane change's
    track gate judges it): a second obstacle in the lane the ego returns to."""
    sensed, avoided = state.obstacle, state.avoided
    if sensed is None or avoided is None:
        return sensed is not None
    return abs(sensed.front_s_m - avoided.at(sensed.time_s)[0]) > parts.settings.track_gate_m


def settled_in_lane(
    parts: Parts,
    state: ControllerState,
    meas: EgoMeasurement,
    path: PathReference | None,
    dx_m: float,
) -> bool:
    """Mode 5 after its path: within ``settle_offset_m`` of the lane centre and its heading
    settled (``heading_settled``: within ``settle_heading_rad`` of the road's, less the
    steady sideslip on a curve) for ``settle_dwell_s``."""
    if not (state.mode is RETURN and path is not None and dx_m >= path.length_m):
        return False
    st = parts.settings
    heading_ok = heading_settled(st, parts.steering, meas)
    if not (abs(meas.d_m) <= st.settle_offset_m and heading_ok):
        state.settle_since_s = None
        return False
    since = state.settle_since_s
    if since is None:
        state.settle_since_s = since = meas.time_s
    return meas.time_s - since >= st.settle_dwell_s - 1e-9


def clear_of_obstacle(
    parts: Parts,
    state: ControllerState,
    meas: EgoMeasurement,
    path: PathReference | None,
    dx_m: float,
) -> bool:
    """Modes 2 and 4: the "desired position", clear of the tracked obstacle
    (``parts.commit``); without a track, the end of the path."""
    obstacle = state.obstacle
    if obstacle is None:
        return path is not None and dx_m >= path.length_m
    return parts.commit.passed(state, meas, obstacle)


def passes_on(
    parts: Parts, state: ControllerState, meas: EgoMeasurement, perception: Perception
) -> bool:
    """Oncoming traffic in mode 2: pass on (mode 4) or abort (mode 3), as ``parts.commit``
    judges it, unless the policy's severity tie-breaker prefers braking in lane."""
    path = state.path
    travel = meas.d_m - path.start_offset_m if path is not None else 0.0
    if not parts.commit.commits(state, meas, perception, travel, state.height_m):
        return False
    return not parts.gate.prefer_braking(meas, perception)


def enter(parts: Parts, state: ControllerState, mode: Mode, meas: EgoMeasurement) -> None:
    """Entry actions of a new mode (mode 4 keeps the lane change of mode 2 going; mode 3
    from 5 keeps the return's path: limit braking while it ends in the lane, ours)."""
    previous = state.mode
    state.arrest = 0.0
    state.braking_return = mode is ONCOMING_BRAKE and previous is RETURN
    if mode is NORMAL and (
        previous is ONCOMING_BRAKE
        or (previous is UPDATE_BRAKE and parts.settings.follow_after_brake)
    ):
        state.following = True  # the obstacle drove on: follow it at a time gap
    if mode is UPDATE_STEER_BRAKE:  # the table lane change for the trigger speed and friction
        state.hold_speed_mps = None
        # to the target lane's centre: one lane width, or centre to centre
        height = lane_change_height_m(
            parts.params, parts.settings, state.obstacle, meas, state.target_offset_m
        )
        state.height_m = height = height or state.target_offset_m or meas.lane_width_m
        state.t_steer_s = meas.time_s
        traj = parts.tables.trajectory(meas.mu, meas.vx_mps)  # clamped to the speed grid
        start_path(parts, state, meas, traj, height)
    elif mode is RETURN:
        state.avoided = state.obstacle  # the track modes 2 and 4 followed
        state.hold_speed_mps = meas.vx_mps
        start_return(parts, state, meas, urgent=previous is ONCOMING_STEER_BRAKE)
    elif mode is ONCOMING_STEER_BRAKE:
        target = passing_offset_m(
            parts.params, parts.settings, state.obstacle, meas, state.target_offset_m
        )
        shift = parts.escapes.shift(target, meas, parts.settings.evasive_lateral_g)
        start_path(parts, state, meas, shift, None)
    elif state.braking_return:
        state.stop_path = None  # the return goes on, the brake takes what it leaves
    elif mode is ONCOMING_BRAKE:
        abort = parts.escapes.abort_path(state, meas)
        if abort is None:
            state.path = None  # the lateral motion is arrested first (no path)
        else:
            start_path(parts, state, meas, abort, None)
    else:
        state.path = None
        parts.longitudinal.reset()
    if int(mode) not in state.modes_visited:
        state.modes_visited.append(int(mode))
    state.mode = mode


def start_return(
    parts: Parts, state: ControllerState, meas: EgoMeasurement, *, urgent: bool
) -> None:
    """Mode 5's path back to the lane centre; urgent (oncoming traffic) an escape at the
    evasive lateral acceleration, else a quintic at the comfortable one."""
    st = parts.settings
    state.urgent_return = urgent
    if urgent:
        start_path(parts, state, meas, parts.escapes.shift(0.0, meas, st.evasive_lateral_g), None)
    else:
        start_path(parts, state, meas, quintic_shift(st, 0.0, meas, st.return_lateral_g), None)


def start_path(
    parts: Parts, state: ControllerState, meas: EgoMeasurement, traj, height_m: float | None
) -> None:
    """Follow ``traj`` from the ego's offset (by ``height_m``, or as it is when None); a
    time-optimal escape in time, at the pace it was laid out with."""
    state.path = PathReference(
        traj,
        start_offset_m=meas.d_m,
        height_m=height_m,
        speed_mps=meas.vx_mps,
        step_m=parts.settings.reference_step_m,
        pace_mps=traj.speed_mps if isinstance(traj, MinTimeShift) else None,
    )
    state.s0_m = meas.s_m
    state.t0_s = meas.time_s
    state.settle_since_s = None
    parts.longitudinal.reset()
