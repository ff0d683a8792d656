"""Table 2 of a batch: our outcome colours beside the paper's (markdown and image).

Rows are the traffic (no oncoming car, then each oncoming start distance) by initial ego
speed, columns the surface friction, as in the paper's Table 2 (a matrix without ``mu``: one
column, the network's own lane frictions); a row more for each other
combination of the settings that vary (``SETTINGS``: vehicle, policy, driver, road, ...),
named in its label; rows and columns follow the order of the results (the matrix's order).
Each cell holds our colour and the paper's; every cell that differs is numbered and listed
below the table with a link to the case's ``summary.json`` and the reason for its outcome. A
batch without a published counterpart (a user's own sweep) gets the same grid with our
colours only, and the list covers every case that was not green.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd

from eoam_sumo.colours import FAILED, LEGEND, MARKERS, OUTCOMES

NEAR_MISS_MARK = "⚡"
TABLE_MD = "table2.md"
TABLE_PNG = "table2.png"


@dataclass(frozen=True)
class Setting:
    """A results.csv column that changes the system under test or its scenario and that a
    matrix may sweep or sample; ``label`` formats its value in a report's row; ``pooled``:
    a drawn value is an uncertain scenario input that one probability map pools over."""

    column: str
    label: str
    pooled: bool = False


#: Every setting a matrix may sweep or sample (``matrix.SCHEMA``'s [sweep] keys and
#: ``matrix.SAMPLED``, ``abs``/``esc``/``abs_esc`` as ``abs_fitted``/``esc_fitted``), in
#: the order a row's label names them. Results of two combinations of them never share a
#: cell of a report or a fit; a report leaves out the ones it lays out itself (its axes).
SETTINGS = (
    Setting("aro_hold_s", "ARO hold {:g} s", pooled=True),
    Setting("aro_decel_mps2", "ARO decel {:g} m/s²", pooled=True),
    Setting("vehicle", "{}"),
    Setting("abs_fitted", "ABS {}"),
    Setting("esc_fitted", "ESC {}"),
    Setting("policy", "{} policy"),
    Setting("driver", "driver {}"),
    Setting("road", "{} road"),
    Setting("los", "LoS {}"),
    Setting("lanes", "{:g} lanes", pooled=True),
    Setting("speed_limit_kmh", "limit {:g} km/h", pooled=True),
    Setting("curve_radius_m", "curve radius {:g} m", pooled=True),
    Setting("mu_belief", "believed mu {}"),
    Setting("radar_model", "{} radar"),
    Setting("radar_range_m", "radar {:g} m"),
    Setting("v2x_range_m", "V2X {:g} m"),
    Setting("v2x_latency_s", "V2X latency {:g} s"),
    Setting("v2x_loss", "V2X loss {:g}"),
    Setting("v2x_penetration", "V2X share {:g}"),
    Setting("max_time_s", "time limit {:g} s"),
    Setting("after_stop_s", "{:g} s after the stop"),
    Setting("sumo_step_s", "SUMO step {:g} s"),
    Setting("ego_speed_kmh", "{:g} km/h", pooled=True),
    Setting("mu", "mu {:g}", pooled=True),
    Setting("oncoming_start_m", "oncoming car at {:g} m", pooled=True),
)
#: Table 2's own axes: the rows' traffic and speed, the columns' friction.
GRID_AXES = ("oncoming_start_m", "ego_speed_kmh", "mu")


def _known(results: pd.DataFrame, column: str) -> pd.Series:
    """A setting's values, but the empty cell of a failed case (a summary field it never
    wrote, such as ``abs_fitted``: no value of its own)."""
    failed = results["status"] != "ok" if "status" in results else False
    return results.loc[~(failed & results[column].isna()), column]


def varying_settings(results: pd.DataFrame, leave_out: tuple[str, ...] = ()) -> list[Setting]:
    """The ``SETTINGS`` (but ``leave_out``) that take more than one value in ``results``
    (an empty cell, the default, is a value of its own)."""
    return [
        s
        for s in SETTINGS
        if s.column in results
        and s.column not in leave_out
        and _known(results, s.column).nunique(dropna=False) > 1
    ]


def setting_text(setting: Setting, value) -> str:
    """A setting's value as a row names it ('' for an empty cell)."""
    if value is None or (not isinstance(value, str) and pd.isna(value)):
        return ""
    return setting.label.format(value)


def settings_label(row, settings: list[Setting]) -> str:
    """'sedan, safe policy, driver r157-cc': the row's values of ``settings``."""
    return ", ".join(t for t in (setting_text(s, row[s.column]) for s in settings) if t)


def subject_of(results: pd.DataFrame) -> str:
    """Whose outcomes a report shows: 'EOAM outcomes', one reference driver's ('r157-cc
    outcomes'), or 'outcomes per driver (eoam, r157-cc)'."""
    drivers = (
        list(pd.unique(_known(results, "driver").fillna("eoam"))) if "driver" in results else []
    )
    if drivers in ([], ["eoam"]):
        return "EOAM outcomes"
    if len(drivers) == 1:
        return f"{drivers[0]} outcomes"
    return f"outcomes per driver ({', '.join(map(str, drivers))})"


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
    mus: tuple[float | None, ...]  # None: each lane's own friction (the network's)
    cells: dict[tuple[int, int], Cell]
    has_paper: bool
    subject: str = "EOAM outcomes"  # whose outcomes: ``subject_of``
    # the frictions under the ego at the start of the cases on the network's own
    net_mus_at_start: tuple[float, ...] = ()

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


@dataclass(frozen=True)
class GridLayout:
    """Where each case of a results frame goes in Table 2's grid: ``rows`` (traffic, speed
    and settings label), ``mus`` (the columns), and per case (in the frame's order) its
    (row, column)."""

    rows: tuple[tuple[str, str], ...]
    mus: tuple[float | None, ...]  # None: each lane's own friction (the network's)
    places: tuple[tuple[int, int], ...]


def grid_layout(results: pd.DataFrame) -> GridLayout:
    """A row per traffic, speed and combination of the other settings that vary
    (``SETTINGS``, labelled after the speed), a column per friction; in the frame's order."""
    varying = varying_settings(results, leave_out=GRID_AXES)
    no_car = results["oncoming_start_m"].isna()
    seen = results.loc[no_car, "oncoming_traffic"] if "oncoming_traffic" in results else []
    scenario_traffic = bool((pd.Series(seen, dtype=object).astype(str) == "True").any())
    rows: list[tuple[str, str]] = []
    row_of: dict[tuple, int] = {}
    mus: list[float | None] = []
    places = []
    for _, row in results.iterrows():
        traffic = traffic_label(row["oncoming_start_m"], scenario_traffic)
        speed = f"{row['ego_speed_kmh']:g} km/h"
        identity = (traffic, speed, *(_identity(row[s.column]) for s in varying))
        if identity not in row_of:
            row_of[identity] = len(rows)
            rows.append((traffic, ", ".join(t for t in (speed, settings_label(row, varying)) if t)))
        mu = _identity(row["mu"])  # empty: the network's own frictions
        if mu not in mus:
            mus.append(mu)
        places.append((row_of[identity], mus.index(mu)))
    return GridLayout(tuple(rows), tuple(mus), tuple(places))


def _identity(value):
    """A setting's value as a row's key: an empty cell is one value (NaN is not NaN)."""
    return None if value is None or (not isinstance(value, str) and pd.isna(value)) else value


def outcome_grid(results: pd.DataFrame) -> OutcomeGrid:
    """The grid of a results frame (``runner.read_results``; layout: ``grid_layout``), the
    paper's colours from its ``paper_outcome`` column (empty where unpublished)."""
    layout = grid_layout(results)
    cells = {}
    for place, (_, row) in zip(layout.places, results.iterrows()):
        cells[place] = Cell(
            row["case_id"],
            row["outcome"] if row["status"] == "ok" else FAILED,
            row["paper_outcome"] or None,
            row["case_dir"],
            _detail(row),
            str(row.get("near_miss", "")) == "True",
            _margins(row),
        )
    has_paper = any(c.paper for c in cells.values())
    return OutcomeGrid(
        layout.rows, layout.mus, cells, has_paper, subject_of(results), net_mus_at_start(results)
    )


def net_mus_at_start(results: pd.DataFrame) -> tuple[float, ...]:
    """The distinct frictions under the ego at the start (``mu_at_start``) of the finished
    cases that ran on the network's own frictions (``mu`` empty), in the frame's order."""
    if "mu_at_start" not in results:
        return ()
    own = results["mu"].isna() & (results["status"] == "ok")
    return tuple(float(m) for m in pd.unique(results.loc[own, "mu_at_start"].dropna()))


def mu_text(mu: float | None) -> str:
    """Friction as the paper writes it: 1.0, 0.7, 0.35; "network's" for each lane's own (None
    or an empty cell)."""
    if mu is None or math.isnan(mu):
        return "network's"
    return f"{mu:.1f}" if round(mu, 1) == mu else f"{mu:g}"


def net_mu_line(grid: OutcomeGrid) -> list[str]:
    """The line saying what the network's own friction was (none when every case set mu)."""
    if None not in grid.mus:
        return []
    start = ", ".join(mu_text(m) for m in grid.net_mus_at_start) or "not recorded"
    return [
        "Surface mu: each lane's own, as the network sets it (no mu in the matrix); under "
        f"the ego at its start: {start}.",
        "",
    ]


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
        f"# {title}: {grid.subject}" + (" — this run / the paper" if grid.has_paper else ""),
        "",
        *_counts_markdown(grid),
        *net_mu_line(grid),
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
        surface = "network's mu" if mu is None else f"mu {mu_text(mu)}"
        lines.append(f"{n}. **{traffic}, {speed}, {surface}** — {versus}: {cell.detail}.{link}")
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
