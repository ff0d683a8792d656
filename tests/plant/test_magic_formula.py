"""Our Magic Formula against CommonRoad's (package ``vehiclemodels``, an independent
implementation; test dependency only) point by point on their tyre set, and the plant's
adaptations: the friction ellipse, the road's friction through LMUX/LMUY.

Where the formulas differ by design the comparison puts theirs in ours: CommonRoad's
cornering stiffness is ``PKY1 Fz`` (ours MF 5.2's ``PKY1 Fz0 sin(2 atan(Fz / (PKY2 Fz0)))``,
passed in as ``kya``), they have no load variation (our ``dfz`` terms zeroed), and their
longitudinal vertical shift ``S_vx`` is added inside the sine (ours outside, as Pacejka 2012
eq. 4.E10; ``PVX1`` zeroed for the comparison) and they omit PEX4 (drive/brake asymmetry of
the curvature). Their slip sign is opposite (``kappa`` is negated inside their
``formula_longitudinal``)."""

import dataclasses
import math

import numpy as np
import pytest

pytest.importorskip("vehiclemodels")
from vehiclemodels.utils import tire_model as cr
from vehiclemodels.utils.tireParameters import TireParameters

from eoam_sumo.plant.magic_formula import (
    PAC2002_235_60R16,
    axle_forces,
    combined_fx,
    combined_fy,
    peak_slip,
    pure_fx,
    pure_fy,
)
from eoam_sumo.plant.ops import FLOAT_OPS

NO_LOAD_VARIATION = dict.fromkeys(
    (
        "pdx2",
        "pex2",
        "pex3",
        "pex4",
        "pkx2",
        "pkx3",
        "phx2",
        "pvx1",
        "pvx2",
        "rex2",
        "pdy2",
        "pey2",
    ),
    0.0,
) | dict.fromkeys(("phy1", "phy2", "pvy1", "pvy2", "rey2", "rhy2", "rvy2", "pey3"), 0.0)
OURS = dataclasses.replace(PAC2002_235_60R16, **NO_LOAD_VARIATION)


def theirs() -> TireParameters:
    names = [f.name for f in dataclasses.fields(TireParameters)]
    values = {n: getattr(OURS, n.replace("_", ""), 0.0) for n in names}
    values |= {"p_dx3": 0.0, "p_dy3": 0.0, "p_hy3": 0.0, "p_vy3": 0.0, "r_vy3": 0.0}
    return TireParameters(**values)


KAPPAS = [-1.0, -0.3, -0.12, -0.05, -0.01, 0.0, 0.02, 0.08, 0.2, 0.6]
ALPHAS = [-0.3, -0.1, -0.04, -0.01, 0.0, 0.005, 0.03, 0.12, 0.25]
LOADS = [1500.0, 4850.0, 7000.0]


@pytest.mark.parametrize("fz", LOADS)
def test_pure_longitudinal_force_is_commonroads(fz):
    p = theirs()
    for kappa in KAPPAS:
        ours = pure_fx(kappa, fz, 1.0, OURS, FLOAT_OPS).force_n
        assert ours == pytest.approx(
            cr.formula_longitudinal(-kappa, 0.0, fz, p), rel=1e-12, abs=1e-9
        )


@pytest.mark.parametrize("fz", LOADS)
def test_pure_lateral_force_is_commonroads(fz):
    p = theirs()
    for alpha in ALPHAS:
        ours = pure_fy(alpha, fz, 1.0, 1.0, OURS, FLOAT_OPS, kya=OURS.pky1 * fz)
        want, mu = cr.formula_lateral(alpha, 0.0, fz, p)
        assert ours.force_n == pytest.approx(want, rel=1e-12, abs=1e-9)
        assert ours.mu == pytest.approx(mu, rel=1e-12)


@pytest.mark.parametrize("fz", LOADS)
def test_combined_slip_forces_are_commonroads(fz):
    p = theirs()
    for kappa in KAPPAS:
        for alpha in ALPHAS:
            fx0 = pure_fx(kappa, fz, 1.0, OURS, FLOAT_OPS).force_n
            fy0 = pure_fy(alpha, fz, 1.0, 1.0, OURS, FLOAT_OPS, kya=OURS.pky1 * fz)
            want_x = cr.formula_longitudinal_comb(kappa, alpha, fx0, p)
            want_y = cr.formula_lateral_comb(kappa, alpha, 0.0, fy0.mu, fz, fy0.force_n, p)
            got_x = combined_fx(kappa, alpha, fz, fx0, OURS, FLOAT_OPS)
            got_y = combined_fy(kappa, alpha, fz, fy0, OURS, FLOAT_OPS)
            assert got_x == pytest.approx(want_x, rel=1e-12, abs=1e-9)
            assert got_y == pytest.approx(want_y, rel=1e-12, abs=1e-9)


def test_load_sensitivity_lowers_the_friction_coefficient_with_load():
    tyre = PAC2002_235_60R16.symmetric()
    mus = [pure_fx(0.15, fz, 1.0, tyre, FLOAT_OPS).mu for fz in (2000.0, 4850.0, 8000.0)]
    assert mus[0] > mus[1] > mus[2]
    assert mus[1] == pytest.approx(tyre.pdx1)


@pytest.mark.parametrize("mu", [0.1, 0.3, 0.7, 1.0, 1.2])
def test_axle_forces_keep_inside_the_friction_ellipse_and_scale_with_mu(mu):
    tyre = PAC2002_235_60R16.symmetric()
    worst = 0.0
    for fz in (300.0, 2500.0, 4850.0, 8000.0):
        dfz = (fz - tyre.fz0) / tyre.fz0
        dx = (tyre.pdx1 + tyre.pdx2 * dfz) / tyre.pdx1 * mu * fz
        dy = (tyre.pdy1 + tyre.pdy2 * dfz) / tyre.pdy1 * mu * fz
        for kappa in np.linspace(-1.0, 1.0, 41):
            for alpha in np.radians(np.linspace(-25.0, 25.0, 41)):
                left, right = axle_forces(
                    (kappa, -kappa), math.tan(alpha), (fz, fz), mu, 1.0, tyre, FLOAT_OPS
                )
                for t in (left, right):
                    assert t.dx_n == pytest.approx(dx) and t.dy_n == pytest.approx(dy)
                    worst = max(worst, math.hypot(t.fx_n / dx, t.fy_n / dy))
    assert worst <= 1.0 + 1e-12
    assert worst > 0.98  # the peak is reached


def test_the_braking_peak_slip_of_the_set():
    assert 0.1 <= peak_slip(PAC2002_235_60R16) <= 0.2
