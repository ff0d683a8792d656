"""Plots of an offline tables folder: DMM phase diagrams (paper Figures 11, 14, 15) and the
lookup-table lane changes and longitudinal-acceleration profiles (Figures 10, 17).

Figures are drawn on matplotlib's Agg canvas through the object interface (no pyplot).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure

from eoam_sumo.decision.dmm import FCW_LEAD_S, Sector, dmm_sector, warning_line_m
from eoam_sumo.offline.tables import NPZ_NAME, PhaseBoundaries

_SECTORS = (Sector.A, Sector.B, Sector.C, Sector.D, Sector.E, Sector.F, Sector.G)
_SECTOR_COLOURS = ("#ef9a9a", "#a5d6a7", "#ffcc80", "#fff59d", "#b3e5fc", "#c5e1a5", "#ffffff")
_CURVES = (  # (Boundary field, label, colour, line style)
    ("stop_m", "stopping distance B0 (eq. 33)", "#c62828", "-"),
    ("stop_buffered_m", "buffered stopping Bb", "#c62828", "--"),
    ("clear_const_m", "min. clearing, constant speed", "#6a1b9a", ":"),
    ("clear_opt_m", "min. clearing, optimised S (eq. 32)", "#1565c0", "-"),
    ("clear_buffered_m", "buffered clearing Sb", "#1565c0", "--"),
)


def _save(fig: Figure, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=110)
    return path


def plot_phase_diagrams(tables_dir, out_dir) -> list[Path]:
    """One DMM phase diagram per friction: relative distance (x) vs relative speed (y), the
    five boundaries, the TTC line and the sectors A-G shaded and lettered."""
    pb = PhaseBoundaries.load(tables_dir)
    out = Path(out_dir)
    speeds = np.linspace(0.0, pb.speed_grid_mps[-1], 141)
    paths = []
    for mu in sorted(pb.mu_grid, reverse=True):
        rows = [pb.at(mu, v) for v in speeds]
        top = rows[-1]
        d_max = 1.1 * max(top.stop_buffered_m, top.clear_buffered_m, top.ttc_s * speeds[-1])
        dist = np.linspace(0.0, d_max, 400)
        index = np.array(
            [[_SECTORS.index(dmm_sector(b, d, v)) for d in dist] for v, b in zip(speeds, rows)]
        )
        fig = Figure(figsize=(8.0, 5.6))
        ax = fig.add_subplot()
        kmh = speeds * 3.6
        ax.pcolormesh(
            dist,
            kmh,
            index,
            cmap=ListedColormap(_SECTOR_COLOURS),
            vmin=-0.5,
            vmax=len(_SECTORS) - 0.5,
            shading="nearest",
            rasterized=True,
        )
        _draw_curves(ax, rows, speeds, kmh)
        _letter_sectors(ax, index, dist, kmh)
        ax.set_xlim(0.0, d_max)
        ax.set_ylim(0.0, kmh[-1])
        ax.set_xlabel("relative distance ARV-ARO (m)")
        ax.set_ylabel("relative speed ARV-ARO (km/h)")
        ax.set_title(f"DMM phase diagram, surface mu = {mu:g}")
        ax.legend(loc="lower right", fontsize=8, framealpha=0.9)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        paths.append(_save(fig, out / f"phase_diagram_mu{mu:.2f}.png"))
    return paths


def _draw_curves(ax, rows: list, speeds: np.ndarray, kmh: np.ndarray) -> None:
    """The five DMM boundaries (eqs. 32-33, plain and buffered) and the TTC line (eq. 34)
    against the relative speed."""
    for field, label, colour, style in _CURVES:
        ax.plot([getattr(b, field) for b in rows], kmh, style, color=colour, lw=1.6, label=label)
    ax.plot(
        [b.ttc_s * v for b, v in zip(rows, speeds)],
        kmh,
        "-.",
        color="#455a64",
        lw=1.4,
        label=f"TTC = {rows[-1].ttc_s:g} s (eq. 34)",
    )
    ax.plot(
        [
            warning_line_m(v, b.clear_buffered_m, b.stop_buffered_m, b.ttc_s)
            for b, v in zip(rows, speeds)
        ],
        kmh,
        "-",
        color="#455a64",
        lw=0.9,
        label=f"W: warning line (T, or {FCW_LEAD_S:g} s before Sb, Bb)",
    )


def _letter_sectors(ax, index: np.ndarray, dist: np.ndarray, kmh: np.ndarray) -> None:
    """Each sector's letter at its grid point nearest the sector's centroid (sectors of fewer
    than 20 grid points unlettered)."""
    for k, sector in enumerate(_SECTORS):
        vi, di = np.nonzero(index == k)
        if vi.size < 20:
            continue
        cv, cd = vi.mean(), di.mean()
        best = np.argmin(
            (vi - cv) ** 2 / index.shape[0] ** 2 + (di - cd) ** 2 / index.shape[1] ** 2
        )
        ax.text(
            dist[di[best]],
            kmh[vi[best]],
            sector.value,
            fontsize=15,
            weight="bold",
            ha="center",
            va="center",
            color="#212121",
        )


def plot_accel_profiles(tables_dir, out_dir) -> list[Path]:
    """Per friction, the lookup-table lane changes y(dx) and their longitudinal-acceleration
    profiles ax(dx) for a selection of entry speeds (Figures 10 and 17)."""
    with np.load(Path(tables_dir) / NPZ_NAME) as data:
        mus, speeds = data["mu_grid"], data["speed_grid_mps"]
        step, lengths = float(data["dx_step_m"]), data["length_m"]
        y_tab, ax_tab = data["y_m"], data["ax_mps2"]
    out = Path(out_dir)
    picks = np.unique(np.linspace(0, len(speeds) - 1, min(8, len(speeds))).round().astype(int))
    paths = []
    for i in sorted(range(len(mus)), key=lambda k: -mus[k]):
        fig = Figure(figsize=(8.0, 6.4))
        ax_y, ax_a = fig.subplots(2, 1, sharex=True)
        colours = [(0.1, 0.3 + 0.6 * t, 0.9 - 0.7 * t) for t in np.linspace(0, 1, len(picks))]
        for colour, j in zip(colours, picks):
            n = int(lengths[i, j] / step) + 1
            dx = np.arange(n) * step
            label = f"{speeds[j] * 3.6:.0f} km/h"
            ax_y.plot(dx, y_tab[i, j, :n], color=colour, lw=1.4, label=label)
            ax_a.plot(dx, ax_tab[i, j, :n], color=colour, lw=1.4, label=label)
        ax_y.set_ylabel("lateral position y (m)")
        ax_y.set_title(
            f"Lookup tables, surface mu = {mus[i]:g}: path and longitudinal "
            "acceleration vs. differential x"
        )
        ax_a.set_ylabel("longitudinal acceleration (m/s$^2$)")
        ax_a.set_xlabel("differential x-position since the trigger (m)")
        for a in (ax_y, ax_a):
            a.grid(alpha=0.3)
        ax_a.legend(loc="lower right", fontsize=8, ncol=2, title="entry speed")
        fig.tight_layout()
        paths.append(_save(fig, out / f"accel_profiles_mu{mus[i]:.2f}.png"))
    return paths
