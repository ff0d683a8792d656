"""The plant's fixed step on vehicles whose wheel-and-tyre mode is fast: a light wheel on a
heavy vehicle's stiff, short-relaxation tyre.

Independent truths: a fixed-step integration that is stable converges, so a stop computed at
the 1 ms step and at a quarter of it agree; no stop is shorter than ``v^2 / (2 mu g)``.
"""

import dataclasses

import pytest

from eoam_sumo.params import G_MPS2
from eoam_sumo.plant import Plant, initial_state
from eoam_sumo.plant.stepping import stable_substeps
from eoam_sumo.vehicle_files import catalogue, load_vehicle

V_MPS = 80.0 / 3.6


def light_wheeled_truck(params):
    """A 12 t vehicle on 0.5 kg m^2 wheels and 0.05 m relaxation: both within the vehicle
    files' ranges, together a wheel mode of about 3800 rad/s."""
    return dataclasses.replace(
        params,
        mass_kg=12000.0,
        yaw_inertia_kgm2=12000.0 * 1.4 * 1.6,
        tyre_nominal_load_n=30000.0,
        wheel_inertia_kgm2=0.5,
        wheel_radius_m=0.5,
        relaxation_length_long_m=0.05,
        max_brake_force_n=12000.0 * G_MPS2 * 1.1,
        max_drive_force_n=60000.0,
        cornering_stiffness_front_npr=6.0e5,
        cornering_stiffness_rear_npr=6.0e5,
    )


def stop(plant):
    """Full brake from 80 km/h on mu 1.0: (distance [m], time [s]) to rest."""
    x = initial_state(0.0, 0.0, 0.0, V_MPS, params=plant.params).tolist()
    steps = 0
    while x[3] > 0.05:
        x, _ = plant.advance(x, (0.0, 0.0, plant.params.max_brake_force_n), 1.0)
        steps += 1
        assert steps < 3000, "the vehicle did not stop in 30 s"
    return x[0], steps * plant.step_s


@pytest.mark.parametrize("name", catalogue())
def test_catalogue_vehicles_keep_the_1_ms_step(name):
    assert stable_substeps(load_vehicle(name), 1e-3, 10) == (1e-3, 10)


def test_a_fast_wheel_mode_converges_at_the_1_ms_step(params, plant_cache_dir):
    truck = light_wheeled_truck(params)
    coarse = Plant(truck, dt_s=1e-3, substeps=10, cache_dir=plant_cache_dir)
    fine = Plant(truck, dt_s=2.5e-4, substeps=40, cache_dir=plant_cache_dir)
    assert coarse.step_s == pytest.approx(0.01)
    (d_coarse, t_coarse), (d_fine, t_fine) = stop(coarse), stop(fine)
    assert d_coarse == pytest.approx(d_fine, rel=0.01)
    assert t_coarse == pytest.approx(t_fine, abs=0.05)
    assert d_fine > V_MPS**2 / (2.0 * G_MPS2)
