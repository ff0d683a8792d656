"""Plots of a batch: the Table 2 grid (ours | paper) and lateral offsets across cases (Fig. 25).

Figures are drawn on matplotlib's Agg canvas through the object interface (no pyplot, no
global backend change).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Patch, Rectangle

from eoam_sumo.batch.report import TABLE_PNG, mu_text, outcome_grid
from eoam_sumo.batch.results import RESULTS_FILE, read_results
from eoam_sumo.colours import DARK_TEXT
from eoam_sumo.colours import HEX as OUTCOME_COLOURS
from eoam_sumo.params import LANE_CHANGE_HEIGHT_M, PONR_FRACTION
from eoam_sumo.plotting.figures import save
from eoam_sumo.sim.runlog import read_timeseries

_MISSING = "#ffffff"
_STYLES = ("-", "--", "-.", ":")
LANE_WIDTH_M = LANE_CHANGE_HEIGHT_M  # the lane change's height (paper sec. 4.2)
PONR_M = PONR_FRACTION * LANE_WIDTH_M  # point of no return (paper sec. 8.1)


def _text_colour(colour: str) -> str:
    return "black" if colour is None or colour in DARK_TEXT else "white"


def plot_table2(grid, path: Path) -> Path:
    """The outcome grid (``report.OutcomeGrid``) as an image: each cell split ours | paper."""
    n_rows, n_cols = len(grid.rows), len(grid.mus)
    halves = 2 if grid.has_paper else 1
    fig = Figure(figsize=(3.2 + 1.9 * n_cols, 1.6 + 0.42 * n_rows), layout="constrained")
    ax = fig.add_subplot()
    for (i, j), cell in grid.cells.items():
        parts = [cell.ours, cell.paper] if halves == 2 else [cell.ours]
        for k, colour in enumerate(parts):
            x0 = j + k / halves
            ax.add_patch(Rectangle((x0, i), 1 / halves, 1, facecolor=OUTCOME_COLOURS.get(
                colour, _MISSING), edgecolor="white", linewidth=0.6))
            ax.text(x0 + 0.5 / halves, i + 0.5, colour or "—", ha="center", va="center",
                    fontsize=8, color=_text_colour(colour))
        ax.add_patch(Rectangle((j, i), 1, 1, fill=False, edgecolor="white", linewidth=3.5))
        if halves == 2 and cell.compared and not cell.agrees:
            ax.add_patch(Rectangle((j + 0.03, i + 0.06), 0.94, 0.88, fill=False,
                                   edgecolor="black", linewidth=2.2))
    labels = []
    previous = None
    for i, (traffic, speed) in enumerate(grid.rows):
        labels.append(f"{traffic}   {speed}" if traffic != previous else speed)
        if previous is not None and traffic != previous:
            ax.axhline(i, color="black", linewidth=1.5)
        previous = traffic
    ax.set_xlim(0, n_cols)
    ax.set_ylim(n_rows, 0)
    ax.set_yticks(np.arange(n_rows) + 0.5, labels, fontsize=9)
    sub = "\nours | paper" if halves == 2 else ""
    ax.set_xticks(np.arange(n_cols) + 0.5, [f"μ = {mu_text(mu)}{sub}" for mu in grid.mus],
                  fontsize=10)
    ax.xaxis.tick_top()
    ax.tick_params(length=0)
    for spine in ax.spines.values():
        spine.set_visible(False)
    if grid.has_paper:
        title = (f"EOAM outcomes: each cell ours | paper (Table 2) — "
                 f"{grid.agreeing}/{grid.compared} cells agree (differences framed)")
    else:
        title = f"EOAM outcomes ({len(grid.cells)} cases)"
    ax.set_title(title, fontsize=11)
    present = {c.ours for c in grid.cells.values()} | {c.paper for c in grid.cells.values()}
    handles = [Patch(facecolor=OUTCOME_COLOURS[c], label=c) for c in OUTCOME_COLOURS
               if c in present]
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), frameon=False)
    return save(fig, path)


def _offsets(batch_dir: Path, case_dir: str) -> pd.DataFrame:
    return read_timeseries(Path(batch_dir) / case_dir / "timeseries.csv",
                           ["time_s", "lateral_offset_m", "mode"])


def _panel(ax, batch_dir: Path, rows: pd.DataFrame, label_of, cmap_name: str) -> int:
    """Lateral offset against time of each ``rows`` case; returns the number of lines."""
    rows = rows[rows["status"] == "ok"]
    cmap = _colormap(cmap_name)
    for k, (_, row) in enumerate(rows.iterrows()):
        ts = _offsets(batch_dir, row["case_dir"])
        colour = cmap(0.45 + 0.55 * k / max(len(rows) - 1, 1))
        ax.plot(ts["time_s"], ts["lateral_offset_m"], color=colour, linewidth=1.8,
                linestyle=_STYLES[k % len(_STYLES)],
                label=f"{label_of(row)} ({row['outcome']})")
        ax.plot(ts["time_s"].iloc[-1], ts["lateral_offset_m"].iloc[-1], marker="s",
                markersize=9, color=OUTCOME_COLOURS.get(row["outcome"], _MISSING),
                markeredgecolor="black")
    ax.axhline(LANE_WIDTH_M, color="0.4", linestyle="--", linewidth=0.8)
    ax.axhline(PONR_M, color="0.4", linestyle=":", linewidth=0.8)
    ax.text(ax.get_xlim()[0], LANE_WIDTH_M, " next lane centre", va="bottom", fontsize=8)
    ax.text(ax.get_xlim()[0], PONR_M, " point of no return", va="bottom", fontsize=8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("lateral offset from the original lane centre [m] (left +)")
    ax.grid(alpha=0.3)
    if len(rows):
        ax.legend(fontsize=8, title="end marker: outcome colour", title_fontsize=8)
    return len(rows)


def _colormap(name: str):
    from matplotlib import colormaps

    return colormaps[name]


def plot_lateral_offsets(batch_dir: Path, results: pd.DataFrame, out_dir: Path,
                         speed_kmh: float | None = None) -> Path | None:
    """Figure 25: lateral offset vs time at one speed, across frictions with no oncoming car
    (left) and across oncoming distances at the highest friction (right).

    ``speed_kmh`` defaults to 120 km/h when the batch has it, else its most common speed;
    None is returned when the batch has no finished case at that speed.
    """
    ok = results[results["status"] == "ok"]
    if ok.empty:
        return None
    speeds = ok["ego_speed_kmh"]
    if speed_kmh is None:
        speed_kmh = 120.0 if (speeds == 120.0).any() else float(speeds.mode().iloc[0])
    at_speed = ok[ok["ego_speed_kmh"] == speed_kmh]
    if at_speed.empty:
        return None
    top_mu = float(at_speed["mu"].max())
    no_onc = at_speed[at_speed["oncoming_start_m"].isna()].sort_values("mu", ascending=False)
    dry = at_speed[at_speed["mu"] == top_mu].sort_values(
        "oncoming_start_m", ascending=False, na_position="first")
    fig = Figure(figsize=(13, 5.2), layout="constrained")
    left, right = fig.subplots(1, 2, sharey=True)
    _panel(left, batch_dir, no_onc, lambda r: f"μ = {mu_text(r['mu'])}", "Blues")
    left.set_title(f"{speed_kmh:g} km/h, no oncoming traffic, across frictions")
    _panel(right, batch_dir, dry, lambda r: "no oncoming" if pd.isna(r["oncoming_start_m"])
           else f"oncoming from {r['oncoming_start_m']:g} m", "Purples")
    right.set_title(f"{speed_kmh:g} km/h, μ = {mu_text(top_mu)}, across oncoming start distances")
    fig.suptitle("Ego lateral position during the EOAM (cf. paper Figure 25)")
    return save(fig, Path(out_dir) / f"lateral_offsets_{speed_kmh:g}kmh.png")


def plot_batch(batch_dir: Path, out_dir: Path) -> list[Path]:
    """Every batch plot of a batch folder (has results.csv): Table 2 image and Figure 25."""
    results = read_results(Path(batch_dir) / RESULTS_FILE)
    if results["draw"].notna().any():  # a sampled batch: its envelopes, no Table 2 grid
        from eoam_sumo.plotting.envelope_plots import plot_envelopes

        return plot_envelopes(results, out_dir)
    paths = [plot_table2(outcome_grid(results), Path(out_dir) / TABLE_PNG)]
    fig25 = plot_lateral_offsets(batch_dir, results, out_dir)
    if fig25 is not None:
        paths.append(fig25)
    return paths
