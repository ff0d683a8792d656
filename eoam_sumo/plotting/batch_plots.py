"""Plots of a batch: the Table 2 grid (ours | paper) and lateral offsets across cases (Fig. 25,
one figure per speed swept).

Figures are drawn on matplotlib's Agg canvas through the object interface (no pyplot, no
global backend change).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Patch, Rectangle

from eoam_sumo.batch.case import PARAMETERS
from eoam_sumo.batch.probabilities import PROBABILITIES_FILE, group_of
from eoam_sumo.batch.report import TABLE_PNG, mu_text, outcome_grid
from eoam_sumo.batch.results import RESULTS_FILE, read_results
from eoam_sumo.batch.vehicles_report import VEHICLES_PNG, sweeps_vehicles
from eoam_sumo.colours import DARK_TEXT
from eoam_sumo.colours import HEX as OUTCOME_COLOURS
from eoam_sumo.params import PONR_FRACTION
from eoam_sumo.plotting.envelope_plots import plot_envelopes
from eoam_sumo.plotting.figures import draw_all, save
from eoam_sumo.plotting.runfacts import (
    fit,
    lane_width_m,
    oncoming_seen,
    point_of_no_return_m,
    traffic_text,
)
from eoam_sumo.plotting.vehicle_plots import plot_vehicles
from eoam_sumo.sim.margins import NEAR_MISS_GAP_M, NEAR_MISS_TTC_S
from eoam_sumo.sim.runlog import read_timeseries, written_as

_MISSING = "#ffffff"
MARGINS_PNG = "margins.png"
_STYLES = ("-", "--", "-.", ":")


def _text_colour(colour: str) -> str:
    return "black" if colour is None or colour in DARK_TEXT else "white"


def plot_table2(grid, path: Path) -> Path:
    """The outcome grid (``report.OutcomeGrid``) as an image: each cell split ours | paper."""
    n_rows, n_cols = len(grid.rows), len(grid.mus)
    halves = 2 if grid.has_paper else 1
    fig = Figure(figsize=(3.2 + 1.9 * n_cols, 1.6 + 0.42 * n_rows), layout="constrained")
    ax = fig.add_subplot()
    for (i, j), cell in grid.cells.items():
        _draw_cell(ax, i, j, cell, halves)
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
    ax.set_xticks(
        np.arange(n_cols) + 0.5, [_mu_tick(grid, mu) + sub for mu in grid.mus], fontsize=10
    )
    ax.xaxis.tick_top()
    ax.tick_params(length=0)
    for spine in ax.spines.values():
        spine.set_visible(False)
    if grid.has_paper:
        title = (
            f"{grid.subject}: each cell ours | paper (Table 2) — "
            f"{grid.agreeing}/{grid.compared} cells agree (differences framed)"
        )
    else:
        title = f"{grid.subject} ({len(grid.cells)} cases)"
    ax.set_title(fit(title, 1.9 * n_cols, 11), fontsize=11)  # centred on the cells
    present = {c.ours for c in grid.cells.values()} | {c.paper for c in grid.cells.values()}
    handles = [
        Patch(facecolor=OUTCOME_COLOURS[c], label=c) for c in OUTCOME_COLOURS if c in present
    ]
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), frameon=False)
    return save(fig, path)


def _mu_tick(grid, mu: float | None) -> str:
    """A column's friction: "μ = 0.7", or each lane's own with the one under the ego at
    the start ("μ: the network's\n(0.4 at the ego's start)")."""
    if mu is not None:
        return f"μ = {mu_text(mu)}"
    start = ", ".join(mu_text(m) for m in grid.net_mus_at_start)
    return "μ: the network's" + (f"\n({start} at the ego's start)" if start else "")


def _draw_cell(ax, i: int, j: int, cell, halves: int) -> None:
    """Cell (row i, column j): ours (and the paper's) colour and name, framed when the two
    differ."""
    parts = [cell.ours, cell.paper] if halves == 2 else [cell.ours]
    for k, colour in enumerate(parts):
        x0 = j + k / halves
        ax.add_patch(
            Rectangle(
                (x0, i),
                1 / halves,
                1,
                facecolor=OUTCOME_COLOURS.get(colour, _MISSING),
                edgecolor="white",
                linewidth=0.6,
            )
        )
        ax.text(
            x0 + 0.5 / halves,
            i + 0.5,
            colour or "—",
            ha="center",
            va="center",
            fontsize=8,
            color=_text_colour(colour),
        )
    ax.add_patch(Rectangle((j, i), 1, 1, fill=False, edgecolor="white", linewidth=3.5))
    if halves == 2 and cell.compared and not cell.agrees:
        ax.add_patch(
            Rectangle(
                (j + 0.03, i + 0.06), 0.94, 0.88, fill=False, edgecolor="black", linewidth=2.2
            )
        )


def _has_series(batch_dir: Path, case_dir: str) -> bool:
    """Whether the case wrote its time series (csv or parquet)."""
    return written_as(Path(batch_dir) / case_dir / "timeseries.csv").is_file()


def _offsets(batch_dir: Path, case_dir: str) -> pd.DataFrame:
    return read_timeseries(
        Path(batch_dir) / case_dir / "timeseries.csv", ["time_s", "lateral_offset_m", "mode"]
    )


#: How a swept matrix key is named in a legend (other keys: ``key = value``).
_SWEEP_FORMATS = {
    "ego_speed_kmh": "{:g} km/h",
    "aro_hold_s": "ARO hold {:g} s",
    "aro_decel_mps2": "ARO decel {:g} m/s²",
    "max_time_s": "time limit {:g} s",
    "radar_range_m": "radar {:g} m",
}


def swept_keys(results: pd.DataFrame) -> list[str]:
    """The matrix keys (results.csv parameter columns, the scenario file too) that take more
    than one value in ``results``."""
    keys = [c for c in PARAMETERS if c not in ("case_id", "draw") and c in results]
    return [c for c in keys if results[c].nunique(dropna=False) > 1]


def _key_text(row, key: str) -> str:
    value = row[key]
    if key == "mu":
        return "the network's μ" if pd.isna(value) else f"μ = {mu_text(value)}"
    if key == "sumocfg":
        return Path(str(value)).name
    if pd.isna(value):
        return f"{key} default"
    fmt = _SWEEP_FORMATS.get(key)
    return (
        fmt.format(value)
        if fmt
        else f"{key} = {value:g}"
        if isinstance(value, float)
        else f"{key} = {value}"
    )


class _CaseFacts:
    """What each case folder of a batch says: lane width recorded, oncoming traffic seen."""

    def __init__(self, batch_dir: Path):
        self.batch_dir = Path(batch_dir)
        self._cache: dict[str, tuple] = {}

    def __call__(self, case_dir: str) -> tuple[float, bool, bool]:
        """(lane width, recorded, oncoming traffic seen) of a case."""
        if case_dir not in self._cache:
            folder = self.batch_dir / case_dir
            try:
                summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
            except (OSError, ValueError):
                summary = {}
            width, recorded = lane_width_m(summary if isinstance(summary, dict) else {})
            self._cache[case_dir] = (width, recorded, oncoming_seen(folder))
        return self._cache[case_dir]


def _label(row, keys: list[str], facts: _CaseFacts) -> str:
    parts = []
    for key in keys:
        if key == "oncoming_start_m":
            parts.append(traffic_text(row[key], facts(row["case_dir"])[2]))
        else:
            parts.append(_key_text(row, key))
    return ", ".join(parts)


def _panel(
    ax, batch_dir: Path, rows: pd.DataFrame, label_of, cmap_name: str, facts: _CaseFacts
) -> int:
    """Lateral offset against time of each ``rows`` case, with the next lane's centre and
    the point of no return of each lane width the cases ran on; returns the number of
    lines."""
    rows = rows[rows["status"] == "ok"]
    cmap = _colormap(cmap_name)
    widths: dict[float, bool] = {}
    for k, (_, row) in enumerate(rows.iterrows()):
        ts = _offsets(batch_dir, row["case_dir"])
        width, recorded, _ = facts(row["case_dir"])
        widths[width] = widths.get(width, True) and recorded
        colour = cmap(0.45 + 0.55 * k / max(len(rows) - 1, 1))
        ax.plot(
            ts["time_s"],
            ts["lateral_offset_m"],
            color=colour,
            linewidth=1.8,
            linestyle=_STYLES[k % len(_STYLES)],
            label=f"{label_of(row)} ({row['outcome']})",
        )
        ax.plot(
            ts["time_s"].iloc[-1],
            ts["lateral_offset_m"].iloc[-1],
            marker="s",
            markersize=9,
            color=OUTCOME_COLOURS.get(row["outcome"], _MISSING),
            markeredgecolor="black",
        )
    for width, recorded in widths.items():
        lane = f"{width:.2f} m lane" + ("" if recorded else ", assumed: not recorded")
        ponr = point_of_no_return_m(width)
        ax.axhline(width, color="0.4", linestyle="--", linewidth=0.8)
        ax.axhline(ponr, color="0.4", linestyle=":", linewidth=0.8)
        ax.text(ax.get_xlim()[0], width, f" next lane centre ({lane})", va="bottom", fontsize=8)
        ax.text(
            ax.get_xlim()[0],
            ponr,
            f" point of no return ({PONR_FRACTION:g} x {width:.2f} m)",
            va="bottom",
            fontsize=8,
        )
    ax.set_xlabel("time [s]")
    ax.set_ylabel("lateral offset from the original lane centre [m] (left +)")
    ax.grid(alpha=0.3)
    if len(rows):
        ax.legend(fontsize=8, title="end marker: outcome colour", title_fontsize=8)
    return len(rows)


def _colormap(name: str):
    from matplotlib import colormaps

    return colormaps[name]


def plot_lateral_offsets(
    batch_dir: Path, results: pd.DataFrame, out_dir: Path, speed_kmh: float
) -> Path | None:
    """Figure 25 at one speed: lateral offset vs time of the cases without an added oncoming
    car (left) and of the cases at the highest friction across the oncoming settings
    (right). Each line is named by every key the batch sweeps (but the speed); None when the
    batch has no finished case at that speed."""
    ok = results[results["status"] == "ok"]
    at_speed = ok[ok["ego_speed_kmh"] == speed_kmh]
    if at_speed.empty:
        return None
    facts = _CaseFacts(batch_dir)
    keys = [k for k in swept_keys(results) if k != "ego_speed_kmh"]
    top_mu = float(at_speed["mu"].max())  # NaN: each lane's own friction (the network's)
    no_onc = at_speed[at_speed["oncoming_start_m"].isna()].sort_values("mu", ascending=False)
    top = at_speed["mu"].isna() if np.isnan(top_mu) else at_speed["mu"] == top_mu
    dry = at_speed[top].sort_values("oncoming_start_m", ascending=False, na_position="first")
    varied = [k for k in keys if k != "oncoming_start_m"]
    left_keys = varied or ["mu"]
    across = f", across {', '.join(_KEY_NAMES.get(k, k) for k in varied)}" if varied else ""
    if any(facts(c)[2] for c in no_onc["case_dir"]):
        left_keys.append("oncoming_start_m")  # the scenario's own traffic: say which saw it
        left_title = "no oncoming car added"
    else:
        left_title = "no oncoming traffic"
    right_keys = ["oncoming_start_m", *(k for k in keys if k not in ("mu", "oncoming_start_m"))]
    fig = Figure(figsize=(13, 5.2), layout="constrained")
    left, right = fig.subplots(1, 2, sharey=True)
    _panel(left, batch_dir, no_onc, lambda r: _label(r, left_keys, facts), "Blues", facts)
    left.set_title(fit(f"{speed_kmh:g} km/h, {left_title}{across}", 6.3, 12))
    _panel(right, batch_dir, dry, lambda r: _label(r, right_keys, facts), "Purples", facts)
    surface = "the network's μ" if np.isnan(top_mu) else f"μ = {mu_text(top_mu)}"
    right.set_title(fit(f"{speed_kmh:g} km/h, {surface}, across oncoming settings", 6.3, 12))
    fig.suptitle("Ego lateral position during the EOAM (cf. paper Figure 25)")
    return save(fig, Path(out_dir) / f"lateral_offsets_{speed_kmh:g}kmh.png")


_KEY_NAMES = {
    "mu": "frictions",
    "aro_hold_s": "ARO hold times",
    "aro_decel_mps2": "ARO decelerations",
    "max_time_s": "time limits",
    "radar_range_m": "radar ranges",
    "sumocfg": "scenarios",
    "policy": "policies",
    "v2x_range_m": "V2X ranges",
    "mu_belief": "friction beliefs",
    "radar_model": "radar models",
    "seed": "seeds",
}


def plot_batch_report(results: pd.DataFrame, out_dir: Path) -> list[Path]:
    """The images ``eoam-sumo batch`` draws beside its report: ``table2.png`` and
    ``margins.png`` (and ``vehicles.png`` when vehicles, ABS/ESC or policies are swept), or
    for a sampled batch ``envelope.png``."""
    if is_sampled(results):
        return plot_envelopes(results, out_dir)
    draws = [
        lambda: plot_margins(results, Path(out_dir) / MARGINS_PNG),
        lambda: plot_table2(outcome_grid(results), Path(out_dir) / TABLE_PNG),
    ]
    if sweeps_vehicles(results):  # vehicles, ABS/ESC or policies swept
        draws.append(lambda: plot_vehicles(results, Path(out_dir) / VEHICLES_PNG))
    margins, *rest = draw_all(draws)  # at once: the margins here, the rest in copies
    return [rest[0], margins, *rest[1:]]


def _batch_rows(batch_dir: Path, results: pd.DataFrame) -> pd.DataFrame:
    """A sampled batch's own draws: per group the first ``n`` rows of results.csv, ``n`` the
    group's in its outcome_probabilities.csv (the batch writes its matrix's rows first; rows
    kept from a larger matrix by ``--resume`` follow, and were counted too). Other batches,
    or one without that file: every row."""
    path = batch_dir / PROBABILITIES_FILE
    if not is_sampled(results) or not path.is_file():
        return results
    try:
        sizes = pd.read_csv(path).groupby("group")["n"].first()
    except (OSError, ValueError, KeyError, pd.errors.ParserError):
        return results
    group = results["case_id"].map(group_of)
    rank = results.groupby(group).cumcount()
    return results[rank < group.map(sizes).fillna(len(results))].reset_index(drop=True)


def is_sampled(results: pd.DataFrame) -> bool:
    """Whether a results frame is of a sampled batch (its cases are numbered draws)."""
    return bool(results["draw"].notna().any())


def plot_batch(batch_dir: Path, out_dir: Path) -> list[Path]:
    """Every batch plot of a batch folder (has results.csv): Table 2 image and Figure 25."""
    results = _batch_rows(Path(batch_dir), read_results(Path(batch_dir) / RESULTS_FILE))
    paths = plot_batch_report(results, out_dir)
    if is_sampled(results):  # its envelopes, no Table 2 grid
        return paths
    ok = results[results["status"] == "ok"]
    ok = ok[[_has_series(batch_dir, d) for d in ok["case_dir"]]]  # --timeseries none: none
    for speed_kmh in pd.unique(ok["ego_speed_kmh"]):
        fig25 = plot_lateral_offsets(batch_dir, ok, out_dir, float(speed_kmh))
        if fig25 is not None:
            paths.append(fig25)
    return paths


def plot_margins(results: pd.DataFrame, path: Path) -> Path:
    """Each case's margins (summary ``min_gap_aro_m``, ``min_gap_oncoming_m``,
    ``min_ttc_oncoming_s``) in the matrix's order, with the near-miss thresholds; near misses
    marked, contacts shown at zero."""
    ok = results[results["status"] == "ok"].reset_index(drop=True)
    x = np.arange(len(ok))
    fig = Figure(figsize=(max(8.0, 0.22 * len(ok) + 2.0), 7.0), layout="constrained")
    gaps, ttcs = fig.subplots(2, 1, sharex=True)
    cap_m, cap_s = 6.0, 6.0  # larger margins are drawn at the cap
    for column, marker, label in (
        ("min_gap_aro_m", "o", "gap to the obstacle (ARO)"),
        ("min_gap_oncoming_m", "s", "gap to oncoming traffic"),
    ):
        gaps.scatter(x, ok[column].clip(upper=cap_m), marker=marker, s=22, label=label)
    gaps.axhline(
        NEAR_MISS_GAP_M,
        color="red",
        linestyle="--",
        linewidth=0.9,
        label=f"near miss: {NEAR_MISS_GAP_M:g} m",
    )
    gaps.set_ylabel(f"smallest box gap [m] (capped at {cap_m:g})")
    ttcs.scatter(
        x,
        ok["min_ttc_oncoming_s"].clip(upper=cap_s),
        marker="D",
        s=22,
        color="0.3",
        label="time to collision with oncoming traffic",
    )
    ttcs.axhline(
        NEAR_MISS_TTC_S,
        color="red",
        linestyle="--",
        linewidth=0.9,
        label=f"near miss: {NEAR_MISS_TTC_S:g} s",
    )
    ttcs.set_ylabel(f"smallest time to collision [s] (capped at {cap_s:g})")
    for k, row in ok.iterrows():
        colour = OUTCOME_COLOURS.get(row["outcome"], _MISSING)
        for ax in (gaps, ttcs):
            ax.axvspan(k - 0.5, k + 0.5, color=colour, alpha=0.18, linewidth=0)
            if str(row.get("near_miss")) == "True":
                ax.axvspan(k - 0.5, k + 0.5, fill=False, hatch="//", edgecolor="red", linewidth=0)
    ttcs.set_xticks(x, ok["case_id"], rotation=90, fontsize=7)
    for ax in (gaps, ttcs):
        ax.set_xlim(-0.5, max(len(ok), 1) - 0.5)
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    gaps.set_title("Margins per case (background: outcome colour; hatched: near miss)")
    return save(fig, path)
