"""Small steering at 80 km/h on a dry road: the linear bicycle model's steady-state yaw gain."""

import math

import numpy as np
import pytest

from eoam_sumo.plant import STATE_NAMES, cruise_drive_force_n, initial_state

VX = STATE_NAMES.index("vx_mps")
R = STATE_NAMES.index("yaw_rate_radps")
STEER = STATE_NAMES.index("steer_rad")


def linear_yaw_gain(params, speed_mps):
    """r / delta = v / (L + K_us v^2), K_us = m / L (b / C_f - a / C_r) (per-axle stiffnesses)."""
    p = params
    length = p.wheelbase_m
    k_us = (
        p.mass_kg
        / length
        * (
            p.cg_to_rear_m / p.front_axle_stiffness_npr
            - p.cg_to_front_m / p.cornering_stiffness_rear_npr
        )
    )
    return speed_mps / (length + k_us * speed_mps**2)


@pytest.mark.parametrize("steer_deg", [0.25, 0.5, 1.0, -0.5])
def test_steady_state_yaw_rate_matches_linear_bicycle_gain(plant, params, steer_deg):
    speed = 80.0 / 3.6
    drive = cruise_drive_force_n(params, speed)
    x = initial_state(0.0, 0.0, 0.0, speed, drive_force_n=drive)
    u = np.array([math.radians(steer_deg), drive, 0.0])
    history = []
    for _ in range(400):  # 4 s: the yaw mode settles in well under a second
        x, _ = plant.step(x, u, 1.0)
        history.append(x[R])
    assert x[STEER] == pytest.approx(math.radians(steer_deg), rel=1e-9)
    assert abs(history[-1] - history[-50]) < 5e-3 * abs(history[-1]), "not in steady state"
    gain = x[R] / x[STEER]
    assert gain == pytest.approx(linear_yaw_gain(params, x[VX]), rel=0.05)
    assert abs(x[VX] - speed) < 0.05 * speed


@pytest.mark.parametrize("speed_kmh,steer_deg", [(80.0, 0.5), (120.0, 0.3), (165.0, 0.15)])
def test_steady_state_sideslip_is_the_steering_controllers(plant, params, speed_kmh, steer_deg):
    """The plant's body sideslip in steady cornering is what the steering controller expects
    on a road of that curvature (linear bicycle, kappa (b - m a v^2 / (L C_r)))."""
    from eoam_sumo.control import SteeringController

    speed = speed_kmh / 3.6
    drive = cruise_drive_force_n(params, speed)
    x = initial_state(0.0, 0.0, 0.0, speed, drive_force_n=drive)
    u = np.array([math.radians(steer_deg), drive, 0.0])
    for _ in range(400):
        x, _ = plant.step(x, u, 1.0)
    vy = x[STATE_NAMES.index("vy_mps")]
    beta = math.atan(vy / x[VX])
    curvature = x[R] / x[VX]
    expected = SteeringController(params).steady_sideslip(x[VX], curvature)
    assert abs(beta) > 1e-3  # a real sideslip, not zero against zero
    assert beta == pytest.approx(expected, rel=0.1)
