"""Table 2 of a batch: our outcome colours beside the paper's (markdown and image).

Rows are the traffic (no oncoming car, then each oncoming start distance) by initial ego
speed, columns the surface friction, as in the paper's Table 2; rows and columns follow the
order of the results (the matrix's order). Each cell holds our colour and the paper's; every
cell that differs is numbered and listed below the table with a link to the case's
``summary.json`` and the reason for its outcome. A batch without a published counterpart (a
user's own sweep) gets the same grid with our colours only, and the list covers every case
that was not green.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd

from eoam_sumo.colours import FAILED, LEGEND, MARKERS, OUTCOMES

NEAR_MISS_MARK = "⚡"
TABLE_MD = "table2.md"
TABLE_PNG = "table2.png"
_EXTRA_PARAMS = (
    ("aro_hold_s", "ARO hold {:g} s"),
    ("aro_decel_mps2", "ARO decel {:g} m/s²"),
    ("vehicle", "{}"),
    ("abs_fitted", "ABS {}"),
    ("esc_fitted", "ESC {}"),
    ("policy", "{} policy"),
)


@dataclass(frozen=True)
class Cell:
    """One case in the grid: our colour (or 'failed'), the paper's (None if unpublished)."""

    case_id: str
    ours: str
    paper: str | None
    case_dir: str
    detail: str
    near_miss: bool = False
    margins: str = ""  # the smallest gaps and time to collision, as table2.md shows them

    @property
    def compared(self) -> bool:
        return self.paper is not None

    @property
    def agrees(self) -> bool:
        return self.paper is not None and self.ours == self.paper


@dataclass(frozen=True)
class OutcomeGrid:
    """Rows x friction columns of cells; ``rows[i]`` is (traffic label, speed label)."""

    rows: tuple[tuple[str, str], ...]
    mus: tuple[float, ...]
    cells: dict[tuple[int, int], Cell]
    has_paper: bool

    @property
    def agreeing(self) -> int:
        return sum(c.agrees for c in self.cells.values())

    @property
    def compared(self) -> int:
        return sum(c.compared for c in self.cells.values())

    def differing(self) -> list[Cell]:
        """Cells to explain, in table order: those that differ from the paper (paper mode) or
        that were not green (own sweep)."""
        keys = sorted(self.cells)
        if self.has_paper:
            return [
                self.cells[k] for k in keys if self.cells[k].compared and not self.cells[k].agrees
            ]
        return [self.cells[k] for k in keys if self.cells[k].ours != "green"]


def traffic_label(oncoming_start_m: float, scenario_traffic: bool = False) -> str:
    """A row's traffic: the oncoming car the co-simulation added, else whether the runs
    without one had oncoming traffic of their scenario (``oncoming_traffic``)."""
    if oncoming_start_m is None or (
        isinstance(oncoming_start_m, float) and math.isnan(oncoming_start_m)
    ):
        return "Scenario's oncoming traffic" if scenario_traffic else "No oncoming"
    return f"Oncoming, {oncoming_start_m:g} m"


def _detail(row) -> str:
    """One line on why the case ended as it did."""
    if row["status"] != "ok":
        return f"failed: {row['error']}"
    parts = [str(row["reason"]) if row["reason"] else "no reason recorded"]
    if row["modes_visited"]:
        parts.append(f"modes {row['modes_visited']}")
    if row["collision_with"] and row["collision_with"] != "none":
        v = float(row["impact_speed_mps"])
        parts.append(
            f"hit {row['collision_with']} ({row['contact_kind']}) at {v:.1f} m/s "
            f"({v * 3.6:.0f} km/h)"
        )
    else:
        parts.append("no contact")
    return "; ".join(parts)


def _figure(value, unit: str) -> str:
    return "—" if value is None or pd.isna(value) else f"{value:.2f} {unit}"


def _margins(row) -> str:
    """'ARO 0.49 m · oncoming 0.54 m · TTC 1.03 s' (— where there was none)."""
    return (
        f"ARO {_figure(row.get('min_gap_aro_m'), 'm')} · oncoming "
        f"{_figure(row.get('min_gap_oncoming_m'), 'm')} · TTC "
        f"{_figure(row.get('min_ttc_oncoming_s'), 's')}"
    )


def outcome_grid(results: pd.DataFrame) -> OutcomeGrid:
    """The grid of a results frame (``runner.read_results``), the paper's colours from its
    ``paper_outcome`` column (empty where unpublished)."""
    varying = [
        (col, fmt)
        for col, fmt in _EXTRA_PARAMS
        if col in results and results[col].notna().any() and results[col].nunique(dropna=False) > 1
    ]
    rows: list[tuple[str, str]] = []
    mus: list[float] = []
    cells = {}
    no_car = results["oncoming_start_m"].isna()
    scenario_traffic = bool((results.loc[no_car, "oncoming_traffic"].astype(str) == "True").any())
    for _, row in results.iterrows():
        speed = f"{row['ego_speed_kmh']:g} km/h"
        extra = [fmt.format(row[col]) for col, fmt in varying if pd.notna(row[col])]
        key = (traffic_label(row["oncoming_start_m"], scenario_traffic), ", ".join([speed, *extra]))
        if key not in rows:
            rows.append(key)
        if row["mu"] not in mus:
            mus.append(row["mu"])
        ours = row["outcome"] if row["status"] == "ok" else FAILED
        cells[(rows.index(key), mus.index(row["mu"]))] = Cell(
            row["case_id"],
            ours,
            row["paper_outcome"] or None,
            row["case_dir"],
            _detail(row),
            str(row.get("near_miss", "")) == "True",
            _margins(row),
        )
    return OutcomeGrid(
        tuple(rows), tuple(mus), cells, has_paper=any(c.paper for c in cells.values())
    )


def mu_text(mu: float) -> str:
    """Friction as the paper writes it: 1.0, 0.7, 0.35."""
    return f"{mu:.1f}" if round(mu, 1) == mu else f"{mu:g}"


def _mark(colour: str | None) -> str:
    return "—" if colour is None else f"{MARKERS.get(colour, '')} {colour}"


def _counts(colours: list[str]) -> str:
    return ", ".join(f"{colours.count(c)} {c}" for c in (*OUTCOMES, FAILED) if colours.count(c))


def _ref(cell: Cell, n: int) -> str:
    """The cell's note number, linked to its summary.json (failed cases have none)."""
    return f"#{n}" if cell.ours == FAILED else f"[#{n}]({cell.case_dir}/summary.json)"


def table2_markdown(grid: OutcomeGrid, title: str = "Table 2") -> str:
    """The grid as markdown: ours / paper per cell, the agreement count, the differences."""
    lines = [
        f"# {title}: EOAM outcomes" + (" — this run / the paper" if grid.has_paper else ""),
        "",
        *_counts_markdown(grid),
        *_grid_markdown(grid),
        "",
        "Legend: "
        + "; ".join(f"{MARKERS[c]} {c}: {LEGEND[c]}" for c in LEGEND)
        + f"; {NEAR_MISS_MARK} near miss: no contact, but within 0.5 m of a road user or "
        "a time to collision with oncoming traffic under 1.5 s",
        "",
        *_differing_markdown(grid),
        "",
        *margins_markdown(grid),
    ]
    return "\n".join(lines) + "\n"


def _counts_markdown(grid: OutcomeGrid) -> list[str]:
    """The outcome counts (ours, and the paper's with the agreement when it is compared)."""
    ours = [c.ours for c in grid.cells.values()]
    if not grid.has_paper:
        return [f"Our outcomes ({len(ours)} cases): {_counts(ours)}.", ""]
    return [
        (
            "Each cell: **ours** / paper (Lowe & Guvenc, Table 2). "
            f"**{grid.agreeing}/{grid.compared} cells agree.**"
        ),
        "",
        f"- ours: {_counts(ours)}",
        f"- paper: {_counts([c.paper for c in grid.cells.values() if c.paper])}",
        "",
    ]


def _grid_markdown(grid: OutcomeGrid) -> list[str]:
    """The table: a row per traffic and speed, a column per friction; each cell ours (and the
    paper's), a near miss marked, a listed cell with its note number."""
    listed = {c.case_id: i for i, c in enumerate(grid.differing(), start=1)}
    lines = [
        "| Traffic | Initial ego speed | "
        + " | ".join(f"{mu_text(mu)} surface mu" for mu in grid.mus)
        + " |",
        "|---|---|" + "---|" * len(grid.mus),
    ]
    previous = None
    for i, (traffic, speed) in enumerate(grid.rows):
        cols = [_cell_markdown(grid, grid.cells.get((i, j)), listed) for j in range(len(grid.mus))]
        lines.append(
            f"| {traffic if traffic != previous else ''} | {speed} | " + " | ".join(cols) + " |"
        )
        previous = traffic
    return lines


def _cell_markdown(grid: OutcomeGrid, cell: Cell | None, listed: dict[str, int]) -> str:
    """One cell of the table (empty where the matrix has no case)."""
    if cell is None:
        return ""
    text = f"**{_mark(cell.ours)}**"
    if cell.near_miss:
        text += f" {NEAR_MISS_MARK}"
    if grid.has_paper:
        text += f" / {_mark(cell.paper)}"
    if cell.case_id in listed:
        text += f" {'✗ ' if grid.has_paper else ''}{_ref(cell, listed[cell.case_id])}"
    return text


def _differing_markdown(grid: OutcomeGrid) -> list[str]:
    """The numbered list of the cells that differ from the paper (or were not green), each
    with why it ended so and a link to its summary.json."""
    differing = grid.differing()
    heading = "Cells that differ from the paper" if grid.has_paper else "Cases that were not green"
    lines = [f"## {heading} ({len(differing)})", ""]
    where = {cell.case_id: key for key, cell in grid.cells.items()}
    for n, cell in enumerate(differing, start=1):
        (traffic, speed), mu = grid.rows[where[cell.case_id][0]], grid.mus[where[cell.case_id][1]]
        versus = f"ours {_mark(cell.ours)}" + (f", paper {_mark(cell.paper)}" if cell.paper else "")
        link = (
            ""
            if cell.ours == FAILED
            else f" [{cell.case_dir}/summary.json]({cell.case_dir}/summary.json)"
        )
        lines.append(
            f"{n}. **{traffic}, {speed}, mu {mu_text(mu)}** — {versus}: {cell.detail}.{link}"
        )
    if not differing:
        lines.append("None.")
    return lines


def margins_markdown(grid: OutcomeGrid) -> list[str]:
    """Each cell's margins in the grid's layout: the smallest gap to the in-lane obstacle and
    to oncoming traffic, the smallest time to collision with it; near misses marked."""
    near = sum(c.near_miss for c in grid.cells.values())
    lines = [
        f"## Margins ({near} near miss{'es' if near != 1 else ''})",
        "",
        (
            "Each cell: smallest box gap to the obstacle (ARO) · to opposite-direction traffic "
            "· smallest time to collision with it (— none); "
            f"{NEAR_MISS_MARK} near miss."
        ),
        "",
        "| Traffic | Initial ego speed | "
        + " | ".join(f"{mu_text(mu)} surface mu" for mu in grid.mus)
        + " |",
        "|---|---|" + "---|" * len(grid.mus),
    ]
    previous = None
    for i, (traffic, speed) in enumerate(grid.rows):
        cols = []
        for j in range(len(grid.mus)):
            cell = grid.cells.get((i, j))
            cols.append(
                ""
                if cell is None
                else cell.margins + (f" {NEAR_MISS_MARK}" if cell.near_miss else "")
            )
        lines.append(
            f"| {traffic if traffic != previous else ''} | {speed} | " + " | ".join(cols) + " |"
        )
        previous = traffic
    return lines
