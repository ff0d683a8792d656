"""Steering law (eq. 38): feedforward against the steady-state bicycle, schedule, stability."""

import math

import numpy as np
import pytest

from eoam_sumo.control import SteeringController, SteeringGains, understeer_gradient
from eoam_sumo.params import ego_e_class_sedan

P = ego_e_class_sedan()


def steady_state_steer(v, radius):
    """Road-wheel angle of the linear single-track model in steady cornering (force balance)."""
    m, a, b = P.mass_kg, P.cg_to_front_m, P.cg_to_rear_m
    cf, cr = P.cornering_stiffness_front_npr, P.cornering_stiffness_rear_npr
    r = v / radius
    fyf = m * v * r * b / (a + b)  # moment balance a*Fyf = b*Fyr, sum = m v r
    fyr = m * v * r * a / (a + b)
    vy = b * r - v * fyr / cr  # rear slip angle alpha_r = -(vy - b r)/v = fyr / cr
    return fyf / cf + (vy + a * r) / v  # alpha_f = delta - (vy + a r)/v


@pytest.mark.parametrize("v", [5.0, 15.0, 33.3, 45.8])
@pytest.mark.parametrize("radius", [50.0, 200.0, -400.0])
def test_feedforward_is_the_steady_state_steer(v, radius):
    ctrl = SteeringController(P)
    _delta, ff, fb, yd, e_la = ctrl.command(
        v, v / radius, 0.0, 0.0, 1.0 / radius, 1.0 / radius, 1.0
    )
    assert fb == 0.0 and yd == 0.0 and e_la == 0.0
    assert ff == pytest.approx(steady_state_steer(v, radius), rel=1e-9)


def test_feedforward_uses_the_preview_curvature_and_yaw_damping_the_current_one():
    ctrl = SteeringController(P)
    v, k_now, k_ahead = 30.0, 0.002, 0.005
    _, ff, _, yd, _ = ctrl.command(v, v * k_now, 0.0, 0.0, k_now, k_ahead, 1.0)
    assert ff == pytest.approx(steady_state_steer(v, 1.0 / k_ahead), rel=1e-9)
    assert yd == 0.0  # yaw rate equals v times the curvature here
    # and the steady lateral acceleration of the feedforward angle is v^2 kappa
    assert ctrl.lateral_accel(v, ff) == pytest.approx(v * v * k_ahead, rel=1e-9)


def test_understeer_gradient_sign_and_value():
    # b / Cf > a / Cr for this car: mildly understeering, about 0.04 deg/(m/s^2)
    k = understeer_gradient(P)
    assert 0.0 < math.degrees(k) < 0.2


def test_feedback_and_yaw_damping_oppose_the_error():
    ctrl = SteeringController(P)
    _, _, fb, _, e_la = ctrl.command(30.0, 0.0, 0.5, 0.0, 0.0, 0.0, 1.0)
    assert e_la == pytest.approx(0.5) and fb < 0.0  # left of the path: steer right
    _, _, fb2, _, e_la2 = ctrl.command(30.0, 0.0, 0.0, 0.02, 0.0, 0.0, 1.0)
    assert e_la2 > 0.0 and fb2 < 0.0  # heading left of the path: steer right
    _, _, _, yd, _ = ctrl.command(30.0, 0.1, 0.0, 0.0, 0.0, 0.0, 1.0)
    assert yd < 0.0


def test_clipped_to_the_steering_lock():
    ctrl = SteeringController(P)
    delta, *_ = ctrl.command(10.0, 0.0, -50.0, 0.0, 0.0, 0.0, 1.0)
    assert delta == P.max_steer_rad
    delta, *_ = ctrl.command(10.0, 0.0, 50.0, 0.0, 0.0, 0.0, 1.0)
    assert delta == -P.max_steer_rad


@pytest.mark.parametrize("v", [3.0, 8.0, 20.0, 33.3, 45.8])
@pytest.mark.parametrize("mu", [1.0, 0.3, 0.1])
def test_schedule_places_the_kinematic_error_poles(v, mu):
    """e' = v psi, psi' = v delta / (L + K v^2): s^2 + 2 zeta omega s + omega^2 at any speed."""
    g = SteeringGains()
    ctrl = SteeringController(P, g)
    k, x = ctrl.schedule(v, mu)
    v_s = max(v, g.schedule_min_speed_mps)  # the schedule's speed floor
    l_eff = P.wheelbase_m + understeer_gradient(P) * v_s * v_s
    a = np.array([[0.0, v_s], [-v_s * k / l_eff, -v_s * k * x / l_eff]])
    omega = g.natural_freq_radps * mu**g.friction_exponent
    omega *= min(1.0, v_s / g.full_bandwidth_speed_mps)
    assert ctrl.natural_freq(v, mu) == pytest.approx(omega, rel=1e-12)
    assert np.poly(a) == pytest.approx([1.0, 2.0 * g.damping_ratio * omega, omega**2], rel=1e-6)


def linear_closed_loop(v, mu, stiffness_scale):
    """Linear single-track model + steering lag closed by eq. 38 (states e, psi, vy, r, delta)."""
    g = SteeringGains()
    k, x = SteeringController(P, g).schedule(v, mu)
    m, iz, a, b = P.mass_kg, P.yaw_inertia_kgm2, P.cg_to_front_m, P.cg_to_rear_m
    cf = P.cornering_stiffness_front_npr * stiffness_scale
    cr = P.cornering_stiffness_rear_npr * stiffness_scale
    lag = P.steer_lag_s
    A = np.zeros((5, 5))
    A[0, 1], A[0, 2], A[1, 3] = v, 1.0, 1.0
    A[2, 2], A[2, 3], A[2, 4] = -(cf + cr) / (m * v), -v - (a * cf - b * cr) / (m * v), cf / m
    A[3, 2] = -(a * cf - b * cr) / (iz * v)
    A[3, 3], A[3, 4] = -(a * a * cf + b * b * cr) / (iz * v), a * cf / iz
    A[4, 0], A[4, 1], A[4, 3], A[4, 4] = -k / lag, -k * x / lag, -g.yaw_damping_s / lag, -1 / lag
    return np.linalg.eigvals(A)


@pytest.mark.parametrize("v", [10.0, 15.3, 25.0, 33.3, 45.8])
@pytest.mark.parametrize("mu", [1.0, 0.7, 0.3, 0.1])
@pytest.mark.parametrize("stiffness_with_mu", [False, True])
def test_closed_loop_linear_bicycle_is_stable(v, mu, stiffness_with_mu):
    poles = linear_closed_loop(v, mu, mu if stiffness_with_mu else 1.0)
    assert poles.real.max() < -0.03


def test_gains_validate():
    with pytest.raises(ValueError, match="natural_freq"):
        SteeringGains(natural_freq_radps=0.0)
    with pytest.raises(ValueError, match="yaw_damping"):
        SteeringGains(yaw_damping_s=math.nan)
