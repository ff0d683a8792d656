"""The vehicles figure of a batch (``vehicles.png``): Table 2's colour counts per vehicle.

One panel per policy; per vehicle one stacked bar per ABS/ESC equipment side by side, the
paper's Table 2 counts (Lowe & Guvenc 2022, sec. 11.2) as the reference bar on the left when
the batch has a paper table.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from eoam_sumo.batch.vehicles_report import GROUP, colour_counts, paper_counts
from eoam_sumo.colours import HEX
from eoam_sumo.decision.policy import POLICIES
from eoam_sumo.plotting.figures import save

_HATCHES = ("", "//", "..", "xx")


def _stack(ax, x: float, counts: dict[str, int], colours: list[str], hatch: str) -> None:
    """One stacked bar at ``x`` of the colour ``counts``."""
    bottom = 0
    for colour in colours:
        n = counts.get(colour, 0)
        if n:
            ax.bar(x, n, 0.8, bottom=bottom, color=HEX[colour], edgecolor="black", hatch=hatch)
            bottom += n


#: The figure's width: the legend's beside the panels, and per bar or gap between bars [in].
_LEGEND_WIDTH_IN = 2.2
_BAR_WIDTH_IN = 0.35


def _panel(ax, counts: pd.DataFrame, paper: dict[str, int], colours: list[str], title: str):
    """One policy's bars: the paper's (if the batch has a paper table), then per vehicle one
    per equipment."""
    equipment = list(pd.unique(counts["equipment"]))
    ticks: list[float] = []
    labels: list[str] = []
    x = -1.0
    if any(paper.values()):
        _stack(ax, 0.0, paper, colours, "")
        ticks, labels, x = [0.0], ["paper"], 1.0
    for vehicle, group in counts.groupby("vehicle", sort=False):
        start = x + 1.0
        for _, row in group.iterrows():
            x += 1.0
            hatch = _HATCHES[equipment.index(row["equipment"]) % len(_HATCHES)]
            _stack(ax, x, row.to_dict(), colours, hatch)
        ticks.append((start + x) / 2.0)  # under the middle of its bars
        labels.append(str(vehicle))
        x += 1.0
    ax.set_xticks(ticks, labels, rotation=30, ha="right")
    ax.set_xlim(-1.0, x)  # the first bar is at 0, the last at x - 1: a bar's space each side
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))  # counts of cells
    ax.set_ylabel("cells")
    # the EOAM's runs are labelled by their policy alone, a reference driver's by its name
    ax.set_title(f"{title} policy" if title in POLICIES else title)


def plot_vehicles(results: pd.DataFrame, path: Path) -> Path:
    """``vehicles.png`` of a results frame (module docstring); return its path."""
    return save(vehicles_figure(results), path)


def vehicles_figure(results: pd.DataFrame) -> Figure:
    """The vehicles figure of a results frame (module docstring), laid out."""
    counts = colour_counts(results)
    paper = paper_counts(results)
    colours = [c for c in counts.columns if c not in (*GROUP, "agree", "compared")]
    policies = list(pd.unique(counts["policy"]))
    bars = len(counts) / len(policies) + counts["vehicle"].nunique() + 1  # with the gaps
    width = _LEGEND_WIDTH_IN + max(_BAR_WIDTH_IN * bars, 3.0)
    fig = Figure(figsize=(width, 4.5 * len(policies)))
    axes = fig.subplots(len(policies), 1, squeeze=False)[:, 0]
    for ax, policy in zip(axes, policies):
        _panel(ax, counts[counts["policy"] == policy], paper, colours, str(policy))
    equipment = list(pd.unique(counts["equipment"]))
    handles = [Patch(facecolor=HEX[c], edgecolor="black", label=c) for c in colours] + [
        Patch(facecolor="white", edgecolor="black", hatch=_HATCHES[i % len(_HATCHES)], label=e)
        for i, e in enumerate(equipment)
    ]
    axes[0].legend(handles=handles, fontsize="small", loc="upper left", bbox_to_anchor=(1, 1))
    fig.suptitle("Table 2 colour counts per vehicle and ABS/ESC")
    fig.tight_layout()
    return fig
