"""table2.md and table2.png from synthetic results frames (the report, not the physics)."""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.batch.pool import TaskResult
from eoam_sumo.batch.report import outcome_grid, table2_markdown
from eoam_sumo.batch.results import COLUMNS, read_results, result_row
from eoam_sumo.batch.runner import write_report
from eoam_sumo.matrix import load_matrix
from eoam_sumo.plotting.batch_plots import plot_batch_report

REPO = Path(__file__).resolve().parents[2]
FLIP = {"green": "orange", "yellow": "red", "orange": "green", "red": "yellow"}


def _summary(case, colour):
    hit = colour != "green"
    return {
        "outcome": colour,
        "collision_with": "oncoming" if hit else "none",
        "impact_speed_mps": 12.5 if hit else 0.0,
        "contact_kind": "side" if hit else "none",
        "reason": f"why {case.case_id}, with a comma",
        "modes_visited": [0, 1, 2, 5],
        "fcw_raised": True,
        "mu": case.mu,
        "sim_time_s": 10.0,
        "wall_time_s": 0.5,
        "realtime_factor": 20.0,
    }


def _results(tmp_path, matrix_path, differ=(), failed=()):
    """A results.csv as the runner writes it: the paper's colours except ``differ`` (flipped)
    and ``failed`` (case indices), read back with ``read_results``."""
    matrix = load_matrix(matrix_path)
    paper = matrix.paper_outcomes()
    rows = []
    for i, case in enumerate(matrix.cases()):
        published = paper.get(case.case_id)
        colour = published or "green"
        if i in differ:
            colour = FLIP[colour]
        if i in failed:
            result = TaskResult(case.case_id, error="worker process died (SIGSEGV)")
        else:
            result = TaskResult(case.case_id, value={"summary": _summary(case, colour)})
        rows.append(result_row(case, result, published))
    path = tmp_path / "results.csv"
    pd.DataFrame(rows, columns=list(COLUMNS)).to_csv(path, index=False)
    return matrix, read_results(path)


def test_table2_counts_agreement_and_links_each_difference(tmp_path):
    differ, failed = (0, 9, 33, 63), (20,)
    matrix, results = _results(tmp_path, REPO / "scenarios" / "table2.toml", differ, failed)
    cases = matrix.cases()
    assert len(cases) == 64
    md = table2_markdown(outcome_grid(results))
    assert "**59/64 cells agree.**" in md
    # the paper's layout: 16 rows (traffic x speed), friction columns 1.0 .. 0.1
    table = [
        ln for ln in md.split("## Margins")[0].splitlines() if ln.startswith("| ") and "km/h" in ln
    ]
    assert len(table) == 16
    assert "| 1.0 surface mu | 0.7 surface mu | 0.3 surface mu | 0.1 surface mu |" in md
    assert table[0].startswith("| No oncoming | 165 km/h |")
    assert table[15].startswith("|  | 55 km/h |")
    # every cell: ours / paper; the first row's first cell was flipped green -> orange
    first_cell = table[0].split("|")[3]
    assert "orange" in first_cell and "/ 🟩 green" in first_cell and "✗" in first_cell
    want = [f"cases/{cases[i].case_id}/summary.json" for i in differ]
    in_cells = re.findall(r"\[#(\d+)\]\((cases/[^)]+/summary\.json)\)", md)
    # numbered in table order; the failed case (index 20) is note 3 and has no link
    assert in_cells == list(zip(["1", "2", "4", "5"], want))
    listed = re.findall(r"^\d+\. .*\[(cases/[^]]+)\]\((cases/[^)]+)\)$", md, re.MULTILINE)
    assert listed == list(zip(want, want))
    for i in differ:
        assert f"why {cases[i].case_id}, with a comma; modes 0-1-2-5" in md
    # the failed case is listed with its error and no link to a summary it never wrote
    failed_id = cases[20].case_id
    assert f"cases/{failed_id}/summary.json" not in md
    assert "failed: worker process died (SIGSEGV)" in md
    assert "## Cells that differ from the paper (5)" in md


def test_agreeing_batch_has_no_differences(tmp_path):
    _, results = _results(tmp_path, REPO / "scenarios" / "table2.toml")
    md = table2_markdown(outcome_grid(results))
    assert "**64/64 cells agree.**" in md
    assert "](cases/" not in md and "None." in md


def test_own_sweep_gets_a_plain_pivot(tmp_path):
    cfg = REPO / "scenarios" / "baseline.sumocfg"
    matrix_path = tmp_path / "own.toml"
    matrix_path.write_text(
        f'[scenario]\nsumocfg = "{cfg}"\n[sweep]\nego_speed_kmh = [100, 70]\n'
        "mu = [0.9, 0.5, 0.2]\noncoming_start_m = [250]\naro_decel_mps2 = [6.0, 9.0]\n"
    )
    _, results = _results(tmp_path, matrix_path, differ=(1,))
    md = table2_markdown(outcome_grid(results))
    assert "agree" not in md and " / " not in md
    table = [
        ln for ln in md.split("## Margins")[0].splitlines() if ln.startswith("| ") and "km/h" in ln
    ]
    # the varying ARO deceleration is part of the row label: 2 speeds x 2 decelerations
    assert len(table) == 4 and "100 km/h, ARO decel 6 m/s²" in table[0]
    assert "| 0.9 surface mu | 0.5 surface mu | 0.2 surface mu |" in md
    assert "## Cases that were not green (1)" in md
    assert md.count("](cases/") == 2


def test_write_report_writes_markdown_and_the_cli_draws_the_pngs(tmp_path):
    _, results = _results(tmp_path, REPO / "scenarios" / "table2.toml", differ=(5,), failed=(6,))
    md = write_report(tmp_path, results)
    png, margins = plot_batch_report(results, tmp_path)
    head, _, rest = table2_markdown(outcome_grid(results)).partition("\n\n")
    text = md.read_text(encoding="utf-8")  # the grid, with the policy's line below the title
    assert text.startswith(f"{head}\n\nPolicy **paper**; forward radar") and text.endswith(rest)
    for image in (png, margins):
        assert image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and image.stat().st_size > 20_000
    assert "## Margins" in text


@pytest.mark.parametrize("colour", ["green", "red"])
def test_grid_cell_holds_both_colours(tmp_path, colour):
    _, results = _results(tmp_path, REPO / "scenarios" / "table2.toml")
    results.loc[0, "outcome"] = colour
    grid = outcome_grid(results)
    cell = grid.cells[(0, 0)]
    assert (cell.ours, cell.paper) == (colour, "green")
    assert cell.agrees == (colour == "green")
