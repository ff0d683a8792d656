"""A lane change that makes the follower in the next lane brake hard shows in the summary."""

from __future__ import annotations

from dataclasses import replace

import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.settings import RunSettings
from tests.builders import VTYPES, network, write_sumocfg

pytestmark = pytest.mark.sumo

ROUTES = """<routes>
  <vType id="car" vClass="passenger" length="4.70" width="1.82" minGap="2.5" maxSpeed="50"
         accel="2.6" decel="4.5" emergencyDecel="9" sigma="0" speedDev="0"/>
  <route id="r" edges="E"/>
  <vehicle id="ego" type="ego" route="r" depart="1" departLane="0" departPos="200"
           departSpeed="45.833" insertionChecks="none"/>
  <vehicle id="aro" type="aro" route="r" depart="1" departLane="0" departPos="325.09"
           departSpeed="16.667" insertionChecks="none">
    <param key="eoam.aro_hold_s" value="2.0"/><param key="eoam.aro_decel_mps2" value="8.0"/>
  </vehicle>
  <vehicle id="follower" type="car" route="r" depart="1" departLane="1" departPos="150"
           departSpeed="44" insertionChecks="none"/>
</routes>"""


def test_a_follower_forced_to_brake_shows_in_the_summary(tmp_path):
    # a one-way road of two lanes: the ego at 165 km/h changes lanes round a braking
    # obstacle, in front of a car 50 m behind in the left lane at 44 m/s
    net = network(
        tmp_path,
        "two",
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="3000" y="0"/></nodes>',
        '<edges><edge id="E" from="a" to="b" numLanes="2" speed="50" width="3.5"/></edges>',
    )
    (tmp_path / "r.rou.xml").write_text(ROUTES)
    cfg = write_sumocfg(tmp_path / "lc.sumocfg", net.name, "r.rou.xml", [VTYPES], 0.01)
    # the paper's policy as published: the lane change ignores the car behind (by default the
    # policy refuses it, tests/sim/test_occupied_lane_runs.py)
    base = RunSettings(max_time_s=20.0)
    policy = replace(base.eoam.policy, check_target_lane=False)
    settings = replace(base, eoam=replace(base.eoam, policy=policy))
    s = run_case(cfg, settings=settings)
    assert 2 in s["modes_visited"]  # the lane change
    assert s["collision_with"] == "none"
    assert s["follower_decel_id"] == "follower"
    assert s["max_follower_decel_mps2"] > 4.0
    assert s["min_gap_rear_m"] is not None and s["min_ttc_rear_s"] is not None
    assert s["near_miss"]  # forced to brake at 6 m/s2 or more: no longer a plain green
