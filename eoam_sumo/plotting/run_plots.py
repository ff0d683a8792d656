"""Plots of one co-simulation run folder (``timeseries.csv`` + ``summary.json``), after the
paper's Figures 21-24 for its 120 km/h dry case:

* ``phase_trace.png`` (Fig. 21): the ARO's range against the closing speed (-range rate)
  as the radar saw it, on the DMM phase diagram (sectors A-G shaded, boundaries drawn) of
  the friction the manoeuvre ran on (under the ego when it began), coloured by EOAM mode;
* ``dynamics.png`` (Fig. 22): mode, FCW, speed and acceleration (target vs actual),
  lateral position (target vs actual), lateral and lookahead errors, differential x;
* ``steering.png`` (Fig. 23): the steering components (feedforward, feedback, yaw damping,
  total command, actual road-wheel angle), hand-wheel angle, lateral acceleration, yaw rate;
* ``gg.png`` (Fig. 24): longitudinal against lateral acceleration inside the friction
  circle of radius mu g of the manoeuvre's friction (and of any other friction met).

Titles name the traffic as the run had it (an added oncoming car, or the scenario's own
oncoming traffic) and are wrapped to the figure's width.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from eoam_sumo.batch.report import mu_text
from eoam_sumo.decision.dmm import FCW_LEAD_S, warning_line_m
from eoam_sumo.errors import InputError
from eoam_sumo.params import G_MPS2, ego_e_class_sedan
from eoam_sumo.plotting.figures import save
from eoam_sumo.plotting.runfacts import (
    fit,
    frictions_seen,
    manoeuvre_mu,
    oncoming_seen,
    traffic_text,
)
from eoam_sumo.sim.runlog import COLUMNS, read_timeseries

MODE_NAMES = {
    0: "0 NORMAL",
    1: "1 UPDATE BRAKE",
    2: "2 STEER+BRAKE",
    3: "3 ONCOMING BRAKE",
    4: "4 ONCOMING STEER+BRAKE",
    5: "5 RETURN",
}
MODE_COLOURS = {0: "#757575", 1: "#1e88e5", 2: "#43a047", 3: "#fdd835", 4: "#fb8c00", 5: "#8e24aa"}
SECTOR_COLOURS = {
    "A": "#ef9a9a",
    "C": "#ffcc80",
    "F": "#c5e1a5",
    "B": "#81c784",
    "D": "#90caf9",
    "E": "#fff59d",
    "G": "#ffffff",
}
_TARGET = {"color": "black", "linestyle": "--", "linewidth": 1.2}
_ACTUAL = {"color": "#1e88e5", "linewidth": 1.6}


def load_run(case_dir: Path) -> tuple[dict, pd.DataFrame]:
    """A run folder's summary and time series (InputError naming the file when either is
    missing or damaged)."""
    case_dir = Path(case_dir)
    path = case_dir / "summary.json"
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot be read as a run summary: {exc}") from exc
    if not isinstance(summary, dict) or not {"outcome", "mu", "modes_visited"} <= summary.keys():
        raise InputError(
            f"{path}: cannot be read as a run summary: not a JSON object with "
            "outcome, mu and modes_visited"
        )
    frame = read_timeseries(case_dir / "timeseries.csv")
    missing = [c for c in COLUMNS if c not in frame.columns]
    if missing:
        raise InputError(
            f"{case_dir / 'timeseries.csv'}: cannot be read as a run's time "
            f"series: no column {missing[0]}"
        )
    return summary, frame


def run_title(summary: dict, ts: pd.DataFrame, run_dir: Path) -> str:
    """'120 km/h, μ = 1.0, no oncoming: green (reason)' from a run: the friction is the one
    the manoeuvre ran on, the traffic the added oncoming car or what the run saw."""
    case = summary.get("case") or {}
    speed_kmh = case.get("ego_speed_kmh") or 3.6 * summary.get("ego_initial_speed_mps", math.nan)
    traffic = traffic_text(case.get("oncoming_start_m"), oncoming_seen(run_dir))
    mu, _ = manoeuvre_mu(summary, ts)
    return (
        f"{speed_kmh:.0f} km/h, μ = {mu_text(mu)}, {traffic}: "
        f"{summary['outcome']} ({summary.get('reason', '')})"
    )


def _mode_spans(ax, ts: pd.DataFrame) -> None:
    """Shade the time axis by EOAM mode."""
    mode = ts["mode"].to_numpy()
    t = ts["time_s"].to_numpy()
    start = 0
    for k in range(1, len(mode) + 1):
        if k == len(mode) or mode[k] != mode[start]:
            if np.isfinite(mode[start]):
                ax.axvspan(
                    t[start],
                    t[min(k, len(t) - 1)],
                    color=MODE_COLOURS.get(int(mode[start]), "white"),
                    alpha=0.10,
                    lw=0,
                )
            start = k


def _mode_legend(modes) -> list[Line2D]:
    return [
        Line2D(
            [],
            [],
            marker="s",
            linestyle="",
            markersize=8,
            color=MODE_COLOURS[m],
            label=MODE_NAMES[m],
        )
        for m in sorted(modes)
    ]


def _modes_in(ts: pd.DataFrame) -> set[int]:
    return {int(m) for m in ts["mode"].dropna().unique()}


def plot_dynamics(case_dir: Path, out_dir: Path) -> Path:
    """Figure 22: modes, FCW, speed, acceleration, lateral position and errors, dx."""
    summary, ts = load_run(case_dir)
    t = ts["time_s"]
    fig = Figure(figsize=(14, 11), layout="constrained")
    axes = fig.subplots(4, 2, sharex=True).ravel()
    panels = [
        ("EOAM mode", [("mode", "mode", {"drawstyle": "steps-post", **_ACTUAL})], "-"),
        (
            "forward-collision warning",
            [("fcw", "FCW flag", {"drawstyle": "steps-post", **_ACTUAL})],
            "-",
        ),
        (
            "longitudinal speed",
            [("vx_mps", "actual", _ACTUAL), ("speed_target_mps", "target", _TARGET)],
            "m/s",
        ),
        (
            "longitudinal acceleration",
            [("ax_mps2", "actual", _ACTUAL), ("ax_target_mps2", "target", _TARGET)],
            "m/s²",
        ),
        (
            "lateral position (left +)",
            [("lateral_offset_m", "actual", _ACTUAL), ("y_target_m", "target", _TARGET)],
            "m",
        ),
        ("lateral offset error", [("lateral_error_m", "lateral error", _ACTUAL)], "m"),
        ("lateral lookahead error", [("lookahead_error_m", "lookahead error", _ACTUAL)], "m"),
        ("differential x-position (lookup-table input)", [("dx_m", "dx", _ACTUAL)], "m"),
    ]
    for ax, (title, lines, unit) in zip(axes, panels):
        _mode_spans(ax, ts)
        for column, label, style in lines:
            ax.plot(t, ts[column], label=label, **style)
        ax.set_title(title, fontsize=10)
        ax.set_ylabel(f"[{unit}]" if unit != "-" else "")
        ax.grid(alpha=0.3)
        if len(lines) > 1:
            ax.legend(fontsize=8, loc="best")
    axes[0].set_yticks(range(6), [MODE_NAMES[m] for m in range(6)], fontsize=7)
    axes[1].set_yticks([0, 1], ["off", "on"])
    for ax in axes[-2:]:
        ax.set_xlabel("time [s]")
    _mode_figure_legend(fig, ts)
    fig.suptitle(
        fit("EOAM dynamics (cf. paper Figure 22) — " + run_title(summary, ts, case_dir), 14, 11),
        fontsize=11,
    )
    return save(fig, Path(out_dir) / "dynamics.png")


def _mode_figure_legend(fig: Figure, ts) -> None:
    """The legend of the EOAM modes shaded behind the curves, below the figure."""
    fig.legend(
        handles=_mode_legend(_modes_in(ts)),
        loc="outside lower center",
        ncols=6,
        fontsize=8,
        title="background: EOAM mode",
        title_fontsize=8,
    )


def plot_steering(case_dir: Path, out_dir: Path) -> Path:
    """Figure 23: steering components, hand-wheel angle, lateral acceleration, yaw rate."""
    summary, ts = load_run(case_dir)
    ratio = ego_e_class_sedan().steering_ratio
    t = ts["time_s"]
    fig = Figure(figsize=(13, 9), layout="constrained")
    axes = fig.subplots(2, 2, sharex=True).ravel()
    deg = math.degrees(1.0)
    for column, label, colour in (
        ("steer_ff_rad", "feedforward", "#43a047"),
        ("steer_fb_rad", "feedback", "#1e88e5"),
        ("steer_yd_rad", "yaw damping", "#8e24aa"),
        ("steer_cmd_rad", "total command", "black"),
    ):
        axes[0].plot(t, ts[column] * deg, label=label, color=colour, linewidth=1.3)
    axes[0].plot(
        t,
        ts["steer_rad"] * deg,
        label="actual (actuator)",
        color="#e53935",
        linestyle="--",
        linewidth=1.3,
    )
    axes[0].set_title("road-wheel steering angle and its components", fontsize=10)
    axes[0].set_ylabel("[deg]")
    axes[0].legend(fontsize=8)
    axes[1].plot(t, ts["steer_rad"] * deg * ratio, **_ACTUAL)
    axes[1].set_title(f"hand-wheel angle (steering ratio {ratio:g})", fontsize=10)
    axes[1].set_ylabel("[deg]")
    axes[2].plot(t, ts["ay_mps2"], **_ACTUAL)
    mu_g = manoeuvre_mu(summary, ts)[0] * G_MPS2
    for sign in (1, -1):
        axes[2].axhline(sign * mu_g, color="#e53935", linestyle=":", linewidth=1)
    axes[2].set_title(f"lateral acceleration (dotted: ±μg = ±{mu_g:.2f} m/s²)", fontsize=10)
    axes[2].set_ylabel("[m/s²]")
    axes[3].plot(t, ts["yaw_rate_radps"] * deg, **_ACTUAL)
    axes[3].set_title("yaw rate", fontsize=10)
    axes[3].set_ylabel("[deg/s]")
    for ax in axes:
        _mode_spans(ax, ts)
        ax.grid(alpha=0.3)
    for ax in axes[2:]:
        ax.set_xlabel("time [s]")
    _mode_figure_legend(fig, ts)
    fig.suptitle(
        fit(
            "Steering, lateral acceleration and yaw rate (cf. paper Figure 23) — "
            + run_title(summary, ts, case_dir),
            13,
            11,
        ),
        fontsize=11,
    )
    return save(fig, Path(out_dir) / "steering.png")


def plot_gg(case_dir: Path, out_dir: Path) -> Path:
    """Figure 24: the g-g diagram with the friction circle of radius mu g."""
    summary, ts = load_run(case_dir)
    mu, what = manoeuvre_mu(summary, ts)
    mu_g = mu * G_MPS2
    fig = Figure(figsize=(7.5, 7.5), layout="constrained")
    ax = fig.add_subplot()
    angle = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(
        mu_g * np.cos(angle),
        mu_g * np.sin(angle),
        color="#e53935",
        linewidth=1.5,
        label=f"friction circle μg = {mu_g:.2f} m/s² (μ = {mu_text(mu)}, {what})",
    )
    for other in frictions_seen(ts):
        if abs(other - mu) > 1e-6:
            r = other * G_MPS2
            ax.plot(
                r * np.cos(angle),
                r * np.sin(angle),
                color="#e53935",
                linewidth=1.0,
                linestyle="--",
                label=f"friction circle μ = {mu_text(other)} (also met)",
            )
            mu_g = max(mu_g, r)
    for mode in sorted(_modes_in(ts)):
        sel = ts[ts["mode"] == mode]
        ax.scatter(
            sel["ay_mps2"], sel["ax_mps2"], s=5, color=MODE_COLOURS[mode], label=MODE_NAMES[mode]
        )
    lim = 1.15 * max(mu_g, float(np.nanmax(np.abs(ts[["ax_mps2", "ay_mps2"]].to_numpy()))))
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.axhline(0, color="0.6", linewidth=0.6)
    ax.axvline(0, color="0.6", linewidth=0.6)
    ax.set_xlabel("lateral acceleration a_y [m/s²] (left +)")
    ax.set_ylabel("longitudinal acceleration a_x [m/s²]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right", markerscale=3)
    ax.set_title(
        fit("g-g diagram (cf. paper Figure 24)\n" + run_title(summary, ts, case_dir), 7.0, 10),
        fontsize=10,
    )
    return save(fig, Path(out_dir) / "gg.png")


def _sector_map(bounds: list, vs: np.ndarray, ds: np.ndarray) -> np.ndarray:
    """Index in ``SECTOR_ORDER`` of the sector at every (range, closing speed) grid point."""
    from eoam_sumo.decision.dmm import SECTOR_ORDER, dmm_sector

    order = {s: k for k, s in enumerate(SECTOR_ORDER)}
    return np.array([[order[dmm_sector(b, d, v)] for v, b in zip(vs, bounds)] for d in ds])


def plot_phase_trace(case_dir: Path, out_dir: Path, tables_dir: Path | None = None) -> Path:
    """Figure 21: the radar's ARO phase trace on the DMM phase diagram of the run's friction.

    The boundaries come from ``phase_boundaries.csv`` in ``tables_dir`` (default: the
    repository's ``tables/``); without readable tables the trace is drawn alone and the title
    says why.
    """
    summary, ts = load_run(case_dir)
    mu, what = manoeuvre_mu(summary, ts)
    seen = ts[np.isfinite(ts["aro_range_m"]) & np.isfinite(ts["aro_range_rate_mps"])]
    closing = -seen["aro_range_rate_mps"]
    v_max = (
        max(
            float(closing.max()) if len(seen) else 0.0,
            summary.get("ego_initial_speed_mps", 0.0) * 0.7,
            5.0,
        )
        * 1.15
    )
    d_max = max(float(seen["aro_range_m"].max()) if len(seen) else 0.0, 20.0) * 1.1
    fig = Figure(figsize=(10, 7), layout="constrained")
    ax = fig.add_subplot()
    note = ""
    try:
        from eoam_sumo.offline.tables import PhaseBoundaries, default_tables_dir

        boundaries = PhaseBoundaries.load(Path(tables_dir or default_tables_dir()))
        vs = np.linspace(v_max / 300, v_max, 300)
        bounds = [boundaries.at(mu, float(v)) for v in vs]
    except (ImportError, OSError, ValueError) as exc:
        bounds, note = None, f"\n(phase boundaries not drawn: {exc})"
    if bounds is not None:
        _draw_sectors(ax, bounds, vs, v_max, d_max)
        _draw_boundaries(ax, bounds, vs)
    _draw_trace(ax, seen, closing)
    ax.set_xlim(0, v_max)
    ax.set_ylim(0, d_max)
    ax.set_xlabel("closing speed to the ARO (-range rate) [m/s]")
    ax.set_ylabel("range to the ARO [m]")
    ax.legend(fontsize=8, loc="upper left", framealpha=0.9)
    ax.set_title(
        fit(
            f"DMM phase diagram at μ = {mu_text(mu)} (the friction {what}) with the "
            f"ARO phase trace (cf. paper Figure 21)\n"
            f"{run_title(summary, ts, case_dir)}{note}",
            9.5,
            10,
        ),
        fontsize=10,
    )
    return save(fig, Path(out_dir) / "phase_trace.png")


def _draw_sectors(ax, bounds: list, vs: np.ndarray, v_max: float, d_max: float) -> None:
    """The DMM sectors A-G shaded over (closing speed, range), each large one lettered."""
    from matplotlib.colors import ListedColormap

    from eoam_sumo.decision.dmm import SECTOR_ORDER

    ds = np.linspace(0.0, d_max, 300)
    index = _sector_map(bounds, vs, ds)
    order = [s.value for s in SECTOR_ORDER]
    cmap = ListedColormap([SECTOR_COLOURS[s] for s in order])
    ax.imshow(
        index,
        origin="lower",
        extent=(0, v_max, 0, d_max),
        aspect="auto",
        cmap=cmap,
        vmin=-0.5,
        vmax=len(order) - 0.5,
        alpha=0.8,
        interpolation="nearest",
    )
    for k, letter in enumerate(order):
        rr, cc = np.nonzero(index == k)
        if len(rr) > 50:
            ax.text(
                vs[int(np.median(cc))],
                ds[int(np.median(rr))],
                letter,
                fontsize=16,
                fontweight="bold",
                ha="center",
                va="center",
                color="0.25",
            )


def _draw_boundaries(ax, bounds: list, vs: np.ndarray) -> None:
    """The DMM boundaries against the closing speed: clearing and stopping distances (plain
    and buffered) and the TTC line."""
    for field, label, style, colour in (
        ("clear_opt_m", "S: min. clearing distance (opt. accel.)", "-", "#2e7d32"),
        ("clear_buffered_m", "Sb: buffered clearing distance", "--", "#2e7d32"),
        ("clear_const_m", "min. clearing distance at constant speed", ":", "#2e7d32"),
        ("stop_m", "B0: stopping distance", "-", "#1565c0"),
        ("stop_buffered_m", "Bb: buffered stopping distance", "--", "#1565c0"),
    ):
        ax.plot(
            vs,
            [getattr(b, field) for b in bounds],
            linestyle=style,
            color=colour,
            linewidth=1.4,
            label=label,
        )
    ttc = np.array([b.ttc_s for b in bounds])
    ax.plot(vs, ttc * vs, ":", color="#6d4c41", linewidth=1.4, label=f"T: TTC line ({ttc[-1]:g} s)")
    warn = [
        warning_line_m(v, b.clear_buffered_m, b.stop_buffered_m, b.ttc_s)
        for b, v in zip(bounds, vs)
    ]
    ax.plot(
        vs,
        warn,
        "-",
        color="#6d4c41",
        linewidth=0.9,
        label=f"W: warning line ({FCW_LEAD_S:g} s lead)",
    )


def _draw_trace(ax, seen: pd.DataFrame, closing: pd.Series) -> None:
    """The ARO as the radar saw it (range against closing speed), coloured by EOAM mode, its
    first and last points marked."""
    for mode in sorted(_modes_in(seen)):
        sel = seen[seen["mode"] == mode]
        ax.scatter(
            -sel["aro_range_rate_mps"],
            sel["aro_range_m"],
            s=9,
            color=MODE_COLOURS[mode],
            edgecolors="black",
            linewidths=0.2,
            label=f"trace, mode {MODE_NAMES[mode]}",
            zorder=3,
        )
    if not len(seen):
        return
    for which, k, offset in (("first", 0, (10, 10)), ("last", -1, (10, -15))):
        ax.annotate(
            f"{which} sensed",
            (closing.iloc[k], seen["aro_range_m"].iloc[k]),
            xytext=offset,
            textcoords="offset points",
            fontsize=9,
            arrowprops={"arrowstyle": "->"},
        )


def plot_run(case_dir: Path, out_dir: Path, tables_dir: Path | None = None) -> list[Path]:
    """Every run plot of a run folder."""
    return [
        plot_phase_trace(case_dir, out_dir, tables_dir),
        plot_dynamics(case_dir, out_dir),
        plot_steering(case_dir, out_dir),
        plot_gg(case_dir, out_dir),
    ]
