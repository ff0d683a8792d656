"""``plot`` and ``animate`` read what ``run`` and ``batch`` write with ``--timeseries parquet``,
and say why there is nothing to draw with ``--timeseries none`` (they asked for a
timeseries.csv the tool had not written: "cannot be read", exit 2)."""

from __future__ import annotations

import pytest

from eoam_sumo.cli import main
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import BASELINE

pytestmark = pytest.mark.sumo


def _run(folder, timeseries: str):
    overrides = ScenarioOverrides(ego_speed_mps=120 / 3.6, mu=0.7, oncoming_start_m=300.0)
    run_case(BASELINE, overrides, folder, RunSettings(max_time_s=12.0), timeseries=timeseries)
    return folder


def test_a_parquet_run_is_plotted_and_animated(tmp_path, capsys):
    run = _run(tmp_path / "run", "parquet")
    assert not (run / "timeseries.csv").exists() and (run / "timeseries.parquet").is_file()
    assert main(["plot", str(run), "--out", str(tmp_path / "p")]) == 0
    assert (tmp_path / "p" / "traffic.png").stat().st_size > 10_000
    assert "no traffic.csv" not in capsys.readouterr().out
    gif = tmp_path / "a.gif"
    assert main(["animate", str(run), "--out", str(gif), "--fps", "5"]) == 0
    assert gif.stat().st_size > 10_000


def test_a_run_without_time_series_says_why(tmp_path, capsys):
    run = _run(tmp_path / "run", "none")
    assert main(["plot", str(run), "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err
    assert "--timeseries none has nothing to plot" in err and len(err.strip().splitlines()) == 1
