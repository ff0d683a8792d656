"""The reports of the shipped matrices, whose settings vary only as the paper's layout has
them, stay byte-identical: table2.md (Table 2, the safe policy with and without V2X) and
vehicles.md (every vehicle, ABS/ESC and policy), from synthetic results frames, against
texts written by the code before the reports learnt to tell every setting apart."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.batch.pool import TaskResult
from eoam_sumo.batch.results import COLUMNS, read_results, result_row
from eoam_sumo.batch.runner import write_report
from eoam_sumo.batch.vehicles_report import vehicles_markdown
from eoam_sumo.matrix import load_matrix

REPO = Path(__file__).resolve().parents[2]
GOLDEN = Path(__file__).with_name("report_golden")
COLOURS = ("green", "yellow", "orange", "red")


def _summary(case, k: int) -> dict:
    """A made-up run summary of the k-th case: colours, contacts, margins and sight figures
    cycling with k (every cell kind of the report is written)."""
    colour = COLOURS[(k + k // 7) % 4]
    hit = colour != "green"
    summary = {
        "outcome": colour,
        "collision_with": "oncoming" if hit else "none",
        "impact_speed_mps": 3.5 * (k % 4),
        "contact_kind": "head_on" if hit else "none",
        "reason": f"why {case.case_id}",
        "modes_visited": [0, 1, 2][: 1 + k % 3],
        "mu": case.mu,
        "near_miss": k % 5 == 0,
        "min_gap_aro_m": 0.25 * (k % 7) if k % 3 else None,
        "min_gap_oncoming_m": 0.5 * (k % 4) if k % 2 else None,
        "min_ttc_oncoming_s": 0.75 * (k % 6) if k % 2 else None,
        "oncoming_traffic": case.oncoming_start_m is not None,
        "abs_fitted": bool(case.abs_fitted),
        "esc_fitted": bool(case.esc_fitted),
    }
    if case.policy == "safe" and k % 4:
        summary.update(
            sight_gate="passed" if k % 2 else "closed",
            sight_needed_m=150.0 + k,
            sight_known_free_m=float("inf") if k % 8 == 1 else 100.0 + k,
        )
    return summary


def _results(tmp_path: Path, matrix: str) -> pd.DataFrame:
    """The matrix's results.csv as the runner writes it, read back."""
    loaded = load_matrix(REPO / "scenarios" / matrix)
    paper = loaded.paper_outcomes()
    rows = []
    for k, case in enumerate(loaded.cases()):
        result = TaskResult(case.case_id, value={"summary": _summary(case, k)})
        rows.append(result_row(case, result, paper.get(case.case_id)))
    path = tmp_path / "results.csv"
    pd.DataFrame(rows, columns=list(COLUMNS)).to_csv(path, index=False)
    return read_results(path)


@pytest.mark.parametrize("matrix", ["table2.toml", "table2_safe.toml", "table2_safe_v2x.toml"])
def test_table2_md_of_the_shipped_tables_is_unchanged(tmp_path, matrix):
    text = write_report(tmp_path, _results(tmp_path, matrix)).read_text(encoding="utf-8")
    golden = GOLDEN / matrix.replace(".toml", ".md")
    assert text == golden.read_text(encoding="utf-8")


def test_vehicles_md_of_the_vehicles_study_is_unchanged(tmp_path):
    text = vehicles_markdown(_results(tmp_path, "vehicles.toml"))
    assert text == (GOLDEN / "vehicles.md").read_text(encoding="utf-8")
