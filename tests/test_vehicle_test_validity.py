"""``eoam-sumo vehicle-test`` reports only what it measured: every test draws its figure, a
test that could not be run or measured says why (and is no pass), a car that does not stop
fails, and the understeer gradient is fitted in the car's linear range on any road."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from eoam_sumo.cli import main
from eoam_sumo.vehicle_files import load_vehicle
from eoam_sumo.vehicle_tests.command import TEST_NAMES
from eoam_sumo.vehicle_tests.common import VehicleTestOptions, verdict, verdict_text
from eoam_sumo.vehicle_tests.harness import Run
from eoam_sumo.vehicle_tests.procedures import TESTS
from eoam_sumo.vehicle_tests.sine_with_dwell import outside_scope
from eoam_sumo.vehicle_tests.steer_figures import drift_over_window, linear_range_g
from eoam_sumo.vehicle_tests.steer_tests import step_sliding

R13H = load_vehicle("sedan-r13h")


def _vehicle_test(capsys, tmp_path, *args: str) -> tuple[dict, str]:
    """Run ``vehicle-test ARGS`` into a fresh folder: its summary and its stdout."""
    out = tmp_path / "out"
    status = main(["vehicle-test", *args, "--out", str(out)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    return json.loads((out / "summary.json").read_text()), captured.out


@pytest.mark.parametrize("test", TEST_NAMES)
def test_every_test_draws_its_figure_through_the_command(test, tmp_path, capsys):
    """Every test the command offers goes through the plotting: a missing drawing is a crash."""
    summary, stdout = _vehicle_test(capsys, tmp_path, test, "--speed-kmh", "40")
    assert (tmp_path / "out" / f"{test}.png").stat().st_size > 10_000
    assert summary["test"] == test
    assert stdout.startswith(f"{test}: ")


def test_brake_in_turn_too_slippery_for_its_first_step_says_why(tmp_path, capsys):
    """mu 0.1: the series' 1 m/s^2 step is beyond mu g = 0.98 m/s^2, so no run brakes."""
    summary, stdout = _vehicle_test(capsys, tmp_path, "brake-in-turn", "--mu", "0.1")
    assert summary["figures"]["runs"] == []
    assert "beyond the road's friction" in summary["not_measured"]
    assert summary["passed"] is None
    assert summary["verdict"] == "NOT MEASURED"
    assert "NOT MEASURED" in stdout and "beyond the road's friction" in stdout
    assert (tmp_path / "out" / "brake-in-turn.png").is_file()


def test_brake_in_turn_off_its_circle_is_not_measured():
    """100 km/h on the 100 m circle asks 7.7 m/s^2 of a mu 0.3 road: the car leaves the circle
    before the brake comes on, and no run's figures are given."""
    result = TESTS["brake-in-turn"](R13H, VehicleTestOptions(speed_kmh=100.0, mu=0.3))
    assert result.summary["figures"]["runs"] == []
    assert "not on the 100 m circle" in result.summary["not_measured"]
    assert len(result.runs) == 1  # the run that shows it is kept
    assert verdict(result.summary) == "NOT MEASURED"


def test_a_car_that_never_stops_fails_with_the_distance_it_travelled():
    """A 1500 N brake on 1723 kg stops in no time window: FAIL, the distance so far (a lower
    bound of the stopping distance, beyond the 70 m limit) and the reason."""
    weak = dataclasses.replace(R13H, max_brake_force_n=1500.0)
    summary = TESTS["brake"](weak, VehicleTestOptions()).summary
    figures = summary["figures"]
    (stopping,) = [c for c in summary["criteria"] if c["name"] == "stopping_distance_m"]
    assert summary["passed"] is False
    assert stopping["passed"] is False
    assert figures["stopped"] is False
    assert figures["stopping_distance_m"] is None
    assert stopping["value_is_lower_bound"] is True
    assert stopping["value"] == pytest.approx(figures["stopping_distance_at_least_m"])
    assert stopping["value"] > stopping["limit"] == 70.0
    assert "not stopped" in verdict_text(summary)


def test_a_car_that_stops_has_no_lower_bound():
    figures = TESTS["brake"](R13H, VehicleTestOptions(speed_kmh=50.0)).summary["figures"]
    assert figures["stopped"] is True
    assert figures["stopping_distance_at_least_m"] is None
    assert figures["stopping_distance_m"] > 0.0


def test_step_steer_beyond_the_roads_friction_reports_no_response(tmp_path, capsys):
    """ISO 7401's 4 m/s^2 is beyond mu 0.3 (mu g = 2.94 m/s^2): no response time, overshoot or
    gain, the reason said, and no pass."""
    summary, stdout = _vehicle_test(
        capsys, tmp_path, "step-steer", "--vehicle", "sedan-r13h", "--mu", "0.3"
    )
    figures = summary["figures"]
    for name in ("yaw_rate_response_time_s", "yaw_rate_overshoot", "yaw_rate_gain_per_s"):
        assert figures[name] is None
    assert figures["steady_lateral_acceleration_mps2"] < 3.0
    assert "short of the standard's 4 m/s^2" in summary["not_measured"]
    assert summary["verdict"] == "NOT MEASURED"
    assert "NOT MEASURED" in stdout


def test_step_steer_on_a_dry_road_is_measured():
    summary = TESTS["step-steer"](R13H, VehicleTestOptions()).summary
    assert "not_measured" not in summary
    assert 0.1 < summary["figures"]["yaw_rate_response_time_s"] < 1.0
    assert verdict(summary) == "figures only"


def test_ramp_steer_gradient_hardly_depends_on_the_roads_friction():
    """The linear understeer gradient is the tyres' cornering stiffness, not their friction:
    on mu 0.3 (peak near 0.3 g) the fit stays below half the peak, and the gradient is within
    10 % of the dry road's (the fixed 0.1-0.4 g range gave 18 deg/g against 2)."""
    dry = TESTS["ramp-steer"](R13H, VehicleTestOptions(mu=1.0)).summary["figures"]
    wet = TESTS["ramp-steer"](R13H, VehicleTestOptions(mu=0.3)).summary["figures"]
    assert wet["understeer_gradient_deg_per_g"] == pytest.approx(
        dry["understeer_gradient_deg_per_g"], rel=0.1
    )
    assert wet["fit_range_g"][1] <= 0.5 * wet["peak_lateral_acceleration_g"] + 1e-4
    assert dry["fit_range_g"] == [0.1, 0.4]


def test_the_linear_range_ends_at_half_the_peak_or_0_4_g():
    assert linear_range_g(1.0) == (0.1, 0.4)
    assert linear_range_g(0.3) == pytest.approx((0.1, 0.15))
    low, high = linear_range_g(0.15)
    assert high < low  # no linear range: nothing is fitted


def test_the_drift_over_the_last_second_is_the_change_of_a_ramp():
    time_s = np.arange(0.0, 5.0, 0.01)
    assert drift_over_window(time_s, 3.0 + 0.2 * time_s) == pytest.approx(0.2)
    assert drift_over_window(time_s, np.full_like(time_s, 4.0)) == pytest.approx(0.0)


@pytest.mark.parametrize(
    ("summary", "word"),
    [
        ({"passed": True}, "PASS"),
        ({"passed": False, "not_measured": "x"}, "FAIL"),
        ({"passed": None, "not_measured": "no run"}, "NOT MEASURED"),
        ({"passed": None}, "figures only"),
    ],
)
def test_the_verdict_never_makes_a_missing_measurement_a_pass(summary, word):
    assert verdict(summary) == word


def test_a_brake_ramp_without_a_locked_axle_is_not_measured():
    """R13-H Annex 5 judges the order in which the axles lock: with ABS no wheel locks on any
    ramp, so there is no order to judge (it was a PASS)."""
    abs_on = dataclasses.replace(R13H, abs_fitted=True)
    summary = TESTS["brake-ramp"](abs_on, VehicleTestOptions()).summary
    assert summary["figures"]["first_locked_axle"] == "none"
    assert summary["passed"] is None
    assert summary["criteria"] == []
    assert "ABS kept every wheel from locking" in summary["not_measured"]
    assert verdict(summary) == "NOT MEASURED"


@pytest.mark.parametrize("speed_kmh", [1.0, 3.5, 4.0])
def test_brake_in_turn_at_walking_pace_is_not_measured(speed_kmh):
    """At a few km/h every brake of the series stops the car within the 1 s after its onset at
    which ISO 7975 takes the figures (1-3.5 km/h crashed, 4 km/h reported the last sample)."""
    result = TESTS["brake-in-turn"](R13H, VehicleTestOptions(speed_kmh=speed_kmh))
    assert result.summary["figures"]["runs"] == []
    assert "stopped" in result.summary["not_measured"]
    assert verdict(result.summary) == "NOT MEASURED"


def test_brake_in_turn_keeps_the_runs_measured_before_the_car_stops_within_the_second():
    """At 15 km/h (4.2 m/s) a brake of 4 m/s^2 or more stops the car within 1 s: the series
    ends there, its measured runs kept and the cut said."""
    summary = TESTS["brake-in-turn"](R13H, VehicleTestOptions(speed_kmh=15.0)).summary
    runs = summary["figures"]["runs"]
    assert [r["target_deceleration_mps2"] for r in runs] == [1.0, 2.0, 3.0]
    assert "from 4 m/s^2 on" in summary["figures"]["series_cut"]
    assert verdict(summary) == "figures only"


def test_a_sine_with_dwell_without_a_is_not_measured():
    """On mu 0.25 the slowly increasing steer never reaches 0.3 g: no A, no series, and the
    standard's pass mark not met by anything measured (it said "figures only")."""
    compact = load_vehicle("compact")
    summary = TESTS["sine-with-dwell"](compact, VehicleTestOptions(mu=0.25)).summary
    assert summary["figures"]["A_deg"] is None
    assert "never reached 0.3 g" in summary["not_measured"]
    assert verdict(summary) == "NOT MEASURED"


def test_a_vehicle_heavier_than_the_esc_standard_covers_gets_figures_only():
    """FMVSS 126 applies up to 4 536 kg gross (S3): heavier, every criterion unjudged."""
    summary = {"criteria": [{"name": "amp_5A.yaw_ratio_1s", "passed": False}], "passed": False}
    outside_scope(summary, 12000.0)
    assert summary["passed"] is None
    assert summary["criteria"][0]["passed"] is None
    assert verdict_text(summary).startswith("figures only: 12000 kg is above the 4536 kg")


def test_a_step_steer_that_ends_in_a_slide_says_so():
    """``ay = vx (r + beta')``: an end where ``vx r`` is far from ``ay`` is a slide or a spin,
    not a steady state above the standard's level (a spinning truck read "44 % above")."""
    sliding = Run(
        "run",
        {
            "vx_mps": np.array([22.2, 16.2]),
            "yaw_rate_radps": np.array([0.0, 0.914]),
            "ay_mps2": np.array([0.0, 6.0]),
        },
    )
    assert "slides or spins (vx r = 14.81" in step_sliding(sliding)
    steady = Run(
        "run",
        {
            "vx_mps": np.array([22.2, 22.1]),
            "yaw_rate_radps": np.array([0.0, 0.181]),
            "ay_mps2": np.array([0.0, 4.0]),
        },
    )
    assert step_sliding(steady) is None
