"""The protocol scorecard as the protocols draw their grids: one panel per test, VUT speed
down the rows, overlap or impact location across, each cell the point's colour (R152: its
verdict) with the scored value and B or S (braked or steered); extended-range cells with a
thick dashed border; a colour legend; the totals of the system and policy in the title."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

FILL = {
    "green": "#2e9e44",
    "yellow": "#f2d22e",
    "orange": "#f28c28",
    "brown": "#8b5a2b",
    "red": "#d62728",
    "not_run": "#bbbbbb",
    "unscored": "#9ecae1",
    "pass": "#2e9e44",
    "fail": "#d62728",
    "undetermined": "#f2d22e",
}
#: the legend's keys by the kind of protocol: scored bands, R152 verdicts, unscored runs
LEGEND = {
    "bands": ("green", "yellow", "orange", "brown", "red", "not_run"),
    "verdicts": ("pass", "fail", "undetermined", "not_run"),
    "unscored": ("unscored", "not_run"),
}
#: characters of the 7 pt footnote per inch of figure width (a spare panel's text wraps)
FOOTNOTE_CHARS_PER_INCH = 18.0
ROW_KEYS = ["ego_speed_kmh", "target_speed_kmh", "gap_m", "target_decel_mps2"]
#: tests scored on the VUT's speed reduction (the cell shows it, not the impact speed)
REDUCTION_TESTS = ("CCFhos", "CCFhol")


def _r152_text(r) -> str:
    """An R152 row: the impact, B/S, the lane (left it: fails) and the warning's lead."""
    hit = "no contact" if not r.impact_speed_kmh else f"hit at {r.impact_speed_kmh:.1f} km/h"
    lane = ", LEFT ITS LANE" if "left its lane" in str(r.note) else ""
    lead = "no warning" if pd.isna(r.warning_lead_s) else f"warning {r.warning_lead_s:.2f} s"
    late = " (< 0.8 s: late)" if r.warning == "fail" else ""
    return f"{hit} {r.manoeuvre}{lane}; {lead}{late}"


def _cell_text(r) -> str:
    """The cell's value (impact or, head-on, reduction km/h) and B/S; '-' not run."""
    if r.status != "ok":
        return "-"
    if str(r.test).startswith("R152"):
        return _r152_text(r)
    reduction = r.test in REDUCTION_TESTS
    value = r.speed_reduction_kmh if reduction else r.impact_speed_kmh
    shown = "0" if pd.isna(value) else f"{value:.0f}"
    if reduction and pd.isna(value):
        shown = "no hit"
    mark = f" {r.manoeuvre}" if isinstance(r.manoeuvre, str) else ""
    warning = {"pass": " W", "fail": " w!"}.get(r.warning, "") if isinstance(r.warning, str) else ""
    return f"{shown}{mark}{warning}"


def _panel_title(test: str, own: pd.DataFrame, totals: dict) -> str:
    """The test, its points (or R152 passes) and what its cells show."""
    shows = "speed reduction [km/h]" if test in REDUCTION_TESTS else "impact speed [km/h]"
    if test.startswith("R152"):
        shows = "impact, manoeuvre, the warning's lead over the braking"
    t = next((x for x in totals.get("tests", []) if x["test"] == test), None)
    if t is not None:
        gated = "" if totals.get("gate_passed", True) else " before the gate"
        head = f"{test}: {t['points']:.2f} of {t['max_points']:.2f} points{gated}"
    elif test.startswith("R152"):
        passed = int((own["verdict"] == "pass").sum())
        head = f"{test}: {passed} of {len(own)} rows pass"
    else:
        head = test
    return f"{head}\ncells: {shows}"


def _draw_panel(ax, test: str, own: pd.DataFrame, totals: dict) -> None:
    rows = sorted({tuple(getattr(r, k) for k in ROW_KEYS) for r in own.itertuples()})
    cols = sorted(set(own["overlap"]))
    for r in own.itertuples():
        i, j = rows.index(tuple(getattr(r, k) for k in ROW_KEYS)), cols.index(r.overlap)
        key = r.verdict if isinstance(r.verdict, str) and r.verdict else r.colour
        ax.add_patch(
            Rectangle((j, i), 1, 1, facecolor=FILL.get(key, "white"), edgecolor="black", lw=0.4)
        )
        if r.range == "extended":
            ax.add_patch(Rectangle((j + 0.06, i + 0.08), 0.88, 0.84, fill=False, lw=1.4, ls="--"))
        ax.text(j + 0.5, i + 0.5, _cell_text(r), ha="center", va="center", fontsize=5.5)
    ax.set_xlim(0, len(cols))
    ax.set_ylim(len(rows), 0)
    r152 = test.startswith("R152")
    xlabels = ["centred"] if r152 else [f"{c:g}" for c in cols]
    ax.set_xticks([j + 0.5 for j in range(len(cols))], xlabels, fontsize=6)
    ax.set_yticks([i + 0.5 for i in range(len(rows))], [_row_label(r) for r in rows], fontsize=6)
    xlabel = "target" if r152 else "overlap / impact location [%]"
    ax.set_xlabel(xlabel, fontsize=7)
    ax.set_ylabel("VUT / target km/h", fontsize=7)
    ax.set_title(_panel_title(test, own, totals), fontsize=8)


def _row_label(row: tuple) -> str:
    ego, target, gap, decel = row
    text = f"{ego:g}/{target:g}"
    return text + (f", {gap:.0f} m, {decel:g} m/s2" if decel else "")


#: what a cell's text says, by the kind of protocol
CELL_TEXT = {
    "bands": "cell: impact km/h (CCFhos, CCFhol: speed reduction km/h); B braked in lane, "
    "S steered",
    "verdicts": "a row passes with its impact within R152's limit, its lane kept and the warning "
    "at least 0.8 s before the braking (unverified: docs/protocols.md); B braked in lane, "
    "S steered",
    "unscored": "cell: impact km/h; B braked in lane, S steered",
}


LINE_IN = 7 * 1.3 / 72  # a 7 pt line [in]
LEGEND_IN = 0.32  # the colour legend's row [in]


def _wrapped(text: str, chars: int) -> list[str]:
    """``text``'s lines wrapped to ``chars``, continued lines indented."""
    return [
        wrapped
        for line in text.split("\n")
        for wrapped in textwrap.wrap(line, chars, subsequent_indent="  ") or [""]
    ]


def _legend(fig: Figure, kind: str, footnote: list[str]) -> float:
    """Under the grids, bottom up: what a cell says (wrapped to the figure's width), the
    colours (and the extended range's border) in one row, then ``footnote``'s lines (the
    tests not built, when no spare panel holds them); returns the height they take (a
    fraction of the figure's)."""
    handles: list = [Patch(facecolor=FILL[k], edgecolor="black", label=k) for k in LEGEND[kind]]
    if kind == "bands":
        handles.append(Line2D([], [], color="black", ls="--", lw=1.4, label="extended range"))
    lines = textwrap.wrap(CELL_TEXT[kind], int(FOOTNOTE_CHARS_PER_INCH * fig.get_figwidth()))
    height_in = fig.get_figheight()
    fig.text(0.5, 0.01, "\n".join(lines), ha="center", va="bottom", fontsize=7)
    legend_y = 0.01 + (len(lines) * LINE_IN + 0.04) / height_in
    fig.legend(
        handles=handles,
        loc="lower center",
        bbox_to_anchor=(0.5, legend_y),
        ncol=len(handles),
        fontsize=7,
    )
    top = legend_y + (LEGEND_IN + len(footnote) * LINE_IN) / height_in
    if footnote:
        fig.text(0.01, top, "\n".join(footnote), va="top", ha="left", fontsize=7)
    return top + 0.01


def plot_scorecard(
    frame: pd.DataFrame,
    path: Path,
    headline: str,
    kind: str,
    totals: dict | None = None,
    footnote: str = "",
) -> Path:
    """Draw the scorecard grid of a protocol's results into ``path`` (PNG): ``headline`` its
    title, ``kind`` a ``LEGEND`` key, ``totals`` (scored protocols) with a ``tests`` list of
    per-test points and maxima for the panel titles, ``footnote`` (the tests not built) in a
    spare panel or under the grids."""
    totals = totals or {}
    panels = list(frame.groupby("test", sort=False))
    ncols = min(3, len(panels))
    nrows = -(-len(panels) // ncols)
    most_rows = max(len(own.groupby(ROW_KEYS)) for _, own in panels)
    width = max(4.4 * ncols, 8.0)
    spare_panels = nrows * ncols - len(panels)
    under = (
        []
        if spare_panels or not footnote
        else _wrapped(footnote, int(FOOTNOTE_CHARS_PER_INCH * width))
    )
    height = (most_rows * 0.3 + 1.3) * nrows + 1.6 + len(under) * LINE_IN
    fig = Figure(figsize=(width, height))
    axes = fig.subplots(nrows, ncols, squeeze=False)
    for ax, (test, own) in zip(axes.flat, panels):
        _draw_panel(ax, str(test), own, totals)
    spare = list(axes.flat)[len(panels) :]
    for ax in spare:
        ax.axis("off")
    fig.suptitle(headline, fontsize=9)
    bottom = _legend(fig, kind, under)
    fig.tight_layout(rect=(0, bottom, 1, 0.95))
    if footnote and spare:  # placed after the layout, which it must not squeeze
        x, y = spare[0].get_position().x0, spare[0].get_position().y1
        chars = int(FOOTNOTE_CHARS_PER_INCH * width * (1.0 - x))
        fig.text(x, y, "\n".join(_wrapped(footnote, chars)), va="top", ha="left", fontsize=7)
    fig.savefig(path, dpi=130)
    return Path(path)
