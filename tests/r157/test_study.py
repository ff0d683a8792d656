"""The R157 studies: a generated cut-in does what its point says (gap at the start, lateral
speed, measured on the road users' boxes SUMO moved), the careful driver brakes for it on
the plant, the R157 test's verdict and the chart; bad options exit 2."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.cli import main
from eoam_sumo.plotting.r157_plots import r157_figure
from eoam_sumo.r157.scenario import DEPART_S, LEAD_IN_S, R157Point
from eoam_sumo.r157.study import eoam_fails_where_careful_avoids, read_results, run_study


@pytest.mark.sumo
def test_a_cut_in_point_runs_as_specified_and_the_careful_driver_brakes(tmp_path):
    point = R157Point("cut-in", 100.0, 20.0, lateral_mps=1.0, relative_kmh=20.0)
    rows = run_study([point], ["r157-cc"], tmp_path, timeseries="csv")
    assert rows[0]["collision"] is False
    run = tmp_path / rows[0]["case_dir"]
    traffic = pd.read_csv(run / "traffic.csv")
    cutter = traffic[traffic.id == "cutter"].set_index("time_s")
    ego = traffic[traffic.id == "ego"].set_index("time_s")
    t0 = DEPART_S + LEAD_IN_S
    at = cutter.index[cutter.index >= t0][0]
    gap = (cutter.x_m[at] - 0.5 * cutter.length_m[at]) - (ego.x_m[at] + 0.5 * ego.length_m[at])
    # within 0.5 m: SUMO moves a departing car from the step after its departure, and the
    # co-simulation's ego starts 0.65 m behind its departPos (measured: 20.46 m)
    assert gap == pytest.approx(20.0, abs=0.5)
    moving = cutter[(cutter.index > t0 + 0.5) & (cutter.index < t0 + 2.5)]
    lateral = (moving.y_m.iloc[-1] - moving.y_m.iloc[0]) / (moving.index[-1] - moving.index[0])
    assert lateral == pytest.approx(-1.0, abs=0.05)  # towards the ego's lane, on the right
    summary = pd.read_json(run / "summary.json", typ="series")
    assert list(summary["modes_visited"]) == [0, 1]  # braked, did not steer
    assert read_results(tmp_path / "results.csv")[0]["gap_m"] == 20.0


def _row(driver, gap, collision):
    return {
        "kind": "cut-in",
        "driver": driver,
        "ego_kmh": 60.0,
        "gap_m": gap,
        "lateral_mps": 1.0,
        "relative_kmh": 20.0,
        "decel_mps2": 0.0,
        "collision": collision,
    }


def test_the_r157_verdict_and_its_chart(tmp_path):
    rows = [
        _row("r157-cc", 5.0, True),
        _row("eoam", 5.0, True),  # both hit: not the EOAM's failure
        _row("r157-cc", 10.0, False),
        _row("eoam", 10.0, True),  # the careful driver avoids, the EOAM not: failed
        _row("r157-cc", 20.0, False),
        _row("eoam", 20.0, False),
    ]
    failed = eoam_fails_where_careful_avoids(rows)
    assert [(r["driver"], r["gap_m"]) for r in failed] == [("eoam", 10.0)]
    png = r157_figure(rows, "cut-in", failed, tmp_path / "chart.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "option",
    [
        ["--speeds-kmh", "fast"],
        ["--speeds-kmh", "300"],
        ["--speeds-kmh", "60,60"],
        ["--drivers", "eoam,human"],
    ],
)
def test_bad_study_options_exit_2(tmp_path, capsys, option):
    code = main(["r157-study", "--type", "cut-in", "--out", str(tmp_path / "o"), *option])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and option[0] in err[0]
    assert not (tmp_path / "o" / "results.csv").exists()
