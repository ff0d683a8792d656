"""An R157 study as the regulation's Appendix 3 figures show it: per ego speed (rows), the
careful driver and the EOAM side by side (columns; FSM and RSS between them when run), the
scenario's two parameters on the axes (cut-in: lateral speed across, initial gap up), each
point a filled circle where the collision is avoided and a cross where it is not; a point
the EOAM fails while the careful driver avoids it (R157's test failed) ringed in red."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from eoam_sumo.plotting.figures import save

AXES = {  # kind -> (x key, x label, y key, y label)
    "cut-in": ("lateral_mps", "cut-in lateral speed [m/s]", "gap_m", "gap at the cut-in [m]"),
    "cut-out": ("lateral_mps", "cut-out lateral speed [m/s]", "gap_m", "to the stopped car [m]"),
    "deceleration": ("decel_mps2", "lead deceleration [m/s^2]", "gap_m", "gap to the lead [m]"),
}
#: The columns, in this order, of the drivers a study ran.
PANELS = (
    ("r157-cc", "R157 careful driver"),
    ("fsm", "Fuzzy Safety Model"),
    ("rss", "RSS"),
    ("eoam", "EOAM"),
)
SAFE, HIT, FAILED = "#2e9e44", "#d62728", "#d62728"


def _panel(ax, rows: list[dict], kind: str, failed: set) -> None:
    xk, xl, yk, yl = AXES[kind]
    for r in rows:
        x, y = r[xk], r[yk]
        if r["collision"]:
            ax.plot(x, y, "x", color=HIT, ms=9, mew=2)
        else:
            ax.plot(x, y, "o", color=SAFE, ms=8)
        if (x, y) in failed:
            ax.plot(x, y, "o", mfc="none", mec=FAILED, ms=16, mew=1.5)
    ax.set_xlabel(xl)
    ax.set_ylabel(yl)
    ax.grid(True, alpha=0.3)


def r157_figure(rows: list[dict], kind: str, failed: list[dict], path: Path) -> Path:
    """The study's chart (``failed``: ``study.eoam_fails_where_careful_avoids``)."""
    speeds = sorted({r["ego_kmh"] for r in rows})
    panels = [(d, t) for d, t in PANELS if any(r["driver"] == d for r in rows)]
    fig = Figure(figsize=(4.5 * len(panels), 3.2 * len(speeds) + 0.8))
    axes = fig.subplots(len(speeds), len(panels), squeeze=False, sharex=True)
    xk, _, yk, _ = AXES[kind]
    for i, v in enumerate(speeds):
        at = {(r[xk], r[yk]) for r in failed if r["ego_kmh"] == v}
        for j, (driver, title) in enumerate(panels):
            sel = [r for r in rows if r["ego_kmh"] == v and r["driver"] == driver]
            _panel(axes[i][j], sel, kind, at if driver == "eoam" else set())
            axes[i][j].set_title(f"{title}, ego {v:g} km/h", fontsize=10)
    handles = [
        Line2D([], [], marker="o", color=SAFE, ls="", label="no collision"),
        Line2D([], [], marker="x", color=HIT, ls="", mew=2, label="collision"),
        Line2D(
            [],
            [],
            marker="o",
            mfc="none",
            mec=FAILED,
            ls="",
            ms=12,
            label="EOAM hits, careful driver avoids",
        ),
    ]
    names = " vs ".join(t for _, t in panels)
    fig.suptitle(f"UN R157 Annex 4 App. 3 {kind}: {names}", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.legend(
        handles=handles, loc="upper center", ncol=3, frameon=False, bbox_to_anchor=(0.5, 0.965)
    )
    return save(fig, path)
