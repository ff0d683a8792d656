"""The time in the next lane and in the opposite lane: on a one-way road there is no opposite
lane (``time_in_opposite_lane_s`` 0), on a two-way road the next lane is the opposite one (the
two times agree). ``time_in_next_lane_s`` is read back from the time series as its truth."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import halted_car_scenario

pytestmark = pytest.mark.sumo

NODES = '<nodes><node id="a" x="0" y="0"/><node id="b" x="1500" y="0"/></nodes>'
ONE_WAY = '<edges><edge id="fwd" from="a" to="b" numLanes="2" speed="50"/></edges>'
TWO_WAY = (
    '<edges><edge id="fwd" from="a" to="b" numLanes="1" speed="50"/>'
    '<edge id="back" from="b" to="a" numLanes="1" speed="50"/></edges>'
)


def _run(tmp_path, edges: str) -> tuple[dict, pd.DataFrame]:
    """The ego at 165 km/h towards a car halted 220 m along the road (seen at 100 m: too
    close to stop): a lane change."""
    cfg = halted_car_scenario(tmp_path, NODES, edges, 220.0)
    out = tmp_path / "run"
    summary = run_case(
        cfg, ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=1.0), out, RunSettings(max_time_s=25.0)
    )
    return summary, pd.read_csv(out / "timeseries.csv")


def _left_of_lane_s(ts: pd.DataFrame, lane_width_m: float, step_s: float = 0.01) -> float:
    """Time with the ego's centre left of its lane: steps (the end state aside) whose lateral
    offset exceeds half a lane."""
    steps = ts.iloc[:-1]
    return float((steps["lateral_offset_m"] > 0.5 * lane_width_m).sum() * step_s)


@pytest.mark.parametrize("edges, opposing", [(ONE_WAY, False), (TWO_WAY, True)])
def test_time_in_the_opposite_lane_counts_only_an_opposite_lane(tmp_path, edges, opposing):
    s, ts = _run(tmp_path, edges)
    assert 2 in s["modes_visited"], s["reason"]  # it changed lanes
    left_s = _left_of_lane_s(ts, s["lane_width_m"])
    assert left_s > 1.0
    assert s["time_in_next_lane_s"] == pytest.approx(left_s, abs=0.015)
    assert s["time_in_opposite_lane_s"] == (s["time_in_next_lane_s"] if opposing else 0.0)
    # added after the older fields (they keep their place), before the margins along the lanes
    assert list(s)[list(s).index("time_in_next_lane_s") + 1 :][0] == "min_ttc_s"


def test_time_in_the_next_lane_counts_an_evasion_to_the_right(tmp_path):
    """The ego and the halted car in the left lane of a one-way road (no lane on its left): it
    evades right, and that time in the next lane counts (it counted only the left before)."""
    cfg = halted_car_scenario(tmp_path, NODES, ONE_WAY, 220.0)
    routes = tmp_path / "r.rou.xml"
    text = routes.read_text().replace('lane="fwd_0"', 'lane="fwd_1"')
    routes.write_text(text.replace("departSpeed=", 'departLane="1" departSpeed='))
    out = tmp_path / "run"
    overrides = ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=1.0)
    s = run_case(cfg, overrides, out, RunSettings(max_time_s=25.0))
    ts = pd.read_csv(out / "timeseries.csv")
    right_s = float((ts.iloc[:-1]["lateral_offset_m"] < -0.5 * s["lane_width_m"]).sum() * 0.01)
    assert right_s > 1.0, s["reason"]
    assert s["time_in_next_lane_s"] == pytest.approx(right_s, abs=0.015)
    assert s["time_in_opposite_lane_s"] == 0.0
