"""A wrong-way car driving at the ego in its lane (Euro NCAP's CCFhos): real SUMO runs.

The network is the project's two-way road plus a westbound one-lane edge whose centre lies
under the ego's lane, shifted by the test's lateral offset (0 or 50 % of the ego's width),
so SUMO drives the other car straight at the ego. The ego cruises at 80 km/h, the other car
at 50 km/h. Without a reaction the ego meets it at the full closing speed, 130 km/h (before
the radar made a wrong-way car in the lane the in-path obstacle, the EOAM stayed in mode 0
and did just that). Now the DMM sees it at the closing speed, and with oncoming traffic the
mode machine brakes in the lane (mode 3, paper sec. 3.2): the impact speed falls by what the
ego sheds while braking.
"""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.settings import RunSettings
from tests.builders import VTYPES, network, write_sumocfg

pytestmark = pytest.mark.sumo

ROAD_M = 2000.0
EGO_LANE_Y_M = -1.75
EGO_W_M = 1.85  # the ego's width (scenarios/vtypes.add.xml)
EGO_MPS, TARGET_MPS = 80 / 3.6, 50 / 3.6
GAP_M = 250.0  # front to front at the start: outside the radar's 100 m


def head_on_scenario(folder: Path, offset_m: float) -> Path:
    """The ego eastbound on E0 (front at x = 100 m) and a car westbound on ``H``, a lane
    centred ``offset_m`` left of the ego lane's centre, its front ``GAP_M`` ahead."""
    y = EGO_LANE_Y_M + offset_m
    nodes = f"""<nodes>
  <node id="west" x="0" y="0"/><node id="east" x="{ROAD_M}" y="0"/>
  <node id="hw" x="0" y="{y:.4f}"/><node id="he" x="{ROAD_M}" y="{y:.4f}"/>
</nodes>"""
    edges = """<edges>
  <edge id="E0" from="west" to="east" numLanes="1" speed="50" width="3.5">
    <lane index="0" friction="1.00"><neigh lane="-E0_0"/></lane></edge>
  <edge id="-E0" from="east" to="west" numLanes="1" speed="50" width="3.5">
    <lane index="0" friction="1.00"><neigh lane="E0_0"/></lane></edge>
  <edge id="H" from="he" to="hw" numLanes="1" speed="50" width="2.0" spreadType="center">
    <lane index="0" friction="1.00"/></edge>
</edges>"""
    network(folder, "headon", nodes, edges)
    (folder / "r.rou.xml").write_text(f"""<routes>
  <vType id="wrong_way" vClass="passenger" length="4.70" width="1.82" maxSpeed="{TARGET_MPS:.6f}"
         accel="2.6" decel="9" sigma="0" speedDev="0"/>
  <route id="east" edges="E0"/><route id="west" edges="H"/>
  <vehicle id="ego" type="ego" route="east" depart="1.00" departLane="0" departPos="100.00"
           departSpeed="{EGO_MPS:.6f}" insertionChecks="none"/>
  <vehicle id="wrong_way" type="wrong_way" route="west" depart="1.00" departLane="0"
           departPos="{ROAD_M - 100.0 - GAP_M:.3f}" departSpeed="{TARGET_MPS:.6f}"
           insertionChecks="none"/>
</routes>""")
    return write_sumocfg(folder / "s.sumocfg", "headon.net.xml", "r.rou.xml", [VTYPES])


@pytest.mark.parametrize(
    ("overlap", "radar_model"), [(0.0, "ideal"), (0.5, "ideal"), (0.5, "automotive")]
)
def test_a_wrong_way_car_in_the_lane_is_braked_for_in_the_lane(tmp_path, overlap, radar_model):
    out = tmp_path / "run"
    cfg = head_on_scenario(tmp_path, overlap * EGO_W_M)
    run_case(cfg, None, out, RunSettings(max_time_s=30.0, radar_model=radar_model, seed=3))
    summary = json.loads((out / "summary.json").read_text())
    ts = pd.read_csv(out / "timeseries.csv")
    modes = summary["modes_visited"]
    assert modes[0] == 0 and 3 in modes  # it leaves mode 0 for limit braking in the lane
    assert 2 not in modes and 4 not in modes  # never a lane change into the oncoming path
    assert summary["collision_with"] == "oncoming"
    assert summary["trigger_range_m"] > 50.0  # seen at the radar's range, not at the bumper
    assert ts["lateral_offset_m"].abs().max() < 0.2  # it stays in its lane
    trigger = ts.index[ts["mode"] != 0][0]
    shed_mps = ts["vx_mps"].iloc[trigger] - ts["vx_mps"].iloc[-1]
    assert shed_mps > 15.0
    unreacted_mps = EGO_MPS + TARGET_MPS  # the closing speed of an ego that does not react
    assert summary["impact_speed_mps"] <= unreacted_mps - shed_mps + 0.05
