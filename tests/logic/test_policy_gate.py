"""The safe policy's sight-distance gate, next-lane checks and severity tie-breaker, against
closed-form physics on the real lookup tables (no SUMO)."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.decision import Mode
from eoam_sumo.decision.policy import (
    PolicySettings,
    SafePolicy,
    beside_time_s,
    braking_impact_speed_mps,
    escape_time_s,
    follower_keeps_distance,
    lane_change_time_s,
    road_user_travel_m,
    sight_needed,
)
from eoam_sumo.eoam import EgoMeasurement, EoamController, EoamSettings, ObjectState, Perception
from eoam_sumo.eoam_messages import NextLaneView
from eoam_sumo.manoeuvre.points import TrajectoryPoint
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import G_MPS2, ego_e_class_sedan

P = ego_e_class_sedan()
LANE = 3.5


@pytest.fixture(scope="module")
def tables():
    return LookupTables.load(default_tables_dir(), params=P)


class _Flat:
    """A trajectory with no acceleration: the lane change at constant speed."""

    length_m = 80.0

    def at(self, dx_m):
        return TrajectoryPoint(0.0, 0.0, 0.0, 0.0, 0.0)


def _need(tables, **kw):
    args = {
        "speed_mps": 30.0,
        "mu": 1.0,
        "opposing_speed_mps": 20.0,
        "trajectory": tables.trajectory(1.0, 30.0),
        "gap_m": 40.0,
        "obstacle_speed_mps": 0.0,
        "obstacle_length_m": 5.09,
        "ego_length_m": P.length_m,
        "ego_width_m": P.width_m,
        "lane_width_m": LANE,
        "pass_margin_m": 1.0,
        "return_lateral_g": 0.3,
        "return_min_length_m": 10.0,
        "margin_s": 0.5,
        "margin_m": 10.0,
    }
    args.update(kw)
    return sight_needed(**args)


def test_escape_time_is_the_friction_limited_sideways_move():
    # 2.68 m at mu 0.3: sqrt(2 * 2.68 / (0.3 * 9.81))
    assert escape_time_s(2.675, 0.3) == pytest.approx(math.sqrt(2 * 2.675 / (0.3 * G_MPS2)))
    assert escape_time_s(0.0, 0.1) == 0.0


def test_a_lane_change_without_acceleration_takes_length_over_speed():
    t, v = lane_change_time_s(_Flat(), 25.0)
    assert t == pytest.approx(80.0 / 25.0)
    assert v == pytest.approx(25.0)


def test_the_tables_lane_change_brakes_so_it_takes_longer_than_at_constant_speed(tables):
    traj = tables.trajectory(1.0, 30.0)
    t, v_end = lane_change_time_s(traj, 30.0)
    assert v_end < 30.0
    assert t > traj.length_m / 30.0


def test_sight_distance_is_the_egos_travel_and_the_opposing_travel_plus_margin(tables):
    need = _need(tables)
    total = need.t_lane_change_s + need.t_beside_s + need.t_return_s + 0.5  # no escape added
    assert need.closing_speed_mps == 50.0
    travel = need.ego_travel_m(total)
    assert need.needed_m == pytest.approx(travel + 20.0 * total + 10.0)
    assert travel < 30.0 * total  # the ego's planned profile brakes
    assert need.t_escape_s == pytest.approx(escape_time_s(0.5 * (LANE + P.width_m), 1.0))


def test_an_obstacle_as_fast_as_the_ego_is_never_passed_unless_it_brakes(tables):
    assert math.isinf(_need(tables, obstacle_speed_mps=30.0).needed_m)
    braking = _need(tables, obstacle_speed_mps=30.0, obstacle_decel_mps2=10.0, gap_m=20.0)
    assert math.isfinite(braking.needed_m) and braking.t_beside_s < 5.0


@pytest.mark.parametrize(
    "left, ego, obstacle, decel",
    [(30.0, 20.0, 25.0, 8.0), (5.0, 20.0, 10.0, 2.0), (40.0, 15.0, 5.0, 0.0)],
)
def test_beside_time_matches_a_numerical_integration(left, ego, obstacle, decel):
    t, gained, v_o, dt = 0.0, 0.0, obstacle, 1e-4
    while gained < left:
        gained += (ego - v_o) * dt
        v_o = max(v_o - decel * dt, 0.0)
        t += dt
    assert beside_time_s(left, ego, obstacle, decel) == pytest.approx(t, abs=2e-3)


def test_the_return_counts_until_the_body_has_left_the_target_lane(tables):
    need = _need(tables)
    whole = _need(tables, ego_width_m=LANE)  # a body as wide as the lane leaves it at the end
    assert need.t_return_s < whole.t_return_s


def test_a_road_user_braking_to_a_stop_covers_half_its_speed_times_the_stopping_time():
    assert road_user_travel_m(20.0, -5.0, 10.0) == pytest.approx(40.0)
    assert road_user_travel_m(20.0, -5.0, 2.0) == pytest.approx(30.0)
    assert road_user_travel_m(-10.0, 0.0, 2.0) == pytest.approx(-20.0)


@settings(max_examples=30, deadline=None)
@given(
    mu=st.sampled_from([1.0, 0.7, 0.3, 0.1]), v=st.floats(15.0, 45.0), v_opp=st.floats(0.0, 50.0)
)
def test_sight_distance_grows_with_faster_opposing_traffic(mu, v, v_opp):
    tables = LookupTables.load(default_tables_dir(), params=P)
    base = _need(
        tables, speed_mps=v, mu=mu, opposing_speed_mps=v_opp, trajectory=tables.trajectory(mu, v)
    )
    faster = _need(
        tables,
        speed_mps=v,
        mu=mu,
        opposing_speed_mps=v_opp + 5.0,
        trajectory=tables.trajectory(mu, v),
    )
    assert faster.needed_m > base.needed_m
    # (not monotone in mu: on a dry road the table's lane change brakes harder, and the
    # slower ego then spends longer beside the obstacle)


def test_braking_impact_speed_is_the_kinematic_remainder():
    assert braking_impact_speed_mps(20.0, 10.0, 8.0) == pytest.approx(math.sqrt(400 - 160))
    assert braking_impact_speed_mps(10.0, 50.0, 8.0) == 0.0


def _meas(v=30.0, d=0.0, t=0.0, mu=1.0):
    return EgoMeasurement(t, v, 0.0, 0.0, 0.0, 0.0, 100.0, d, 0.0, 0.0, mu, LANE)


def _view(free, nearest=None, speed=None, opposing=True, behind=None, behind_speed=None):
    return NextLaneView(
        opposing,
        20.0,
        coverage_ahead_m=free,
        nearest_ahead_m=nearest,
        nearest_ahead_speed_mps=speed,
        nearest_behind_m=behind,
        nearest_behind_speed_mps=behind_speed,
    )


def _policy(tables):
    return SafePolicy(P, tables, EoamSettings(), PolicySettings(name="safe"))


def _seen(view, gap=40.0, closing=30.0):
    return Perception(gap, -closing, False, ObjectState(150.0, 0.0, 0.0, 5.09, 1.99), None, view)


def test_the_gate_opens_exactly_when_the_known_free_length_covers_the_need(tables):
    pol = _policy(tables)
    need = pol.sight_need(_meas(), _seen(None), _view(0.0)).needed_m
    assert pol.blocks(_meas(), _seen(_view(need - 1.0)), True, False)
    assert pol.gate == "refused" and pol.known_free_m == pytest.approx(need - 1.0)
    assert not _policy(tables).blocks(_meas(), _seen(_view(need + 1.0)), True, False)
    assert _policy(tables).blocks(_meas(), _seen(None), True, False)  # nothing known


def test_during_the_lane_change_any_road_user_within_the_remaining_need_blocks(tables):
    pol = _policy(tables)
    assert not pol.blocks(_meas(), _seen(_view(5000.0)), True, False)
    # a van creeping at 1.5 m/s 60 m ahead, neither standing nor oncoming for the radar
    assert pol.blocks(_meas(t=0.5), _seen(_view(60.0, 60.0, -1.5)), False, True)
    # once the manoeuvre's time has run out and the body is back, only the margins remain
    far = (30.0 + 1.5) * 0.5 + 10.0 + 1.0
    assert not pol.blocks(_meas(t=100.0), _seen(_view(far, far, -1.5)), False, True)
    # still in the target lane: the escape from where it is counts
    assert pol.blocks(_meas(t=100.0, d=LANE), _seen(_view(far, far, -1.5)), False, True)
    assert pol.reason == "an oncoming road user in the target lane"


def test_same_direction_lane_blocks_on_a_faster_car_closing_from_behind(tables):
    pol = _policy(tables)
    clear = _view(500.0, opposing=False)
    assert not pol.blocks(_meas(), _seen(clear), True, False)
    fast_behind = _view(500.0, opposing=False, behind=30.0, behind_speed=40.0)
    assert _policy(tables).blocks(_meas(), _seen(fast_behind), True, False)
    slow_behind = _view(500.0, opposing=False, behind=30.0, behind_speed=25.0)
    assert not _policy(tables).blocks(_meas(), _seen(slow_behind), True, False)


def test_a_car_overtaking_in_the_opposite_lane_from_behind_blocks(tables):
    pol = _policy(tables)
    need = pol.sight_need(_meas(), _seen(None), _view(0.0)).needed_m
    overtaker = _view(need + 100.0, behind=20.0, behind_speed=40.0)
    assert _policy(tables).blocks(_meas(), _seen(overtaker), True, False)
    falling_back = _view(need + 100.0, behind=30.0, behind_speed=20.0)
    assert not _policy(tables).blocks(_meas(), _seen(falling_back), True, False)


def test_tie_breaker_brakes_in_lane_when_the_head_on_would_be_harder(tables):
    pol = _policy(tables)
    # past the point of no return (d 1.5 m), an oncoming car 40 m ahead at 20 m/s: passing
    # on cannot finish; braking brings the ego back before it arrives and into the obstacle
    # 12 m ahead at a lower speed than the 50 m/s head-on
    perc = _seen(_view(40.0, 40.0, -20.0), gap=12.0, closing=30.0)
    assert pol.prefer_braking(_meas(d=1.5), perc)
    assert pol.tie_break == "brake"
    # an oncoming car far away: passing on ends without contact
    far = _seen(_view(900.0, 900.0, -20.0), gap=12.0, closing=30.0)
    assert not _policy(tables).prefer_braking(_meas(d=1.5), far)


def test_the_controller_brakes_in_lane_when_the_gate_refuses(tables):
    ctrl = EoamController(P, tables, EoamSettings(policy=PolicySettings(name="safe")))
    ctrl.reset(33.0)
    cmd = None
    for k in range(400):  # the obstacle stands 70 m ahead, closing at 33 m/s
        t = k * 0.01
        gap = 70.0 - 33.0 * t
        meas = EgoMeasurement(t, 33.0, 0, 0, 0, 0, 33.0 * t, 0.0, 0.0, 0.0, 1.0, LANE)
        cmd = ctrl.step(meas, _seen(_view(90.0), gap=gap, closing=33.0), 0.01)
        if ctrl.mode is not Mode.NORMAL and ctrl.mode is not Mode.UPDATE_BRAKE:
            break
    assert ctrl.mode is Mode.ONCOMING_BRAKE
    assert 2 not in ctrl.modes_visited
    assert cmd.brake_force_cmd_n > 0.0
    assert ctrl.policy.summary()["sight_gate"] == "refused"


def test_mode_3_in_lane_keeps_braking_while_it_corrects_an_offset(tables):
    """Mode 3 above walking speed with the body in its lane: the brake keeps at least
    ``limit_brake_floor`` of the limit, the steering stays within the ellipse's rest."""
    ctrl = EoamController(P, tables, EoamSettings(policy=PolicySettings(name="safe")))
    ctrl.reset(33.0)
    floor = EoamSettings().limit_brake_floor
    braking = []
    for k in range(400):
        t = k * 0.01
        gap = 70.0 - 33.0 * t
        # a 10 cm offset and a strong lateral acceleration: the ellipse would go to steering
        meas = EgoMeasurement(t, 33.0, 0.0, 0.0, 0.0, 9.0, 33.0 * t, 0.1, 0.0, 0.0, 1.0, LANE)
        cmd = ctrl.step(meas, _seen(_view(90.0), gap=gap, closing=33.0), 0.01)
        if ctrl.mode is Mode.ONCOMING_BRAKE:
            braking.append(cmd.brake_force_cmd_n)
    assert braking
    limit = ctrl.state.friction_now().brake_limit_n
    assert min(braking) >= floor * limit - 1e-6


def test_a_car_ahead_in_the_target_lane_braking_hard_closes_it_at_constant_speed_it_does_not(
    tables,
):
    meas = _meas()
    need = _policy(tables).sight_need(meas, _seen(None), _view(0.0))
    t = need.t_total_s + need.margin_s
    # just far enough ahead, as fast as the ego will be, not to be caught up at its speed
    margin = _policy(tables).settings.margin_m
    gap = max(need.ego_travel_m(x) - 30.0 * x for x in (0.0, need.t_lane_change_s, t)) + margin + 5
    steady = NextLaneView(False, 36.0, coverage_ahead_m=5000.0, ahead=((gap, 30.0),))
    braking = NextLaneView(
        False, 36.0, coverage_ahead_m=5000.0, ahead=((gap, 30.0),), accel_ahead_mps2=(-8.0,)
    )
    pol = _policy(tables)
    assert not pol.blocks(meas, _seen(steady), True, False), pol.reason
    pol = _policy(tables)
    assert pol.blocks(meas, _seen(braking), True, False)
    assert pol.reason == "a road user ahead in the target lane"


def test_a_follower_accelerating_until_it_reacts_needs_a_larger_gap(tables):
    need = _policy(tables).sight_need(_meas(), _seen(None), _view(0.0))
    t = need.t_total_s + need.margin_s
    gaps = [g * 0.5 for g in range(200)]
    steady = next(g for g in gaps if follower_keeps_distance(need, g, 32.0, t, 2.0))
    pushing = next(g for g in gaps if follower_keeps_distance(need, g, 32.0, t, 2.0, 3.0))
    assert pushing > steady
