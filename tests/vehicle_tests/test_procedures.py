"""The five tests on the sedan with today's plant: physics that holds whatever the chassis,
and the adapter to the chassis features the plant may lack."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from eoam_sumo.params import G_MPS2, ego_e_class_sedan
from eoam_sumo.plant import OUTPUT_NAMES
from eoam_sumo.vehicle_files import load_vehicle
from eoam_sumo.vehicle_tests.common import VehicleTestOptions
from eoam_sumo.vehicle_tests.equipment import equipped, wheel_speeds
from eoam_sumo.vehicle_tests.harness import COLUMNS
from eoam_sumo.vehicle_tests.procedures import TESTS

SEDAN = ego_e_class_sedan()
R13H = load_vehicle("sedan-r13h")


def test_every_test_gives_time_series_with_the_columns_and_a_summary():
    for name, test in TESTS.items():
        result = test(SEDAN, VehicleTestOptions(speed_kmh=60.0))
        assert result.summary["test"] == name
        assert {"figures", "criteria", "passed"} <= set(result.summary)
        for run in result.runs:
            assert set(run.columns) == set(COLUMNS)
            assert run["time_s"][0] == 0.0
            assert np.all(np.diff(run["time_s"]) > 0)


def test_braking_to_standstill_keeps_the_wheels_at_or_above_zero_and_the_car_at_rest():
    for mu in (1.0, 0.3):
        result = TESTS["brake"](SEDAN, VehicleTestOptions(mu=mu))
        figures = result.summary["figures"]
        assert figures["min_wheel_speed_mps"] >= 0.0
        assert figures["max_speed_at_rest_mps"] < 0.01
        run = result.runs[0]
        assert run["vx_mps"].min() > -0.01  # the tyres' relaxed slip springs back a few mm/s


def test_the_stop_is_longer_on_a_slippery_road_and_no_shorter_than_friction_allows():
    dry = TESTS["brake"](SEDAN, VehicleTestOptions(mu=1.0)).summary["figures"]
    wet = TESTS["brake"](SEDAN, VehicleTestOptions(mu=0.3)).summary["figures"]
    v0 = 100 / 3.6
    for figures, mu in ((dry, 1.0), (wet, 0.3)):
        assert figures["stopping_distance_m"] > v0 * v0 / (2 * mu * G_MPS2)
        assert figures["friction_utilisation"] <= 1.0
    assert wet["stopping_distance_m"] > 2.5 * dry["stopping_distance_m"]


def test_the_brake_ramp_locks_the_r13h_sedans_front_axle_first():
    """The corrected sedan's 73/27 split locks the front first on every friction (UN R13-H
    Annex 5), below the friction's braking rate: the loaded front tyres lose friction (load
    sensitivity). The paper's 65/35 locks the rear first on dry road."""
    assert (
        TESTS["brake-ramp"](SEDAN, VehicleTestOptions(mu=1.0)).summary["figures"][
            "first_locked_axle"
        ]
        == "rear"
    )
    for mu in (1.0, 0.7, 0.3):
        summary = TESTS["brake-ramp"](R13H, VehicleTestOptions(mu=mu)).summary
        assert summary["figures"]["first_locked_axle"] == "front"
        assert 0.8 * mu < summary["figures"]["front_lock_braking_rate"] <= 1.05 * mu
        assert summary["passed"] is True


def test_the_ramp_steer_gradient_is_the_steady_state_one():
    """Against the linear single-track gradient m/L (b/Cf - a/Cr), which the tyres' lateral
    load transfer raises over 0.1-0.4 g (a front roll-stiffness share above the front's
    static load share): within 0.5 deg/g above it."""
    p = SEDAN
    linear = (
        math.degrees(
            p.mass_kg
            / p.wheelbase_m
            * (
                p.cg_to_rear_m / p.front_axle_stiffness_npr
                - p.cg_to_front_m / p.cornering_stiffness_rear_npr
            )
        )
        * G_MPS2
    )
    figures = TESTS["ramp-steer"](p, VehicleTestOptions()).summary["figures"]
    assert linear <= figures["understeer_gradient_deg_per_g"] <= linear + 0.5
    assert 0.8 < figures["peak_lateral_acceleration_g"] <= 1.0


def test_the_step_steer_reaches_the_standards_lateral_acceleration():
    figures = TESTS["step-steer"](SEDAN, VehicleTestOptions()).summary["figures"]
    assert figures["steady_lateral_acceleration_mps2"] == pytest.approx(4.0, abs=0.05)
    assert 0.1 < figures["yaw_rate_response_time_s"] < 1.0


def test_the_sine_with_dwell_judges_each_amplitude():
    summary = TESTS["sine-with-dwell"](SEDAN, VehicleTestOptions()).summary
    runs = summary["figures"]["runs"]
    assert summary["figures"]["A_deg"] > 0
    assert runs[0]["amplitude_A"] == 1.5
    assert runs[-1]["amplitude_deg"] == pytest.approx(270.0)
    first = runs[0]
    assert abs(first["yaw_ratio_1s"]) < 0.35  # a small input settles
    judged = {
        c["name"].split(".lateral")[0] for c in summary["criteria"] if "displacement" in c["name"]
    }
    assert judged == {r["run"] for r in runs if r["amplitude_A"] >= 5.0}


def test_abs_and_esc_are_switched_per_run():
    assert equipped(SEDAN, False, False) == SEDAN
    both = equipped(SEDAN, True, True)
    assert both.abs_fitted and both.esc_fitted
    assert dataclasses.replace(both, abs_fitted=False, esc_fitted=False) == SEDAN


def test_wheel_speeds_are_the_plants_outputs():
    outputs = [0.0] * len(OUTPUT_NAMES)
    outputs[OUTPUT_NAMES.index("wheel_speed_front_mps")] = 12.5
    outputs[OUTPUT_NAMES.index("wheel_speed_rear_mps")] = 3.0
    assert wheel_speeds(outputs) == (12.5, 3.0)


def test_the_steering_robot_reaches_every_sine_with_dwell_amplitude():
    """FMVSS 126 S7.9's robot, not the EOAM's rate-limited actuator: the 270 deg run needs
    2 pi 0.7 x 270 = 1188 deg/s at the hand wheel, and its peak is the amplitude."""
    runs = TESTS["sine-with-dwell"](R13H, VehicleTestOptions()).summary["figures"]["runs"]
    assert runs[-1]["amplitude_deg"] == 270.0
    for run in runs:
        assert run["peak_steer_wheel_deg"] == pytest.approx(run["amplitude_deg"], rel=0.002)


def _steady_single_track(p, vx_mps: float, steer_rad: float) -> tuple[float, float]:
    """The linear single-track model's steady turn at ``steer_rad``: (vy, r) from its lateral
    force and yaw moment balances, solved as a 2 x 2 linear system."""
    a, b, cf, cr = (
        p.cg_to_front_m,
        p.cg_to_rear_m,
        p.front_axle_stiffness_npr,
        (p.cornering_stiffness_rear_npr),
    )
    # Fyf = cf (steer - (vy + a r) / vx), Fyr = cr (b r - vy) / vx;
    # Fyf + Fyr = m vx r, a Fyf - b Fyr = 0
    lhs = np.array(
        [
            [-(cf + cr) / vx_mps, (-cf * a + cr * b) / vx_mps - p.mass_kg * vx_mps],
            [(-cf * a + cr * b) / vx_mps, -(cf * a * a + cr * b * b) / vx_mps],
        ]
    )
    vy, r = np.linalg.solve(lhs, np.array([-cf * steer_rad, -a * cf * steer_rad]))
    return float(vy), float(r)


@pytest.mark.parametrize("speed_kmh", [80.0, 250.0])
def test_the_linear_sideslip_gain_is_the_steady_turns(speed_kmh):
    """``linear_sideslip_gain_s`` = d vy / d ay of the single-track model's steady turns."""
    from eoam_sumo.vehicle_tests.steer_tests import linear_sideslip_gain_s

    vx = speed_kmh / 3.6
    vy, r = _steady_single_track(R13H, vx, 0.01)
    assert linear_sideslip_gain_s(R13H, vx) == pytest.approx(vy / (vx * r), rel=1e-9)


def test_a_steady_ramp_at_250_kmh_is_measured():
    """ISO 4138 at 250 km/h (D4 of the type-approval review): the ramp's own sideslip growth,
    ``ay - vx r = dvy/dt`` of about -0.21 m/s^2 at 0.2 g, is no slide; the run goes on to the
    limit as at 230 km/h (2.19 deg/g, 0.888 g), not stopped at 0.2 g as NOT MEASURED."""
    summary = TESTS["ramp-steer"](R13H, VehicleTestOptions(speed_kmh=250.0)).summary
    figures = summary["figures"]
    assert "not_measured" not in summary
    assert figures["peak_lateral_acceleration_g"] > 0.85
    assert 2.0 < figures["understeer_gradient_deg_per_g"] < 2.5
    assert figures["ramp_end"].startswith("the turn stopped being quasi-steady at 0.8")


def test_a_spinning_ramp_still_ends_and_says_why():
    """An oversteering car beyond its critical speed (rear cornering stiffness 40 000 N/rad:
    58 km/h) has no steady turn at 80 km/h: the ramp ends at 0.2 g as a slide or a spin,
    NOT MEASURED, and the reason says so."""
    oversteer = dataclasses.replace(R13H, cornering_stiffness_rear_npr=40000.0)
    critical_mps = math.sqrt(-oversteer.wheelbase_m / oversteer.understeer_gradient_rad_per_mps2)
    assert critical_mps < 80.0 / 3.6
    summary = TESTS["ramp-steer"](oversteer, VehicleTestOptions()).summary
    assert summary["figures"]["peak_lateral_acceleration_g"] < 0.25
    assert "slide or a spin" in summary["not_measured"]
    assert summary["figures"]["ramp_end"] in summary["not_measured"]
