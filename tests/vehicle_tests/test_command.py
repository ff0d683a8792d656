"""``eoam-sumo vehicle-test``: each test into a folder, and bad input in one line with exit 2."""

from __future__ import annotations

import csv
import json

import pytest

from eoam_sumo.cli import main
from eoam_sumo.vehicle_tests.command import TEST_NAMES
from eoam_sumo.vehicle_tests.harness import COLUMNS
from eoam_sumo.vehicle_tests.procedures import TESTS


def test_the_command_names_every_test():
    assert set(TEST_NAMES) == set(TESTS)


@pytest.mark.parametrize("test", ["brake", "brake-ramp", "ramp-steer", "step-steer"])
def test_a_single_run_test_writes_its_series_summary_and_figure(test, tmp_path, capsys):
    out = tmp_path / test
    assert main(["vehicle-test", test, "--speed-kmh", "60", "--mu", "0.8", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["test"] == test
    assert summary["speed_kmh"] == 60.0
    assert summary["mu"] == 0.8
    assert summary["timeseries"] == {"run": "timeseries.csv"}
    with open(out / "timeseries.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert tuple(rows[0]) == COLUMNS
    assert len(rows) > 10
    assert (out / f"{test}.png").stat().st_size > 10_000
    assert test in capsys.readouterr().out


def test_the_sine_with_dwell_writes_one_series_per_run(tmp_path):
    out = tmp_path / "swd"
    assert main(["vehicle-test", "sine-with-dwell", "--vehicle", "sedan", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    files = summary["timeseries"]
    assert files["sis"] == "runs/sis/timeseries.csv"
    assert files["amp_1.5A"] == "runs/amp_1.5A/timeseries.csv"
    assert len(files) == len(summary["figures"]["runs"]) + 1
    assert all((out / path).is_file() for path in files.values())
    assert summary["passed"] in (True, False)
    assert (out / "sine-with-dwell.png").is_file()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["vehicle-test", "skid-pad"], "invalid choice: 'skid-pad'"),
        (["vehicle-test", "brake", "--vehicle", "truck"], "not in the catalogue"),
        (["vehicle-test", "brake", "--mu", "0"], "mu 0 is outside"),
        (["vehicle-test", "brake", "--mu", "wet"], "'wet' is not a number"),
        (["vehicle-test", "brake", "--speed-kmh", "-5"], "speed -5 km/h"),
        (["vehicle-test", "brake", "--abs", "maybe"], "invalid choice: 'maybe'"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(args, message, tmp_path, capsys):
    assert main([*args, "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1


def test_a_stop_from_100_kmh_with_abs_meets_r13h(tmp_path):
    """UN R13-H: at most 0.1 v + 0.0060 v^2 = 70 m from 100 km/h on a dry road, with ABS."""
    out = tmp_path / "abs"
    assert main(["vehicle-test", "brake", "--abs", "on", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["abs"] is True
    assert summary["figures"]["stopping_distance_m"] <= 70.0
    assert summary["passed"] is True


def test_an_output_folder_that_cannot_be_written_is_one_line(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["vehicle-test", "brake", "--out", str(blocker / "out")]) == 2
    assert "cannot be written" in capsys.readouterr().err


@pytest.mark.parametrize("flags, expected", [([], (True, True)), (["--esc", "off"], (True, False))])
def test_the_equipment_is_the_vehicle_s_own_unless_given(tmp_path, monkeypatch, flags, expected):
    """The compact's file fits ABS and ESC: the test runs with them unless switched off (it
    ran without both unless given, and a car carrying ESC failed sine with dwell)."""
    from eoam_sumo.vehicle_tests import procedures

    seen = []

    def spy(params, options):
        seen.append((params.abs_fitted, params.esc_fitted))
        return real(params, options)

    real = procedures.TESTS["brake"]
    monkeypatch.setitem(procedures.TESTS, "brake", spy)
    argv = ["vehicle-test", "brake", "--vehicle", "compact", *flags, "--out", str(tmp_path / "o")]
    assert main(argv) == 0
    assert seen == [expected]
