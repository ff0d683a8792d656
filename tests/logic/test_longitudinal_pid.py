"""Longitudinal controllers: force split, limits, PID convergence on a lagged point mass."""

import math
from dataclasses import replace

import pytest

from eoam_sumo.control import LongitudinalController, LongitudinalGains, Pid
from eoam_sumo.params import ego_e_class_sedan

P = ego_e_class_sedan()
#: the mass the forces move: the body and its four wheels spinning with it (the plant's wheels)
M_EQ = P.mass_kg + 4.0 * P.wheel_inertia_kgm2 / P.wheel_radius_m**2


def resistance_n(v):
    """Rolling resistance and drag, written out independently of the controller."""
    return (
        P.mass_kg * 9.81 * P.rolling_resistance_coeff + 0.5 * 1.2 * P.drag_area_m2 * v * v
        if v > 0.0
        else 0.0
    )


def point_mass(ctrl_fn, v0, seconds, dt=0.01, sub=10):
    """m_eq v' = F_drive - F_brake - F_res with first-order actuator lags (the plant's
    actuators and its wheels' inertia)."""
    v, fd, fb, ax = v0, 0.0, 0.0, 0.0
    trace = []
    for k in range(round(seconds / dt)):
        drive, brake = ctrl_fn(k * dt, v, ax)
        assert drive >= 0.0 and brake >= 0.0 and drive * brake == 0.0
        h = dt / sub
        for _ in range(sub):
            fd += (drive - fd) * h / P.drive_lag_s
            fb += (brake - fb) * h / P.brake_lag_s
            ax = (fd - fb - resistance_n(v)) / M_EQ
            v += ax * h
        trace.append((k * dt, v, ax))
    return trace


def test_split_never_both_and_within_limits():
    split = LongitudinalController.split
    assert split(1000.0, 3000.0, 5000.0) == (1000.0, 0.0)
    assert split(-1000.0, 3000.0, 5000.0) == (0.0, 1000.0)
    assert split(-9000.0, 3000.0, 5000.0) == (0.0, 5000.0)
    assert split(9000.0, 3000.0, 5000.0) == (3000.0, 0.0)


def test_force_limits_engine_traction_and_friction_ellipse():
    c = LongitudinalController(P)
    g = LongitudinalGains()
    rear_load = P.mass_kg * 9.81 * P.cg_to_front_m / P.wheelbase_m
    # straight, low speed: the lesser of eq. 37 (mu times the engine force) and the traction share
    drive, brake = c.limits(10.0, 1.0, 0.0, 12000.0)
    assert drive == pytest.approx(min(P.max_drive_force_n, g.traction_fraction * rear_load))
    assert brake == 12000.0
    # power limit at speed
    assert c.limits(40.0, 1.0, 0.0, 1.0)[0] == pytest.approx(P.max_drive_power_w / 40.0)
    # on ice the rear axle's friction binds: a share of mu times its static load
    assert c.limits(20.0, 0.1, 0.0, 1.0)[0] == pytest.approx(0.1 * g.traction_fraction * rear_load)
    # lateral acceleration in use shrinks both by the friction ellipse
    ay = 0.5 * 9.81 / g.ellipse_margin
    d2, b2 = c.limits(10.0, 1.0, ay, 5000.0)
    assert b2 == pytest.approx(5000.0 * math.sqrt(0.75))
    assert d2 == pytest.approx(drive * math.sqrt(0.75))
    # without ABS the brake also stays below what locks the unloaded inner front wheel
    lock = c.wheel_lock_limit_n(10.0, 1.0, ay)
    assert lock < 12000.0 * math.sqrt(0.75)
    assert c.limits(10.0, 1.0, ay, 12000.0)[1] == pytest.approx(lock)
    assert (
        LongitudinalController(replace(P, abs_fitted=True)).wheel_lock_limit_n(10.0, 1.0, ay)
        == math.inf
    )
    # nothing left once the lateral acceleration uses all the friction
    assert c.limits(10.0, 0.3, 0.3 * 9.81, 12000.0) == (0.0, 0.0)


def test_resistance_feedforward_matches_the_closed_form():
    c = LongitudinalController(P)
    for v in (0.0, 5.0, 30.0, 45.8):
        assert c.resistance_n(v) == pytest.approx(resistance_n(v), rel=1e-12)


@pytest.mark.parametrize(("v0", "v_ref", "mu"), [(30.0, 33.3, 1.0), (25.0, 20.0, 0.3)])
def test_speed_pid_reaches_the_set_speed(v0, v_ref, mu):
    c = LongitudinalController(P)
    brake_limit = 0.8 * mu * P.mass_kg * 9.81
    trace = point_mass(
        lambda t, v, ax: c.track_speed(v_ref, v, mu, *c.limits(v, mu, 0.0, brake_limit), 0.01)[:2],
        v0,
        40.0,
    )
    final = [v for t, v, _ in trace if t > 35.0]
    assert max(abs(v - v_ref) for v in final) < 0.05
    # acceleration demand bounded by the comfort/traction limit
    lim = LongitudinalGains().speed_accel_limit_g * mu * 9.81
    assert max(abs(ax) for _, _, ax in trace) < lim + 0.1
    overshoot = max((v - v_ref) * math.copysign(1.0, v_ref - v0) for _, v, _ in trace)
    assert overshoot < 0.15


@pytest.mark.parametrize("mu", [1.0, 0.3])
def test_acceleration_pid_tracks_a_profile(mu):
    c = LongitudinalController(P)
    brake_limit = 0.8 * mu * P.mass_kg * 9.81

    def ref(t):
        return -4.0 * mu if t < 3.0 else 0.5 * mu

    trace = point_mass(
        lambda t, v, ax: c.track_accel(ref(t), ax, v, *c.limits(v, mu, 0.0, brake_limit), 0.01),
        30.0,
        6.0,
    )
    for t_lo, t_hi in ((1.5, 3.0), (4.5, 6.0)):
        errs = [abs(ax - ref(t)) for t, _, ax in trace if t_lo <= t < t_hi]
        assert max(errs) < 0.031


def test_acceleration_never_asks_above_the_brake_limit():
    c = LongitudinalController(P)
    for _ in range(200):
        drive, brake = c.track_accel(-20.0, 0.0, 30.0, 4000.0, 9000.0, 0.01)
        assert drive == 0.0 and brake == 9000.0


def test_pid_does_not_wind_up_while_clipped():
    pid = Pid(kp=1.0, ki=10.0, kd=0.0, i_limit=100.0)
    for _ in range(1000):
        assert pid.update(5.0, 0.01, -1.0, 1.0) == 1.0
    assert pid.integral <= 1.0  # integrated only while not pushing further into the clip
    # the error reverses: the output leaves the clip at once
    assert pid.update(-0.5, 0.01, -1.0, 1.0) < 1.0


def test_gains_validate():
    with pytest.raises(ValueError, match="accel_kp"):
        LongitudinalGains(accel_kp=-1.0)
    with pytest.raises(ValueError, match="speed_accel_limit_g"):
        LongitudinalGains(speed_accel_limit_g=0.0)
    with pytest.raises(ValueError, match="traction_fraction"):
        LongitudinalGains(traction_fraction=0.0)


def test_a_brake_force_decelerates_the_plant_as_the_equivalent_mass_says():
    """The plant braked straight at a constant force below the lock: its deceleration is the
    force (plus the resistance) over the body and its spinning wheels, as the controller's
    feedforward assumes (``equivalent_mass_kg``), not over the body alone."""
    from eoam_sumo.control import equivalent_mass_kg
    from eoam_sumo.plant import ReferencePlant, initial_state

    assert equivalent_mass_kg(P) == pytest.approx(M_EQ)
    plant = ReferencePlant(P)
    x = initial_state(0.0, 0.0, 0.0, 20.0, params=P)
    brake_n = 0.4 * P.mass_kg * 9.81
    for _ in range(100):  # 1 s: the line pressure settles
        x, y = plant.step(x, (0.0, 0.0, brake_n), 1.0)
    v = x[3]
    expected = -(brake_n + resistance_n(v)) / M_EQ
    assert y[0] == pytest.approx(expected, rel=0.01)
    assert abs(y[0] - expected) < 0.2 * abs(-(brake_n + resistance_n(v)) / P.mass_kg - expected)
