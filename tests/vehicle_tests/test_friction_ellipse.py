"""No tyre ever gives more than its friction: at every recorded step of every standard test
(and of a full brake application with the hand wheel at 90 deg, the review's case), each
tyre's force lies inside its own friction ellipse, ``sqrt((Fx/Dx)^2 + (Fy/Dy)^2) <= 1``
(``Dx``, ``Dy`` its pure-slip peaks at its load on this road), and ``|F| / (mu Fz)`` within
the Magic Formula's own load sensitivity of the road's mu."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eoam_sumo.plant.magic_formula import FZ_MIN_N, PAC2002_235_60R16
from eoam_sumo.vehicle_files import load_vehicle
from eoam_sumo.vehicle_tests.common import VehicleTestOptions
from eoam_sumo.vehicle_tests.equipment import equipped
from eoam_sumo.vehicle_tests.harness import Controls, PlantVehicle, simulate
from eoam_sumo.vehicle_tests.procedures import TESTS

ELLIPSE_TOLERANCE = 1e-9
"""Rounding only: the plant scales each tyre's force onto its ellipse exactly."""


def _load_sensitivity_ceiling() -> float:
    """The largest ``mu_tyre(Fz) / mu`` of the tyre set: PDX2, PDY2 < 0 give a lightly loaded
    tyre (down to the formulas' floor ``FZ_MIN_N``) a peak above the road's nominal mu."""
    c = PAC2002_235_60R16.symmetric()
    dfz = (FZ_MIN_N - c.fz0) / c.fz0
    return max((c.pdx1 + c.pdx2 * dfz) / c.pdx1, (c.pdy1 + c.pdy2 * dfz) / c.pdy1)


USE_CEILING = _load_sensitivity_ceiling() + ELLIPSE_TOLERANCE


def _assert_inside(runs) -> None:
    for run in runs:
        ellipse, use = run["friction_ellipse_max"][1:], run["friction_use_max"][1:]
        assert np.isfinite(ellipse).all()
        assert ellipse.max() <= 1.0 + ELLIPSE_TOLERANCE, run.label
        assert use.max() <= USE_CEILING, run.label


R13H_ON = equipped(load_vehicle("sedan-r13h"), True, True)


@pytest.mark.parametrize("test", sorted(TESTS))
def test_every_standard_test_keeps_each_tyre_inside_its_ellipse(test):
    _assert_inside(TESTS[test](R13H_ON, VehicleTestOptions()).runs)


@pytest.mark.parametrize("mu", [1.0, 0.3])
@pytest.mark.parametrize("esc", [True, False])
def test_brake_in_turn_keeps_each_tyre_inside_its_ellipse(mu, esc):
    params = equipped(load_vehicle("sedan-r13h"), esc, esc)
    _assert_inside(TESTS["brake-in-turn"](params, VehicleTestOptions(mu=mu)).runs)


@pytest.mark.parametrize("mu", [1.0, 0.3])
def test_full_braking_with_the_wheel_at_90_deg_and_esc_stays_inside(mu):
    """The review's case (1.96 before ESC went through the wheels): 80 km/h, full brake, the
    hand wheel at 90 deg; the car's total acceleration is bounded by the road as well."""
    steer = math.radians(90.0) / R13H_ON.steering_ratio
    full = R13H_ON.max_brake_force_n
    run = simulate(
        PlantVehicle(R13H_ON),
        80.0 / 3.6,
        lambda t, s: Controls(steer * min(t / 0.2, 1.0), 0.0, full),
        6.0,
        mu,
        stop=lambda t, s: s.vx_mps < 1.0,
    )
    _assert_inside([run])
    total = np.hypot(run["ax_mps2"], run["ay_mps2"]) / (mu * 9.81)
    assert total.max() <= USE_CEILING
