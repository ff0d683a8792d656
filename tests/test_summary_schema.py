"""One source of truth: summary.json's fields, results.csv's columns and the docs agree."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pandas as pd

from eoam_sumo.batch.case import PARAMETERS
from eoam_sumo.batch.results import COLUMNS, NUMERIC_COLUMNS, RENAMED, SUMMARY_COLUMNS
from eoam_sumo.eoam import Command, EgoMeasurement, Perception
from eoam_sumo.sim import runlog
from eoam_sumo.sim.summary import FIELDS, RunSummary

OUTPUTS_DOC = Path(__file__).resolve().parents[1] / "docs" / "outputs.md"


def _outputs() -> str:
    return OUTPUTS_DOC.read_text(encoding="utf-8")


def test_the_readme_lists_every_summary_field_in_order():
    rows = re.findall(r"^\| (`[^|]+`) \|", _outputs(), flags=re.MULTILINE)
    documented = [name for cell in rows for name in re.findall(r"`(\w+)`", cell)]
    assert tuple(documented) == FIELDS


def test_the_readme_names_every_results_column():
    text = " ".join(_outputs().split("`results.csv` (batch)", 1)[1].split())
    named = {n.strip() for quoted in re.findall(r"`([^`]+)`", text) for n in quoted.split(",")}
    assert set(COLUMNS) - set(SUMMARY_COLUMNS) - named == set()
    listing = re.search(r"settings \(`([^`]+)`\)", text).group(1)
    assert tuple(c.strip() for c in listing.split(",")) == COLUMNS[: len(PARAMETERS) - 1]


def test_results_columns_are_the_parameters_status_and_every_summary_field():
    # every summary field is a column once: those that repeat a case parameter are that column
    assert set(COLUMNS) >= {RENAMED.get(f, f) for f in FIELDS}
    assert (
        tuple(c for c in (RENAMED.get(f, f) for f in FIELDS) if c not in PARAMETERS)
        == SUMMARY_COLUMNS
    )
    assert COLUMNS[: len(PARAMETERS) - 1] == PARAMETERS[:-1]
    assert COLUMNS[-2:] == ("sumocfg", "inputs_sha256") and len(set(COLUMNS)) == len(COLUMNS)
    # numbers are the fields typed as numbers (or None), and nothing typed otherwise
    hints = {f.name: f.type for f in dataclasses.fields(RunSummary)}
    for name in FIELDS:
        column = RENAMED.get(name, name)
        numeric = hints[name] in ("float", "int", "float | None")
        assert (column in NUMERIC_COLUMNS) == numeric, name


def test_every_timeseries_column_has_one_source():
    sources = [
        *runlog._FROM_STATE,
        *runlog._FROM_MEAS,
        *runlog._FROM_CMD,
        *runlog._FROM_PERCEPTION,
        runlog._SECTOR,
        runlog._ROAD_MU,
        "brake_force_n",
    ]
    assert sorted(sources) == sorted(runlog.COLUMNS)
    assert set(runlog._FROM_MEAS.values()) <= set(EgoMeasurement._fields)
    assert set(runlog._FROM_CMD.values()) <= set(Command._fields)
    assert set(runlog._FROM_PERCEPTION.values()) <= set(Perception._fields)


def test_a_logged_step_lands_in_its_named_columns():
    log = runlog.RunLog(3, brake_gains=(0.6, 0.4))
    meas = EgoMeasurement(1.5, 30.0, 0.1, 0.02, -1.0, 0.5, 200.0, 0.25, 0.01, 0.0, 0.7, 3.5)
    x = [10.0, -1.75, 0.05, 30.0, 0.1, 0.02, 0.003, 100.0, 200.0, 150.0]
    cmd = Command(
        0.004, 110.0, 0.0, 2, True, "F", -2.0, 1.0, 3.0, 0.1, 0.2, 0.001, 0.002, 0.0005, 29.0
    )
    log.add(meas, x, cmd, Perception(55.0, -12.0, True), 0.9)
    log.add(meas, x, None, None, 0.9)
    first, end = (dict(zip(runlog.COLUMNS, row)) for row in log.array())
    assert first["time_s"] == 1.5 and first["lateral_offset_m"] == 0.25
    assert first["steer_rad"] == 0.003 and first["brake_force_n"] == 0.6 * 200.0 + 0.4 * 150.0
    assert first["steer_cmd_rad"] == 0.004 and first["sector"] == ord("F")
    assert first["aro_range_m"] == 55.0 and first["oncoming_detected"] == 1.0
    assert first["mode"] == 2 and first["speed_target_mps"] == 29.0
    assert first["mu"] == 0.9  # the road's friction, not the 0.7 the EOAM believed
    assert np.isnan(end["mode"]) and np.isnan(end["aro_range_m"]) and end["mu"] == 0.9


def test_the_end_row_carries_the_mode_and_sector_in_force_and_no_other_command():
    log = runlog.RunLog(3, (0.6, 0.4))
    meas = EgoMeasurement(1.5, 30.0, 0.1, 0.02, -1.0, 0.5, 200.0, 0.25, 0.01, 0.0, 0.7, 3.5)
    x = [10.0, -1.75, 0.05, 30.0, 0.1, 0.02, 0.003, 100.0, 200.0, 150.0]
    cmd = Command(
        0.004, 110.0, 0.0, 3, True, "E", -2.0, 1.0, 3.0, 0.1, 0.2, 0.001, 0.002, 0.0005, 29.0
    )
    log.add(meas, x, cmd, Perception(55.0, -12.0, True), 0.9)
    log.add_end(meas, x, cmd, 0.9)
    frame = log.frame()
    end = frame.iloc[-1]
    assert end["mode"] == 3 and end["sector"] == "E"
    command_columns = set(runlog._FROM_CMD) - {"mode"}
    assert all(pd.isna(end[c]) for c in command_columns)
    assert pd.isna(end["aro_range_m"]) and end["x_m"] == 10.0
    log.add_end(meas, x, None, 0.9)  # no step made: nothing in force
    assert pd.isna(log.frame().iloc[-1]["mode"]) and log.frame().iloc[-1]["sector"] == ""
