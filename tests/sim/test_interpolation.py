"""Road users between SUMO's steps (sim/interpolation.py) and contact found between them,
against closed-form motion."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.errors import InputError
from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.sim.interpolation import between, ego_ahead, interpolate_reports, travel_m
from eoam_sumo.sim.settings import RunSettings, check_sumo_step_s
from eoam_sumo.sim.severity import substep_contact
from eoam_sumo.world.bodies import Body


def _car(vid: str, x_m: float, yaw_rad: float, speed_mps: float, parked: bool = False) -> Body:
    return Body(vid, "passenger", x_m, 0.0, yaw_rad, speed_mps, 4.5, 1.8, parked)


def test_constant_acceleration_travel_is_closed_form():
    # s = v t + a t^2 / 2, v' = v + a t
    assert travel_m(10.0, 2.0, 0.05) == pytest.approx((0.5025, 10.1), abs=1e-12)
    assert travel_m(10.0, 0.0, 0.1) == pytest.approx((1.0, 10.0), abs=1e-12)


def test_a_braking_road_user_stops_and_stays():
    # 1 m/s braking at 8 m/s^2 stops after 0.125 s, 1/16 m on; never backwards
    for dt in (0.125, 0.2, 1.0):
        dist, speed = travel_m(1.0, -8.0, dt)
        assert (dist, speed) == pytest.approx((1.0 / 16.0, 0.0), abs=1e-12)


@given(
    v=st.floats(0.0, 60.0),
    a=st.floats(-12.0, 6.0),
    dt=st.floats(0.0, 0.1),
)
def test_travel_is_never_backwards_nor_negative_speed(v, a, dt):
    dist, speed = travel_m(v, a, dt)
    assert dist >= -1e-12
    assert speed >= 0.0
    # no farther than the motion without braking
    assert dist <= v * dt + 0.5 * max(a, 0.0) * dt * dt + 1e-9


def test_between_two_reports_is_constant_acceleration_along_the_way():
    # 20 -> 16 m/s over 0.1 s: a = -40 m/s^2 (braking), 1.8 m travelled; at 50 ms
    # s = 20 * 0.05 - 20 * 0.05^2 = 0.95 m, v = 18 m/s
    b0 = Body("o", "passenger", 5.0, 2.0, math.pi / 2, 20.0, 4.5, 1.8)
    b1 = Body("o", "passenger", 5.0, 3.8, math.pi / 2, 16.0, 4.5, 1.8)
    mid = between(b0, b1, 0.05, 0.1)
    assert (mid.x_m, mid.y_m) == pytest.approx((5.0, 2.95), abs=1e-12)
    assert mid.speed_mps == pytest.approx(18.0, abs=1e-12)
    assert mid.box.y_m == pytest.approx(mid.y_m)  # the box follows
    assert (mid.vid, mid.length_m, mid.width_m) == ("o", 4.5, 1.8)
    assert between(b0, b1, 0.1, 0.1) is b1  # the later report itself


def test_between_follows_a_lane_change_along_the_chord_and_turns_evenly():
    b0 = Body("o", "passenger", 0.0, 0.0, 0.0, 10.0, 4.5, 1.8)
    b1 = Body("o", "passenger", 1.0, 0.2, 0.1, 10.0, 4.5, 1.8)
    q = between(b0, b1, 0.025, 0.1)
    assert (q.x_m, q.y_m, q.yaw_rad) == pytest.approx((0.25, 0.05, 0.025), abs=1e-12)
    # heading across +-pi turns the short way
    c0 = Body("o", "passenger", 0.0, 0.0, math.pi - 0.05, 10.0, 4.5, 1.8)
    c1 = Body("o", "passenger", -1.0, 0.0, -math.pi + 0.05, 10.0, 4.5, 1.8)
    assert between(c0, c1, 0.05, 0.1).yaw_rad == pytest.approx(math.pi, abs=1e-12)


def test_a_standing_road_user_is_the_same_object():
    b = _car("p", 3.0, 0.0, 0.0, parked=True)
    assert interpolate_reports([b], [b], 0.07, 0.1)[0] is b


def test_a_new_road_user_is_as_sumo_reported_it():
    a0, a1 = _car("a", 0.0, 0.0, 10.0), _car("a", 1.0, 0.0, 10.0)
    n = _car("n", 50.0, 0.0, 10.0)
    got = interpolate_reports([a0], [a1, n], 0.05, 0.1)
    assert got[0].x_m == pytest.approx(0.5)
    assert got[1] is n


def test_the_ego_carried_on_ahead():
    # 20 m/s braking at 5 m/s^2 heading +y, yaw rate 0.1 rad/s, 90 ms on
    x = [1.0, 2.0, math.pi / 2, 20.0, 0.0, 0.1]
    X, Y, yaw, v = ego_ahead(x, -5.0, 0.09)
    assert pytest.approx((1.0, 2.0 + 20.0 * 0.09 - 2.5 * 0.09**2), abs=1e-12) == (X, Y)
    assert (yaw, v) == pytest.approx((math.pi / 2 + 0.009, 19.55), abs=1e-12)


def test_head_on_contact_between_sumo_steps_is_timed_by_the_interpolation():
    """The ego at 15 m/s and a car at 10 m/s head-on, boxes 2.0 m apart at SUMO's report at
    t0, the car reported again 100 ms later: they touch 2.0 / 25 = 80 ms after t0, between
    SUMO's steps; the control steps (10 ms) with their 1 ms sub-steps find it at 80 ms, on the
    car interpolated between the reports."""
    p = ego_e_class_sedan()
    front = p.cg_to_front_bumper_m
    x_ego = [0.0, 0.0, 0.0, 15.0, 0.0, 0.0]  # CG at 0, front bumper at `front`
    gap0 = 2.0
    car0 = _car("o", front + gap0 + 2.25, math.pi, 10.0)  # its front 2.0 m ahead of the ego's
    car1 = _car("o", car0.x_m - 1.0, math.pi, 10.0)
    dt, k = 0.01, 10
    before = car0
    for j in range(1, k + 1):
        x_next = [15.0 * dt * j, 0.0, 0.0, 15.0, 0.0, 0.0]
        (now,) = interpolate_reports([car0], [car1], dt * j, 0.1)
        found = substep_contact(x_ego, x_next, now, before, p.length_m, p.width_m, front, 10)
        if found is not None:
            break
        x_ego, before = x_next, now
    assert found is not None
    assert j == 8  # the control step ending at 80 ms
    ego_box, car_box = found[1], found[2]
    # when the boxes were found touching: the ego's front travelled at 15 m/s
    t_contact_s = (ego_box.x_m + 0.5 * p.length_m - front) / 15.0
    assert t_contact_s == pytest.approx(gap0 / 25.0, abs=1.001e-3)
    # the car placed by the interpolation then: its front 10 m/s x t nearer
    assert car_box.x_m - 2.25 == pytest.approx(front + gap0 - 10.0 * t_contact_s, abs=1e-9)
    overlap = (ego_box.x_m + 0.5 * p.length_m) - (car_box.x_m - 2.25)
    assert -1e-9 <= overlap <= 25.0 * 0.001 + 1e-9


def test_sumo_step_settings_are_checked():
    assert RunSettings(sumo_step_s=0.1).sumo_every == 10
    assert RunSettings().sumo_every == 1
    assert RunSettings().sumo_step_length_s == 0.01
    for bad in (0.015, 0.2, 0.005):
        with pytest.raises(ValueError, match="sumo_step_s"):
            RunSettings(sumo_step_s=bad)
    assert check_sumo_step_s(0.05, "x") == 0.05
    for bad in (0.0, 0.11, 0.025, "0.1", True, math.nan):
        with pytest.raises(InputError, match="--sumo-step-s"):
            check_sumo_step_s(bad, "--sumo-step-s")
