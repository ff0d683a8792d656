"""Reference drivers on the real plant through SUMO: R157's deceleration scenario (the lead
at 1.6 s of headway brakes at 6 m/s^2 to a standstill) at 100 km/h; the gap and the ego's
speed against the driver's closed form within 0.2 m and 0.15 m/s (the plant's brake lags:
the profile is commanded ahead, ``drivers.controller``). FSM: it brakes and stops short."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from eoam_sumo.r157.scenario import DEPART_S, LEAD_IN_S, R157Point, write_scenario
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.settings import RunSettings
from tests.drivers.test_closed_form import FULL, JERK, ego_closed_form, seen_braking_s

pytestmark = pytest.mark.sumo

DT = 0.01
V0, DECEL = 100 / 3.6, 6.0
T_BRAKE = DEPART_S + LEAD_IN_S  # the lead's scripted stop begins


def run(tmp_path, driver):
    point = R157Point("deceleration", 100.0, round(1.6 * V0, 2), decel_mps2=DECEL)
    cfg = write_scenario(point, tmp_path / "scenario")
    summary = run_case(cfg, None, tmp_path / "run", RunSettings(max_time_s=12.0, driver=driver))
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["outcome"] == "green"
    assert summary["collision_with"] == "none"
    assert summary["modes_visited"] == [0, 1]
    return pd.read_csv(tmp_path / "run" / "timeseries.csv")


def rss_distance(vr, vf):  # Definition 1, JRC-FSM's parameters (restated)
    return vr * 0.75 + 3.0 * 0.75**2 / 2 + (vr + 0.75 * 3.0) ** 2 / 12 - vf**2 / 12


def worst_errors(ts, first, delay_accel, decel_from):
    """Worst |gap| and |speed| errors from ``first`` (a row: the response's start) on."""
    v_lead0 = ts.vx_mps.iloc[0] + ts.aro_range_rate_mps.iloc[0]

    def lead_from(t):  # the lead's travel since its departure
        if t <= T_BRAKE:
            return v_lead0 * (t - DEPART_S)
        s = min(t - T_BRAKE, v_lead0 / DECEL)
        return v_lead0 * LEAD_IN_S + v_lead0 * s - 0.5 * DECEL * s * s

    worst_gap = worst_v = 0.0
    for r in ts[ts.time_s >= first.time_s].itertuples():
        if pd.isna(r.aro_range_m):
            continue
        x_cf, v_cf = ego_closed_form(
            r.time_s - first.time_s, first.vx_mps, 0.0, 0.75, delay_accel, decel_from, JERK, FULL
        )
        gap_cf = first.aro_range_m + lead_from(r.time_s) - lead_from(first.time_s) - x_cf
        worst_gap = max(worst_gap, abs(r.aro_range_m - gap_cf))
        worst_v = max(worst_v, abs(r.vx_mps - v_cf))
    return worst_gap, worst_v


def test_the_careful_driver_on_the_plant_matches_its_closed_form(tmp_path):
    ts = run(tmp_path, "r157-cc")
    # the lead's braking seen when its speed's slope over 0.5 s passes -1 m/s^2, perceived
    # 0.4 s later (within a step: SUMO's scripted stop begins on the step grid)
    t_react = seen_braking_s(V0, DECEL, T_BRAKE) + 0.4
    first = ts[ts["mode"] == 1].iloc[0]
    assert first.time_s == pytest.approx(t_react, abs=DT + 1e-9)
    worst_gap, worst_v = worst_errors(ts, first, -0.4, 0.4)
    assert worst_gap < 0.2
    assert worst_v < 0.15


def test_rss_on_the_plant_matches_its_closed_form(tmp_path):
    ts = run(tmp_path, "rss")
    k = ts.index[ts["mode"] == 1][0]  # the response's start: closer than Definition 1 ...
    for row, closer in ((ts.loc[k], True), (ts.loc[k - 1], False)):  # ... not a step before
        vf = row.vx_mps + row.aro_range_rate_mps
        assert bool(row.aro_range_m < rss_distance(row.vx_mps, vf)) is closer
    worst_gap, worst_v = worst_errors(ts, ts.loc[k], 0.0, 0.0)
    assert worst_gap < 0.2
    assert worst_v < 0.15


def test_fsm_on_the_plant_brakes_and_stops_short(tmp_path):
    ts = run(tmp_path, "fsm")
    assert ts.vx_mps.iloc[-1] < 0.05
    assert ts.aro_range_m.dropna().min() > 2.0
