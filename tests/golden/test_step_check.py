"""The step check (``tests/golden/step_check.py``): its sorting of differences, and a few
Table 2 cells at the study's SUMO step against the golden 10 ms files."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.sim.settings import STUDY_SUMO_STEP_S
from tests.golden.step_check import report, run_table2_at, step_differences
from tests.golden.table2_golden import EXPECTED, _read, cells


def _cells(**changed) -> pd.DataFrame:
    """Two golden rows, the first with ``changed`` fields."""
    rows = _read(EXPECTED).head(2).copy()
    for column, value in changed.items():
        rows.loc[rows.index[0], column] = value
    return rows


def test_differences_are_sorted_by_kind_and_only_the_cases_run_count():
    want = _read(EXPECTED)
    first = want.iloc[0]
    gap = f"{float(first['min_gap_aro_m']) + 0.03:.3f}"  # tolerance 0.02
    within = f"{float(first['sim_time_s']) + 0.04:.3f}"  # tolerance 0.05
    got = _cells(outcome="red", min_gap_aro_m=gap, sim_time_s=within)
    diff = step_differences(got, want)  # the other 62 golden cases were not run
    assert diff["words"] == [f"{first['case_id']} outcome: green -> red"]
    assert len(diff["figures"]) == 1 and "min_gap_aro_m" in diff["figures"][0]
    assert diff["switches"] == []
    assert "does not keep" in report(diff, 0.05, 2)
    clean = step_differences(_cells(), want)
    assert not any(clean.values()) and " keeps " in report(clean, 0.05, 2)


@pytest.mark.sumo
def test_cells_at_the_study_step_keep_the_golden_words_and_figures(tmp_path):
    # the knife-edge cell (overlap 0.513 against the 0.5 of an offset hit) and a head-on
    # hit of the oncoming car on ice
    run = run_table2_at(tmp_path, STUDY_SUMO_STEP_S, cases=r"^onc-(400_v120|300_v165)_mu0\.1$")
    got = cells(run)
    assert len(got) == 2
    diff = step_differences(got, _read(EXPECTED))
    assert not any(diff.values()), report(diff, STUDY_SUMO_STEP_S, len(got))
