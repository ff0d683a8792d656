"""How long a run goes on after the ego stops (``RunSettings.after_stop_s``)."""

from __future__ import annotations

import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.settings import RunSettings
from tests.builders import VTYPES, network, write_sumocfg

pytestmark = pytest.mark.sumo

ROUTES = """<routes>
  <vType id="late" vClass="passenger" length="4.70" width="1.82" minGap="2.5" maxSpeed="50"
         accel="2.6" decel="4.5" emergencyDecel="4.5" sigma="0" speedDev="0"/>
  <vType id="slow_ego" vClass="passenger" length="4.92" width="1.85" minGap="2.0"
         maxSpeed="60" accel="4" decel="{ego_decel}" emergencyDecel="{ego_decel}" sigma="0"
         speedDev="0"/>
  <route id="r" edges="E"/>
  <vehicle id="ego" type="slow_ego" route="r" depart="1" departLane="0" departPos="300"
           departSpeed="33.333" insertionChecks="none"/>
  <vehicle id="aro" type="aro" route="r" depart="1" departLane="0" departPos="425.09"
           departSpeed="16.667" insertionChecks="none">
    <param key="eoam.aro_hold_s" value="2.0"/><param key="eoam.aro_decel_mps2" value="8.0"/>
  </vehicle>
  <vehicle id="follower" type="late" route="r" depart="1" departLane="0" departPos="{pos}"
           departSpeed="33.333" insertionChecks="none"/>
</routes>"""


def _scenario(tmp_path, follower_pos_m: float, ego_decel_mps2: float = 4.0):
    # one lane one way: the ego stops behind a braking obstacle, a car that brakes at
    # 4.5 m/s2 at most follows it, expecting the ego to brake at ``ego_decel_mps2`` at most
    # (SUMO keeps its gap for that; the EOAM brakes at mu g)
    net = network(
        tmp_path,
        "one",
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="3000" y="0"/></nodes>',
        '<edges><edge id="E" from="a" to="b" numLanes="1" speed="50" width="3.5"/></edges>',
    )
    (tmp_path / "r.rou.xml").write_text(ROUTES.format(pos=follower_pos_m, ego_decel=ego_decel_mps2))
    return write_sumocfg(tmp_path / "f.sumocfg", net.name, "r.rou.xml", [VTYPES], 0.01)


def test_by_default_the_run_waits_for_the_follower_and_its_hit_is_a_contact(tmp_path):
    cfg = _scenario(tmp_path, 230.0)
    early = run_case(cfg, settings=RunSettings(after_stop_s=0.0))
    assert early["collision_with"] == "none" and early["end_cause"] == "settled"
    waited = run_case(cfg, settings=RunSettings())
    assert early["final_speed_mps"] < 0.05  # the ego had stopped
    assert waited["end_cause"] == "contact"
    assert waited["collision_with_id"] == "follower"
    assert waited["collision_with"] == "other"  # a follower, never the obstacle
    assert waited["contact_kind"] == "rear_end" and waited["outcome"] != "green"
    assert waited["sim_time_s"] > early["sim_time_s"]


def test_after_stop_s_is_the_time_after_the_stop(tmp_path):
    cfg = _scenario(tmp_path, 20.0)  # far behind: it stops well short of the ego
    short = run_case(cfg, settings=RunSettings(after_stop_s=0.0))
    longer = run_case(cfg, settings=RunSettings(after_stop_s=5.0))
    assert longer["sim_time_s"] == pytest.approx(short["sim_time_s"] + 5.0, abs=0.011)
    assert longer["collision_with"] == "none"
