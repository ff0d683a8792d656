"""Straight-line braking from 100 km/h against closed-form stopping distances."""

import dataclasses
import math

import numpy as np
import pytest

from eoam_sumo.params import AIR_DENSITY_KGPM3, G_MPS2
from eoam_sumo.plant import OUTPUT_NAMES, STATE_NAMES, Plant, initial_state

V0_MPS = 100.0 / 3.6
MUS = (1.0, 0.7, 0.3, 0.1)
VX = STATE_NAMES.index("vx_mps")
YOUT = {name: i for i, name in enumerate(OUTPUT_NAMES)}


def brake_to_rest(plant, mu, brake_n, max_time_s=60.0):
    """Brake with the brake actuator already at ``brake_n`` (no lag); return the final state and
    the lock flags of every step while faster than 0.5 m/s."""
    x = initial_state(0.0, 0.0, 0.0, V0_MPS, brake_force_n=brake_n)
    u = np.array([0.0, 0.0, brake_n])
    locks = []
    for _ in range(int(max_time_s / plant.step_s)):
        x, y = plant.step(x, u, mu)
        if x[VX] > 0.5:
            locks.append((y[YOUT["front_locked"]], y[YOUT["rear_locked"]]))
        if x[VX] < 1e-4:
            return x, locks
    raise AssertionError(f"not at rest after {max_time_s} s: {x}")


def drag_distance_m(params, decel_mps2):
    """Exact distance of m v' = -m decel - k v^2 from V0: (m / 2k) ln(1 + k V0^2 / (m decel))."""
    k = 0.5 * AIR_DENSITY_KGPM3 * params.drag_area_m2
    return params.mass_kg / (2 * k) * math.log1p(k * V0_MPS**2 / (params.mass_kg * decel_mps2))


@pytest.mark.parametrize("mu", MUS)
def test_locked_wheels_slide_to_the_closed_form_distance(plant, params, mu):
    x, locks = brake_to_rest(plant, mu, params.max_brake_force_n)
    assert set(locks) == {(1.0, 1.0)}, "full brake demand must lock both axles"
    # Both axles sliding: m v' = -mu_slide m g - k v^2 (no rolling resistance while sliding).
    expected_m = drag_distance_m(params, params.sliding_friction_ratio * mu * G_MPS2)
    assert x[0] == pytest.approx(expected_m, rel=0.01)
    assert x[0] >= V0_MPS**2 / (2 * mu * G_MPS2)


@pytest.fixture(scope="module")
def plant_no_drag(params, plant_cache_dir):
    return Plant(dataclasses.replace(params, drag_area_m2=0.0), cache_dir=plant_cache_dir)


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("brake_n", [1000.0, 3000.0, 6000.0, 9000.0, 12000.0, 16000.0, 22000.0])
def test_no_brake_demand_beats_the_friction_limit(plant, plant_no_drag, params, mu, brake_n):
    # Without drag only the tyres decelerate: at most mu g, so at least v^2 / (2 mu g).
    x, _ = brake_to_rest(plant_no_drag, mu, brake_n, max_time_s=120.0)
    assert x[0] >= V0_MPS**2 / (2 * mu * G_MPS2)
    # With drag the honest floor is tyres at mu g plus the drag, integrated exactly.
    x, _ = brake_to_rest(plant, mu, brake_n, max_time_s=120.0)
    assert x[0] >= drag_distance_m(params, mu * G_MPS2)


def test_partial_brake_without_lock_matches_constant_deceleration(plant_no_drag, params):
    # Dry road, 6 kN: neither axle locks; the only forces are the brake and rolling resistance.
    brake_n = 6000.0
    x, locks = brake_to_rest(plant_no_drag, 1.0, brake_n)
    assert set(locks) == {(0.0, 0.0)}
    decel = brake_n / params.mass_kg + params.rolling_resistance_coeff * G_MPS2
    assert x[0] == pytest.approx(V0_MPS**2 / (2 * decel), rel=0.005)


@pytest.mark.parametrize(("mu", "brake_n"), [(1.0, 6000.0), (0.1, 1800.0), (0.1, 22000.0)])
def test_normal_loads_carry_the_longitudinal_load_transfer(plant, params, mu, brake_n):
    # Quasi-static pitch balance: Fz_f = (m g b - h Fx) / L with Fx the tyre force sum, here
    # solved in closed form for each lock state (rolling axles deliver brake + rolling
    # resistance; a locked axle slides at mu_slide Fz).
    p, m_g = params, params.mass_kg * G_MPS2
    x = initial_state(0.0, 0.0, 0.0, 80.0 / 3.6, brake_force_n=brake_n)
    _, y = plant.step(x, np.array([0.0, 0.0, brake_n]), mu)
    front_locked, rear_locked = y[YOUT["front_locked"]], y[YOUT["rear_locked"]]
    slide, rr, h, length = (
        p.sliding_friction_ratio * mu,
        p.rolling_resistance_coeff,
        p.cg_height_m,
        p.wheelbase_m,
    )
    # -Fx = k_f Fz_f + k_r Fz_r + c with Fz_r = m g - Fz_f.
    k_f = slide if front_locked else rr
    k_r = slide if rear_locked else rr
    c = (0.0 if front_locked else p.brake_front_share * brake_n) + (
        0.0 if rear_locked else (1 - p.brake_front_share) * brake_n
    )
    fz_front = (m_g * p.cg_to_rear_m + h * (k_r * m_g + c)) / (length - h * (k_f - k_r))
    assert (front_locked, rear_locked) == {6000.0: (0, 0), 1800.0: (1, 0), 22000.0: (1, 1)}[brake_n]
    assert y[YOUT["fz_front_n"]] == pytest.approx(fz_front, rel=2e-4)
    assert y[YOUT["fz_rear_n"]] == pytest.approx(m_g - fz_front, rel=2e-4)


def test_vehicle_stays_at_rest_under_brake_and_never_reverses(plant, params):
    x, _ = brake_to_rest(plant, 0.7, params.max_brake_force_n)
    resting = x.copy()
    u = np.array([0.3, 0.0, params.max_brake_force_n])  # steering at rest moves nothing
    for _ in range(300):
        x, y = plant.step(x, u, 0.7)
        assert np.all(np.isfinite(x)) and np.all(np.isfinite(y))
        assert x[VX] >= 0.0
    assert x[VX] < 1e-6
    assert np.hypot(x[0] - resting[0], x[1] - resting[1]) < 1e-5
    assert abs(x[2] - resting[2]) < 1e-6


def test_rest_without_brake_stays_put_and_drive_moves_forward(plant):
    x = initial_state(5.0, 2.0, 0.3, 0.0)
    for _ in range(100):
        x, _ = plant.step(x, np.zeros(3), 0.5)
    assert np.array_equal(x[:6], np.array([5.0, 2.0, 0.3, 0.0, 0.0, 0.0]))
    for _ in range(100):
        x, _ = plant.step(x, np.array([0.0, 3000.0, 0.0]), 0.5)
    heading = np.array([math.cos(0.3), math.sin(0.3)])
    assert x[VX] > 0.5
    assert np.dot(x[:2] - np.array([5.0, 2.0]), heading) > 0.2
