"""The vehicle catalogue (``vehicles/``) on the standard tests: every vehicle but the paper's
own car locks its front axle first without ABS (UN R13-H Annex 5) and passes the sine with
dwell with ESC (FMVSS 126 / UN R140); the corrected sedan's dynamic index is a measured
passenger car's; the high vehicles have the lower static stability factors."""

from __future__ import annotations

import pytest

from eoam_sumo.params import G_MPS2
from eoam_sumo.vehicle_files import (
    catalogue,
    dynamic_index,
    load_vehicle,
    sources_of,
    static_stability_factor,
)
from eoam_sumo.vehicle_tests.common import VehicleTestOptions
from eoam_sumo.vehicle_tests.equipment import equipped
from eoam_sumo.vehicle_tests.procedures import TESTS

PAPERS_CAR = "sedan"
"""The paper's car, kept as published (its 65/35 brake split locks the rear first on dry)."""
CORRECTED = ["compact", "pickup", "sedan-r13h", "suv", "van"]
HIGH = ["pickup", "suv", "van"]


def test_the_catalogue_is_the_papers_car_and_the_corrected_vehicles():
    assert catalogue() == sorted([PAPERS_CAR, *CORRECTED])


@pytest.mark.parametrize("name", CORRECTED)
@pytest.mark.parametrize("mu", [1.0, 0.3])
def test_without_abs_the_front_axle_locks_first(name, mu):
    """UN R13-H Annex 5: front first (or together) for braking rates 0.15-0.8, on the ramp
    of Appendix 1 (first lock 0.5-1 s after braking begins, from 100 km/h, 65 km/h at mu 0.5
    or less); the lock comes below the road's friction (its peak at the loaded tyres)."""
    params = equipped(load_vehicle(name), abs_on=False, esc_on=False)
    summary = TESTS["brake-ramp"](params, VehicleTestOptions(mu=mu)).summary
    assert summary["speed_kmh"] == (100.0 if mu > 0.5 else 65.0)
    assert 0.5 <= summary["figures"]["first_lock_time_s"] <= 1.0
    assert summary["figures"]["first_locked_axle"] == "front"
    assert 0.75 * mu < summary["figures"]["front_lock_braking_rate"] <= 1.05 * mu
    assert summary["passed"] is True


@pytest.mark.parametrize("name", CORRECTED)
def test_the_brake_split_locks_the_front_first_up_to_the_regulations_braking_rate(name):
    """The closed form with a constant friction: the ideal front share ``(b + z h) / L`` lies
    below the fixed split for every braking rate up to 0.8 (UN R13-H Annex 5 para. 3.1.1)."""
    p = load_vehicle(name)
    ideal_at_08 = (p.cg_to_rear_m + 0.8 * p.cg_height_m) / p.wheelbase_m
    assert p.brake_front_share > ideal_at_08


@pytest.mark.parametrize("name", CORRECTED)
def test_with_esc_the_sine_with_dwell_passes(name):
    """FMVSS 126 S5.2: every amplitude's yaw-rate ratios (35 %, 20 %) and, from 5 A, the
    lateral displacement (1.83 m); the whole amplitude series at 80 km/h on mu 1.0."""
    params = equipped(load_vehicle(name), abs_on=False, esc_on=True)
    summary = TESTS["sine-with-dwell"](params, VehicleTestOptions()).summary
    failed = [c["name"] for c in summary["criteria"] if c["passed"] is not True]
    assert failed == []
    assert summary["passed"] is True
    assert not any(run["spun"] for run in summary["figures"]["runs"])


def test_the_corrected_sedans_dynamic_index_is_a_measured_cars():
    """k^2/(a b) of the NHTSA-measured passenger cars: close to 1 (SAE 1999-01-1336)."""
    assert 0.9 <= dynamic_index(load_vehicle("sedan-r13h")) <= 1.1
    assert dynamic_index(load_vehicle(PAPERS_CAR)) == pytest.approx(1.34, abs=0.01)


def test_the_static_stability_factor_is_half_the_track_over_the_cg_height():
    p = load_vehicle("van")
    assert static_stability_factor(p) == pytest.approx(1.5591 / (2 * 0.7478), rel=1e-6)
    rigid_tip_g = (p.track_m / 2) * p.mass_kg * G_MPS2 / (p.cg_height_m * p.mass_kg * G_MPS2)
    assert static_stability_factor(p) == pytest.approx(rigid_tip_g)


def test_the_high_vehicles_tip_at_a_lower_lateral_acceleration_than_the_cars():
    """The SUV, van and pickup: SSF 1.0-1.2 (NHTSA's light-truck range); the cars above."""
    cars = [static_stability_factor(load_vehicle(n)) for n in ("compact", "sedan-r13h")]
    for name in HIGH:
        ssf = static_stability_factor(load_vehicle(name))
        assert 1.0 <= ssf <= 1.2
        assert ssf < min(cars)


@pytest.mark.parametrize("name", CORRECTED)
def test_every_assumed_value_says_why(name):
    """A value without a published figure is labelled ``assumed:`` with its reasoning."""
    for key, source in sources_of(name).items():
        if source.startswith("assumed"):
            assert len(source.split(":", 1)[1].strip()) > 15, key


@pytest.mark.parametrize("name", CORRECTED)
def test_the_catalogue_vehicles_carry_their_equipment(name):
    p = load_vehicle(name)
    expected = {"compact": "fwd", "suv": "eawd", "van": "rwd", "pickup": "rwd", "sedan-r13h": "rwd"}
    assert p.drivetrain == expected[name]
    fitted = name != "sedan-r13h"  # the paper's sedan, corrected, keeps its lack of ABS/ESC
    assert p.abs_fitted is fitted and p.esc_fitted is fitted
