"""Time-optimal lateral escapes (``manoeuvre.min_time_shift.MinTimeShift``) against closed-form
kinematics.

A rest-to-rest shift of D with the lateral acceleration bounded by A and its rate by J = A / r
is quickest as ramp r, hold h, swing 2r, hold h, ramp r, covering D = A (r + h)(2r + h): its
duration is T = r + sqrt(r^2 + 4 D / A) (h >= 0, i.e. D >= 2 A r^2).
"""

import itertools
import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from eoam_sumo.eoam_messages import EgoMeasurement
from eoam_sumo.manoeuvre.lateral_state import lateral_state
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift

SPEED = 30.0  # forward speed [m/s]


def _samples(shift, n=400):
    return [shift.state_at(shift.duration_s * i / n) for i in range(n + 1)]


@settings(max_examples=60, deadline=None)
@given(st.floats(0.5, 6.0), st.floats(0.5, 9.0), st.floats(0.05, 0.3))
def test_rest_to_rest_duration_is_the_closed_form(dist, accel, ramp):
    if dist < 2.0 * accel * ramp * ramp:
        return  # no hold phase: the closed form below does not apply
    shift = MinTimeShift(0.0, 0.0, 0.0, dist, SPEED, accel, ramp)
    expected = ramp + math.sqrt(ramp * ramp + 4.0 * dist / accel)
    assert shift.duration_s == pytest.approx(expected, rel=1e-6)
    assert shift.y_end_m == pytest.approx(dist, abs=1e-6)
    # never beyond the friction budget, never past the target, ends at rest
    for y, _v, a in _samples(shift):
        assert abs(a) <= accel * (1 + 1e-9)
        assert y <= dist + 1e-6
    assert shift.state_at(shift.duration_s + 1.0) == pytest.approx((dist, 0.0, 0.0), abs=1e-6)


@settings(max_examples=40, deadline=None)
@given(st.floats(0.5, 5.0), st.floats(1.0, 9.0))
def test_quicker_than_the_shortest_quintic_within_the_same_budget(dist, accel):
    shift = MinTimeShift(0.0, 0.0, 0.0, dist, SPEED, accel, 0.15)
    quintic = QuinticShift.for_lateral_accel(0.0, 0.0, dist, SPEED, accel, 1.0)
    t_quintic = quintic.length_m / SPEED
    assume(60.0 * dist / t_quintic**3 <= accel / 0.15)  # the quintic within the jerk limit too
    assert shift.duration_s < t_quintic
    # and no quicker than bang-bang without a jerk limit, 2 sqrt(D / A)
    assert shift.duration_s >= 2.0 * math.sqrt(dist / accel) - 1e-9


@settings(max_examples=60, deadline=None)
@given(st.floats(-1.0, 4.0), st.floats(-3.0, 4.0), st.floats(-6.0, 6.0), st.floats(2.0, 9.0))
def test_from_a_moving_state_it_arrests_the_motion_and_ends_at_the_target(d0, v0, a0, accel):
    a0 = max(min(a0, accel), -accel)
    shift = MinTimeShift(d0, v0, a0, 0.0, SPEED, accel, 0.15)
    jerk = accel / 0.15
    states = _samples(shift, 2000)
    dt = shift.duration_s / 2000
    for (_, _, a1), (_, _, a2) in itertools.pairwise(states):
        assert abs(a2 - a1) <= jerk * dt * (1 + 1e-6) + 1e-9
    assert states[0] == pytest.approx((d0, v0, a0), abs=1e-9)
    rest = d0 + v0 * abs(v0) / (2 * accel)
    if shift.y_end_m == pytest.approx(0.0, abs=1e-6):
        assert states[-1][1] == pytest.approx(0.0, abs=1e-6)
    else:  # only when it runs towards the target too fast to stop there
        assert v0 < 0.0 and rest < 0.0
    # the furthest left it goes is at least where bang-bang without a jerk limit stops
    if v0 > 0.0:
        assert shift.max_offset_m() >= d0 + v0 * v0 / (2 * accel) - 1e-6


def test_time_within_a_line_matches_the_profile():
    shift = MinTimeShift(3.6, 1.0, -2.6, 0.0, 38.0, 2.65, 0.15)
    t = shift.time_within_s(1.665)
    assert shift.state_at(t)[0] == pytest.approx(1.665, abs=1e-6)
    assert all(shift.state_at(t + k * 0.05)[0] <= 1.665 + 1e-9 for k in range(40))
    assert shift.time_within_s(5.0) == 0.0
    assert shift.time_within_s(-0.1) == math.inf


def test_path_form_matches_the_time_profile():
    shift = MinTimeShift(0.5, 2.0, 3.0, 0.0, 25.0, 6.0, 0.15)
    for dx in (0.0, 5.0, 17.5, shift.length_m * 0.9):
        y, vy, ay = shift.state_at(dx / 25.0)
        pt = shift.at(dx)
        assert pt.y_m == pytest.approx(y)
        assert math.tan(pt.yaw_rad) == pytest.approx(vy / 25.0)
        assert pt.curvature_1pm * (1 + (vy / 25.0) ** 2) ** 1.5 == pytest.approx(ay / 625.0)


@pytest.mark.parametrize("bad", [{"accel_mps2": 0.0}, {"ramp_s": 0.0}, {"speed_mps": 0.0}])
def test_bad_budget_is_refused(bad):
    kw = {
        "y0_m": 0.0,
        "v0_mps": 0.0,
        "a0_mps2": 0.0,
        "y1_m": 1.0,
        "speed_mps": 20.0,
        "accel_mps2": 5.0,
        "ramp_s": 0.1,
    }
    kw.update(bad)
    with pytest.raises(ValueError):
        MinTimeShift(**kw)


def test_lateral_state_of_a_measurement():
    e, vx, vy = 0.1, 30.0, -0.5  # heading 0.1 rad left of the road, sliding right in the body
    meas = EgoMeasurement(0.0, vx, vy, 0.0, 0.0, 2.0, 0.0, 1.0, e, 0.001, 1.0, 3.5)
    v_lat, a_lat, along = lateral_state(meas)
    assert v_lat == pytest.approx(vx * math.sin(e) + vy * math.cos(e))
    assert along == pytest.approx(vx * math.cos(e) - vy * math.sin(e))
    assert a_lat == pytest.approx(2.0 - 0.001 * along * along)  # less the road's curving


@settings(max_examples=60, deadline=None)
@given(st.floats(0.5, 4.0), st.floats(1.0, 9.0), st.floats(0.05, 0.3))
def test_turn_time_is_the_closed_form(v0, accel, ramp):
    """Moving away from the target at v0 with no lateral acceleration, the motion turns after
    the ramp to -A and the hold: v0 = A r / 2 + A (t - r), t = v0 / A + r / 2 (v0 >= A r / 2)."""
    assume(v0 >= 0.5 * accel * ramp)
    shift = MinTimeShift(0.0, v0, 0.0, -1.0, SPEED, accel, ramp)
    t = shift.turn_s()
    assert t == pytest.approx(v0 / accel + 0.5 * ramp, rel=1e-9, abs=1e-9)
    assert shift.state_at(t)[1] == pytest.approx(0.0, abs=1e-9)
    assert shift.state_at(t)[0] == pytest.approx(shift.max_offset_m(), abs=1e-9)


def test_no_turn_when_moving_towards_the_target():
    assert MinTimeShift(1.0, -1.0, 0.0, 0.0, SPEED, 5.0, 0.15).turn_s() == 0.0
    assert MinTimeShift(1.0, 0.0, 0.0, 0.0, SPEED, 5.0, 0.15).turn_s() == 0.0
