"""What the plots read of a run folder: the manoeuvre's friction, the lane width, the
oncoming traffic, wrapped titles (hand-made time series and files)."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from eoam_sumo.plotting.runfacts import (
    fit,
    frictions_seen,
    lane_width_m,
    manoeuvre_mu,
    oncoming_seen,
    point_of_no_return_m,
    traffic_text,
)


def _ts(modes, mus) -> pd.DataFrame:
    return pd.DataFrame({"mode": modes, "mu": mus})


def test_the_manoeuvre_friction_is_the_one_under_the_ego_when_it_began():
    ts = _ts([0, 0, 1, 2, 5, 0, math.nan], [1.0, 1.0, 0.2, 0.2, 1.0, 1.0, 1.0])
    assert manoeuvre_mu({"mu": 1.0}, ts) == (0.2, "under the ego when the manoeuvre began")
    assert frictions_seen(ts) == [1.0, 0.2]


def test_without_a_manoeuvre_the_friction_is_the_one_at_the_start():
    ts = _ts([0, 0, math.nan], [0.7, 0.7, 0.7])
    assert manoeuvre_mu({"mu": 0.7}, ts) == (0.7, "under the ego at the start")


def test_lane_width_and_point_of_no_return():
    assert lane_width_m({"lane_width_m": 3.0}) == (3.0, True)
    assert lane_width_m({}) == (3.5, False)
    assert lane_width_m({"lane_width_m": None}) == (3.5, False)
    assert point_of_no_return_m(3.0) == pytest.approx(0.9)


def test_traffic_is_named_from_the_setting_or_from_what_the_run_saw():
    assert traffic_text(400.0, False) == "oncoming from 400 m"
    assert traffic_text(400.0, True) == "oncoming from 400 m"
    assert traffic_text(math.nan, True) == "oncoming traffic"
    assert traffic_text(None, True) == "oncoming traffic"
    assert traffic_text(None, False) == "no oncoming"


def test_oncoming_seen_reads_traffic_csv_else_the_radar_flag(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    pd.DataFrame({"time_s": [1.0], "oncoming_detected": [0]}).to_csv(run / "timeseries.csv")
    assert not oncoming_seen(run)
    pd.DataFrame({"time_s": [1.0, 1.01], "oncoming_detected": [0, 1]}).to_csv(
        run / "timeseries.csv"
    )
    assert oncoming_seen(run)
    (run / "traffic.csv").write_text("time_s,id,role\n1.0,ego,ego\n1.0,car,other\n")
    assert not oncoming_seen(run)  # traffic.csv, the ground truth, wins over the radar
    (run / "traffic.csv").write_text("time_s,id,role\n1.0,ego,ego\n1.0,car,oncoming\n")
    assert oncoming_seen(run)


def test_fit_wraps_to_the_width_and_keeps_every_word():
    text = "DMM phase diagram " * 12 + "\nsecond line stays"
    wrapped = fit(text, 4.0, 10)
    limit = int(4.0 * 72 / 5.5)
    assert all(len(line) <= limit for line in wrapped.splitlines())
    assert wrapped.split() == text.split()
    assert wrapped.splitlines()[-1] == "second line stays"
