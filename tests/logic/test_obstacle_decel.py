"""The in-path obstacle's deceleration estimated from the range rate, and where it stops."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.decision.obstacle import ObstacleDecel, stopping_range_m


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
