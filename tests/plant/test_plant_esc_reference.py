"""The ESC's yaw-rate reference follows the car's own yaw dynamics (Rajamani 2012 ch. 8), so
an ordinary manoeuvre that the car follows as a linear car would asks next to nothing of it."""

from __future__ import annotations

import math

from eoam_sumo.plant import OUTPUT_NAMES, Plant, cruise_drive_force_n, initial_state
from eoam_sumo.vehicle_files import load_vehicle
from eoam_sumo.vehicle_tests.equipment import equipped

ESC = OUTPUT_NAMES.index("esc_moment_nm")
AY = OUTPUT_NAMES.index("ay_mps2")


def _sine(amplitude_deg: float) -> tuple[float, float]:
    """Two cycles of a 0.7 Hz hand-wheel sine at 80 km/h, speed held: the largest ESC moment
    [N m] and |ay| [m/s2]."""
    p = equipped(load_vehicle("sedan-r13h"), True, True)
    plant = Plant(p, dt_s=0.001, substeps=10)
    v = 80.0 / 3.6
    x = list(initial_state(0.0, 0.0, 0.0, v, params=p))
    amp = math.radians(amplitude_deg) / p.steering_ratio
    moment = ay = 0.0
    for k in range(400):
        t = k * 0.01
        steer = amp * math.sin(2.0 * math.pi * 0.7 * t) if t < 2.0 / 0.7 else 0.0
        x, y = plant.advance(x, [steer, cruise_drive_force_n(p, v), 0.0], 1.0)
        moment, ay = max(moment, abs(y[ESC])), max(ay, abs(y[AY]))
    return moment, ay


def test_an_ordinary_sine_asks_little_of_the_esc_and_a_violent_one_much():
    """A sine of A (0.3 g in the slowly increasing steer; 26 deg): under 450 N m (1087 N m
    with the steady-state reference); a sine of 6.5 A: several kN m."""
    small, ay = _sine(26.0)
    assert ay < 0.35 * 9.81
    assert small < 450.0
    large, _ = _sine(6.5 * 26.0)
    assert large > 5.0 * small
