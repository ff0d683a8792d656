"""Steering compliance as a steer-angle correction: the road wheels turn back by
``Fy_f / k_s`` and the tyres' own curve stays as it is (Gillespie 1992 ch. 6)."""

from __future__ import annotations

import dataclasses

import pytest

from eoam_sumo.params import G_MPS2
from eoam_sumo.plant.chassis import constants
from eoam_sumo.vehicle_files import load_vehicle
from eoam_sumo.vehicle_tests.common import VehicleTestOptions
from eoam_sumo.vehicle_tests.procedures import TESTS

R13H = load_vehicle("sedan-r13h")  # front_steer_compliance 0.75
STIFF = dataclasses.replace(R13H, front_steer_compliance=1.0)


def test_the_compliance_is_the_steering_in_series_with_the_tyres():
    c, c_f = R13H.front_steer_compliance, R13H.cornering_stiffness_front_npr
    k_s = 1.0 / constants(R13H).steer_compliance_rad_per_n
    assert 1.0 / (1.0 / c_f + 1.0 / k_s) == pytest.approx(c * c_f, rel=1e-12)
    assert constants(STIFF).steer_compliance_rad_per_n == 0.0


def test_the_tyre_curve_does_not_change_with_the_compliance():
    assert constants(R13H).lky_front == constants(STIFF).lky_front


def test_the_understeer_gradient_grows_as_the_linear_theory_says_and_the_peak_stays():
    """K = m (b / (c C_f) - a / C_r) / L [rad per m/s2]: the compliance adds
    m b (1 / c - 1) / (C_f L); the peak lateral acceleration is the tyres' (within 3 %)."""
    stiff = TESTS["ramp-steer"](STIFF, VehicleTestOptions()).summary["figures"]
    soft = TESTS["ramp-steer"](R13H, VehicleTestOptions()).summary["figures"]
    p = R13H
    added = p.mass_kg * p.cg_to_rear_m * (1.0 / p.front_steer_compliance - 1.0)
    added_deg_per_g = added / (p.cornering_stiffness_front_npr * p.wheelbase_m) * G_MPS2
    added_deg_per_g *= 180.0 / 3.141592653589793
    got = soft["understeer_gradient_deg_per_g"] - stiff["understeer_gradient_deg_per_g"]
    assert got == pytest.approx(added_deg_per_g, rel=0.1)
    assert soft["peak_lateral_acceleration_mps2"] == pytest.approx(
        stiff["peak_lateral_acceleration_mps2"], rel=0.03
    )
