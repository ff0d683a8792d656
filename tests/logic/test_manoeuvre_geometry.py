"""The manoeuvre package (``eoam_sumo.manoeuvre``): angle wrapping against its definition and a
time-optimal shift's end (its place beneath decision and control: tests/test_layers.py)."""

import math
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

import eoam_sumo
from eoam_sumo.manoeuvre import MinTimeShift, wrap_angle

PACKAGE = Path(eoam_sumo.__file__).resolve().parent
TAU = 2.0 * math.pi


def _circular_gap(a: float, b: float) -> float:
    """|a - b| on the circle [rad]."""
    return abs(math.remainder(a - b, TAU))


@given(st.floats(-1e3, 1e3))
def test_wrap_angle_lands_in_one_turn_and_keeps_the_direction(angle):
    wrapped = wrap_angle(angle)
    # [-pi, pi) up to rounding: just below -pi, (x + pi) % 2pi rounds up to 2pi
    assert -math.pi <= wrapped <= math.pi
    assert _circular_gap(wrapped, angle) <= 1e-12 * max(1.0, abs(angle))


@given(st.floats(-1e3, 1e3), st.integers(-50, 50))
def test_wrap_angle_is_periodic_in_whole_turns(angle, turns):
    shifted = wrap_angle(angle + turns * TAU)
    assert _circular_gap(shifted, wrap_angle(angle)) <= 1e-12 * max(
        1.0, abs(angle) + abs(turns) * TAU
    )


@given(st.floats(-math.pi, math.pi, exclude_max=True))
def test_wrap_angle_keeps_an_angle_within_one_turn_as_it_is(angle):
    assert wrap_angle(angle) == angle


def test_wrap_angle_of_a_half_turn_is_minus_pi():
    assert wrap_angle(math.pi) == -math.pi
    assert wrap_angle(3.0 * math.pi) == -math.pi


@given(st.floats(-2.0, 2.0), st.floats(-2.0, 2.0), st.floats(2.0, 9.0))
def test_min_time_shift_ends_at_rest_at_its_target_from_rest(y0, y1, accel):
    shift = MinTimeShift(y0, 0.0, 0.0, y1, 30.0, accel, 0.15)
    y, v, a = shift.state_at(shift.duration_s)
    assert abs(y - y1) <= 1e-6 and abs(v) <= 1e-9 and abs(a) <= 1e-9
    assert abs(shift.at(shift.length_m).yaw_rad) <= 1e-9
