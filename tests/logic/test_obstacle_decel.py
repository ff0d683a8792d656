"""The in-path obstacle's deceleration estimated from the range rate, and where it stops."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.decision.obstacle import (
    ObstacleDecel,
    ObstacleTrack,
    speed_match_factor,
    stopping_range_m,
)
from eoam_sumo.eoam_messages import EgoMeasurement, ObjectState


@given(decel=st.floats(0.5, 10.0), v0=st.floats(10.0, 40.0), ego=st.floats(15.0, 45.0))
@settings(max_examples=40, deadline=None)
def test_estimate_converges_to_a_constant_deceleration(decel, v0, ego):
    """Range rate = obstacle speed - ego speed at 10 ms samples: after five time constants
    the filtered derivative is the obstacle's deceleration (exact for a ramp)."""
    est = ObstacleDecel(time_constant_s=0.1)
    for k in range(60):
        t = 0.01 * k
        rate = (v0 - decel * t) - ego
        est.update(t, ego + rate)
    assert est.decel_mps2 == pytest.approx(decel, rel=1e-2)


def test_a_speed_step_no_car_makes_restarts_the_estimate():
    est = ObstacleDecel()
    for k in range(30):
        est.update(0.01 * k, 20.0 - 5.0 * 0.01 * k)
    assert est.decel_mps2 > 4.0
    est.update(0.30, 5.0)  # 13 m/s in 10 ms: another object
    assert est.decel_mps2 == 0.0
    est.reset()
    assert est.update(1.0, 10.0) == 0.0  # one sample: no derivative yet


def test_stopping_range():
    assert stopping_range_m(30.0, 20.0, 4.0) == pytest.approx(30.0 + 400.0 / 8.0)
    assert stopping_range_m(30.0, 20.0, 0.0) == math.inf  # holds its speed
    assert stopping_range_m(30.0, 0.0, 4.0) == 30.0  # already standing
    with pytest.raises(ValueError):
        ObstacleDecel(time_constant_s=0.0)


def test_obstacle_track_predicts_its_stop():
    track = ObstacleTrack(1.0, 100.0, 10.0, 0.995, 4.0, 5.09)
    # within its stop: s = v t - a t^2 / 2; after it, where it stopped (v^2 / 2a = 12.5 m)
    assert track.at(2.0) == pytest.approx((100.0 + 10.0 - 2.0, 6.0))
    assert track.at(10.0) == pytest.approx((112.5, 0.0))
    holding = track._replace(decel_mps2=0.0)
    assert holding.at(4.0) == pytest.approx((130.0, 10.0))


def test_obstacle_track_from_the_sensor():
    meas = EgoMeasurement(2.0, 30.0, 0.0, 0.0, 0.0, 0.0, 50.0, 0.0, 0.0, 0.0, 1.0, 3.5)
    obj = ObjectState(90.0, 0.1, 12.0, 5.0, 2.0)
    assert ObstacleTrack.sensed(meas, 3.9, 30.0, 18.0, obj, 12.0, 1.5) == (
        2.0,
        92.5,
        12.0,
        1.1,
        1.5,
        5.0,
    )
    # without an object: the range from the front bumper, an assumed length, a lane's width
    assert ObstacleTrack.sensed(meas, 3.9, 30.0, 18.0, None, 12.0, 0.0) == pytest.approx(
        (2.0, 50.0 + 3.9 + 30.0 + 12.0, 12.0, 1.75, 0.0, 12.0)
    )


def least_gap_m(range_m: float, v_ego: float, a_ego: float, v_obj: float, a_obj: float) -> float:
    """The least gap of two bodies braking to their stops, by 1 ms time steps (exact
    positions of each step)."""
    gap, t, dt = range_m, 0.0, 1e-3
    while v_ego - a_ego * t > 0.0:
        t += dt
        ego = v_ego * t - 0.5 * a_ego * t * t
        t_obj = min(t, v_obj / a_obj) if a_obj > 0.0 else t
        obj = v_obj * t_obj - 0.5 * a_obj * t_obj * t_obj
        gap = min(gap, range_m + obj - ego)
    return gap


@given(
    v_ego=st.floats(15.0, 40.0),
    v_obj=st.floats(0.5, 30.0),
    a_obj=st.floats(0.0, 10.0),
    a_ego=st.floats(3.0, 9.0),
)
@settings(max_examples=60, deadline=None)
def test_the_speed_match_distance_is_where_the_least_gap_is_zero(v_ego, v_obj, a_obj, a_ego):
    """Starting the factor times the paper's stopping distance v_rel^2 / (2 a_ego) apart,
    the least gap is about zero when the obstacle still moves at the speed match; at least
    zero otherwise (factor 1: the paper's rule or the standing placement decides)."""
    closing = v_ego - v_obj
    if closing < 1.0:
        return
    factor = speed_match_factor(closing, v_obj, a_obj, a_ego)
    start_m = factor * closing * closing / (2.0 * a_ego)
    gap = least_gap_m(start_m, v_ego, a_ego, v_obj, a_obj)
    standing_m = v_ego**2 / (2.0 * a_ego) - (v_obj**2 / (2.0 * a_obj) if a_obj > 0 else 0.0)
    if factor > 1.0:
        assert gap == pytest.approx(0.0, abs=0.05)
        assert start_m >= standing_m - 0.05  # the standing placement asks for less
    elif a_obj > 0.0:
        assert least_gap_m(max(start_m, standing_m), v_ego, a_ego, v_obj, a_obj) > -0.05
