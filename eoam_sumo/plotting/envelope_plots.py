"""Envelope plots of a sampled batch: probability of contact and of red over speed x friction.

Each cell pools every finished draw at that speed and friction (over the other swept and
sampled values) and shows p with its Wilson 95 % interval and n. A sampled (continuous)
speed or friction is binned into ``BINS`` equal-width bins.
"""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from eoam_sumo.plotting.figures import save
from eoam_sumo.sampling import wilson_interval

ENVELOPE_PNG = "envelope.png"
BINS = 6
MAX_LEVELS = 12  # more distinct values than this: binned


def _levels(values: pd.Series) -> tuple[pd.Series, list[str]]:
    """Each value's level index and the level labels (distinct values, or bins)."""
    distinct = sorted(values.dropna().unique())
    if len(distinct) <= MAX_LEVELS:
        index = values.map({v: i for i, v in enumerate(distinct)})
        return index, [f"{v:g}" for v in distinct]
    edges = np.linspace(distinct[0], distinct[-1], BINS + 1)
    index = pd.Series(np.clip(np.digitize(values, edges[1:-1]), 0, BINS - 1), index=values.index)
    return index, [f"{a:.3g}-{b:.3g}" for a, b in pairwise(edges)]


def envelope_table(results: pd.DataFrame, event: pd.Series) -> tuple:
    """(count, n, speed labels, friction labels) arrays of ``event`` over the finished draws."""
    ok = results["status"] == "ok"
    speed_i, speeds = _levels(results.loc[ok, "ego_speed_kmh"])
    mu_i, mus = _levels(results.loc[ok, "mu"])
    count = np.zeros((len(speeds), len(mus)), dtype=int)
    n = np.zeros_like(count)
    for i, j, e in zip(speed_i, mu_i, event[ok]):
        n[i, j] += 1
        count[i, j] += bool(e)
    return count, n, speeds, mus


def _events(results: pd.DataFrame) -> dict[str, pd.Series]:
    return {
        "P(contact with any road user)": results["collision_with"].fillna("none") != "none",
        "P(red: head-on after a lane change)": results["outcome"] == "red",
    }


def _panel(ax, results: pd.DataFrame, event: pd.Series, title: str, fig: Figure) -> None:
    """One envelope: ``event``'s probability over speed x friction, each cell annotated."""
    count, n, speeds, mus = envelope_table(results, event)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = np.where(n > 0, count / np.maximum(n, 1), np.nan)
    image = ax.imshow(p, cmap="Reds", vmin=0.0, vmax=1.0, aspect="auto")
    for i in range(len(speeds)):
        for j in range(len(mus)):
            if n[i, j] == 0:
                continue
            low, high = wilson_interval(int(count[i, j]), int(n[i, j]))
            ax.text(
                j,
                i,
                f"{p[i, j]:.2f}\n[{low:.2f}, {high:.2f}]\nn={n[i, j]}",
                ha="center",
                va="center",
                fontsize=8,
                color="white" if p[i, j] > 0.6 else "black",
            )
    ax.set_xticks(range(len(mus)), mus)
    ax.set_yticks(range(len(speeds)), speeds)
    ax.invert_yaxis()  # the highest speed on top
    ax.set_xlabel("surface friction mu")
    ax.set_ylabel("initial ego speed [km/h]")
    ax.set_title(title)
    fig.colorbar(image, ax=ax, shrink=0.8, label="probability")


def _title(results: pd.DataFrame, what: str) -> str:
    failed = int((results["status"] != "ok").sum())
    return (
        f"{what}: {int((results['status'] == 'ok').sum())} draws"
        + (f" ({failed} failed, left out)" if failed else "")
        + "; each cell p [Wilson 95 %] and n"
    )


def plot_envelopes(results: pd.DataFrame, out_dir: Path) -> list[Path]:
    """``envelope.png``: P(contact) and P(red) over initial speed x friction; for generated
    scenarios (a ``road`` column) one ``envelope_<road>.png`` per road instead, a row of
    the two per level of service."""
    if not (results["status"] == "ok").any():
        return []
    roads = results["road"].fillna("").astype(str) if "road" in results else pd.Series()
    if (roads != "").any():
        return [
            _road_envelopes(results[roads == road], road, out_dir)
            for road in sorted(set(roads) - {""})
        ]
    fig = Figure(figsize=(12, 5.5), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, (title, event) in zip(axes, _events(results).items()):
        _panel(ax, results, event, title, fig)
    fig.suptitle(_title(results, "Outcome envelopes"))
    return [save(fig, Path(out_dir) / ENVELOPE_PNG)]


def _road_envelopes(results: pd.DataFrame, road: str, out_dir: Path) -> Path:
    """``envelope_<road>.png``: per level of service (rows), P(contact) and P(red)."""
    levels = sorted(set(results["los"].fillna("").astype(str)) - {""}) or [None]
    fig = Figure(figsize=(12, 4.8 * len(levels)), layout="constrained")
    axes = fig.subplots(len(levels), 2, squeeze=False)
    for row, level in zip(axes, levels):
        subset = results if level is None else results[results["los"] == level]
        for ax, (title, event) in zip(row, _events(subset).items()):
            _panel(ax, subset, event, f"LoS {level}: {title}", fig)
    fig.suptitle(_title(results, f"Outcome envelopes, {road} road"))
    return save(fig, Path(out_dir) / f"envelope_{road}.png")
