"""Envelopes of sampled batches: round bin edges, counts per cell, empty cells NaN; labels
that do not overlap at 24 and 312 draws (measured on the laid-out figure); degenerate batches
drawn without error."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from eoam_sumo.batch.probability_map import MAP_FILE
from eoam_sumo.plotting import envelope_plots
from eoam_sumo.plotting.envelope_bins import (
    MAX_BINS,
    MIN_MEDIAN_DRAWS,
    cell_counts,
    cell_probability,
    choose_axes,
    median_cell_draws,
    round_edges,
)


def _is_round(edge: float, step: float) -> bool:
    mantissa = step / 10.0 ** math.floor(math.log10(step))
    ratio = edge / step
    return round(mantissa, 9) in {1.0, 2.0, 2.5, 5.0} and abs(ratio - round(ratio)) < 1e-9


@pytest.mark.parametrize("n", [24, 60, 312, 2000])
def test_sampled_values_are_cut_on_round_edges_with_enough_draws_per_cell(n):
    rng = np.random.default_rng(n)
    speeds, mus = rng.uniform(60, 165, n), rng.uniform(0.172, 0.93, n)
    sx, sy = choose_axes(speeds, mus)
    for axis, values in ((sx, speeds), (sy, mus)):
        assert all(_is_round(e, axis.step) for e in axis.edges), axis.edges
        assert axis.edges[0] <= values.min() and values.max() <= axis.edges[-1]
        assert 2 <= axis.cells <= MAX_BINS  # both parameters resolved, never one bin of either
    assert median_cell_draws(sx, sy) >= MIN_MEDIAN_DRAWS
    count, draws = cell_counts(sx, sy, speeds > 120)
    assert draws.sum() == n and count.sum() == (speeds > 120).sum()
    # each draw's cell holds its value
    for k in rng.choice(n, 10):
        i, j = sx.index[k], sy.index[k]
        assert sx.edges[i] <= speeds[k] <= sx.edges[i + 1]
        assert sy.edges[j] <= mus[k] <= sy.edges[j + 1]


def test_swept_values_stay_levels_and_empty_cells_are_nan():
    speeds = np.array([80.0] * 6 + [120.0] * 6)
    mus = np.array([0.4, 1.0] * 3 + [0.4] * 6)  # no draw at 120 km/h on mu 1.0
    sx, sy = choose_axes(speeds, mus)
    assert sx.levels == (80.0, 120.0) and sy.levels == (0.4, 1.0)
    assert sx.labels() == ["80", "120"] and sy.labels() == ["0.4", "1"]
    count, draws = cell_counts(sx, sy, speeds > 100)
    assert draws.tolist() == [[3, 3], [6, 0]] and count.tolist() == [[0, 0], [6, 0]]
    p = cell_probability(count, draws)
    assert p[0, 0] == 0.0 and p[1, 0] == 1.0 and np.isnan(p[1, 1])


def test_round_edges_cover_the_range():
    assert round_edges(0.172, 0.93, 0.1) == (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
    assert round_edges(80.0, 80.0, 10.0) == (80.0, 90.0)


def _results(n: int, seed: int, *, traffic: bool = False) -> pd.DataFrame:
    """Fabricated results.csv rows of a sampled batch (the columns the envelope reads)."""
    rng = np.random.default_rng(seed)
    if traffic:  # traffic_levels.toml: 2 roads x 3 levels x 2 speeds x 2 frictions x 13
        grid = pd.MultiIndex.from_product(
            [["rural", "motorway"], ["A", "C", "E"], [80.0, 120.0], [1.0, 0.4], range(13)]
        ).to_frame(index=False, name=["road", "los", "ego_speed_kmh", "mu", "draw"])
    else:
        grid = pd.DataFrame(
            {"ego_speed_kmh": rng.uniform(60, 165, n), "mu": rng.uniform(0.1, 1.0, n)}
        ).assign(draw=range(n))
    eta = -2.0 + 0.06 * (grid["ego_speed_kmh"] - 110) - 4.0 * (grid["mu"] - 0.55)
    hit = rng.uniform(size=len(grid)) < 1 / (1 + np.exp(-eta))
    red = hit & (rng.uniform(size=len(grid)) < 0.3)
    return grid.assign(
        case_id=[f"g_d{k:03d}" for k in range(len(grid))],
        status="ok",
        collision_with=np.where(hit, "aro", "none"),
        outcome=np.where(red, "red", np.where(hit, "yellow", "green")),
        near_miss=np.where(~hit & (rng.uniform(size=len(grid)) < 0.3), "True", "False"),
    )


def _drawn(monkeypatch, results, tmp_path):
    """plot_envelopes' figures, laid out, and the files it wrote."""
    figures = []

    def keep(fig, path, dpi=120):
        figures.append(fig)
        path.write_bytes(b"")
        return path

    monkeypatch.setattr(envelope_plots, "save", keep)
    paths = envelope_plots.plot_envelopes(results, tmp_path)
    renderers = []
    for fig in figures:
        canvas = FigureCanvasAgg(fig)
        fig.draw_without_rendering()
        renderers.append(canvas.get_renderer())
    return list(zip(figures, renderers)), paths


def _overlapping(texts, renderer) -> list[tuple[str, str]]:
    shown = [t for t in texts if t.get_visible() and t.get_text()]
    boxes = [t.get_window_extent(renderer) for t in shown]
    return [
        (shown[i].get_text(), shown[k].get_text())
        for i in range(len(boxes))
        for k in range(i + 1, len(boxes))
        if boxes[i].overlaps(boxes[k])
    ]


@pytest.mark.parametrize(
    ("n", "traffic", "names"),
    [
        (24, False, ["envelope.png"]),
        (312, False, ["envelope.png"]),
        (312, True, ["envelope_motorway.png", "envelope_rural.png"]),
    ],
)
def test_no_two_labels_overlap(monkeypatch, tmp_path, n, traffic, names):
    """Tick labels of an axis, the cells' counts and the panels' titles: no two touch."""
    drawn, paths = _drawn(monkeypatch, _results(n, 1, traffic=traffic), tmp_path)
    assert [p.name for p in paths] == names and (tmp_path / MAP_FILE).is_file()
    for fig, renderer in drawn:
        titles = [ax.title for ax in fig.axes] + [fig._suptitle]
        assert _overlapping(titles, renderer) == []
        for ax in fig.axes:
            assert _overlapping(ax.get_xticklabels(), renderer) == []
            assert _overlapping(ax.get_yticklabels(), renderer) == []
            cells = [t for t in ax.texts if "/" in t.get_text()]
            assert _overlapping(cells, renderer) == []
            assert all(t.get_visible() for t in cells)  # every count shown
            if traffic:  # each level's cells: one speed x one friction, 13 draws
                assert all(t.get_text().endswith("/13") for t in cells)


@pytest.mark.parametrize(
    "change",
    [
        {"collision_with": "none", "outcome": "green", "near_miss": "False"},  # nothing
        {"collision_with": "aro", "outcome": "red", "near_miss": "False"},  # everything
        {"ego_speed_kmh": 120.0},  # one speed
        {"ego_speed_kmh": 120.0, "mu": 0.5},  # one speed and one friction
    ],
)
def test_degenerate_batches_are_drawn(monkeypatch, tmp_path, change):
    drawn, paths = _drawn(monkeypatch, _results(30, 3).assign(**change), tmp_path)
    assert [p.name for p in paths] == ["envelope.png"] and len(drawn) == 1


def test_a_tiny_batch_is_drawn_with_its_fallback_said(monkeypatch, tmp_path):
    drawn, _ = _drawn(monkeypatch, _results(3, 4), tmp_path)
    written = pd.read_csv(tmp_path / MAP_FILE)
    assert written["model"].str.startswith("none (3 draws)").all()
    texts = [t.get_text() for fig, _ in drawn for ax in fig.axes for t in ax.texts]
    assert any(t.startswith("no map: 3 draws") for t in texts)
