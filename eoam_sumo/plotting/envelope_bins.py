"""The cells of an envelope: speed x friction levels, or bins on round values.

A parameter with at most ``MAX_LEVELS`` distinct values, each drawn at least twice (a swept or
``choice`` parameter), keeps its values as levels. Any other (a sampled continuous one) is cut
into bins of a round width, a step of the 1-2-2.5-5 series times a power of ten, the edges on
multiples of it. Of the pairs of widths giving at most ``MAX_BINS`` bins per parameter, the
finest whose median non-empty cell holds at least ``MIN_MEDIAN_DRAWS`` draws is chosen: the most
bins on the axis with fewer, then the most cells, then the more even split (one bin of speed by
five of friction says nothing about speed); when none does, the coarsest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import product

import numpy as np
import pandas as pd

MAX_LEVELS = 8
MAX_BINS = 10
MIN_MEDIAN_DRAWS = 5
ROUND_STEPS = (1.0, 2.0, 2.5, 5.0)


@dataclass(frozen=True)
class Axis:
    """One parameter's cells: ``edges`` (bins, len cells + 1) or ``levels`` (distinct values)
    and each draw's cell index."""

    index: np.ndarray
    edges: tuple[float, ...] = ()
    levels: tuple[float, ...] = ()
    step: float = 0.0

    @property
    def cells(self) -> int:
        return len(self.levels) if self.levels else len(self.edges) - 1

    def labels(self) -> list[str]:
        """Tick labels: the levels, or the edges with the decimals the step needs."""
        if self.levels:
            return [f"{v:g}" for v in self.levels]
        return [f"{e:.{decimals(self.step)}f}" for e in self.edges]


def decimals(step: float) -> int:
    """Decimals that print every multiple of a round ``step`` exactly (0.25: 2, 10: 0)."""
    for d in range(8):
        if abs(round(step, d) - step) < 1e-9 * max(1.0, step):
            return d
    return 8


def round_steps(low: float, high: float) -> list[float]:
    """Round bin widths giving 1 to ``MAX_BINS`` bins over [low, high], finest first."""
    span = max(high - low, 1e-12)
    steps = []
    for exponent in range(
        math.floor(math.log10(span / MAX_BINS)) - 1, math.ceil(math.log10(span)) + 2
    ):
        for base in ROUND_STEPS:
            step = base * 10.0**exponent
            if 1 <= len(round_edges(low, high, step)) - 1 <= MAX_BINS:
                steps.append(step)
    return sorted(set(steps))


def round_edges(low: float, high: float, step: float) -> tuple[float, ...]:
    """Edges on multiples of ``step`` covering [low, high] (at least one bin)."""
    first = math.floor(low / step + 1e-9)
    last = max(math.ceil(high / step - 1e-9), first + 1)
    return tuple(round(k * step, 10) for k in range(first, last + 1))


def binned(values: np.ndarray, step: float) -> Axis:
    """``values`` cut into bins of width ``step`` (the last bin closed on the right)."""
    edges = round_edges(float(values.min()), float(values.max()), step)
    index = np.clip(np.searchsorted(edges, values, side="right") - 1, 0, len(edges) - 2)
    return Axis(index=index, edges=edges, step=step)


def leveled(values: np.ndarray) -> Axis | None:
    """``values`` as levels: one value, or at most ``MAX_LEVELS`` each drawn twice or more;
    else None."""
    distinct, counts = np.unique(values, return_counts=True)
    if len(distinct) > 1 and (len(distinct) > MAX_LEVELS or counts.min() < 2):
        return None
    return Axis(index=np.searchsorted(distinct, values), levels=tuple(float(v) for v in distinct))


def _choices(values: np.ndarray) -> list[Axis]:
    levels = leveled(values)
    if levels is not None:
        return [levels]
    return [binned(values, step) for step in round_steps(float(values.min()), float(values.max()))]


def median_cell_draws(x: Axis, y: Axis) -> float:
    """Median number of draws of the non-empty cells."""
    _, counts = np.unique(np.stack([x.index, y.index]), axis=1, return_counts=True)
    return float(np.median(counts))


def choose_axes(speeds: np.ndarray, mus: np.ndarray) -> tuple[Axis, Axis]:
    """The envelope's speed and friction axes (rule: module docstring)."""
    pairs = list(product(_choices(np.asarray(speeds, float)), _choices(np.asarray(mus, float))))
    good = [p for p in pairs if median_cell_draws(*p) >= MIN_MEDIAN_DRAWS]
    if not good:
        return min(pairs, key=lambda p: (p[0].cells * p[1].cells, abs(p[0].cells - p[1].cells)))
    return max(
        good,
        key=lambda p: (
            min(p[0].cells, p[1].cells),
            p[0].cells * p[1].cells,
            -abs(p[0].cells - p[1].cells),
        ),
    )


def cell_counts(x: Axis, y: Axis, event: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(events, draws) per cell, arrays of shape (x cells, y cells)."""
    n = np.zeros((x.cells, y.cells), dtype=int)
    count = np.zeros_like(n)
    np.add.at(n, (x.index, y.index), 1)
    np.add.at(count, (x.index, y.index), np.asarray(event, dtype=int))
    return count, n


def cell_probability(count: np.ndarray, n: np.ndarray) -> np.ndarray:
    """count / n per cell; NaN where a cell holds no draw (empty, not zero)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, count / np.maximum(n, 1), np.nan)


def axes_of(results: pd.DataFrame) -> tuple[Axis, Axis]:
    """The axes of a frame's speeds and frictions (``ego_speed_kmh``, ``mu``)."""
    return choose_axes(results["ego_speed_kmh"].to_numpy(float), results["mu"].to_numpy(float))
