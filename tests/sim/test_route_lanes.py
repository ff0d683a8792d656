"""The lane the ego follows along its route, the lanes beside it on the way, the obstacle's
lane through its stop, and the road's end (SUMO numbers lanes from the right, and netconvert
may connect a lane elsewhere: the reviews' networks, built here)."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import netconvert, network, straight_road, write_sumocfg

pytestmark = pytest.mark.sumo


@pytest.mark.parametrize(("lanes", "centre_m"), [([1, 2, 1], 1.75), ([2, 3], 5.25)])
def test_a_lane_added_on_the_right_does_not_pull_the_ego_over(tmp_path, lanes, centre_m):
    """SUMO numbers lanes from the right: where a lane is added on the right the ego's lane
    straight on has the next index, and netconvert may connect the ego's lane to the added
    one (2 -> 3 lanes: lane 0 to lane 0, 3.5 m to the right over 8 m). The centre line
    followed the same index or the connection: the ego swerved a lane over at 0.73 g in
    mode 0, "no manoeuvre needed" (with a car parked in the added lane, it spun)."""
    straight_road(tmp_path, "added", [3.5] * len(lanes), lanes)
    out = tmp_path / "run"
    summary = run_case(
        tmp_path / "added.sumocfg",
        ScenarioOverrides(ego_speed_mps=100 / 3.6, mu=1.0),
        out,
        RunSettings(max_time_s=30.0),
    )
    assert summary["outcome"] == "none"
    road = pd.read_csv(out / "road.csv")
    assert road["y_m"].to_numpy() == pytest.approx(-centre_m, abs=0.05)  # one lane's centre
    ts = pd.read_csv(out / "timeseries.csv")
    assert ts["s_m"].iloc[-1] > 600.0
    assert ts["lateral_offset_m"].abs().max() < 0.1
    assert ts["ay_mps2"].abs().max() < 0.5


def test_an_obstacle_in_the_roads_last_50_m_is_met_not_cut_off(tmp_path):
    """The run ended 50 m before the road's end whatever stood there: an obstacle whose back is
    14.5 m from the end was never reached ("unfinished", no gap). Braking from 100 km/h on
    mu 1.0 on a one-lane road, the ego now stops behind it (or hits it)."""
    straight_road(tmp_path, "short", [3.5], [1])
    (tmp_path / "short.rou.xml").write_text(
        '<routes><vType id="car" length="4.9" width="1.85" sigma="0"/>'
        '<vehicle id="obs" type="car" depart="0" departPos="490" departLane="0" '
        'departSpeed="0"><route edges="e0"/><stop lane="e0_0" endPos="490" duration="1000"/>'
        "</vehicle>"
        '<vehicle id="ego" type="car" depart="0" departPos="50" departLane="0" '
        'departSpeed="30"><route edges="e0"/></vehicle></routes>'
    )
    summary = run_case(
        tmp_path / "short.sumocfg",
        ScenarioOverrides(ego_speed_mps=100 / 3.6, mu=1.0),
        tmp_path / "run",
        RunSettings(max_time_s=40.0),
    )
    assert summary["end_cause"] != "road_end"
    assert summary["outcome"] in ("green", "yellow")
    assert summary["min_gap_aro_m"] is not None and summary["min_gap_aro_m"] < 10.0


def _ramp(tmp_path, route: str, depart_lane: int) -> object:
    """A 2-lane motorway widening to 3 lanes, then an exit on the right and 2 lanes on."""
    netconvert(
        tmp_path,
        "ramp",
        '<nodes><node id="A" x="0" y="0"/><node id="B" x="1000" y="0"/>'
        '<node id="C" x="1300" y="0"/><node id="D" x="3000" y="0"/>'
        '<node id="X" x="1700" y="-80"/></nodes>',
        '<edges><edge id="m1" from="A" to="B" numLanes="2" speed="33.33"/>'
        '<edge id="dec" from="B" to="C" numLanes="3" speed="33.33"/>'
        '<edge id="m2" from="C" to="D" numLanes="2" speed="33.33"/>'
        '<edge id="exit" from="C" to="X" numLanes="1" speed="22.22"/></edges>',
    )
    (tmp_path / "ramp.rou.xml").write_text(
        '<routes><vType id="car" length="4.9" width="1.85" sigma="0"/>'
        f'<vehicle id="ego" type="car" depart="0" departLane="{depart_lane}" departPos="800" '
        f'departSpeed="30"><route edges="{route}"/></vehicle></routes>'
    )
    return write_sumocfg(tmp_path / "ramp.sumocfg", "ramp.net.xml", "ramp.rou.xml")


def test_an_exit_route_follows_the_lane_that_leads_to_the_exit(tmp_path):
    """The lane straight ahead of the ego's on the widened edge does not lead to the exit on
    its route: the connected lane that does is followed (the route was refused)."""
    cfg = _ramp(tmp_path, "m1 dec exit", 0)
    summary = run_case(cfg, ScenarioOverrides(ego_speed_mps=25.0, mu=1.0), tmp_path / "run")
    assert summary["outcome"] == "none"


def test_an_ego_lane_that_merges_away_is_refused_by_name(tmp_path):
    """Straight on, the ego's right lane ends into the lane left of it (a connection file
    merges it): the centre line jumped 3.5 m in 8 m and the ego swerved at 7.7 m/s^2 in mode
    0 ("left the road")."""
    from eoam_sumo.errors import InputError

    (tmp_path / "merge.con.xml").write_text(
        '<connections><connection from="e0" to="e1" fromLane="0" toLane="0"/></connections>'
    )
    netconvert(
        tmp_path,
        "merge",
        '<nodes><node id="A" x="0" y="0"/><node id="B" x="500" y="0"/>'
        '<node id="C" x="1500" y="0"/></nodes>',
        '<edges><edge id="e0" from="A" to="B" numLanes="2" speed="33.33"/>'
        '<edge id="e1" from="B" to="C" numLanes="1" speed="33.33"/></edges>',
        "--connection-files",
        str(tmp_path / "merge.con.xml"),
    )
    net = (tmp_path / "merge.net.xml").read_text()
    assert 'from="e0" to="e1" fromLane="0"' in net  # the lane is connected: it merges
    (tmp_path / "merge.rou.xml").write_text(
        '<routes><vType id="car" length="4.9" width="1.85" sigma="0"/>'
        '<vehicle id="ego" type="car" depart="0" departLane="0" departPos="50" '
        'departSpeed="30"><route edges="e0 e1"/></vehicle></routes>'
    )
    cfg = write_sumocfg(tmp_path / "merge.sumocfg", "merge.net.xml", "merge.rou.xml")
    with pytest.raises(InputError, match="lane e0_0 does not continue onto edge 'e1'"):
        run_case(cfg, ScenarioOverrides(ego_speed_mps=30.0, mu=1.0))


def test_a_braking_obstacle_keeps_its_lane(tmp_path):
    """The scripted stop gave the obstacle its lane changes back when it began to brake: on a
    road of two lanes each way SUMO moved it from the left lane to the right one in one 10 ms
    step, into the lane the ego was evading into (the contact then counted as 'other')."""
    network(
        tmp_path,
        "dual",
        '<nodes><node id="A" x="0" y="0"/><node id="B" x="3000" y="0"/></nodes>',
        '<edges><edge id="E" from="A" to="B" numLanes="2" speed="33.33" width="3.5"/>'
        '<edge id="-E" from="B" to="A" numLanes="2" speed="33.33" width="3.5"/></edges>',
    )
    (tmp_path / "dual.rou.xml").write_text(
        '<routes><vType id="car" length="4.9" width="1.85" decel="9" sigma="0"/>'
        '<vehicle id="aro" type="car" depart="1" departLane="1" departPos="225" '
        'departSpeed="16.67" insertionChecks="none"><route edges="E"/>'
        '<param key="eoam.aro_hold_s" value="2.0"/><param key="eoam.aro_decel_mps2" value="8.0"/>'
        "</vehicle>"
        '<vehicle id="ego" type="car" depart="1" departLane="1" departPos="100" '
        'departSpeed="33.33" insertionChecks="none"><route edges="E"/></vehicle></routes>'
    )
    cfg = write_sumocfg(tmp_path / "dual.sumocfg", "dual.net.xml", "dual.rou.xml")
    out = tmp_path / "run"
    summary = run_case(
        cfg,
        ScenarioOverrides(ego_speed_mps=120 / 3.6, mu=0.3, oncoming_start_m=250.0),
        out,
        RunSettings(max_time_s=20.0),
    )
    traffic = pd.read_csv(out / "traffic.csv")
    aro = traffic[traffic["id"] == "aro"]
    assert len(aro) > 100
    assert aro["y_m"].max() - aro["y_m"].min() < 0.01
    assert summary["collision_with"] in ("none", "aro")


def test_a_bus_lane_beside_the_ego_further_on_closes_the_evasion(tmp_path):
    """A lane added on the right shifts SUMO's indices: the lane beside the ego on the next
    edge is its index + 1 there, a bus lane; the check took the start edge's index (the ego's
    own lane there) and the ego evaded through the bus lane for 3.9 s (the connections as a
    user wrote them: the lanes straight on, the added lane unconnected)."""
    summary = _braking_obstacle_ahead(
        tmp_path,
        '<edge id="e2" from="B" to="C" numLanes="3" speed="33.33" width="3.5">'
        '<lane index="2" allow="bus"/></edge>',
        '<connection from="e1" to="e2" fromLane="0" toLane="1"/>'
        '<connection from="e1" to="e2" fromLane="1" toLane="2"/>',
    )
    modes = summary["modes_visited"]
    assert 1 in modes or 3 in modes  # it met the obstacle in its lane
    assert 2 not in modes and 4 not in modes  # and did not evade through the bus lane
    assert summary["time_in_next_lane_s"] == 0.0


def test_a_lane_that_ends_beside_the_ego_is_no_way_out(tmp_path):
    """The lanes beside the ego were judged on its start edge: the left lane ends 130 m
    ahead, and the ego evaded into it and on beyond the road's edge (scored green). The side
    must now lie beside the ego along the manoeuvre's reach: it brakes in its lane."""
    summary = _braking_obstacle_ahead(
        tmp_path,
        '<edge id="e2" from="B" to="C" numLanes="1" speed="33.33" width="3.5" '
        'shape="500,-3.5 3000,-3.5"/>',
        '<connection from="e1" to="e2" fromLane="0" toLane="0"/>',
    )
    modes = summary["modes_visited"]
    assert 1 in modes or 3 in modes
    assert 2 not in modes and 4 not in modes
    assert summary["left_road"] is False


def _braking_obstacle_ahead(tmp_path, next_edge: str, connections: str) -> dict:
    """A 2-lane road (e1, 500 m) on to ``next_edge`` (e2, B to C, 2.5 km) as netconvert builds
    it with ``connections`` (a user's connection file); the obstacle 120 m ahead of the ego
    in e1's right lane at 60 km/h, holding 2 s then braking at 8 m/s^2; the ego at 120 km/h
    on mu 0.3, both routed e1 e2 (SUMO at 10 ms, as the review's scenarios): the summary."""
    (tmp_path / "n.con.xml").write_text(f"<connections>{connections}</connections>")
    netconvert(
        tmp_path,
        "n",
        '<nodes><node id="A" x="0" y="0"/><node id="B" x="500" y="0"/>'
        '<node id="C" x="3000" y="0"/></nodes>',
        '<edges><edge id="e1" from="A" to="B" numLanes="2" speed="33.33" width="3.5"/>'
        f"{next_edge}</edges>",
        "--connection-files",
        str(tmp_path / "n.con.xml"),
    )
    (tmp_path / "n.rou.xml").write_text(
        '<routes><vType id="car" length="4.92" width="1.85" decel="9" sigma="0" speedDev="0"/>'
        '<vType id="aro" length="5.09" width="1.99" accel="2.5" decel="9" emergencyDecel="12" '
        'maxSpeed="50" sigma="0" speedDev="0"/>'
        '<vehicle id="aro" type="aro" depart="1" departLane="0" departPos="490" '
        'departSpeed="16.67" insertionChecks="none"><route edges="e1 e2"/>'
        '<param key="eoam.aro_hold_s" value="2.0"/><param key="eoam.aro_decel_mps2" value="8.0"/>'
        "</vehicle>"
        '<vehicle id="ego" type="car" depart="1" departLane="0" departPos="370" '
        'departSpeed="33.33" insertionChecks="none"><route edges="e1 e2"/></vehicle></routes>'
    )
    cfg = tmp_path / "n.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="n.net.xml"/><route-files value="n.rou.xml"/>'
        '</input><time><begin value="0"/><step-length value="0.01"/></time></configuration>'
    )
    return run_case(cfg, ScenarioOverrides(mu=0.3), tmp_path / "o")
