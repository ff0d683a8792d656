"""The safe policy's predictions are bounded: a closing speed near 0 (the cut-in car about as
fast as the ego) gives a finite answer at once, against closed-form physics."""

import math

import pytest

from eoam_sumo.decision.policy import (
    FOLLOWER_DECEL_MPS2,
    FOLLOWER_HEADWAY_S,
    PLAN_HORIZON_S,
    PolicySettings,
    SafePolicy,
    SightNeed,
    follower_keeps_distance,
)
from eoam_sumo.eoam import EgoMeasurement, EoamSettings, ObjectState, Perception
from eoam_sumo.eoam_messages import NextLaneView
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import ego_e_class_sedan

P = ego_e_class_sedan()
LANE = 3.5


@pytest.fixture(scope="module")
def tables():
    return LookupTables.load(default_tables_dir(), params=P)


def _plan(t_lc=3.0, v=33.3):
    return SightNeed(math.inf, v, t_lc, math.inf, 2.0, 1.0, 0.5, 10.0, v * t_lc, v)


def test_a_follower_as_fast_as_the_ego_over_10058_s_is_answered_from_the_steady_gap():
    # the reported hang: t_s = 10 058 s; the answer is the steady one (gap > headway)
    need = _plan()
    assert follower_keeps_distance(need, 40.0, 33.0, 10_058.0, 10.0)
    # a gap below its own headway fails at once, whatever the horizon
    assert not follower_keeps_distance(need, 20.0, 33.0, 10_058.0, 10.0)
    assert follower_keeps_distance(need, 40.0, 33.0, math.inf, 10.0)


def test_a_faster_follower_braking_to_the_egos_speed_keeps_its_headway_exactly():
    # the follower at 40 m/s behind an ego at 30 m/s reacts after 0.4 s and brakes at 3 m/s2
    # down to 30 m/s. Gap minus its 1 s headway, tau into the braking:
    # g0 - 0.4 * 10 - 40 - (10 - 3) tau + 1.5 tau^2, least at tau = 7 / 3
    assert FOLLOWER_DECEL_MPS2 == 3.0 and FOLLOWER_HEADWAY_S == 1.0
    tau = 7.0 / 3.0
    needed = 4.0 + 40.0 + 7.0 * tau - 1.5 * tau * tau
    need = _plan(t_lc=0.0, v=30.0)
    assert follower_keeps_distance(need, needed + 0.5, 40.0, 1e6, 2.0)
    assert not follower_keeps_distance(need, needed - 0.5, 40.0, 1e6, 2.0)


def _meas(v):
    return EgoMeasurement(0.0, v, 0.0, 0.0, 0.0, 0.0, 100.0, 0.0, 0.0, 0.0, 0.5, LANE)


def _seen(view, gap, closing):
    obj = ObjectState(150.0, 0.0, 0.0, 4.5, 1.8)
    return Perception(gap, -closing, False, obj, None, view)


@pytest.mark.parametrize("closing", [0.0, 1e-9, 0.003, 0.05])
def test_an_obstacle_nearly_as_fast_as_the_ego_is_never_passed(tables, closing):
    # 33.3 m/s behind a cut-in car 20 m ahead closing at mm/s: passing it would take hours
    view = NextLaneView(
        False,
        36.0,
        coverage_ahead_m=200.0,
        coverage_behind_m=80.0,
        nearest_behind_m=30.0,
        nearest_behind_speed_mps=33.0,
    )
    pol = SafePolicy(P, tables, EoamSettings(), PolicySettings(name="safe"))
    need, reason = pol.lane_reason(_meas(33.3), _seen(view, 20.0, closing), view)
    assert math.isinf(need.t_total_s)
    assert reason == "the obstacle would never be passed"
    assert pol.summary()["sight_needed_m"] is None
    # and the watch during a manoeuvre is bounded too
    pol.blocks(_meas(33.3), _seen(view, 20.0, closing), True, False)
    pol.blocks(_meas(33.3), _seen(view, 20.0, closing), False, True)


def test_a_pass_within_the_horizon_is_still_planned(tables):
    # closing at 5 m/s on a car 20 m ahead: about 8 s beside it, well inside the horizon
    view = NextLaneView(False, 36.0, coverage_ahead_m=2000.0, coverage_behind_m=200.0)
    pol = SafePolicy(P, tables, EoamSettings(), PolicySettings(name="safe"))
    need, _ = pol.lane_reason(_meas(33.3), _seen(view, 20.0, 5.0), view)
    assert math.isfinite(need.t_total_s) and need.t_total_s < PLAN_HORIZON_S


def _lane(**kw):
    return NextLaneView(False, 36.0, coverage_ahead_m=0.0, **kw)


def test_the_paper_check_closes_an_occupied_lane_and_leaves_oncoming_traffic_to_the_paper(
    tables,
):
    pol = SafePolicy(P, tables, EoamSettings(), PolicySettings(name="paper"))
    meas, seen = _meas(33.3), (lambda v: _seen(v, 40.0, 33.3))
    # nothing seen in the lane, and no sight distance asked of the paper's policy
    assert pol.occupied_reason(meas, seen(_lane()), _lane()) == ""
    beside = _lane(ahead=((-1.0, 33.3),))
    assert "beside" in pol.occupied_reason(meas, seen(beside), beside)
    follower = _lane(nearest_behind_m=5.0, nearest_behind_speed_mps=40.0)
    assert "behind" in pol.occupied_reason(meas, seen(follower), follower)
    slower = _lane(ahead=((15.0, 20.0),))  # caught up within the manoeuvre
    assert "ahead" in pol.occupied_reason(meas, seen(slower), slower)
    oncoming = NextLaneView(True, 27.0, coverage_ahead_m=0.0, ahead=((80.0, -27.0),))
    assert pol.occupied_reason(meas, seen(oncoming), oncoming) == ""
    parked = _lane(ahead=((30.0, 0.0),))
    assert pol.occupied_reason(meas, seen(parked), parked) == ""
