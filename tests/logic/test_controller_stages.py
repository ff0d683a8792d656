"""The EOAM step's stages on their own, without SUMO: the DMM stage, the mode machine's
stage, the point-of-no-return rules and the rules chosen from the settings."""

import math
from dataclasses import replace

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from eoam_sumo.control import LongitudinalGains, equivalent_mass_kg
from eoam_sumo.control.brake_split import BrakeSplit
from eoam_sumo.decision import SECTOR_ORDER, Action, Mode, Sector, dmm_sector
from eoam_sumo.decision.obstacle import ObstacleDecel
from eoam_sumo.decision.policy import PolicySettings, SafePolicy
from eoam_sumo.eoam import EgoMeasurement, EoamController, EoamSettings, Perception
from eoam_sumo.eoam.decide import decide, sector_action
from eoam_sumo.eoam.parts import build_parts
from eoam_sumo.eoam.perceive import curve_stop_factor, friction_at
from eoam_sumo.eoam.state import ControllerState, Decision, Situation
from eoam_sumo.eoam.strategies import (
    ArrestFirst,
    BrakingObstaclePlacement,
    CompareOutcomes,
    LateralStopPonr,
    MinTimeEscapes,
    NextLaneGate,
    OffsetPonr,
    PaperPlacement,
    PonrCommit,
    QuinticEscapes,
    SafeGate,
    StableReturn,
    TimerReturn,
)
from eoam_sumo.eoam.transitions import advance_mode
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import AIR_DENSITY_KGPM3, PONR_FRACTION, ego_e_class_sedan
from eoam_sumo.sim.vehicle import vehicle_tables

P = ego_e_class_sedan()
LANE = 3.5
FIXTURE = [HealthCheck.function_scoped_fixture]  # the tables fixture is read-only
PAPER = EoamSettings(
    obstacle_decel_in_dmm=False,
    ponr_at_lateral_stop=False,
    compare_outcomes=False,
    min_time_escapes=False,
    return_when_stable=False,
)


@pytest.fixture(scope="module")
def tables():
    return LookupTables.load(default_tables_dir(), params=P)


def measurement(v=30.0, d=0.0, e_yaw=0.0, mu=1.0, left_lane=True, t=0.0, s=0.0):
    return EgoMeasurement(t, v, 0.0, 0.0, 0.0, 0.0, s, d, e_yaw, 0.0, mu, LANE, left_lane)


def stage_inputs(tables, st_=None, mu=1.0, mode=Mode.NORMAL):
    parts = build_parts(P, tables, st_ or EoamSettings())
    state = ControllerState(ObstacleDecel(), 30.0, mode=mode)
    state.friction = friction_at(parts, mu)
    return parts, state


def stop_scale(tables, mu):
    """How much longer limit braking stops than the tables' B0 says where the wheel-lock cap binds
    (``control.brake_split``: straight, slow, 0.95 of the lock command, no ABS)."""
    p = tables.params
    eq33 = equivalent_mass_kg(p) * tables.limit_brake_decel_mps2(mu)
    rolling = p.rolling_resistance_coeff * p.mass_kg * 9.81
    drag = 0.5 * AIR_DENSITY_KGPM3 * p.drag_area_m2  # at 1 m/s, as the controller takes it
    lock = BrakeSplit(p).limit_n(mu, 0.0, rolling + drag, 0.0, equivalent_mass_kg(p))
    return eq33 / min(eq33, LongitudinalGains().wheel_lock_fraction * lock)


def boundaries_at(tables, mu, closing_mps):
    """The tables' boundaries with B0 and Bb lengthened by ``stop_scale``."""
    b = tables.boundaries.at(mu, closing_mps)
    longer = b.stop_m * (stop_scale(tables, mu) - 1.0)
    return b._replace(stop_m=b.stop_m + longer, stop_buffered_m=b.stop_buffered_m + longer)


def near_a_boundary(tables, mu, range_m, closing_mps, tol_m=1e-6):
    b = boundaries_at(tables, mu, closing_mps)
    lines = (b.clear_opt_m, b.clear_buffered_m, b.stop_m, b.stop_buffered_m, b.ttc_s * closing_mps)
    return any(abs(range_m - x) <= tol_m for x in lines)


@settings(max_examples=300, deadline=None, suppress_health_check=FIXTURE)
@given(
    mu=st.sampled_from([0.3, 0.5, 0.8, 1.0]),
    closing=st.floats(0.5, 45.0),
    obstacle_speed=st.floats(0.0, 20.0),
    range_m=st.floats(0.0, 250.0),
    paper=st.booleans(),
)
def test_dmm_stage_places_a_steady_obstacle_in_the_tables_sector(
    tables, mu, closing, obstacle_speed, range_m, paper
):
    """An obstacle holding its speed is placed, by the paper's rule and by ours alike, in the
    sector of (range, closing speed) of the tables' own boundaries at that closing speed."""
    if near_a_boundary(tables, mu, range_m, closing):
        return
    parts, state = stage_inputs(tables, PAPER if paper else None, mu)
    meas = measurement(v=closing + obstacle_speed, mu=mu)
    situation = Situation(range_m, closing, 0.0, False, False, False)
    sector, action = sector_action(parts, state, meas, situation)
    expected = dmm_sector(boundaries_at(tables, mu, closing), range_m, closing)
    assert sector is expected
    if expected.action is not Action.STEER or meas.vx_mps < EoamSettings().min_steer_speed_mps:
        assert action is (Action.BRAKE if expected.action is Action.STEER else expected.action)
    else:
        assert action is Action.STEER
        no_lane = sector_action(parts, state, meas._replace(left_lane_available=False), situation)
        assert no_lane == (sector, Action.LIMIT_BRAKE)  # no lane to change into
        base = PAPER if paper else EoamSettings()
        aeb, aeb_state = stage_inputs(tables, replace(base, steering_inhibited=True), mu)
        # steering inhibited (an AEB): the same sector brakes at the limit in lane
        assert sector_action(aeb, aeb_state, meas, situation) == (sector, Action.LIMIT_BRAKE)


@settings(max_examples=200, deadline=None, suppress_health_check=FIXTURE)
@given(
    closing=st.floats(1.0, 40.0),
    range_m=st.floats(1.0, 150.0),
    decel=st.floats(0.0, 10.0),
)
def test_a_braking_obstacle_is_never_less_urgent_than_the_papers_sector(
    tables, closing, range_m, decel
):
    """Where its measured braking stops the obstacle (ours) the sector is the paper's or a
    more urgent one, never a less urgent one."""
    _parts, state = stage_inputs(tables)
    curve = state.friction.curve
    v = closing + 10.0
    a_ego = state.friction.brake_decel_mps2
    paper = PaperPlacement().place(curve, range_m, closing, v, decel, a_ego)[0]
    ours, stop_range = BrakingObstaclePlacement().place(curve, range_m, closing, v, decel, a_ego)
    assert SECTOR_ORDER.index(ours) <= SECTOR_ORDER.index(paper)
    if decel > 0.0:
        assert stop_range == pytest.approx(range_m + 100.0 / (2.0 * decel))


def test_nothing_in_the_path_is_no_sector_and_no_action(tables):
    parts, state = stage_inputs(tables)
    situation = Situation(None, 0.0, 0.0, True, False, False)
    decision = decide(parts, state, measurement(), Perception(), situation)
    assert decision == Decision(None, Action.NONE, False)
    near = decide(parts, state, measurement(), Perception(), situation._replace(coasted_near=True))
    assert near.action is Action.BRAKE  # a coasted object within the stopping distance


@settings(max_examples=100, deadline=None, suppress_health_check=FIXTURE)
@given(
    action=st.sampled_from([Action.NONE, Action.FCW]),
    oncoming=st.booleans(),
    d=st.floats(-1.0, 1.0),
    e_yaw=st.floats(-0.2, 0.2),
    t=st.floats(0.0, 100.0),
    paper=st.booleans(),
)
def test_the_mode_stage_never_leaves_normal_without_a_threat(
    tables, action, oncoming, d, e_yaw, t, paper
):
    """Without a braking or steering sector (nothing in the path, or a warning only) the
    mode machine stays in NORMAL, oncoming traffic or not, and begins no manoeuvre."""
    parts, state = stage_inputs(tables, PAPER if paper else None)
    meas = measurement(d=d, e_yaw=e_yaw, t=t)
    sector = None if action is Action.NONE else Sector.E
    advance_mode(parts, state, meas, Perception(), Decision(sector, action, oncoming), True)
    assert state.mode is Mode.NORMAL and state.path is None and state.modes_visited == [0]


def test_the_mode_stage_enters_a_lane_change_on_steer(tables):
    parts, state = stage_inputs(tables)
    meas = measurement(t=1.5, s=40.0, d=0.1)
    advance_mode(parts, state, meas, Perception(), Decision(Sector.F, Action.STEER, False), False)
    assert state.mode is Mode.UPDATE_STEER_BRAKE and state.modes_visited == [0, 2]
    assert (state.t_steer_s, state.s0_m, state.height_m) == (1.5, 40.0, LANE)
    assert state.path.at(0.0).y_m == pytest.approx(0.1)  # from where the ego is
    assert state.path.at(state.path.length_m).y_m == pytest.approx(0.1 + LANE)


@pytest.mark.parametrize("travel_m", [0.5, 1.0, 1.1, 2.0])
def test_point_of_no_return_rules(tables, travel_m):
    """The paper's: the offset reached is ponr_fraction of the lane change's height. Ours
    judges where the lateral motion would stop: moving outwards, it is past sooner; moving
    along the road (no lateral speed), where it is."""
    st_ = EoamSettings()
    state = ControllerState(ObstacleDecel())
    still = measurement(d=travel_m)
    outwards = measurement(d=travel_m, e_yaw=0.05)  # 1.5 m/s to the left
    paper = OffsetPonr(st_).past(state, still, travel_m, LANE)
    assert paper is (travel_m >= PONR_FRACTION * LANE) and state.stop_path is None
    ours = LateralStopPonr(st_)
    assert ours.past(state, still, travel_m, LANE) is paper
    assert state.stop_path.y1_m == pytest.approx(travel_m, abs=0.01)  # bisected to 1 cm
    past = ours.past(state, outwards, travel_m, LANE)
    v_lat, accel = 30.0 * math.sin(0.05), st_.evasive_lateral_g * 9.81
    # beyond what the reaction time and a constant-deceleration stop cover
    beyond_m = v_lat * st_.lateral_reaction_s + v_lat * v_lat / (2.0 * accel)
    assert state.stop_path.y1_m >= travel_m + beyond_m - 1e-6
    assert past is (state.stop_path.y1_m >= PONR_FRACTION * LANE)
    assert past or not paper


def test_strategies_are_chosen_from_the_settings(tables):
    ours = build_parts(P, tables, EoamSettings())
    assert type(ours.placement) is BrakingObstaclePlacement
    assert type(ours.commit) is CompareOutcomes and type(ours.commit.ponr) is LateralStopPonr
    assert type(ours.escapes) is ArrestFirst
    assert type(ours.return_rule) is StableReturn
    assert type(ours.gate) is NextLaneGate and ours.gate.policy is None
    paper = build_parts(P, tables, PAPER)
    assert type(paper.placement) is PaperPlacement
    assert type(paper.commit) is PonrCommit and type(paper.commit.ponr) is OffsetPonr
    assert type(paper.escapes) is QuinticEscapes
    assert type(paper.return_rule) is TimerReturn
    no_arrest = build_parts(P, tables, EoamSettings(arrest_first=False))
    assert type(no_arrest.escapes) is MinTimeEscapes
    safe = EoamController(P, tables, EoamSettings(policy=PolicySettings(name="safe")))
    assert type(safe.parts.gate) is SafeGate and isinstance(safe.policy, SafePolicy)
    assert EoamController(P, tables).policy is None


def test_reset_starts_a_new_state_and_the_properties_read_it(tables):
    ctrl = EoamController(P, tables)
    ctrl.reset(20.0)
    before = ctrl.state
    ctrl.step(measurement(v=20.0), Perception(10.0, -20.0), 0.01)
    assert ctrl.mode is before.mode is Mode.UPDATE_BRAKE and ctrl.sector == before.sector
    assert ctrl.modes_visited == [0, 1] and ctrl.fcw_raised and ctrl.oncoming_choice is None
    ctrl.reset(20.0)
    assert ctrl.state is not before and ctrl.mode is Mode.NORMAL
    assert ctrl.modes_visited == [0] and not ctrl.fcw_raised and ctrl.sector == ""
    assert math.isfinite(ctrl.state.initial_speed_mps)


def _curve_factor(tables, params, kappa_1pm, speed_mps, mu=1.0):
    parts = build_parts(params, tables, EoamSettings())
    state = ControllerState(ObstacleDecel(), speed_mps)
    state.friction = friction_at(parts, mu)
    meas = EgoMeasurement(0.0, speed_mps, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, kappa_1pm, mu, LANE)
    return curve_stop_factor(parts, state, meas)


def test_on_a_curve_the_stopping_distance_grows_by_what_the_ellipse_takes():
    """With ABS (no wheel-lock cap) the brake limit on a curve of curvature k is the straight
    one times sqrt(1 - q^2), q = 1.1 k v^2 / (mu g) (``ellipse_margin``): stopping from V
    following the curve, s = int v dv / a(v) = B0 arcsin(x) / x with x = q(V)."""
    abs_params = replace(P, abs_fitted=True)
    abs_tables = vehicle_tables("sedan", abs_params)
    v, mu = 130 / 3.6, 1.0
    for radius in (600.0, 300.0):
        x = LongitudinalGains().ellipse_margin * v * v / radius / (mu * 9.81)
        factor = _curve_factor(abs_tables, abs_params, 1.0 / radius, v, mu)
        assert factor == pytest.approx(math.asin(x) / x, rel=2e-3)
    assert _curve_factor(abs_tables, abs_params, 0.0, v, mu) == 1.0


def test_without_abs_the_curve_factor_also_carries_the_wheel_lock_cap(tables):
    """Without ABS the inner wheels' lock (lateral load transfer) cuts the brake further on a
    curve: the factor is above the ellipse's alone, grows with the curvature, is 1 on a
    straight road (either turning direction the same), and on this 600 m curve at 130 km/h
    lengthens B0 by 7 % (6.3 m at 84 m), more than the 4.5 m a straight road's boundary left."""
    v = 130 / 3.6
    x = LongitudinalGains().ellipse_margin * v * v / 600.0 / 9.81
    f600 = _curve_factor(tables, P, 1.0 / 600.0, v)
    assert f600 > math.asin(x) / x
    assert _curve_factor(tables, P, -1.0 / 600.0, v) == f600
    assert (
        1.0
        < _curve_factor(tables, P, 1.0 / 2000.0, v)
        < f600
        < _curve_factor(tables, P, 1.0 / 400.0, v)
    )
    assert _curve_factor(tables, P, 0.0, v) == 1.0
    assert 1.05 < f600 < 1.10
