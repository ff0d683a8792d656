"""Inverse dynamics along a path (paper sec. 4.4, Figures 6-7) against closed forms and the
forward design model."""

import math

import numpy as np
import pytest

from eoam_sumo.offline.boundaries import max_decel_no_lock_mps2
from eoam_sumo.offline.inverse import inverse_dynamics
from eoam_sumo.offline.model import dynamics
from eoam_sumo.offline.quintic import ArcLengthPath, quintic_path
from eoam_sumo.params import G_MPS2, ego_e_class_sedan

P = ego_e_class_sedan()


def _arc(speed, radius, duration=2.0, n=401):
    """A circular arc (radius inf: a straight line) driven at constant speed."""
    t = np.linspace(0.0, duration, n)
    s = speed * t
    if math.isinf(radius):
        x, y, theta, k = s, 0 * s, 0 * s, 0 * s
    else:
        theta = s / radius
        x, y, k = radius * np.sin(theta), radius * (1 - np.cos(theta)), np.full(n, 1 / radius)
    return ArcLengthPath(speed, duration, 0.0, t, s, x, y, theta, k, np.zeros(n))


@pytest.mark.parametrize(
    "mu,speed,radius", [(1.0, 20.0, 150.0), (0.3, 25.0, 600.0), (0.7, 10.0, 60.0)]
)
def test_steady_cornering_matches_linear_bicycle_closed_form(mu, speed, radius):
    inv = inverse_dynamics(_arc(speed, radius), P, mu)
    cf, cr = mu * P.cornering_stiffness_front_npr, mu * P.cornering_stiffness_rear_npr
    k_us = P.mass_kg / P.wheelbase_m * (P.cg_to_rear_m / cf - P.cg_to_front_m / cr)
    steer = P.wheelbase_m / radius + k_us * speed**2 / radius
    assert inv.steer_rad[200] == pytest.approx(steer, rel=0.02)
    ay = speed**2 / radius
    assert inv.fy_front_n[200] + inv.fy_rear_n[200] == pytest.approx(P.mass_kg * ay, rel=0.01)
    # rear slip and sideslip of the linear model: alpha_r = m a_y a / (L Cr), beta = b/R - alpha_r
    alpha_r = P.mass_kg * ay * P.cg_to_front_m / (P.wheelbase_m * cr)
    assert inv.alpha_rear_rad[200] == pytest.approx(alpha_r, rel=0.01)
    assert inv.sideslip_rad[200] == pytest.approx(P.cg_to_rear_m / radius - alpha_r, abs=2e-4)
    assert inv.feasible.all()


@pytest.mark.parametrize("mu", [1.0, 0.7, 0.3, 0.1])
def test_straight_line_acceleration_limits_are_the_closed_forms(mu):
    speed = 20.0
    inv = inverse_dynamics(_arc(speed, math.inf), P, mu)
    assert inv.ax_min_mps2 == pytest.approx(-max_decel_no_lock_mps2(P, mu), rel=1e-9)
    # rear-drive traction with load transfer: D = mu m (g a + ax h) / L and ax = D / m
    traction = mu * G_MPS2 * P.cg_to_front_m / (P.wheelbase_m - mu * P.cg_height_m)
    engine = min(P.max_drive_force_n, P.max_drive_power_w / speed) / P.mass_kg
    assert inv.ax_max_mps2 == pytest.approx(min(traction, engine), rel=1e-9)


def test_cornering_narrows_the_acceleration_limits():
    straight = inverse_dynamics(_arc(20.0, math.inf), P, 0.7)
    curve = inverse_dynamics(_arc(20.0, 80.0), P, 0.7)  # 5 m/s^2 of the 6.9 available
    assert curve.ax_min_mps2[200] > straight.ax_min_mps2[200] + 0.5
    assert curve.ax_max_mps2[200] < straight.ax_max_mps2[200]


def test_infeasible_lateral_demand_is_flagged():
    hard = inverse_dynamics(quintic_path(20.0, 1.6, 3.5), P, 0.7)  # peak 7.9 > 6.9 m/s^2
    assert not hard.feasible.all() and hard.feasible.any()
    assert np.isnan(hard.ax_min_mps2[~hard.feasible]).all()
    assert np.isfinite(hard.ax_max_mps2[hard.feasible]).all()
    gentle = inverse_dynamics(quintic_path(20.0, 3.0, 3.5), P, 0.7)  # peak 2.2 m/s^2
    assert gentle.feasible.all()


@pytest.mark.parametrize(
    "speed,duration,mu", [(27.0, 2.2, 1.0), (10.0, 2.0, 1.0), (40.0, 5.0, 0.1), (15.0, 3.0, 0.7)]
)
def test_inverse_is_the_inverse_of_the_forward_design_model(speed, duration, mu):
    """At the inverse-dynamics state and steering, the forward model (model.dynamics) gives
    the path's lateral acceleration V^2 K and yaw acceleration d(V K)/dt."""
    path = quintic_path(speed, duration, 3.5, samples=401)
    inv = inverse_dynamics(path, P, mu)
    v = np.gradient(path.s_m, path.t_s)
    a_n = v**2 * path.curvature_1pm
    yaw_acc = np.gradient(v * path.curvature_1pm, path.t_s)
    ay_model, yaw_acc_model = [], []
    for i, th in enumerate(path.theta_rad):
        x = [
            0.0,
            v[i] * math.cos(th),
            0.0,
            v[i] * math.sin(th),
            inv.yaw_rad[i],
            inv.yaw_rate_radps[i],
            inv.steer_rad[i],
        ]
        xdot, out = dynamics(x, (0.0, 0.0), mu, P, math)
        ay_model.append(out.ay_body_mps2)
        yaw_acc_model.append(xdot[5])
    expected_ay = a_n * np.cos(inv.sideslip_rad)
    assert np.abs(np.array(ay_model) - expected_ay).max() < 0.02 * np.abs(a_n).max()
    assert np.abs(np.array(yaw_acc_model) - yaw_acc).max() < 0.02 * np.abs(yaw_acc).max()
    assert np.allclose(inv.yaw_rad, path.theta_rad - inv.sideslip_rad)
