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


def test_a_copy_that_hangs_is_killed_and_its_figure_drawn_here(tmp_path, monkeypatch):
    """A forked copy may hang (a lock another thread held when it forked): past the time
    limit it is killed and the figure drawn in this process."""
    import os
    import time

    from eoam_sumo.plotting import figures

    monkeypatch.setattr(figures, "FORK_TIMEOUT_S", 1.0)
    here, path = os.getpid(), tmp_path / "second.txt"

    def hangs_in_a_copy() -> Path:
        if os.getpid() != here:
            time.sleep(600)
        path.write_text(f"drawn by {os.getpid()}")
        return path

    got = draw_all([_writer(tmp_path / "first.txt", "drawn"), hangs_in_a_copy])
    assert got == [tmp_path / "first.txt", path]
    assert path.read_text() == f"drawn by {here}"
