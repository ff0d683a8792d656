"""The in-path obstacle's deceleration estimated from the range rate, and where it stops."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.decision.obstacle import ObstacleDecel, ObstacleTrack, stopping_range_m
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
