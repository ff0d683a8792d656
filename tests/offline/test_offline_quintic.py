"""Quintic lane-change path and its arc-length parameterisation (paper eqs. 7-13)."""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from eoam_sumo.offline.design import QUINTIC_PEAK_COEFF, DesignSettings
from eoam_sumo.offline.quintic import quintic_lateral, quintic_path
from eoam_sumo.params import G_MPS2

H = 3.5


def test_peak_lateral_acceleration_is_5_77_h_over_t_squared():
    for duration in (1.5, 2.5, 5.0):
        t = np.linspace(0.0, duration, 200001)
        ddy = quintic_lateral(t, duration, H)[2]
        assert np.abs(ddy).max() == pytest.approx(
            10.0 * math.sqrt(3.0) / 3.0 * H / duration**2, rel=1e-8
        )
        # the peak sits at tau = (3 - sqrt 3) / 6 (closed form)
        t_peak = (3.0 - math.sqrt(3.0)) / 6.0 * duration
        assert quintic_lateral(t_peak, duration, H)[2] == pytest.approx(
            QUINTIC_PEAK_COEFF * H / duration**2, rel=1e-12
        )


def test_boundary_conditions_of_the_quintic():
    y, dy, ddy, _ = quintic_lateral(np.array([0.0, 2.0]), 2.0, H)
    assert y.tolist() == pytest.approx([0.0, H])
    assert dy.tolist() == pytest.approx([0.0, 0.0], abs=1e-12)
    assert ddy.tolist() == pytest.approx([0.0, 0.0], abs=1e-12)


def test_derivatives_match_finite_differences():
    t = np.linspace(0.1, 1.9, 50)
    e = 1e-6
    for k in range(3):
        hi = quintic_lateral(t + e, 2.0, H)[k]
        lo = quintic_lateral(t - e, 2.0, H)[k]
        assert quintic_lateral(t, 2.0, H)[k + 1] == pytest.approx(
            (hi - lo) / (2 * e), rel=1e-5, abs=1e-6
        )


def test_time_rule_ties_peak_lateral_acceleration_to_friction():
    s = DesignSettings()
    for mu in (1.0, 0.7, 0.3, 0.1):
        t = s.quintic_time_s(mu)
        assert QUINTIC_PEAK_COEFF * H / t**2 == pytest.approx(s.lat_accel_fraction * mu * G_MPS2)
    assert s.quintic_time_s(0.01) == s.max_quintic_time_s
    with pytest.raises(ValueError, match="mu"):
        s.quintic_time_s(0.0)


@pytest.mark.parametrize("speed,duration", [(25.0, 1.8), (8.0, 3.0), (45.0, 5.0)])
def test_arc_length_exceeds_chord_and_matches_quadrature(speed, duration):
    path = quintic_path(speed, duration, H, samples=401)

    def integrand(t):
        dy = quintic_lateral(t, duration, H)[1]
        return math.hypot(speed, float(dy))

    for i in (100, 250, 400):
        exact, _ = quad(integrand, 0.0, path.t_s[i], epsabs=1e-12, epsrel=1e-12)
        assert path.s_m[i] == pytest.approx(exact, rel=1e-10)
    chord = math.hypot(path.x_m[-1], path.y_m[-1])
    assert path.length_m > chord
    assert np.all(np.diff(path.s_m) > 0.0)


def test_curvature_integrates_to_path_yaw_and_position():
    """eqs. 10-12: theta = int K ds, x = int cos(theta) ds, y = int sin(theta) ds."""
    speed, duration = 15.0, 2.0
    path = quintic_path(speed, duration, H, samples=401)

    def ds_dt(t):
        return math.hypot(speed, float(quintic_lateral(t, duration, H)[1]))

    def curvature(t):
        _, dy, ddy, _ = quintic_lateral(t, duration, H)
        return speed * float(ddy) / (speed**2 + float(dy) ** 2) ** 1.5

    def theta(t):
        return math.atan2(float(quintic_lateral(t, duration, H)[1]), speed)

    for i in (60, 200, 330, 400):
        t = path.t_s[i]
        yaw, _ = quad(lambda u: curvature(u) * ds_dt(u), 0.0, t, epsabs=1e-13, epsrel=1e-12)
        x, _ = quad(lambda u: math.cos(theta(u)) * ds_dt(u), 0.0, t, epsabs=1e-13)
        y, _ = quad(lambda u: math.sin(theta(u)) * ds_dt(u), 0.0, t, epsabs=1e-13)
        assert path.theta_rad[i] == pytest.approx(yaw, abs=1e-10)
        assert path.x_m[i] == pytest.approx(x, abs=1e-9)
        assert path.y_m[i] == pytest.approx(y, abs=1e-9)
    assert path.theta_rad[-1] == pytest.approx(0.0, abs=1e-12)


def test_curvature_derivative_matches_finite_difference_in_arc_length():
    path = quintic_path(20.0, 2.0, H, samples=20001)
    fd = np.gradient(path.curvature_1pm, path.s_m)
    inner = slice(10, -10)
    assert path.dcurvature_1pm2[inner] == pytest.approx(fd[inner], abs=1e-6)


def test_curvature_matches_graph_formula():
    """eq. 9: K = y''(x) / (1 + y'(x)^2)^(3/2) with y as a function of x = v t."""
    speed, duration = 12.0, 2.5
    path = quintic_path(speed, duration, H, samples=101)
    _, dy, ddy, _ = quintic_lateral(path.t_s, duration, H)
    yx, yxx = dy / speed, ddy / speed**2
    assert path.curvature_1pm == pytest.approx(yxx / (1.0 + yx**2) ** 1.5, rel=1e-12, abs=1e-15)


def test_bad_inputs_raise_value_error():
    with pytest.raises(ValueError, match="speed_mps"):
        quintic_path(0.0, 2.0, H)
    with pytest.raises(ValueError, match="duration_s"):
        quintic_lateral(1.0, -1.0, H)
