"""The vehicles report (vehicles.md, vehicles.png) from a hand-made results frame."""

from __future__ import annotations

import pandas as pd

from eoam_sumo.batch.vehicles_report import (
    changed_cells,
    colour_counts,
    paper_counts,
    sweeps_vehicles,
    vehicles_markdown,
)
from eoam_sumo.plotting.vehicle_plots import plot_vehicles, vehicles_figure

CELLS = [(None, 165.0, 1.0, "green"), (None, 120.0, 0.1, "yellow"), (300.0, 90.0, 0.7, "red")]


def _frame(colours: dict) -> pd.DataFrame:
    """Rows for every (vehicle, ABS/ESC) in ``colours``: its outcome per ``CELLS`` cell."""
    rows = []
    for (vehicle, on), outcomes in colours.items():
        for (onc, speed, mu, paper), outcome in zip(CELLS, outcomes):
            rows.append(
                {
                    "case_id": f"{vehicle}_{on}_{speed}_{mu}",
                    "vehicle": vehicle,
                    "policy": "paper",
                    "abs_fitted": on,
                    "esc_fitted": on,
                    "oncoming_start_m": onc,
                    "ego_speed_kmh": speed,
                    "mu": mu,
                    "status": "ok",
                    "outcome": outcome,
                    "paper_outcome": paper,
                    "reason": f"because {outcome}",
                }
            )
    return pd.DataFrame(rows)


FRAME = _frame(
    {
        ("suv", False): ["green", "orange", "red"],
        ("suv", True): ["green", "yellow", "red"],
        ("van", False): ["orange", "yellow", "red"],
        ("van", True): ["orange", "yellow", "orange"],
    }
)


def test_counts_and_agreement_per_vehicle_and_equipment():
    counts = colour_counts(FRAME).set_index(["vehicle", "equipment"])
    suv_off = counts.loc[("suv", "ABS/ESC off")]
    assert (suv_off["green"], suv_off["yellow"], suv_off["orange"], suv_off["red"]) == (1, 0, 1, 1)
    assert (suv_off["agree"], suv_off["compared"]) == (2, 3)
    assert counts.loc[("suv", "ABS/ESC on"), "agree"] == 3
    assert counts.loc[("van", "ABS/ESC on"), "orange"] == 2
    assert paper_counts(FRAME) == {"green": 1, "yellow": 1, "orange": 0, "red": 1}


def test_the_cells_abs_esc_changes_are_named():
    changed = changed_cells(FRAME)
    assert changed[["vehicle", "cell", "without", "with"]].values.tolist() == [
        ["suv", "onc-none_v120_mu0.1", "orange", "yellow"],
        ["van", "onc-300_v90_mu0.7", "red", "orange"],
    ]
    assert list(changed["reason"]) == ["because yellow", "because orange"]
    text = vehicles_markdown(FRAME)
    assert "| **paper (Table 2)** | | | 1 | 1 | 0 | 1 | |" in text
    assert "| suv | ABS/ESC off | paper | 1 | 0 | 1 | 1 | 2/3 |" in text
    assert "| onc-300_v90_mu0.7 |" in text and "(ABS/ESC on) | because orange |" in text


def test_only_a_varied_batch_is_a_vehicles_batch(tmp_path):
    assert sweeps_vehicles(FRAME)
    table2 = FRAME[(FRAME["vehicle"] == "suv") & ~FRAME["abs_fitted"]]
    assert not sweeps_vehicles(table2)
    assert plot_vehicles(FRAME, tmp_path / "vehicles.png").stat().st_size > 0


def test_a_failed_case_is_no_equipment_of_its_own():
    """A failed case's ABS/ESC cells are empty: one failed case made a plain batch a vehicles
    batch (vehicles.md with a row "ABS/ESC ?")."""
    table2 = FRAME[(FRAME["vehicle"] == "suv") & ~FRAME["abs_fitted"]].astype({"abs_fitted": str})
    failed = table2.iloc[:1].assign(abs_fitted="", esc_fitted="", status="failed")
    assert not sweeps_vehicles(pd.concat([table2, failed]))


def test_one_vehicle_without_a_paper_table_gets_readable_panels():
    """One vehicle, two policies, no paper table: the panels keep their width (they were
    squeezed to a sliver beside the legend, the bars invisible) and no empty paper bar."""
    one = FRAME[FRAME["vehicle"] == "suv"].assign(paper_outcome=None)
    one = pd.concat([one, one.assign(policy="safe")], ignore_index=True)
    fig = vehicles_figure(one)
    axes = [ax for ax in fig.axes if ax.get_title().endswith("policy")]
    assert len(axes) == 2
    for ax in axes:
        assert ax.get_position().width * fig.get_figwidth() >= 2.0  # inches
        assert [t.get_text() for t in ax.get_xticklabels()] == ["suv"]
        # the bars are drawn: two equipments of three cells each
        assert sum(p.get_height() for p in ax.patches) == 6
