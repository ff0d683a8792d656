"""Wheelspin, a car rolling backwards, lifted wheels, and the ESC braking through the ABS.

Independent truths: the friction bound of a stop ``v^2 / (2 mu g)``, the engine's power at
the wheels ``F omega r_w <= P``, a coasting car's symmetry forwards and backwards, the weight
that the four loads carry, and the sine with dwell's yaw-rate ratios (FMVSS 126 S5.2)."""

import dataclasses
import itertools
import math

import pytest

from eoam_sumo.params import G_MPS2
from eoam_sumo.plant import STATE_NAMES, Plant, initial_state
from eoam_sumo.plant.model import tyre_loads_n
from eoam_sumo.plant.ops import FLOAT_OPS
from eoam_sumo.vehicle_files import load_vehicle

S = {name: i for i, name in enumerate(STATE_NAMES)}
SPINS = [S[f"wheel_spin_{w}_radps"] for w in ("fl", "fr", "rl", "rr")]


@pytest.fixture(scope="module")
def equipped_params(r13h_params):
    return dataclasses.replace(r13h_params, abs_fitted=True, esc_fitted=True)


@pytest.fixture(scope="module")
def equipped_plant(equipped_params, plant_cache_dir):
    return Plant(equipped_params, dt_s=1e-3, substeps=10, cache_dir=plant_cache_dir)


def _drive(plant, x, u, mu, seconds):
    xs = [x]
    for _ in range(round(seconds / 0.01)):
        x, _y = plant.advance(x, list(u), mu)
        xs.append(x)
    return x, xs


def _distance_m(xs) -> float:
    return sum(
        math.hypot(b[S["x_m"]] - a[S["x_m"]], b[S["y_m"]] - a[S["y_m"]])
        for a, b in itertools.pairwise(xs)
    )


@pytest.mark.parametrize(
    "vehicle, drive_g",
    [("sedan-r13h", 0.06), ("sedan-r13h", 0.15), ("compact", 0.15), ("suv", 0.15)],
)
def test_after_wheelspin_on_ice_the_abs_still_stops_the_car(vehicle, drive_g, plant_cache_dir):
    """Throttle that spins the driven wheels (rear, front, all four), then full brake: the
    speed estimate must not follow the spinning wheels, or the ABS reads every wheel as
    locked and dumps the brakes."""
    p = dataclasses.replace(load_vehicle(vehicle), abs_fitted=True, esc_fitted=True)
    plant, mu = Plant(p, dt_s=1e-3, substeps=10, cache_dir=plant_cache_dir), 0.1
    x = [float(v) for v in initial_state(0.0, 0.0, 0.0, 15.0, params=p)]
    x, _ = _drive(plant, x, (0.0, drive_g * p.mass_kg * G_MPS2, 0.0), mu, 2.0)
    v0 = x[S["vx_mps"]]
    x, xs = _drive(plant, x, (0.0, 0.0, p.max_brake_force_n), mu, 25.0)
    assert x[S["vx_mps"]] < 0.1
    assert _distance_m(xs) <= 1.15 * v0 * v0 / (2.0 * mu * G_MPS2)


def test_full_throttle_on_ice_delivers_no_more_than_the_engines_power(
    equipped_plant, equipped_params
):
    p = equipped_params
    x = [float(v) for v in initial_state(0.0, 0.0, 0.0, 10.0, params=p)]
    x, xs = _drive(equipped_plant, x, (0.0, p.max_drive_force_n, 0.0), 0.1, 5.0)
    for state in xs[50:]:
        wheel_mps = max(state[i] for i in SPINS[2:]) * p.wheel_radius_m  # driven: the rear
        delivered_n = min(state[S["drive_force_n"]], p.max_drive_force_n)
        assert min(delivered_n, p.max_drive_power_w / max(wheel_mps, 1.0)) * wheel_mps <= (
            p.max_drive_power_w * 1.001
        )
    # the spin levels off where the power left for the tyre's friction force is spent: at
    # P / (mu Fz) of the driven (rear) axle's static load, not without bound
    rear_load_n = p.mass_kg * G_MPS2 * p.cg_to_front_m / p.wheelbase_m
    levelled_mps = p.max_drive_power_w / (0.1 * rear_load_n)
    assert max(xs[-1][i] for i in SPINS) * p.wheel_radius_m < 1.5 * levelled_mps


def test_a_car_rolling_backwards_coasts_as_one_rolling_forwards(plant, params):
    ends = []
    for v0 in (10.0, -10.0):
        x = [float(v) for v in initial_state(0.0, 0.0, 0.0, abs(v0), params=params)]
        x[S["vx_mps"]] = v0
        for i in SPINS:
            x[i] = v0 / params.wheel_radius_m
        x, _ = _drive(plant, x, (0.0, 0.0, 0.0), 1.0, 2.0)
        ends.append(x[S["vx_mps"]])
    assert ends[0] == pytest.approx(-ends[1], rel=1e-4)  # it stopped in 1.4 s before
    assert 9.5 < ends[0] < 10.0


@pytest.mark.parametrize(
    "ax_mps2, ay_mps2", [(-40.0, 0.0), (30.0, 0.0), (0.0, 25.0), (-25.0, -20.0), (8.0, 40.0)]
)
def test_the_loads_carry_the_weight_whatever_lifts(r13h_params, ax_mps2, ay_mps2):
    """Accelerations that lift wheels (load transfer past the static load): no load below
    zero, and none made up: the four add up to the weight."""
    p = r13h_params
    x = [0.0] * len(STATE_NAMES)
    x[S["ax_load_mps2"]], x[S["ay_load_mps2"]] = ax_mps2, ay_mps2
    loads = tyre_loads_n(x, p, FLOAT_OPS)
    assert min(loads) >= 0.0
    assert sum(loads) == pytest.approx(p.mass_kg * G_MPS2, rel=1e-12)


@pytest.mark.parametrize("vehicle, mu", [("sedan-r13h", 0.7), ("suv", 1.0), ("suv", 0.7)])
def test_the_esc_keeps_its_corrective_moment_through_the_abs(vehicle, mu):
    """FMVSS 126 S5.2's yaw-rate ratios (<= 0.35 at 1 s, <= 0.20 at 1.75 s after the dwell),
    dry and wet: the ABS must not dump the pressure the ESC applies in a slide, nor a wheel
    the ESC brakes pull the speed estimate down (the eAWD suv)."""
    from eoam_sumo.vehicle_tests.common import VehicleTestOptions
    from eoam_sumo.vehicle_tests.procedures import TESTS

    p = dataclasses.replace(load_vehicle(vehicle), abs_fitted=True, esc_fitted=True)
    runs = TESTS["sine-with-dwell"](p, VehicleTestOptions(mu=mu)).summary["figures"]["runs"]
    assert max(run["yaw_ratio_1s"] for run in runs) <= 0.35
    assert max(run["yaw_ratio_1.75s"] for run in runs) <= 0.20
