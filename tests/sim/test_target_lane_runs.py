"""The lane a lane change would take, in real SUMO runs: a van creeping towards the ego is
oncoming traffic to the paper's EOAM, and a car at the far side of a wider target lane is in
that lane (the reviewer's D2 and D4)."""

from __future__ import annotations

from pathlib import Path

import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import netconvert
from tests.sim.test_safe_policy_runs import _scenario as beside_the_obstacle

pytestmark = pytest.mark.sumo


def test_the_paper_policy_does_not_steer_into_a_van_creeping_towards_the_ego(tmp_path):
    """A van at 1.5 m/s towards the ego in the opposite lane beside where the obstacle stops:
    neither standing nor oncoming for the radar, it was hit head-on at 165 km/h (red); now it
    is oncoming traffic and the EOAM brakes in its lane (the paper's rule)."""
    cfg = beside_the_obstacle(tmp_path, van_x_m=300.0, user="van")
    s = run_case(cfg, ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=1.0), None, RunSettings())
    assert s["outcome"] != "red", s["reason"]
    assert s["collision_with"] in ("none", "aro"), s["reason"]
    assert 2 not in s["modes_visited"] and 3 in s["modes_visited"]


ROUTES = """<routes>
<vType id="ego" vClass="passenger" length="4.92" width="1.85" maxSpeed="60" sigma="0"/>
<vType id="car" vClass="passenger" length="4.7" width="1.82" maxSpeed="60" sigma="0"/>
<vType id="aro" vClass="passenger" length="5.09" width="1.99" maxSpeed="60" sigma="0"/>
<vehicle id="far" type="car" depart="0" departPos="2710" departPosLat="right" departSpeed="0"
         insertionChecks="none"><route edges="-E"/>
  <stop lane="-E_0" endPos="2710" duration="1000"/></vehicle>
<vehicle id="ego" type="ego" depart="1" departPos="100" departSpeed="38.89"
         insertionChecks="none"><route edges="E"/></vehicle>
<vehicle id="aro" type="aro" depart="1" departPos="225.09" departSpeed="16.67"
         insertionChecks="none"><route edges="E"/>
  <param key="eoam.aro_hold_s" value="2"/><param key="eoam.aro_decel_mps2" value="8"/></vehicle>
</routes>"""


def _wide_road(folder: Path) -> Path:
    """A two-way road, the ego's lane 3 m, the opposite lane 5 m, with a car standing at the
    kerb side of the opposite lane 15 m beyond where the obstacle stops (the reviewer's
    ``wide_far``)."""
    netconvert(
        folder,
        "n",
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="3000" y="0"/></nodes>',
        '<edges><edge id="E" from="a" to="b" numLanes="1" speed="40" width="3.0"/>'
        '<edge id="-E" from="b" to="a" numLanes="1" speed="40" width="5.0"/></edges>',
        "--no-turnarounds",
        "true",
    )
    (folder / "r.rou.xml").write_text(ROUTES)
    cfg = folder / "s.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="n.net.xml"/><route-files value="r.rou.xml"/>'
        '</input><processing><lateral-resolution value="0.2"/></processing></configuration>'
    )
    return cfg


def test_a_car_at_the_far_side_of_a_wide_target_lane_is_not_driven_into(tmp_path):
    """The radar's next-lane band was the ego lane's width: the car's centre, 5.59 m from the
    ego's lane centre, lay beyond it and the ego changed lanes into it (red, 22 m/s). With the
    target lane's width (``RadarSettings.next_lane_width_m``, which the run gives the radar
    from the session's side lane) it is a standing car in the next lane: the EOAM brakes in
    its lane."""
    s = run_case(_wide_road(tmp_path), ScenarioOverrides(), None, RunSettings(max_time_s=20.0))
    assert s["collision_with"] in ("none", "aro"), s["reason"]
    assert 2 not in s["modes_visited"] and 3 in s["modes_visited"]
