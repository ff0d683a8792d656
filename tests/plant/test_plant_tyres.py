"""The tyres: Fiala (the design's) against the textbook, the Magic Formula against CommonRoad's
formulas point by point on their tyre set, the friction ellipse; the CasADi form of the model."""

import dataclasses
import itertools
import math

import casadi
import numpy as np
import pytest

from eoam_sumo.plant import CASADI_OPS, FLOAT_OPS, INPUT_NAMES, STATE_NAMES, outputs, rhs
from eoam_sumo.plant.tyres import fiala_lateral_force_n

C_NPR = 133800.0
PEAK_N = 9000.0


def textbook_fiala(alpha_rad, c, f_max):
    """Pacejka (2012) sec. 3.2.2 / Hindiyeh & Gerdes (2014), the cubic up to full sliding."""
    t = math.tan(alpha_rad)
    if abs(t) >= 3 * f_max / c:
        return -f_max * math.copysign(1.0, t)
    return -c * t + c**2 / (3 * f_max) * abs(t) * t - c**3 / (27 * f_max**2) * t**3


@pytest.mark.parametrize("alpha_deg", [-20.0, -11.0, -5.0, -1.0, -0.01, 0.0, 0.3, 2.0, 8.0, 30.0])
def test_fiala_matches_the_textbook_cubic(alpha_deg):
    alpha = math.radians(alpha_deg)
    got = fiala_lateral_force_n(math.tan(alpha), C_NPR, PEAK_N, FLOAT_OPS)
    assert got == pytest.approx(textbook_fiala(alpha, C_NPR, PEAK_N), rel=1e-12, abs=1e-9)


def test_fiala_slope_at_zero_is_the_cornering_stiffness_and_it_saturates_at_the_peak():
    h = 1e-7
    slope = (fiala_lateral_force_n(h, C_NPR, PEAK_N, FLOAT_OPS)) / h
    assert slope == pytest.approx(-C_NPR, rel=1e-5)
    slips = np.tan(np.radians(np.linspace(0.0, 40.0, 401)))
    forces = [-fiala_lateral_force_n(t, C_NPR, PEAK_N, FLOAT_OPS) for t in slips]
    assert max(forces) == pytest.approx(PEAK_N, rel=1e-12)
    assert all(b >= a for a, b in itertools.pairwise(forces))  # monotone up to full sliding


@pytest.mark.parametrize("esc", [False, True])
def test_casadi_form_of_the_model_equals_the_float_form(params, esc):
    params = dataclasses.replace(
        params, esc_fitted=esc, abs_fitted=esc, drivetrain="eawd", front_steer_compliance=0.75
    )
    x = casadi.MX.sym("x", len(STATE_NAMES))
    u = casadi.MX.sym("u", len(INPUT_NAMES))
    mu = casadi.MX.sym("mu")
    xs = [x[i] for i in range(len(STATE_NAMES))]
    us = [u[i] for i in range(len(INPUT_NAMES))]
    fn = casadi.Function(
        "f", [x, u, mu],
        [casadi.vertcat(*rhs(xs, us, mu, params, CASADI_OPS)),
         casadi.vertcat(*outputs(xs, mu, params, CASADI_OPS))],
    )  # fmt: skip
    rng = np.random.default_rng(3)
    for _ in range(30):
        lo = [-50, -50, -3, 0, -2, -0.8, -0.6, 0, *[0] * 8, *[-1] * 4, -0.5, -0.5, -9, -9, -5e3, -1]
        hi = [50, 50, 3, 45, 2, 0.8, 0.6, 7000, *[150] * 4, *[140] * 4, *[1] * 4, 0.5, 0.5, 9, 9]
        hi.extend([5e3, 1.0])
        lo.extend([0.0, 0.05, -0.3])  # the estimates: speed, friction, sideslip
        hi.extend([45.0, 1.2, 0.3])
        lo.extend([0.0] * 4)  # the ABS valves' cuts
        hi.extend([4500.0] * 4)
        xv = rng.uniform(lo, hi)
        uv = rng.uniform([-0.7, 0, 0], [0.7, 7000, 22000])
        muv = rng.uniform(0.1, 1.2)
        dx, y = fn(xv, uv, muv)
        np.testing.assert_allclose(
            dx.full().ravel(), rhs(list(xv), list(uv), muv, params, FLOAT_OPS), rtol=1e-12,
            atol=1e-9,
        )  # fmt: skip
        np.testing.assert_allclose(
            y.full().ravel(), outputs(list(xv), muv, params, FLOAT_OPS), rtol=1e-12, atol=1e-9
        )
