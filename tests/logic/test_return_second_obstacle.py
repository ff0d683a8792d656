"""Mode 5 (the return, paper sec. 3.2) with a second obstacle in the lane the ego returns to:
the DMM's braking is acted on (mode 3, limit braking while the return ends on its path), the
obstacle the lane change steered around is not a second one (the paper's mode 5)."""

import pytest

from eoam_sumo.decision import Mode
from eoam_sumo.decision.dmm import BRAKE, FCW, LIMIT_BRAKE, NONE, STEER
from eoam_sumo.decision.modes import next_mode
from eoam_sumo.decision.obstacle import ObstacleDecel, ObstacleTrack
from eoam_sumo.eoam import EoamSettings, ObjectState
from eoam_sumo.eoam.state import ControllerState
from tests.logic.test_mode_transitions import (
    LANE,
    P,
    range_in,
    start_steer,
    tables,  # noqa: F401 (the module's fixture)
)


def events(**changes):
    """The mode machine's events in mode 5 after a lane change, nothing else happening."""
    names = ("oncoming", "past_ponr", "timer_expired", "stable_in_next_lane")
    names += ("clear_of_obstacle", "settled", "threat_gone", "another_obstacle")
    return dict.fromkeys(names, False) | changes


@pytest.mark.parametrize("action", [BRAKE, LIMIT_BRAKE, STEER])
def test_a_second_obstacle_asking_for_action_turns_the_return_into_limit_braking(action):
    assert next_mode(Mode.RETURN, action, **events(another_obstacle=True)) is Mode.ONCOMING_BRAKE
    # with oncoming traffic seen, or settled in the lane, the same
    for extra in ({"oncoming": True}, {"settled": True}):
        new = next_mode(Mode.RETURN, action, **events(another_obstacle=True, **extra))
        assert new is Mode.ONCOMING_BRAKE


@pytest.mark.parametrize("action", [NONE, FCW])
def test_a_warning_or_nothing_keeps_the_papers_return(action):
    assert next_mode(Mode.RETURN, action, **events(another_obstacle=True)) is Mode.RETURN
    assert next_mode(Mode.RETURN, action, **events(settled=True)) is Mode.NORMAL


def test_the_obstacle_steered_around_keeps_the_papers_return():
    """Mode 4 returns before its obstacle is passed (the return keeps clear of it): still
    sensed ahead in sector A, it is no reason to brake."""
    assert next_mode(Mode.RETURN, LIMIT_BRAKE, **events()) is Mode.RETURN
    assert next_mode(Mode.RETURN, LIMIT_BRAKE, **events(settled=True)) is Mode.NORMAL


def test_mode_4_hands_over_through_the_return():
    new = next_mode(
        Mode.ONCOMING_STEER_BRAKE, BRAKE, **events(clear_of_obstacle=True, another_obstacle=True)
    )
    assert new is Mode.RETURN


def _state(sensed, avoided):
    state = ControllerState(ObstacleDecel(0.1), 30.0)
    state.obstacle, state.avoided = sensed, avoided
    return state


def test_another_obstacle_is_judged_by_the_lane_changes_track_gate(tables):  # noqa: F811
    from eoam_sumo.eoam.parts import build_parts
    from eoam_sumo.eoam.transitions import another_obstacle

    parts = build_parts(P, tables, EoamSettings())
    gate = EoamSettings().track_gate_m
    # the van steered around, braking from 10 m/s at 4 m/s^2: front at 112.5 m 2.5 s later
    van = ObstacleTrack(0.0, 100.0, 10.0, 1.0, 4.0, 5.0)
    same = ObstacleTrack(2.5, 112.5 + 0.8 * gate, 0.0, 1.0, 0.0, 5.0)
    second = ObstacleTrack(2.5, 112.5 + 1.2 * gate, 0.0, 1.0, 0.0, 5.0)
    assert not another_obstacle(parts, _state(same, van))
    assert another_obstacle(parts, _state(second, van))
    assert another_obstacle(parts, _state(second, None))  # no track steered around
    assert not another_obstacle(parts, _state(None, van))  # nothing sensed


def test_return_brakes_for_a_second_obstacle_on_its_own_path(tables):  # noqa: F811
    """In mode 5 a standing car in sector D far beyond the first obstacle: mode 3 at once,
    braking at the limit (drive off) while the return goes on along its path, not a new
    shift (the lateral reference continues where it was)."""
    drive = start_steer(tables)
    while drive.mode is not Mode.RETURN:
        drive.step(d_m=LANE)
    for _ in range(50):
        drive.step(d_m=drive.cmd.y_target_m)
    path, y_before, dx_before = drive.ctrl.state.path, drive.cmd.y_target_m, drive.cmd.dx_m
    rng = range_in(tables, 1.0, drive.v, "D")
    centre = drive.s + P.cg_to_front_bumper_m + rng + 2.5
    drive.step(range_m=rng, d_m=y_before, obj=ObjectState(centre, 0.0, 0.0, 5.0, 1.9))
    assert drive.mode is Mode.ONCOMING_BRAKE
    assert drive.ctrl.modes_visited == [0, 2, 5, 3]
    assert drive.ctrl.state.path is path  # the return's own path, followed on
    assert drive.cmd.dx_m > dx_before
    assert abs(drive.cmd.y_target_m - y_before) < 0.05
    assert drive.cmd.drive_force_cmd_n == 0.0
    # terminal: on after the obstacle left the view, the return ending, then the whole limit
    # (the synthetic ego's heading stays the road's: its steering takes the ellipse until then)
    for _ in range(300):
        drive.step(d_m=drive.cmd.y_target_m)
    assert drive.mode is Mode.ONCOMING_BRAKE and drive.cmd.y_target_m == pytest.approx(0.0)
    limit = drive.ctrl.state.friction_now().brake_limit_n
    assert drive.cmd.brake_force_cmd_n == pytest.approx(limit, rel=0.02)


def test_the_return_keeps_its_share_of_the_ellipse(tables):  # noqa: F811
    """Mode 3's brake floor (the brake first, the steering the rest) is for corrections in
    the lane: the return mode 5 began keeps the lateral share it was laid out with, up to
    0.9 mu g when urgent, and the brake takes what it leaves."""
    from eoam_sumo.eoam import EgoMeasurement
    from eoam_sumo.eoam.longitudinal import shares_ellipse
    from eoam_sumo.eoam.parts import build_parts

    parts = build_parts(P, tables, EoamSettings())
    meas = EgoMeasurement(0.0, 30.0, 0, 0, 0, 0, 0, 0.2, 0, 0, 1.0, LANE)  # inside its lane
    state = _state(None, None)
    state.mode = Mode.ONCOMING_BRAKE
    assert shares_ellipse(parts, state, meas)
    state.braking_return = True
    assert not shares_ellipse(parts, state, meas)
