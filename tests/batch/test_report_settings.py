"""Every setting a matrix sweeps has rows of its own in table2.md / .png and vehicles.md: two
settings' results never share a cell or a row's count (the review's drivers, LoS and
driver x policy batches), and the title names whose outcomes they are."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.batch.policy_report import policy_line, policy_title, sight_markdown
from eoam_sumo.batch.pool import TaskResult
from eoam_sumo.batch.report import GRID_AXES, SETTINGS, outcome_grid, table2_markdown
from eoam_sumo.batch.results import COLUMNS, read_results, result_row
from eoam_sumo.batch.vehicles_report import colour_counts, vehicles_markdown
from eoam_sumo.matrix import EQUIPMENT_KEYS, SAMPLED, SCHEMA, load_matrix

REPO = Path(__file__).resolve().parents[2]
SPEEDS = "ego_speed_kmh = [165, 120, 90, 55]\n"


def _matrix(tmp_path: Path, sweep: str, scenario: str = "", paper: bool = True) -> Path:
    path = tmp_path / "m.toml"
    text = (
        f'[scenario]\nsumocfg = "{REPO / "scenarios" / "baseline.sumocfg"}"\nmax_time_s = 60.0\n'
        f"{scenario}[sweep]\n{sweep}"
    )
    if paper:
        text += f'[paper]\ntable = "{REPO / "scenarios" / "paper_table2.csv"}"\n'
    path.write_text(text)
    return path


def _results(tmp_path: Path, matrix: Path, colour_of, sight: bool = False) -> pd.DataFrame:
    """The matrix's results.csv as the runner writes it, each case's colour
    ``colour_of(case, paper colour)``, read back."""
    loaded = load_matrix(matrix)
    paper = loaded.paper_outcomes()
    rows = []
    for case in loaded.cases():
        published = paper.get(case.case_id)
        summary = {
            "outcome": colour_of(case, published),
            "collision_with": "none",
            "reason": f"why {case.case_id}",
            "mu": case.mu,
            "abs_fitted": bool(case.abs_fitted),
            "esc_fitted": bool(case.esc_fitted),
        }
        if sight and case.policy == "safe":
            summary.update(sight_gate="passed", sight_needed_m=300.0, sight_known_free_m=900.0)
        rows.append(
            result_row(case, TaskResult(case.case_id, value={"summary": summary}), published)
        )
    path = tmp_path / "results.csv"
    pd.DataFrame(rows, columns=list(COLUMNS)).to_csv(path, index=False)
    return read_results(path)


def _careful(case, published):
    """The review's outcomes: the EOAM as the paper, the careful driver yellow at mu 0.3."""
    if case.driver == "eoam":
        return published or "green"
    return "yellow" if case.mu < 0.5 else "green"


def _table_rows(md: str) -> list[str]:
    grid = md.split("## Margins", maxsplit=1)[0]
    return [ln for ln in grid.splitlines() if ln.startswith("| ") and "km/h" in ln]


def test_two_drivers_get_a_row_each_and_the_title_names_them(tmp_path):
    sweep = SPEEDS + 'mu = [1.0, 0.3]\noncoming_start_m = ["none"]\ndriver = ["eoam", "r157-cc"]\n'
    results = _results(tmp_path, _matrix(tmp_path, sweep), _careful)
    grid = outcome_grid(results)
    assert len(results) == 16 and len(grid.cells) == 16 and len(grid.rows) == 8
    speeds = [speed for _, speed in grid.rows]  # in the matrix's order: driver, then speed
    assert speeds[0] == "165 km/h, driver eoam" and speeds[4] == "165 km/h, driver r157-cc"
    assert (grid.agreeing, grid.compared) == (12, 16)
    md = table2_markdown(grid, policy_title(results))
    assert md.startswith("# Table 2: outcomes per driver (eoam, r157-cc) — this run / the paper")
    assert "EOAM outcomes" not in md and "**12/16 cells agree.**" in md
    assert len(_table_rows(md)) == 8
    assert {c.case_id for c in grid.cells.values()} == set(results["case_id"])


def test_a_reference_driver_alone_is_not_called_the_eoam(tmp_path):
    sweep = SPEEDS + 'mu = [1.0, 0.3]\noncoming_start_m = ["none"]\n'
    matrix = _matrix(tmp_path, sweep, scenario='driver = "r157-cc"\n')
    grid = outcome_grid(_results(tmp_path, matrix, _careful))
    assert grid.subject == "r157-cc outcomes" and len(grid.cells) == 8


def test_levels_of_service_get_a_row_each(tmp_path):
    path = tmp_path / "los.toml"
    path.write_text(
        '[scenario]\nmax_time_s = 20.0\nroad = "rural"\n'
        '[sweep]\nlos = ["A", "E"]\nego_speed_kmh = [80]\nmu = [1.0, 0.4]\n'
    )
    grid = outcome_grid(_results(tmp_path, path, lambda case, _: "green"))
    assert len(grid.cells) == 4
    assert [speed for _, speed in grid.rows] == ["80 km/h, LoS A", "80 km/h, LoS E"]


@pytest.mark.parametrize(
    "setting", [s for s in SETTINGS if s.column not in GRID_AXES], ids=lambda s: s.column
)
def test_any_setting_that_differs_splits_the_row(setting):
    base = {
        "case_id": "a",
        "ego_speed_kmh": 90.0,
        "mu": 1.0,
        "oncoming_start_m": float("nan"),
        "status": "ok",
        "outcome": "green",
        "paper_outcome": "",
        "case_dir": "cases/a",
        "reason": "r",
        "modes_visited": "0",
        "collision_with": "none",
        "oncoming_traffic": "False",
    }
    values = {"vehicle": ("sedan", "suv"), "abs_fitted": (False, True), "esc_fitted": (True, False)}
    text = {"policy", "driver", "road", "los", "mu_belief", "radar_model"}
    first, second = values.get(setting.column, ("x", "y") if setting.column in text else (1, 2))
    frame = pd.DataFrame(
        [{**base, setting.column: first}, {**base, "case_id": "b", setting.column: second}]
    )
    grid = outcome_grid(frame)
    assert len(grid.cells) == 2 and len(set(grid.rows)) == 2


def test_the_settings_cover_every_key_a_matrix_sweeps_or_samples():
    """A key added to the matrix must be added to ``SETTINGS`` (or be one of the seeds)."""
    keys = set(SCHEMA["sweep"]) | set(SAMPLED)
    keys = (keys - set(EQUIPMENT_KEYS)) | {"abs_fitted", "esc_fitted"}
    scenario = set(SCHEMA["scenario"]) - set(EQUIPMENT_KEYS) - {"sumocfg", "seed"}
    assert keys | scenario <= {s.column for s in SETTINGS}


def test_a_failed_case_does_not_split_its_row(tmp_path):
    """A failed case has no ABS/ESC of its own (summary fields): not a setting of its own."""
    sweep = SPEEDS + 'mu = [1.0, 0.3]\noncoming_start_m = ["none"]\n'
    results = _results(tmp_path, _matrix(tmp_path, sweep), _careful)
    results.loc[1, ["status", "outcome", "abs_fitted", "esc_fitted"]] = ["failed", None, None, None]
    grid = outcome_grid(results)
    assert len(grid.rows) == 4 and grid.rows[0] == ("No oncoming", "165 km/h")
    assert grid.cells[(0, 1)].ours == "failed"


def test_swept_policies_are_named_and_their_sight_distances_kept(tmp_path):
    sweep = SPEEDS + 'mu = [0.3]\noncoming_start_m = [300]\npolicy = ["paper", "safe"]\n'
    results = _results(tmp_path, _matrix(tmp_path, sweep), _careful, sight=True)
    assert policy_title(results) == "Table 2, policies paper and safe"
    assert policy_line(results).startswith("Policies **paper**, **safe** (a row each);")
    sight = sight_markdown(results)
    assert "| Oncoming, 300 m | 165 km/h, paper policy | — |" in sight
    assert "|  | 165 km/h, safe policy | 300 / 900 ✓ |" in sight


def test_the_careful_driver_under_two_policies_is_two_rows_of_vehicles_md(tmp_path):
    sweep = (
        SPEEDS + 'mu = [0.3]\noncoming_start_m = ["none"]\n'
        'driver = ["eoam", "r157-cc"]\npolicy = ["paper", "safe"]\n'
    )
    results = _results(tmp_path, _matrix(tmp_path, sweep), _careful)
    counts = colour_counts(results).set_index("policy")
    assert list(counts.index) == ["paper", "r157-cc, paper policy", "safe", "r157-cc, safe policy"]
    cells = counts[["green", "yellow", "orange", "red"]].sum(axis=1)
    assert (cells == 4).all() and (counts["compared"] == 4).all()
    assert counts.loc["r157-cc, safe policy", "yellow"] == 4
    assert "| sedan | ABS/ESC off | r157-cc, paper policy |" in vehicles_markdown(results)


def test_other_varying_settings_are_named_in_vehicles_md(tmp_path):
    sweep = SPEEDS + 'mu = [0.3]\noncoming_start_m = ["none"]\naro_hold_s = [1.0, 2.0]\n'
    sweep += 'vehicle = ["sedan", "suv"]\n'
    counts = colour_counts(_results(tmp_path, _matrix(tmp_path, sweep), _careful))
    assert list(counts["policy"]) == ["paper, ARO hold 1 s", "paper, ARO hold 2 s"] * 2
    assert (counts["compared"] == 4).all()


def test_table2_png_has_the_drivers_rows_and_names_them(tmp_path, monkeypatch):
    from eoam_sumo.plotting import batch_plots

    figures = []
    monkeypatch.setattr(batch_plots, "save", lambda fig, path, **_: figures.append(fig) or path)
    sweep = SPEEDS + 'mu = [1.0, 0.3]\noncoming_start_m = ["none"]\ndriver = ["eoam", "r157-cc"]\n'
    grid = outcome_grid(_results(tmp_path, _matrix(tmp_path, sweep), _careful))
    batch_plots.plot_table2(grid, tmp_path / "table2.png")
    (ax,) = figures[0].axes
    title = ax.get_title().replace("\n", " ")
    assert title.startswith("outcomes per driver (eoam, r157-cc): each cell") and "12/16" in title
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert len(labels) == 8 and labels[4] == "165 km/h, driver r157-cc"
