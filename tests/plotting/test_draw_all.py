"""plotting.figures.draw_all: every figure drawn (some in forked copies), paths in order, a
failing draw raising as it would alone."""

from __future__ import annotations

from pathlib import Path

import pytest

from eoam_sumo.plotting.figures import draw_all


def _writer(path: Path, text: str):
    def draw() -> Path:
        path.write_text(text)
        return path

    return draw


def test_every_figure_drawn_and_paths_in_order(tmp_path):
    paths = [tmp_path / f"{k}.txt" for k in range(3)]
    got = draw_all([_writer(p, f"figure {k}") for k, p in enumerate(paths)])
    assert got == paths
    assert [p.read_text() for p in paths] == ["figure 0", "figure 1", "figure 2"]


def test_a_failing_draw_raises_here_the_others_still_drawn(tmp_path):
    def broken() -> Path:
        raise ValueError("no data to draw")

    first = tmp_path / "first.txt"
    with pytest.raises(ValueError, match="no data to draw"):
        draw_all([_writer(first, "drawn"), broken])
    assert first.read_text() == "drawn"
