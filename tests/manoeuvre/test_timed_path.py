"""A time-optimal escape followed in time: where the ego is on it, and its course and
curvature re-timed to the ego's speed (``PathReference.progress``, ``retimed``)."""

import math

import pytest

from eoam_sumo.manoeuvre import MinTimeShift, PathReference
from eoam_sumo.manoeuvre.path_reference import MIN_PACE_RATIO, retimed

V0 = 25.0  # the pace the escape is laid out at [m/s]


def escape():
    return MinTimeShift(3.5, 0.0, 0.0, 0.0, V0, 2.65, 0.15)


def timed(pace=V0):
    return PathReference(
        escape(), start_offset_m=3.5, height_m=None, speed_mps=V0, step_m=0.05, pace_mps=pace
    )


def test_a_path_in_distance_is_where_the_ego_travelled():
    ref = timed(None)
    assert ref.progress(1.0, 20.0, 20.0) == (20.0, 1.0)


@pytest.mark.parametrize(("elapsed", "travelled", "speed"), [(1.0, 23.0, 21.0), (2.0, 46.0, 27.0)])
def test_a_path_in_time_is_at_its_pace(elapsed, travelled, speed):
    dx, rate = timed().progress(elapsed, travelled, speed)
    assert dx == pytest.approx(V0 * elapsed)
    assert rate == pytest.approx(V0 / speed)
    # its lateral position is the escape's at that time, whatever the distance travelled
    assert timed().at(dx).y_m == pytest.approx(escape().state_at(elapsed)[0], abs=1e-3)


def test_a_slow_ego_follows_it_no_faster_than_the_floor():
    travelled = 10.0  # in 1 s: 10 m/s, below half the pace
    dx, rate = timed().progress(1.0, travelled, 8.0)
    assert dx == pytest.approx(travelled / MIN_PACE_RATIO) and dx < V0
    assert rate == pytest.approx(1.0 / MIN_PACE_RATIO)


@pytest.mark.parametrize("t", [0.3, 0.9, 1.4, 2.0])
@pytest.mark.parametrize("speed", [0.8 * V0, 1.1 * V0])
def test_retimed_course_and_curvature_give_the_escapes_lateral_motion(t, speed):
    """At the ego's speed v the re-timed path's slope is v_y / v and its curvature
    a_y / v^2 / (1 + slope^2)^1.5, with the escape's v_y, a_y at that time."""
    _, vy, ay = escape().state_at(t)
    point = retimed(timed().at(V0 * t), V0 / speed)
    slope = math.tan(point.yaw_rad)
    assert slope * speed == pytest.approx(vy, abs=1e-3)
    assert point.curvature_1pm * speed**2 * (1 + slope * slope) ** 1.5 == pytest.approx(
        ay, abs=2e-2
    )


def test_rate_one_is_the_path_itself():
    point = timed().at(30.0)
    assert retimed(point, 1.0) == point


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_a_bad_pace_is_refused(bad):
    with pytest.raises(ValueError, match="pace_mps"):
        timed(bad)
