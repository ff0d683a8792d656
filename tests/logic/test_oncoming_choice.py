"""The commit/abort decision (``decision.oncoming``) against closed-form kinematics.

Lane 3.5 m, ego 1.85 m wide, an oncoming car 1.82 m wide centred in the opposite lane: the
ego is out of its path with its centre at most 3.5 - 0.91 - 0.925 = 1.665 m left of its own
lane centre (less the lateral margin).
"""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.decision.obstacle import ObstacleTrack
from eoam_sumo.decision.oncoming import (
    Budget,
    Lateral,
    Tracked,
    choose,
    commit_choice,
    predict_abort,
    predict_hold,
    predict_pass,
    return_clears,
    time_to_pass_s,
    weigh,
)
from eoam_sumo.eoam_messages import EgoMeasurement, ObjectState
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift

MU_G = 0.7 * 9.81
BUDGET = Budget(
    lateral_mps2=0.9 * MU_G,
    ramp_s=0.15,
    lag_s=0.1,
    brake_mps2=0.95 * MU_G,
    mu_g_mps2=MU_G,
    width_m=1.85,
    length_m=4.92,
    cg_to_front_m=3.9,
    side_clearance_m=0.5,
    pass_margin_m=1.0,
    margin_m=0.2,
    margin_s=0.2,
    return_mps2=0.6 * MU_G,
    arrest_min_mps=0.5,
)
LINE = 3.5 - 0.91 - 0.925 - 0.2  # the ego's centre out of the oncoming path [m]
V = 40.0  # ego speed [m/s]


def oncoming(gap_m, speed_mps=20.0):
    return Tracked(gap_m, -speed_mps, 0.0, 4.7, 3.5 - 0.91)


def standing(gap_m):
    return Tracked(gap_m, 0.0, 0.0, 5.09, 0.995)


def test_meeting_time_is_gap_over_closing_speed():
    opt = predict_pass(Lateral(0.0, 0.0, 0.0), V, None, oncoming(120.0), BUDGET)
    assert opt.meet_s == pytest.approx(120.0 / (V + 20.0), abs=0.011)


def test_abort_in_lane_hits_the_obstacle_at_the_braking_closed_form():
    # at rest on the lane centre there is no lateral manoeuvre: full braking at once, and the
    # standing obstacle is hit at sqrt(v^2 - 2 b g); the ego's delta-v is half of it
    gap = 50.0
    opt = predict_abort(Lateral(0.0, 0.0, 0.0), V, standing(gap), oncoming(300.0), BUDGET)
    impact = math.sqrt(V * V - 2.0 * BUDGET.brake_mps2 * gap)
    assert not opt.head_on
    assert opt.delta_v_mps == pytest.approx(0.5 * impact, rel=0.01)


def test_abort_stops_short_of_a_far_obstacle():
    gap = V * V / (2.0 * BUDGET.brake_mps2) + 5.0
    opt = predict_abort(Lateral(0.0, 0.0, 0.0), V, standing(gap), oncoming(400.0), BUDGET)
    assert not opt.head_on and opt.delta_v_mps == 0.0


@settings(max_examples=50, deadline=None)
@given(st.floats(-0.5, LINE - 0.01), st.floats(20.0, 150.0))
def test_ego_at_rest_out_of_the_path_is_never_a_head_on(d, gap):
    opt = predict_abort(Lateral(d, 0.0, 0.0), V, None, oncoming(gap), BUDGET)
    assert not opt.head_on and opt.out_s <= BUDGET.lag_s + 1e-9


def test_ego_in_the_path_too_late_to_leave_it_is_a_head_on_at_half_the_closing_speed():
    # centred in the opposite lane, the fronts 30 m apart: leaving the path takes longer
    # than the 0.5 s before they meet, whatever the ego does
    opt = predict_pass(Lateral(3.5, 0.0, 0.0), V, None, oncoming(30.0), BUDGET)
    assert opt.head_on
    assert opt.delta_v_mps == pytest.approx(0.5 * (V + 20.0))
    # the time-optimal escape from rest: sqrt(2 (3.5 - line) / a) is a lower bound of it
    assert opt.out_s >= math.sqrt(2.0 * (3.5 - LINE) / BUDGET.lateral_mps2)


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 1.5), st.floats(0.0, 3.0), st.floats(40.0, 140.0), st.floats(5.0, 60.0))
def test_seeing_the_oncoming_car_later_never_makes_an_option_safer(d, v_lat, gap, less):
    lat = Lateral(d, v_lat, 0.0)
    far, near = oncoming(gap), oncoming(gap - less)
    for predict in (predict_abort, predict_pass):
        a, b = (
            predict(lat, V, standing(30.0), far, BUDGET),
            predict(lat, V, standing(30.0), near, BUDGET),
        )
        assert not (a.head_on and not b.head_on)
        assert b.delta_v_mps >= a.delta_v_mps - 1e-9


def test_choice_is_the_lower_predicted_delta_v():
    lat = Lateral(0.65, 2.4, 5.3)  # early in a lane change at 165 km/h, mu 0.7
    # seen 1.74 s before the fronts meet: with the time margin, the abort (arrested, then
    # back at 0.6 mu g) leaves the oncoming path in time, passing does not
    seen_late = weigh(lat, V, standing(31.0), oncoming(104.0), BUDGET, passed=False)
    assert seen_late.passing.head_on and not seen_late.abort.head_on
    assert not seen_late.pass_on  # a hit on the obstacle is softer than the head-on
    seen_early = choose(lat, V, standing(31.0), oncoming(400.0), BUDGET, passed=False)
    assert not seen_early.passing.head_on and seen_early.pass_on  # passing ends clean
    assert not seen_early.least_margin


def _slack_s(option) -> float:
    return option.meet_s - option.out_s


def test_the_time_margin_ranks_only_where_an_option_keeps_clear_with_it():
    """Seen 1.74 s before the fronts meet, passing leaves the oncoming path 0.18 s before
    they meet: inside the 0.2 s margin, so with it every option ends in contact (the abort
    hits the obstacle 31 m ahead at 37.7 m/s). Passing is clear with the least margin
    (0.1 s) and is taken; where some option keeps the full margin, nothing changes."""
    lat, obs, onc = Lateral(0.65, 2.4, 5.3), standing(31.0), oncoming(104.0)
    with_margin = weigh(lat, V, obs, onc, BUDGET, passed=False)
    assert with_margin.passing.head_on and with_margin.abort.delta_v_mps > 15.0
    assert not with_margin.pass_on
    choice = choose(lat, V, obs, onc, BUDGET, passed=False)
    assert choice.pass_on and choice.least_margin
    assert not choice.passing.head_on and choice.passing.delta_v_mps == 0.0
    assert BUDGET.margin_min_s <= _slack_s(choice.passing) < BUDGET.margin_s
    # a stretch of road ahead long enough to stop in: the abort keeps clear, with the margin
    far_obstacle = standing(V * V / (2.0 * BUDGET.brake_mps2) + 5.0)
    kept = choose(lat, V, far_obstacle, onc, BUDGET, passed=False)
    assert kept == weigh(lat, V, far_obstacle, onc, BUDGET, passed=False)


def test_passing_inside_the_least_margin_is_not_taken():
    """Seen 1.6 s before the fronts meet, passing leaves the oncoming path 0.03 s before
    they meet: within the prediction's error, so the abort stays."""
    lat, obs, onc = Lateral(0.65, 2.4, 5.3), standing(31.0), oncoming(95.0)
    passing = predict_pass(lat, V, obs, onc, BUDGET._replace(margin_s=0.0))
    assert 0.0 < _slack_s(passing) < BUDGET.margin_min_s
    choice = choose(lat, V, obs, onc, BUDGET, passed=False)
    assert not choice.pass_on and not choice.least_margin


def test_a_sensor_state_is_carried_on_to_now_and_never_taken_on_the_least_margin():
    """The seen-late pass above from measurements: with an exact state of now it is taken on
    the least margin; the same car reported 0.125 s late (a tracked sensor's latency: 2.5 m
    further off then) is carried on to the same station now, but its noise is not in the
    prediction, so only the full margin counts and the abort is taken."""
    meas = EgoMeasurement(0.0, V, 2.4, 0.0, 0.0, 5.3, 0.0, 0.65, 0.0, 0.0, 0.7, 3.5)
    front = BUDGET.cg_to_front_m
    obstacle = ObstacleTrack(0.0, front + 31.0 + 5.09, 0.0, 0.995, 0.0, 5.09)
    now = ObjectState(front + 104.0 + 2.35, 3.5, -20.0, 4.7, 1.82)
    late = now._replace(s_m=now.s_m + 2.5, time_s=-0.125)
    exact = commit_choice(meas, now, obstacle, BUDGET)
    assert exact.pass_on and exact.least_margin
    tracked = commit_choice(meas, late, obstacle, BUDGET)
    assert tracked.passing[2:] == exact.passing[2:]  # the same times: the same station now
    assert tracked.passing.head_on  # within the full margin
    assert not tracked.pass_on and not tracked.least_margin


def _taken(choice):
    if choice.pass_on:
        return choice.passing
    return choice.hold if choice.hold_in_place else choice.abort


@settings(max_examples=60, deadline=None)
@given(st.floats(0.0, 1.5), st.floats(-1.0, 3.0), st.floats(20.0, 90.0), st.floats(60.0, 300.0))
def test_the_least_margin_only_where_every_option_with_the_margin_ends_in_contact(
    d, v_lat, obs, gap
):
    lat = Lateral(d, v_lat, 0.0)
    with_margin = weigh(lat, V, standing(obs), oncoming(gap), BUDGET, passed=False)
    choice = choose(lat, V, standing(obs), oncoming(gap), BUDGET, passed=False)
    if not choice.least_margin:
        assert choice == with_margin
        return
    taken = _taken(with_margin)
    assert taken.head_on or taken.delta_v_mps > 0.0  # contact with the margin
    least = _taken(choice)
    assert not least.head_on and least.delta_v_mps == 0.0  # none with the least one
    assert choice == weigh(
        lat, V, standing(obs), oncoming(gap), BUDGET._replace(margin_s=BUDGET.margin_min_s), False
    )._replace(least_margin=True)


def test_past_the_obstacle_the_escape_is_taken():
    choice = choose(
        Lateral(3.6, 1.0, -2.6), V, standing(-10.0), oncoming(100.0), BUDGET, passed=True
    )
    assert choice.pass_on


def test_time_to_pass_a_braking_obstacle():
    # the obstacle stops after v^2 / (2 a) = 4 m in 2 s; the ego at 30 m/s gains 30 t - 4
    obstacle = Tracked(0.0, 4.0, 2.0, 5.0, 1.0)
    assert time_to_pass_s(30.0, 100.0, obstacle) == pytest.approx(104.0 / 30.0)
    # within the obstacle's stop: 26 t + t^2 = 20
    assert time_to_pass_s(30.0, 20.0, obstacle) == pytest.approx(-13.0 + math.sqrt(189.0))
    assert time_to_pass_s(4.0, 20.0, Tracked(0.0, 4.0, 0.0, 5.0, 1.0)) == math.inf


def _ego(d_m, s_m=0.0):
    return EgoMeasurement(0.0, V, 0.0, 0.0, 0.0, 0.0, s_m, d_m, 0.0, 0.0, 0.7, 3.5)


def test_return_after_passing_waits_until_it_keeps_the_side_clear():
    rear = 0.0 + BUDGET.cg_to_front_m - BUDGET.length_m  # the ego's rear station at s = 0
    side = 0.995 + 0.5 * BUDGET.width_m + BUDGET.side_clearance_m

    def obstacle(front_ahead_of_rear_m):
        return ObstacleTrack(0.0, rear + front_ahead_of_rear_m, 0.0, 0.995, 0.0, 5.09)

    # still behind the obstacle, not yet out beside it: no return
    assert not return_clears(_ego(1.2), obstacle(30.0), BUDGET)
    # out beside it at rest: the return takes the ego within the side clearance after
    # the time it needs to drop from 2.8 m to the side offset at the budget (jerk-limited)
    escape_s = MinTimeShift(
        2.8, 0.0, 0.0, 0.0, V, BUDGET.lateral_mps2, BUDGET.ramp_s
    ).time_within_s(side)
    gain = V * escape_s - BUDGET.pass_margin_m  # what the ego gains on it meanwhile
    assert not return_clears(_ego(2.8), obstacle(gain + 1.0), BUDGET)
    assert return_clears(_ego(2.8), obstacle(gain - 1.0), BUDGET)
    assert return_clears(_ego(1.2), obstacle(-2.0), BUDGET)  # already past it


# ------------------------------------------------------------------ braking in place (hold)
def test_holding_in_place_hits_the_obstacle_slower_than_returning_and_is_chosen():
    """A small drift (0.3 m out, 0.8 m/s left), a standing car 30 m ahead, the oncoming car
    100 m off (passing meets it head-on): the abort and the hold stay out of its path and hit
    the obstacle, the hold at the lower speed (no shift back to share the ellipse with), at
    least the full limit's sqrt(v^2 - 2 a gap)."""
    lat, obs, onc = Lateral(0.3, 0.8, 0.0), standing(30.0), oncoming(100.0)
    hold = predict_hold(lat, V, obs, onc, BUDGET)
    abort = predict_abort(lat, V, obs, onc, BUDGET)
    assert not hold.head_on and not abort.head_on
    floor = 0.5 * math.sqrt(V * V - 2.0 * BUDGET.brake_mps2 * 30.0)
    assert floor - 0.05 <= hold.delta_v_mps < abort.delta_v_mps
    choice = choose(lat, V, obs, onc, BUDGET, passed=False)
    assert choice.passing.head_on
    assert choice.hold_in_place and not choice.pass_on and choice.hold == hold


def test_an_arrest_ending_in_the_oncoming_path_is_never_held():
    """2.5 m/s left at 1.2 m out: the arrest ends past the line, so holding there meets the
    oncoming car (head-on), whatever its predicted delta-v; the abort is taken."""
    lat, obs, onc = Lateral(1.2, 2.5, 0.0), standing(30.0), oncoming(150.0)
    hold = predict_hold(lat, V, obs, onc, BUDGET)
    assert hold.head_on and hold.out_s == math.inf
    choice = choose(lat, V, obs, onc, BUDGET, passed=False)
    assert not choice.hold_in_place


def test_holding_beside_a_narrow_obstacle_has_no_contact():
    """An obstacle whose left side is 0.4 m right of the lane centre (a cyclist at the kerb):
    held at 0.8 m the ego's side is clear of it and of the oncoming path, no contact."""
    obs = Tracked(30.0, 0.0, 0.0, 1.8, -0.4)
    lat = Lateral(0.5, 1.0, 0.0)
    hold = predict_hold(lat, V, obs, oncoming(100.0), BUDGET)
    assert not hold.head_on and hold.delta_v_mps == 0.0
    assert choose(lat, V, obs, oncoming(100.0), BUDGET, passed=False).hold_in_place
