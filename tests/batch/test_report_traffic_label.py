"""Table 2 rows without an added oncoming car are named by what their runs had: a scenario
whose own traffic came against the ego is never 'No oncoming'."""

from __future__ import annotations

import pandas as pd

from eoam_sumo.batch.report import outcome_grid, traffic_label
from eoam_sumo.batch.results import COLUMNS


def _results(oncoming_start_m: list, oncoming_traffic: list) -> pd.DataFrame:
    rows = []
    for k, (start, seen) in enumerate(zip(oncoming_start_m, oncoming_traffic)):
        row = dict.fromkeys(COLUMNS)
        row.update(
            case_id=f"c{k}",
            ego_speed_kmh=90.0 + 30.0 * (k % 2),
            mu=1.0,
            oncoming_start_m=start,
            status="ok",
            outcome="green",
            paper_outcome="",
            case_dir=f"cases/c{k}",
            reason="r",
            modes_visited="[0]",
            collision_with="none",
            oncoming_traffic=str(seen),
        )
        rows.append(row)
    return pd.DataFrame(rows, columns=list(COLUMNS))


def test_labels():
    assert traffic_label(float("nan")) == "No oncoming"
    assert traffic_label(None, scenario_traffic=True) == "Scenario's oncoming traffic"
    assert traffic_label(400.0, scenario_traffic=True) == "Oncoming, 400 m"


def test_a_row_whose_runs_met_oncoming_traffic_is_named_so():
    grid = outcome_grid(_results([None, None, 400.0, 400.0], [False, True, True, True]))
    assert [traffic for traffic, _ in grid.rows] == [
        "Scenario's oncoming traffic",
        "Scenario's oncoming traffic",
        "Oncoming, 400 m",
        "Oncoming, 400 m",
    ]


def test_a_row_without_any_stays_no_oncoming():
    grid = outcome_grid(_results([None, None, 300.0], [False, False, True]))
    assert [traffic for traffic, _ in grid.rows][:2] == ["No oncoming", "No oncoming"]
