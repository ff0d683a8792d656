"""A reference driver on the real plant through SUMO: R157's deceleration scenario (the lead
at 1.6 s of headway brakes at 6 m/s^2 to a standstill) run with ``--driver r157-cc``; the
gap and the ego's speed against the careful driver's closed form within 0.2 m and 0.15 m/s
(the plant's brake lags: the profile is commanded ahead, ``drivers.controller``)."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from eoam_sumo.r157.scenario import DEPART_S, LEAD_IN_S, R157Point, write_scenario
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.settings import RunSettings
from tests.drivers.test_closed_form import FULL, JERK, ego_closed_form

pytestmark = pytest.mark.sumo

DT = 0.01
V0, DECEL = 100 / 3.6, 6.0


def test_the_careful_driver_on_the_plant_matches_its_closed_form(tmp_path):
    point = R157Point("deceleration", 100.0, round(1.6 * V0, 2), decel_mps2=DECEL)
    cfg = write_scenario(point, tmp_path / "scenario")
    out = tmp_path / "run"
    summary = run_case(cfg, None, out, RunSettings(max_time_s=12.0, driver="r157-cc"))
    assert summary["collision_with"] == "none"
    assert summary["modes_visited"] == [0, 1]
    ts = pd.read_csv(out / "timeseries.csv")
    t_brake = DEPART_S + LEAD_IN_S  # the lead's scripted stop begins
    t_react = t_brake + DT + 0.4  # seen one step later, perceived 0.4 s after
    first = ts[ts.time_s >= t_react - 1e-9].iloc[0]
    v_lead0 = ts.vx_mps.iloc[0] + ts.aro_range_rate_mps.iloc[0]

    def lead_from(t):  # the lead's travel since its departure
        if t <= t_brake:
            return v_lead0 * (t - DEPART_S)
        s = min(t - t_brake, v_lead0 / DECEL)
        return v_lead0 * LEAD_IN_S + v_lead0 * s - 0.5 * DECEL * s * s

    worst_gap = worst_v = 0.0
    for r in ts[ts.time_s >= first.time_s].itertuples():
        if pd.isna(r.aro_range_m):
            continue
        x_cf, v_cf = ego_closed_form(
            r.time_s - first.time_s, first.vx_mps, 0.0, 0.75, -0.4, 0.4, JERK, FULL
        )
        gap_cf = first.aro_range_m + lead_from(r.time_s) - lead_from(first.time_s) - x_cf
        worst_gap = max(worst_gap, abs(r.aro_range_m - gap_cf))
        worst_v = max(worst_v, abs(r.vx_mps - v_cf))
    assert worst_gap < 0.2
    assert worst_v < 0.15
    assert json.loads((out / "summary.json").read_text())["outcome"] == "green"
