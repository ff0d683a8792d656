"""ESC on ice: the control unit's friction estimate starts at a dry road's, so a car that
cannot turn as steered read as understeer and the ESC braked an inner rear wheel with the
estimate still near 1: on mu 0.1 the rear slid and every catalogue car spun (33-40 deg of
sideslip) where it stayed within a few degrees without ESC. The estimate now falls to the
achieved acceleration within ``MU_EST_ESC_FALL_S`` while the ESC sees understeer."""

from __future__ import annotations

import math

import numpy as np
import pytest

from eoam_sumo.vehicle_files import load_vehicle
from eoam_sumo.vehicle_tests.equipment import equipped
from eoam_sumo.vehicle_tests.harness import Controls, PlantVehicle, simulate

SPEED_MPS = 30.0


def _max_sideslip_deg(run) -> float:
    return float(np.degrees(np.abs(np.arctan2(run["vy_mps"], run["vx_mps"]))).max())


def _sine_dwell(amp_rad: float):
    """A sine-with-dwell-like road-wheel angle: a half sine at 0.7 Hz, held 0.5 s, straight."""

    def drive(t_s: float, _sample) -> Controls:
        if t_s < 0.357:
            return Controls(amp_rad * math.sin(2.0 * math.pi * 0.7 * t_s), 0.0, 0.0)
        return Controls(amp_rad if t_s < 0.857 else 0.0, 0.0, 0.0)

    return drive


@pytest.mark.parametrize("name", ["compact", "van"])
def test_esc_does_not_spin_a_car_on_ice_after_a_steer(name):
    """mu 0.1, 30 m/s, 0.1 rad of road-wheel angle: with ESC the sideslip stays within
    10 deg (it reached 36-39 deg), and the car ends heading within 15 deg of the road."""
    esc = simulate(
        PlantVehicle(equipped(load_vehicle(name), True, True)),
        SPEED_MPS,
        _sine_dwell(0.1),
        6.0,
        0.1,
    )
    assert _max_sideslip_deg(esc) < 10.0
    assert abs(math.degrees(esc["yaw_rad"][-1])) < 15.0


def test_esc_braking_in_a_turn_on_ice_does_no_worse_than_without():
    """mu 0.1, 30 m/s, 0.06 rad held, full brake from 1 s, ABS on: the corrected sedan's
    largest sideslip with ESC is no larger than without it (88 deg against 22 deg)."""
    params = load_vehicle("sedan-r13h")

    def drive(t_s: float, _sample) -> Controls:
        return Controls(
            0.06 if t_s > 0.2 else 0.0, 0.0, params.max_brake_force_n if t_s > 1.0 else 0.0
        )

    peaks = [
        _max_sideslip_deg(
            simulate(PlantVehicle(equipped(params, True, esc)), SPEED_MPS, drive, 20.0, 0.1)
        )
        for esc in (True, False)
    ]
    assert peaks[0] <= peaks[1] + 1.0
