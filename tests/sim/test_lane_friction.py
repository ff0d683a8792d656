"""Per-lane friction: braking in the ego's own lane is held to the friction under the ego,
not to the lower friction of the lane a lane change would take (which still plans it)."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from eoam_sumo.cli import main
from tests.builders import network, write_sumocfg

pytestmark = pytest.mark.sumo

ROUTES = """<routes>
<vType id="ego" vClass="passenger" length="4.92" width="1.85" minGap="2" maxSpeed="60"
 accel="4" decel="9" emergencyDecel="12" sigma="0"/>
<vType id="car" vClass="passenger" length="4.7" width="1.82" minGap="2" maxSpeed="80"
 accel="2.6" decel="9" emergencyDecel="12" sigma="0"/>
<vType id="aro" vClass="passenger" length="5.09" width="1.99" minGap="2" maxSpeed="60"
 accel="2.5" decel="9" emergencyDecel="12" sigma="0"/>
<vehicle id="ego" type="ego" depart="1" departLane="0" departPos="100" departSpeed="38.89"
 insertionChecks="none"><route edges="E"/></vehicle>
<vehicle id="aro" type="aro" depart="1" departLane="0" departPos="225.09" departSpeed="16.67"
 insertionChecks="none"><route edges="E"/><param key="eoam.aro_hold_s" value="2"/>
 <param key="eoam.aro_decel_mps2" value="8"/></vehicle>
<vehicle id="beside" type="car" depart="1" departLane="1" departPos="100" departSpeed="38.89"
 insertionChecks="none"><route edges="E"/></vehicle>
</routes>
"""


def _scenario(folder, left_mu: float):
    edges = (
        '<edges><edge id="E" from="a" to="b" numLanes="2" speed="40" width="3.5">'
        f'<lane index="0" friction="1.0"/><lane index="1" friction="{left_mu}"/></edge></edges>'
    )
    network(
        folder,
        "ow2",
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="3000" y="0"/></nodes>',
        edges,
    )
    (folder / "s.rou.xml").write_text(ROUTES)
    return write_sumocfg(folder / "s.sumocfg", "ow2.net.xml", "s.rou.xml")


def test_a_blocked_lane_change_brakes_at_the_friction_under_the_ego(tmp_path):
    """A car beside the ego closes the lane change; the ego brakes in its dry lane at the dry
    limit (about 0.8 g), though the left lane it does not take is icy, and stops behind the
    obstacle (it hit it at 31.9 m/s braking at 0.2 g)."""
    cfg = _scenario(tmp_path, 0.2)
    out = tmp_path / "out"
    assert main(["run", str(cfg), "--speed-kmh", "140", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["collision_with"] == "none"
    series = pd.read_csv(out / "timeseries.csv")
    braking = series[series["mode"].isin([1, 3]) & (series["vx_mps"] > 5.0)]
    assert braking["ax_mps2"].min() < -0.7 * 9.81


def test_a_lane_change_plans_on_the_icy_lane_it_takes_on_a_later_edge(tmp_path):
    """The left lane is dry on the start edge and icy (0.15) on the next, where the obstacle
    stops: the lane change's friction is the icy one (it planned a dry lane change and slid
    off the road: orange), so the EOAM believes 0.15 at the trigger and ends with no
    contact."""
    edges = (
        '<edges><edge id="E1" from="a" to="m" numLanes="2" speed="40" width="3.5"/>'
        '<edge id="E2" from="m" to="b" numLanes="2" speed="40" width="3.5">'
        '<lane index="0" friction="1.0"/><lane index="1" friction="0.15"/></edge></edges>'
    )
    nodes = (
        '<nodes><node id="a" x="0" y="0"/><node id="m" x="500" y="0"/>'
        '<node id="b" x="3000" y="0"/></nodes>'
    )
    network(tmp_path, "ice", nodes, edges)
    routes = ROUTES.split('<vehicle id="ego"', maxsplit=1)[0] + (
        '<vehicle id="ego" type="ego" depart="1" departLane="0" departPos="400" '
        'departSpeed="38.89" insertionChecks="none"><route edges="E1 E2"/></vehicle>'
        '<vehicle id="aro" type="aro" depart="1" departLane="0" departPos="25.09" '
        'departSpeed="16.67" insertionChecks="none"><route edges="E2"/>'
        '<param key="eoam.aro_hold_s" value="2"/><param key="eoam.aro_decel_mps2" value="8"/>'
        "</vehicle></routes>"
    )
    (tmp_path / "s.rou.xml").write_text(routes)
    cfg = write_sumocfg(tmp_path / "s.sumocfg", "ice.net.xml", "s.rou.xml")
    out = tmp_path / "out"
    assert main(["run", str(cfg), "--speed-kmh", "140", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["mu_believed_at_trigger"] == pytest.approx(0.15)
    assert summary["outcome"] == "green"
