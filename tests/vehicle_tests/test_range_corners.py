"""The corners of the vehicle ranges (``params.VEHICLE_RANGES`` and the relations) drive: a
light car with every stiffness, lag and length at its low end and a heavy one at its high
end, each also with the opposite tyre and lag ends, give finite time series on the brake stop
and the step steer at the highest test speed (a zero or 1e-300 gave NaN or a traceback)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.vehicle_tests.common import VehicleTestOptions
from eoam_sumo.vehicle_tests.procedures import TESTS

QUICK_LAGS = {"steer_lag_s": 0.005, "drive_lag_s": 0.005, "brake_lag_s": 0.005, "esc_lag_s": 0.005}
SLOW_LAGS = {"steer_lag_s": 2.0, "drive_lag_s": 2.0, "brake_lag_s": 2.0, "esc_lag_s": 2.0}
#: 200 kg, dynamic index 0.3, 0.1 x FNOMIN per tyre, the shortest relaxation and lags
LIGHT = dict(
    mass_kg=200.0,
    cg_to_front_m=0.6,
    cg_to_rear_m=0.6,
    yaw_inertia_kgm2=21.6,
    cg_height_m=0.4,
    track_m=1.0,
    width_m=1.2,
    length_m=2.0,
    front_overhang_m=0.3,
    cornering_stiffness_front_npr=1e4,
    cornering_stiffness_rear_npr=1e4,
    wheel_inertia_kgm2=0.1,
    wheel_radius_m=0.15,
    relaxation_length_long_m=0.05,
    relaxation_length_lat_m=0.05,
    max_brake_force_n=2600.0,
    max_drive_force_n=1000.0,
    max_drive_power_w=4000.0,
    **QUICK_LAGS,
)
#: 3950 kg (2 x FNOMIN per tyre), dynamic index 3, the stiffest tyres, slowest lags
HEAVY = dict(
    mass_kg=3950.0,
    cg_to_front_m=1.5,
    cg_to_rear_m=1.5,
    yaw_inertia_kgm2=26660.0,
    cg_height_m=3.0,
    track_m=2.0,
    width_m=2.55,
    length_m=6.0,
    front_overhang_m=1.0,
    cornering_stiffness_front_npr=3e6,
    cornering_stiffness_rear_npr=3e6,
    wheel_inertia_kgm2=50.0,
    wheel_radius_m=0.75,
    relaxation_length_long_m=2.0,
    relaxation_length_lat_m=2.0,
    max_brake_force_n=1e6,
    max_drive_force_n=6e5,
    max_drive_power_w=2e6,
    **SLOW_LAGS,
)
CORNERS = {
    "light": LIGHT,
    "light-stiff": {
        **LIGHT,
        "cornering_stiffness_front_npr": 3e6,
        "cornering_stiffness_rear_npr": 3e6,
    },
    "heavy": HEAVY,
    "heavy-soft": {
        **HEAVY,
        "cornering_stiffness_front_npr": 1e4,
        "cornering_stiffness_rear_npr": 1e4,
        "wheel_inertia_kgm2": 0.1,
        "relaxation_length_long_m": 0.05,
        "relaxation_length_lat_m": 0.05,
        "max_brake_force_n": 500.0,
        **QUICK_LAGS,
    },
}


#: columns the plant's step writes: NaN in the harness's start row, before the first step
FROM_THE_PLANT = ("friction_use_max", "friction_ellipse_max")


@pytest.mark.parametrize("fitted", [False, True], ids=["plain", "abs-esc"])
@pytest.mark.parametrize("test", ["brake", "step-steer"])
@pytest.mark.parametrize("corner", sorted(CORNERS))
def test_a_corner_of_the_ranges_gives_a_finite_time_series(corner, test, fitted):
    params = dataclasses.replace(
        ego_e_class_sedan(), name=corner, abs_fitted=fitted, esc_fitted=fitted, **CORNERS[corner]
    )
    result = TESTS[test](params, VehicleTestOptions(speed_kmh=300.0, mu=1.0))
    for run in result.runs:
        for name, column in run.columns.items():
            values = np.asarray(column)
            if name in FROM_THE_PLANT:  # the start row is the harness's: no tyre forces yet
                values = values[1:]
            if values.dtype.kind == "f":
                assert np.isfinite(values).all(), (corner, test, run.label, name)
