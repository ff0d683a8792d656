"""The protocol scorecard as the protocols draw their grids: one panel per test, VUT speed
down the rows, overlap or impact location across, each cell the point's colour with its
impact speed; extended-range cells dashed; R152 rows coloured by verdict."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

FILL = {
    "green": "#2e9e44",
    "yellow": "#f2d22e",
    "orange": "#f28c28",
    "brown": "#8b5a2b",
    "red": "#d62728",
    "not_run": "#bbbbbb",
    "pass": "#2e9e44",
    "fail": "#d62728",
    "undetermined": "#f2d22e",
}


def _panels(frame: pd.DataFrame) -> list[tuple[str, pd.DataFrame]]:
    out = []
    for (test, side), own in frame.groupby(["test", "policy_side"], sort=False, dropna=False):
        label = f"{test} ({side})" if isinstance(side, str) and side else str(test)
        out.append((label, own))
    return out


def _draw_panel(ax, label: str, own: pd.DataFrame) -> None:
    rows = sorted(
        {
            (r.ego_speed_kmh, r.target_speed_kmh, r.gap_m, r.target_decel_mps2)
            for r in own.itertuples()
        }
    )
    cols = sorted(set(own["overlap"]))
    for r in own.itertuples():
        i = rows.index((r.ego_speed_kmh, r.target_speed_kmh, r.gap_m, r.target_decel_mps2))
        j = cols.index(r.overlap)
        key = r.verdict if isinstance(r.verdict, str) and r.verdict else r.colour
        ax.add_patch(
            Rectangle(
                (j, i),
                1,
                1,
                facecolor=FILL.get(key, "white"),
                edgecolor="black",
                linewidth=0.5,
                linestyle="--" if r.range == "extended" else "-",
            )
        )
        text = "-" if pd.isna(r.impact_speed_kmh) else f"{r.impact_speed_kmh:.0f}"
        ax.text(j + 0.5, i + 0.5, text, ha="center", va="center", fontsize=6)
    ax.set_xlim(0, len(cols))
    ax.set_ylim(len(rows), 0)
    ax.set_xticks([j + 0.5 for j in range(len(cols))], [f"{c:g}" for c in cols], fontsize=6)
    ax.set_yticks([i + 0.5 for i in range(len(rows))], [_row_label(r) for r in rows], fontsize=6)
    ax.set_xlabel("overlap / impact location [%]", fontsize=7)
    ax.set_title(label, fontsize=8)


def _row_label(row: tuple) -> str:
    ego, target, gap, decel = row
    text = f"{ego:g}/{target:g}"
    return text + (f", {gap:.0f} m, {decel:g} m/s2" if decel else "")


def plot_scorecard(frame: pd.DataFrame, path: Path, title: str = "") -> Path:
    """Draw the scorecard grid of a protocol's results into ``path`` (PNG)."""
    panels = _panels(frame)
    ncols = min(3, len(panels))
    nrows = -(-len(panels) // ncols)
    heights = [
        max(
            len(own.groupby(["ego_speed_kmh", "target_speed_kmh", "gap_m", "target_decel_mps2"]))
            for _, own in panels
        )
        * 0.28
        + 1.2
    ]
    fig = Figure(figsize=(4.2 * ncols, heights[0] * nrows))
    axes = fig.subplots(nrows, ncols, squeeze=False)
    for ax, (label, own) in zip(axes.flat, panels):
        _draw_panel(ax, label, own)
    for ax in list(axes.flat)[len(panels) :]:
        ax.axis("off")
    fig.suptitle(
        title + "  (cell: impact speed km/h; rows VUT/target km/h; dashed: extended)", fontsize=9
    )
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    return Path(path)
