"""Envelope plots of a sampled batch: each outcome's probability over speed x friction.

Per outcome (any contact, red, near miss) a row of three panels: the draws pooled in cells
(:mod:`eoam_sumo.plotting.envelope_bins`; each cell ``events/draws``, empty cells hatched),
the probability map (:mod:`eoam_sumo.batch.probability_map`, a binomial GLM; the draws
marked) and the width of its 95 % band. An outcome no draw had is named in the title instead
of drawn. A row per slice of the map (``probability_map.slices``: policy, vehicle, level of
service, ...) and outcome; generated-scenario studies: one ``envelope_<road>.png`` per road.
The map's values go to ``outcome_probability_map.csv`` beside them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle
from matplotlib.transforms import Bbox

from eoam_sumo.batch.probability_map import (
    OUTCOMES,
    UNDECIDED,
    X,
    Y,
    decided,
    probability_map,
    slice_name,
    slices,
    write_probability_map,
)
from eoam_sumo.plotting.envelope_bins import Axis, axes_of, cell_counts, cell_probability
from eoam_sumo.plotting.figures import save
from eoam_sumo.plotting.label_fit import fit_in_cells, thin_ticks
from eoam_sumo.sampling import wilson_interval

ENVELOPE_PNG = "envelope.png"
LABELS = {"contact": "P(contact)", "red": "P(red: head-on after a lane change)"}
LABELS["near_miss"] = "P(near miss)"
SPEED_LABEL, MU_LABEL = "initial ego speed [km/h]", "surface friction mu"
LEVELS = np.linspace(0.0, 1.0, 11)


def _coords(axis: Axis) -> tuple[np.ndarray, list[float], list[str]]:
    """Cell edges in plot coordinates, tick positions, tick labels (levels: 0, 1, ...)."""
    if axis.levels:
        edges = np.arange(len(axis.levels) + 1) - 0.5
        return edges, list(range(len(axis.levels))), axis.labels()
    return np.asarray(axis.edges), list(axis.edges), axis.labels()


def _hatch_empty(ax) -> None:
    """Cells without draws show the hatched background (NaN cells are left undrawn)."""
    ax.add_patch(
        Rectangle(
            (0, 0),
            1,
            1,
            transform=ax.transAxes,
            fill=False,
            hatch="///",
            edgecolor="0.75",
            linewidth=0,
            zorder=0,
        )
    )


def _bins_panel(ax, draws: pd.DataFrame, event: np.ndarray, title: str) -> list:
    """Events/draws per cell over speed (y) x friction (x); the texts with their cells."""
    sx, sy = axes_of(draws)
    count, n = cell_counts(sx, sy, event)
    (ye, yt, yl), (xe, xt, xl) = _coords(sx), _coords(sy)
    _hatch_empty(ax)
    mesh = ax.pcolormesh(xe, ye, cell_probability(count, n), cmap="Reds", vmin=0, vmax=1)
    texts = []
    for i, j in zip(*np.nonzero(n)):
        p = count[i, j] / n[i, j]
        text = ax.text(
            (xe[j] + xe[j + 1]) / 2,
            (ye[i] + ye[i + 1]) / 2,
            f"{count[i, j]}/{n[i, j]}",
            ha="center",
            va="center",
            fontsize=8,
            color="white" if p > 0.6 else "black",
        )
        texts.append((text, Bbox.from_extents(xe[j], ye[i], xe[j + 1], ye[i + 1])))
    ax.set_xticks(xt, xl, rotation=45 if len(xl) > 6 else 0)
    ax.set_yticks(yt, yl)
    ax.set_xlabel(MU_LABEL + ("" if sy.levels else f" (bins of {sy.step:g})"))
    ax.set_ylabel(SPEED_LABEL if sx.levels else f"{SPEED_LABEL} (bins of {sx.step:g})")
    ax.set_title(f"{title}: events/draws per cell", fontsize=9)
    ax.figure.colorbar(mesh, ax=ax, shrink=0.85, label="probability")
    return texts


def _short(model: str) -> str:
    return model.replace(X, "v").replace(Y, "mu").replace("logit GLM: ", "logit GLM ")


def _map_panels(ax_p, ax_w, fitted: pd.DataFrame, draws: pd.DataFrame, event) -> None:
    """The map (colours and contours of p, the draws marked) and its band's width."""
    xs, ys = np.unique(fitted[Y]), np.unique(fitted[X])
    model = str(fitted["model"].iloc[0])
    if model.startswith("none"):
        p, low, high = fitted[["p", "p_low", "p_high"]].iloc[0]
        for ax in (ax_p, ax_w):
            ax.set_axis_off()
        ax_p.text(
            0.5,
            0.5,
            f"no map: {model[model.index('(') + 1 : model.index(')')]}\n"
            f"overall p = {p:.2f} [{low:.2f}, {high:.2f}]",
            ha="center",
            va="center",
            transform=ax_p.transAxes,
            fontsize=9,
            wrap=True,
        )
        return
    if len(xs) < 2 or len(ys) < 2:  # one parameter constant: a curve with its band
        _curve(ax_p, fitted, draws, event, model)
        ax_w.set_axis_off()
        return
    grid = fitted.pivot_table(index=X, columns=Y, values=["p", "p_low", "p_high"])
    fig = ax_p.figure
    filled = ax_p.contourf(xs, ys, grid["p"].to_numpy(), levels=LEVELS, cmap="Reds")
    lines = ax_p.contour(
        xs, ys, grid["p"].to_numpy(), levels=[0.1, 0.5, 0.9], colors="k", linewidths=0.6
    )
    ax_p.clabel(lines, fontsize=7, fmt="%.1f")
    hit = np.asarray(event, bool)
    marks = {"clip_on": False, "zorder": 3}  # swept levels sit on the axes' edges and corners
    ax_p.scatter(
        draws[Y][~hit],
        draws[X][~hit],
        s=14,
        facecolors="none",
        edgecolors="0.3",
        linewidths=0.6,
        **marks,
    )
    ax_p.scatter(draws[Y][hit], draws[X][hit], s=22, marker="x", color="k", linewidths=0.9, **marks)
    ax_p.set_title(f"map: {_short(model)}\n(o no event, x event)", fontsize=9)
    fig.colorbar(filled, ax=ax_p, shrink=0.85, label="probability")
    width = (grid["p_high"] - grid["p_low"]).to_numpy()
    band = ax_w.contourf(xs, ys, width, levels=LEVELS, cmap="Greys")
    ax_w.set_title("map's 95 % band: p_high - p_low", fontsize=9)
    fig.colorbar(band, ax=ax_w, shrink=0.85, label="band width")
    for ax in (ax_p, ax_w):
        ax.set_xlabel(MU_LABEL)
        ax.set_ylabel(SPEED_LABEL)


def _curve(ax, fitted: pd.DataFrame, draws: pd.DataFrame, event, model: str) -> None:
    """A map over one parameter: p with its 95 % band, the draws at 0 and 1."""
    column = X if fitted[X].nunique() > 1 else Y
    fitted = fitted.sort_values(column)
    ax.fill_between(
        fitted[column], fitted["p_low"], fitted["p_high"], color="C3", alpha=0.25, label="95 % band"
    )
    ax.plot(fitted[column], fitted["p"], color="C3", label="p")
    ax.scatter(draws[column], np.asarray(event, float), s=8, marker="|", color="k")
    ax.set_ylim(-0.05, 1.05)
    ax.set_xlabel(SPEED_LABEL if column == X else MU_LABEL)
    ax.set_ylabel("probability")
    ax.set_title(f"map: {_short(model)}", fontsize=9)
    ax.legend(fontsize=7, loc="best")


def _rows(results: pd.DataFrame, fitted: pd.DataFrame, slice_of) -> tuple[list, list[str]]:
    """(slice name, draws, outcome, its map) per drawn row; notes on outcomes none had."""
    rows, notes = [], []
    ok = decided(results)
    for outcome, event in OUTCOMES.items():
        hits = event(ok)
        if not hits.any():
            high = wilson_interval(0, len(ok))[1]
            notes.append(f"{LABELS[outcome]} = 0 in all {len(ok)} draws [0, {high:.3f}]")
            continue
        for name, draws, selected in slice_of(ok, fitted):
            rows.append((name, draws, outcome, selected[selected["outcome"] == outcome]))
    return rows, notes


def _figure(rows: list, notes: list[str], title: str, path: Path) -> Path:
    """The figure of ``rows`` (three panels each), titled, labels fitted, saved."""
    fig = Figure(figsize=(15, 3.4 * max(len(rows), 1) + 0.6), layout="constrained")
    texts = []
    if rows:
        axes = fig.subplots(len(rows), 3, squeeze=False)
        for (name, draws, outcome, fitted), (ax_b, ax_p, ax_w) in zip(rows, axes):
            event = OUTCOMES[outcome](draws).to_numpy()
            texts += _bins_panel(ax_b, draws, event, f"{name}{LABELS[outcome]}")
            _map_panels(ax_p, ax_w, fitted, draws, event)
    fig.suptitle("\n".join([title, *notes]), fontsize=11)
    thin_ticks(fig)
    fit_in_cells(fig, texts)
    return save(fig, path)


def _title(results: pd.DataFrame, what: str) -> str:
    failed = int((results["status"] != "ok").sum())
    undecided = int((results["status"] == "ok").sum()) - len(decided(results))
    left_out = [f"{failed} failed"] * bool(failed) + [f"{undecided} {UNDECIDED}"] * bool(undecided)
    own = Y in results and bool(results[Y].isna().any())  # no mu: the network's frictions
    return (
        f"{what}: {len(decided(results))} draws"
        + (f" ({', '.join(left_out)}, left out)" if left_out else "")
        + "; hatched cells: no draw"
        + ("; mu: the network's own, under the ego at its start" if own else "")
    )


def _matching(fitted: pd.DataFrame, values: dict) -> pd.DataFrame:
    """The map's rows of one slice (an empty value matches an empty cell)."""
    keep = pd.Series(True, index=fitted.index)
    for column, value in values.items():
        same = fitted[column].isna() if pd.isna(value) else fitted[column] == value
        keep &= same
    return fitted[keep]


def _slices_of(results: pd.DataFrame, road: str | None = None):
    """The rows' source: per slice of the map (``probability_map.slices`` of every finished
    draw; of one road only when given), its name, draws and maps."""
    every = slices(decided(results))

    def slice_of(_ok: pd.DataFrame, fitted: pd.DataFrame):
        for values, draws in every:
            if road is None or values.get("road") == road:
                name = slice_name(values, leave_out=("road",) if road else ())
                yield (f"{name}: " if name else ""), draws, _matching(fitted, values)

    return slice_of


def plot_envelopes(results: pd.DataFrame, out_dir: Path) -> list[Path]:
    """``envelope.png`` and ``outcome_probability_map.csv``, a row of panels per slice of
    the map and outcome; for generated scenarios (a ``road`` column) one
    ``envelope_<road>.png`` per road instead."""
    if decided(results).empty:
        return []
    fitted = probability_map(results)
    write_probability_map(Path(out_dir), fitted)
    roads = results["road"].fillna("").astype(str) if "road" in results else pd.Series()
    if (roads != "").any():
        return [
            _road_envelopes(results, roads == road, fitted, road, out_dir)
            for road in sorted(set(roads) - {""})
        ]
    rows, notes = _rows(results, fitted, _slices_of(results))
    path = Path(out_dir) / ENVELOPE_PNG
    return [_figure(rows, notes, _title(results, "Outcome envelopes"), path)]


def _road_envelopes(
    results: pd.DataFrame, on_road: pd.Series, fitted: pd.DataFrame, road: str, out_dir
) -> Path:
    """``envelope_<road>.png``: per slice of the road's maps (its level of service, ...)
    and outcome, the three panels."""
    rows, notes = _rows(results[on_road], fitted, _slices_of(results, road))
    title = _title(results[on_road], f"Outcome envelopes, {road} road")
    return _figure(rows, notes, title, Path(out_dir) / f"envelope_{road}.png")
