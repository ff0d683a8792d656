"""The figure of a standard vehicle test (``eoam-sumo vehicle-test``): one PNG per test from its
summary and its runs' time series (``eoam_sumo.vehicle_tests``)."""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from eoam_sumo.params import G_MPS2
from eoam_sumo.plotting.figures import save

Series = Mapping[str, np.ndarray]
LIMIT = {"color": "#e53935", "linestyle": "--", "linewidth": 1.2}


def plot_vehicle_test(
    summary: Mapping[str, Any], runs: Sequence[tuple[str, Series]], path: Path
) -> Path:
    """Draw the test named in ``summary["test"]`` from its runs (label, columns) into ``path``."""
    fig = Figure(figsize=(13, 8.5), layout="constrained")
    axes = fig.subplots(2, 2).ravel()
    DRAW[summary["test"]](axes, summary, runs)
    verdict = (
        summary.get("verdict")
        or {True: "PASS", False: "FAIL", None: "figures only"}[summary.get("passed")]
    )
    fig.suptitle(
        f"{summary['test']}: {summary['vehicle']}, {summary['speed_kmh']:.1f} km/h, "
        f"mu {summary['mu']:g}, ABS {'on' if summary['abs'] else 'off'}, "
        f"ESC {'on' if summary['esc'] else 'off'} - {verdict}",
        fontsize=12,
    )
    return save(fig, path)


def _labelled(ax, title: str, xlabel: str, ylabel: str) -> None:
    ax.set_title(title, fontsize=10)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)


def _figures_text(ax, figures: Mapping[str, Any]) -> None:
    lines = [
        textwrap.fill(f"{k}: {v}", 72, subsequent_indent="    ")
        for k, v in figures.items()
        if not isinstance(v, list | dict) and "clause" not in k
    ]
    clauses = [textwrap.fill(f"{v}", 60) for k, v in figures.items() if "clause" in k]
    ax.axis("off")
    ax.text(0.0, 1.0, "\n".join([*lines, "", *clauses]), va="top", family="monospace", fontsize=9)


def _brake(axes, summary, runs) -> None:
    ts = runs[0][1]
    t = ts["time_s"]
    axes[0].plot(t, ts["vx_mps"], color="black", label="body")
    axes[0].plot(t, ts["wheel_speed_front_mps"], "--", label="front wheels")
    axes[0].plot(t, ts["wheel_speed_rear_mps"], ":", label="rear wheels")
    axes[0].legend(fontsize=8)
    _labelled(axes[0], "speeds", "time [s]", "[m/s]")
    axes[1].plot(t, -ts["ax_mps2"] / G_MPS2, color="black")
    _labelled(axes[1], "deceleration", "time [s]", "[g]")
    distance = np.concatenate(([0.0], np.cumsum(np.hypot(np.diff(ts["x_m"]), np.diff(ts["y_m"])))))
    axes[2].plot(t, distance, color="black")
    axes[2].axhline(summary["figures"]["stopping_distance_limit_m"], **LIMIT, label="limit")
    axes[2].legend(fontsize=8)
    _labelled(axes[2], "distance since the brake was applied", "time [s]", "[m]")
    _figures_text(axes[3], summary["figures"])


def _brake_ramp(axes, summary, runs) -> None:
    ts = runs[0][1]
    t = ts["time_s"]
    axes[0].plot(t, -ts["ax_mps2"] / G_MPS2, color="black")
    for rate in (0.15, 0.8):
        axes[0].axhline(rate, **LIMIT)
    _labelled(axes[0], "braking rate (R13-H Annex 5 band dashed)", "time [s]", "z [g]")
    axes[1].plot(t, ts["vx_mps"], color="black", label="body")
    axes[1].plot(t, ts["wheel_speed_front_mps"], "--", label="front wheels")
    axes[1].plot(t, ts["wheel_speed_rear_mps"], ":", label="rear wheels")
    axes[1].legend(fontsize=8)
    _labelled(axes[1], "speeds", "time [s]", "[m/s]")
    axes[2].plot(t, ts["brake_force_n"] / 1000.0, color="black")
    _labelled(axes[2], "brake force (actuator)", "time [s]", "[kN]")
    _figures_text(axes[3], summary["figures"])


def _ramp_steer(axes, summary, runs) -> None:
    ts = runs[0][1]
    t = ts["time_s"]
    axes[0].plot(ts["ay_mps2"] / G_MPS2, ts["steer_wheel_deg"], color="black")
    fit_range_g = summary["figures"].get("fit_range_g")
    if fit_range_g:
        axes[0].axvspan(*fit_range_g, color="grey", alpha=0.2, label="fit range")
        axes[0].legend(fontsize=8)
    _labelled(axes[0], "hand-wheel angle over lateral acceleration", "ay [g]", "[deg]")
    axes[1].plot(t, ts["ay_mps2"] / G_MPS2, color="black")
    _labelled(axes[1], "lateral acceleration", "time [s]", "[g]")
    axes[2].plot(t, np.degrees(ts["yaw_rate_radps"]), color="black")
    _labelled(axes[2], "yaw rate", "time [s]", "[deg/s]")
    _figures_text(axes[3], summary["figures"])


def _step_steer(axes, summary, runs) -> None:
    ts = runs[0][1]
    t = ts["time_s"]
    axes[0].plot(t, ts["steer_wheel_deg"], color="black")
    _labelled(axes[0], "hand-wheel angle", "time [s]", "[deg]")
    yaw_degps = np.degrees(ts["yaw_rate_radps"])
    axes[1].plot(t, yaw_degps, color="black")
    axes[1].axhline(0.9 * np.mean(yaw_degps[t >= t[-1] - 1.0]), color="grey", linestyle=":")
    _labelled(axes[1], "yaw rate (90 % of steady state dotted)", "time [s]", "[deg/s]")
    axes[2].plot(t, ts["ay_mps2"], color="black")
    target = summary["figures"].get("target_lateral_acceleration_mps2")
    if target is not None:
        axes[2].axhline(target, color="grey", linestyle=":")
    _labelled(axes[2], "lateral acceleration (the standard's dotted)", "time [s]", "[m/s^2]")
    _figures_text(axes[3], summary["figures"])


def _sine_with_dwell(axes, summary, runs) -> None:
    swd = [ts for label, ts in runs if label != "sis"]
    colours = [f"C{k % 10}" for k in range(len(swd))]
    for ts, colour in zip(swd, colours, strict=True):
        axes[0].plot(ts["time_s"], ts["steer_wheel_deg"], color=colour, linewidth=0.9)
        axes[1].plot(ts["time_s"], np.degrees(ts["yaw_rate_radps"]), color=colour, linewidth=0.9)
    _labelled(axes[0], "hand-wheel angle, every amplitude", "time [s]", "[deg]")
    _labelled(axes[1], "yaw rate, every amplitude", "time [s]", "[deg/s]")
    per_run = summary["figures"].get("runs", [])
    amps = [r["amplitude_A"] for r in per_run]
    axes[2].plot(amps, [r["yaw_ratio_1s"] for r in per_run], "o-", label="1.0 s after steer")
    axes[2].plot(amps, [r["yaw_ratio_1.75s"] for r in per_run], "s-", label="1.75 s after")
    axes[2].axhline(0.35, **LIMIT)
    axes[2].axhline(0.20, **LIMIT)
    axes[2].legend(fontsize=8)
    _labelled(axes[2], "yaw-rate ratios (limits 0.35, 0.20)", "amplitude [A]", "[-]")
    axes[3].plot(amps, [r["lateral_displacement_m"] for r in per_run], "o-", color="black")
    axes[3].axhline(1.83, **LIMIT)
    axes[3].axvline(5.0, color="grey", linestyle=":")
    a_deg = summary["figures"].get("A_deg")
    title = f"lateral displacement 1.07 s after the steer begins (A = {a_deg} deg)"
    _labelled(axes[3], title, "amplitude [A]", "[m]")


def _brake_in_turn(axes, summary, runs) -> None:
    """ISO 7975: each run's departure from the initial circle and its yaw rate around the
    brake's onset; the figures 1 s after it against the deceleration (or why none was)."""
    figures = summary["figures"]
    onset_s = figures.get("brake_onset_s", 0.0)
    after_s = figures.get("measured_after_onset_s", 1.0)
    for k, (label, ts) in enumerate(runs):
        t = ts["time_s"] - onset_s
        shown = t >= -1.0
        colour = f"C{k % 10}"
        deviation_m = _circle_deviation_m(ts, onset_s)
        axes[0].plot(t[shown], deviation_m[shown], color=colour, label=label)
        axes[1].plot(t[shown], np.degrees(ts["yaw_rate_radps"][shown]), color=colour)
    for ax in axes[:2]:
        for x in (0.0, after_s):
            ax.axvline(x, color="grey", linestyle=":")
    if runs:
        axes[0].legend(fontsize=7, ncol=2)
    title = "path's distance outside the initial circle (onset, measurement dotted)"
    _labelled(axes[0], title, "time after onset [s]", "[m]")
    _labelled(axes[1], "yaw rate", "time after onset [s]", "[deg/s]")
    per_run = figures.get("runs", [])
    if not per_run:
        for ax in axes[2:]:
            ax.axis("off")
        reason = textwrap.fill(f"not measured: {summary.get('not_measured', 'no run')}", 70)
        axes[2].text(0.0, 1.0, reason, va="top", fontsize=10)
        return
    _turn_ratios(axes[2], per_run, after_s)
    _turn_deviation(axes[3], per_run, after_s)


def _circle_deviation_m(ts: Series, onset_s: float) -> np.ndarray:
    """Each sample's distance outside the circle the car drove at ``onset_s`` (its radius
    ``|v| / r`` there, tangent to the path), as the test's ``path_deviation_m``."""
    k = int(np.searchsorted(ts["time_s"], onset_s - 1e-9))
    vx, vy, r = ts["vx_mps"][k], ts["vy_mps"][k], ts["yaw_rate_radps"][k]
    radius_m = np.hypot(vx, vy) / r if r else np.inf
    if not np.isfinite(radius_m):
        return np.full_like(ts["time_s"], np.nan)
    course = ts["yaw_rad"][k] + np.arctan2(vy, max(vx, 0.1))
    centre_x = ts["x_m"][k] - radius_m * np.sin(course)
    centre_y = ts["y_m"][k] + radius_m * np.cos(course)
    return np.hypot(ts["x_m"] - centre_x, ts["y_m"] - centre_y) - radius_m


def _turn_ratios(ax, per_run: Sequence[Mapping[str, Any]], after_s: float) -> None:
    decel = [r["mean_deceleration_mps2"] for r in per_run]
    for key, marker in (
        ("yaw_rate_ratio", "o-"),
        ("yaw_rate_over_course", "s-"),
        ("lateral_acceleration_ratio", "^-"),
    ):
        ax.plot(decel, [r[key] for r in per_run], marker, label=key.replace("_", " "))
    spun = [(d, r["yaw_rate_ratio"]) for d, r in zip(decel, per_run, strict=True) if r["spun"]]
    if spun:
        ax.plot(*zip(*spun, strict=True), "x", color="black", markersize=10, label="spun")
    ax.axhline(1.0, color="grey", linestyle=":")
    ax.legend(fontsize=8)
    title = f"{after_s:g} s after the onset, over the mean deceleration"
    _labelled(ax, title, "mean deceleration [m/s^2]", "ratio to the onset [-]")


def _turn_deviation(ax, per_run: Sequence[Mapping[str, Any]], after_s: float) -> None:
    decel = [r["mean_deceleration_mps2"] for r in per_run]
    ax.plot(decel, [r["path_deviation_m"] for r in per_run], "o-", color="black")
    ax.axhline(0.0, color="grey", linestyle=":")
    locked = [(d, r["path_deviation_m"]) for d, r in zip(decel, per_run, strict=True)]
    locked = [p for p, r in zip(locked, per_run, strict=True) if r["a_wheel_locked"]]
    if locked:
        ax.plot(*zip(*locked, strict=True), "o", mfc="none", color="C3", markersize=10)
    title = (
        f"path deviation from the circle {after_s:g} s after (+ outside; red ring: a wheel locked)"
    )
    _labelled(ax, title, "mean deceleration [m/s^2]", "[m]")
    twin = ax.twinx()
    twin.plot(decel, [r["sideslip_change_deg"] for r in per_run], "s--", color="C1")
    twin.set_ylabel("sideslip change [deg]", color="C1")


DRAW = {
    "brake": _brake,
    "brake-ramp": _brake_ramp,
    "brake-in-turn": _brake_in_turn,
    "ramp-steer": _ramp_steer,
    "step-steer": _step_steer,
    "sine-with-dwell": _sine_with_dwell,
}
"""Each test's drawing (``vehicle_tests.command.TEST_NAMES``)."""
