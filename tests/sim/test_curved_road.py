"""A curved road made of several edges, as users' networks are: the ego keeps its lane centre."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import network, write_sumocfg

pytestmark = pytest.mark.sumo

RADIUS_M = 1500.0
EDGE_M = 700.0
CHORD_M = 25.0


def _shape(s0: float, s1: float, reverse: bool = False) -> str:
    n = math.ceil((s1 - s0) / CHORD_M)
    pts = [s0 + (s1 - s0) * k / n for k in range(n + 1)]
    xy = [(RADIUS_M * math.sin(s / RADIUS_M), RADIUS_M * (1 - math.cos(s / RADIUS_M))) for s in pts]
    if reverse:
        xy.reverse()
    return " ".join(f"{x:.3f},{y:.3f}" for x, y in xy)


@pytest.fixture
def curve_scenario(tmp_path):
    """A left arc of radius 1500 m, three 700 m edges each way (neighbours across), 3.5 m
    lanes, 50 m/s; the ego alone."""
    nodes, edges = [], []
    for k in range(4):
        s = k * EDGE_M
        nodes.append(
            f'<node id="n{k}" x="{RADIUS_M * math.sin(s / RADIUS_M):.3f}" '
            f'y="{RADIUS_M * (1 - math.cos(s / RADIUS_M)):.3f}" type="priority"/>'
        )
    for k in range(3):
        s0, s1 = k * EDGE_M, (k + 1) * EDGE_M
        edges.append(
            f'<edge id="c{k}" from="n{k}" to="n{k + 1}" numLanes="1" speed="50" width="3.5" '
            f'shape="{_shape(s0, s1)}"><lane index="0"><neigh lane="-c{k}_0"/></lane></edge>'
            f'<edge id="-c{k}" from="n{k + 1}" to="n{k}" numLanes="1" speed="50" width="3.5" '
            f'shape="{_shape(s0, s1, True)}"><lane index="0"><neigh lane="c{k}_0"/></lane>'
            "</edge>"
        )
    network(
        tmp_path, "curve", f"<nodes>{''.join(nodes)}</nodes>", f"<edges>{''.join(edges)}</edges>"
    )
    (tmp_path / "curve.rou.xml").write_text(
        '<routes><vType id="car" length="4.9" width="1.85" sigma="0"/>'
        '<vehicle id="ego" type="car" depart="0" departPos="50" departSpeed="30">'
        '<route edges="c0 c1 c2"/></vehicle></routes>'
    )
    return write_sumocfg(tmp_path / "curve.sumocfg", "curve.net.xml", "curve.rou.xml")


@pytest.mark.parametrize("speed_kmh", [120.0, 165.0])
def test_the_ego_keeps_the_lane_centre_on_a_curve_across_edges(curve_scenario, tmp_path, speed_kmh):
    """1.4 m/s^2 of cornering at 165 km/h: no steady offset from the body's sideslip, no
    steps at the junctions between edges (the road heading and curvature are smooth)."""
    out = tmp_path / "run"
    summary = run_case(
        curve_scenario,
        ScenarioOverrides(ego_speed_mps=speed_kmh / 3.6, mu=1.0),
        out,
        RunSettings(max_time_s=40.0),
    )
    assert summary["outcome"] == "none"
    ts = pd.read_csv(out / "timeseries.csv")
    assert ts["s_m"].iloc[-1] > 1.5 * EDGE_M  # through at least one junction
    assert ts["lateral_offset_m"].abs().max() < 0.2


def _straight_edges(tmp_path, name: str, widths: list[float], lanes: list[int]) -> None:
    """A straight one-way road of 500 m edges with these lane widths and lane counts."""
    nodes = "".join(f'<node id="n{k}" x="{500.0 * k}" y="0"/>' for k in range(len(widths) + 1))
    edges = "".join(
        f'<edge id="e{k}" from="n{k}" to="n{k + 1}" numLanes="{n}" speed="50" width="{w}"/>'
        for k, (w, n) in enumerate(zip(widths, lanes))
    )
    network(tmp_path, name, f"<nodes>{nodes}</nodes>", f"<edges>{edges}</edges>")
    route = " ".join(f"e{k}" for k in range(len(widths)))
    (tmp_path / f"{name}.rou.xml").write_text(
        '<routes><vType id="car" length="4.9" width="1.85" sigma="0"/>'
        '<vehicle id="ego" type="car" depart="0" departPos="50" departLane="0" '
        f'departSpeed="30"><route edges="{route}"/></vehicle></routes>'
    )
    write_sumocfg(tmp_path / f"{name}.sumocfg", f"{name}.net.xml", f"{name}.rou.xml")


def test_lane_width_changes_along_the_route_do_not_throw_the_ego_off(tmp_path):
    """The lane centre shifts by up to 0.6 m at each junction: the ego follows it smoothly
    (not swerving into the next lane at the heading step seen 30 m ahead)."""
    _straight_edges(tmp_path, "widths", [3.5, 3.0, 4.0, 2.8, 3.5], [1] * 5)
    out = tmp_path / "run"
    summary = run_case(
        tmp_path / "widths.sumocfg",
        ScenarioOverrides(ego_speed_mps=120 / 3.6, mu=1.0),
        out,
        RunSettings(max_time_s=60.0),
    )
    assert summary["outcome"] == "none"
    ts = pd.read_csv(out / "timeseries.csv")
    assert ts["s_m"].iloc[-1] > 2000.0
    assert ts["lateral_offset_m"].abs().max() < 0.7  # the centre itself shifts up to 0.6 m
    assert ts["ay_mps2"].abs().max() < 3.0


def test_an_ego_lane_that_ends_is_refused_by_name(tmp_path):
    from eoam_sumo.errors import InputError

    _straight_edges(tmp_path, "drop", [3.5, 3.5], [2, 1])  # the right lane ends
    with pytest.raises(InputError, match="lane e0_0 does not continue onto edge 'e1'"):
        run_case(tmp_path / "drop.sumocfg", ScenarioOverrides(ego_speed_mps=30.0, mu=1.0))


def test_a_straight_edge_then_a_curve_keeps_the_lane_centre(tmp_path):
    """A 1000 m straight edge, then a 500 m curve of 25 m chords (the heading of a straight
    edge must not lean towards the curve it meets, or the ego drifts 0.9 m on the straight)."""
    radius = 500.0
    curve = [
        (
            1000.0 + radius * math.sin(k * CHORD_M / radius),
            radius * (1 - math.cos(k * CHORD_M / radius)),
        )
        for k in range(33)
    ]
    end = curve[-1]
    shape = " ".join(f"{x:.3f},{y:.3f}" for x, y in curve)
    back = " ".join(f"{x:.3f},{y:.3f}" for x, y in reversed(curve))
    network(
        tmp_path,
        "bend",
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="1000" y="0"/>'
        f'<node id="c" x="{end[0]:.3f}" y="{end[1]:.3f}"/></nodes>',
        '<edges><edge id="s" from="a" to="b" numLanes="1" speed="50" width="3.5">'
        '<lane index="0"><neigh lane="-s_0"/></lane></edge>'
        '<edge id="-s" from="b" to="a" numLanes="1" speed="50" width="3.5">'
        '<lane index="0"><neigh lane="s_0"/></lane></edge>'
        f'<edge id="c" from="b" to="c" numLanes="1" speed="50" width="3.5" shape="{shape}">'
        '<lane index="0"><neigh lane="-c_0"/></lane></edge>'
        f'<edge id="-c" from="c" to="b" numLanes="1" speed="50" width="3.5" shape="{back}">'
        '<lane index="0"><neigh lane="c_0"/></lane></edge></edges>',
    )
    (tmp_path / "bend.rou.xml").write_text(
        '<routes><vType id="car" length="4.9" width="1.85" sigma="0"/>'
        '<vehicle id="ego" type="car" depart="0" departPos="50" departSpeed="30">'
        '<route edges="s c"/></vehicle></routes>'
    )
    cfg = write_sumocfg(tmp_path / "bend.sumocfg", "bend.net.xml", "bend.rou.xml")
    out = tmp_path / "run"
    summary = run_case(
        cfg, ScenarioOverrides(ego_speed_mps=100 / 3.6, mu=1.0), out, RunSettings(max_time_s=60.0)
    )
    assert summary["outcome"] == "none"
    ts = pd.read_csv(out / "timeseries.csv")
    assert ts["s_m"].iloc[-1] > 1300.0  # well into the curve
    assert ts["lateral_offset_m"].abs().max() < 0.15


def _arc(radius_m: float, length_m: float, reverse: bool = False) -> str:
    n = math.ceil(length_m / 20.0)
    xy = [
        (radius_m * math.sin(s / radius_m), radius_m * (1 - math.cos(s / radius_m)))
        for s in (length_m * k / n for k in range(n + 1))
    ]
    return " ".join(f"{x:.3f},{y:.3f}" for x, y in (reversed(xy) if reverse else xy))


def test_a_queue_on_a_600_m_curve_at_130_kmh_is_stopped_for(tmp_path):
    """A 600 m left curve at 130 km/h on mu 1.0, a car halted in the ego's lane and one beside
    it in the opposite lane (no lane to change into): first seen at the radar's 100 m, which
    is inside the curve's braking boundary (the lateral 2.2 m/s^2 takes part of the friction
    ellipse and, without ABS, the inner wheels lock sooner: B0 x 1.07). The ego brakes at
    once and stops short; with the straight road's boundaries it braked 3 m later and hit at
    2.5 m/s."""
    radius, length, pos = 600.0, 1000.0, 600.0
    end = (radius * math.sin(length / radius), radius * (1 - math.cos(length / radius)))
    network(
        tmp_path,
        "arc",
        f'<nodes><node id="a" x="0" y="0"/><node id="b" x="{end[0]:.3f}" y="{end[1]:.3f}"/>'
        "</nodes>",
        f'<edges><edge id="fwd" from="a" to="b" numLanes="1" speed="50" width="3.5" '
        f'shape="{_arc(radius, length)}"><lane index="0"><neigh lane="bwd_0"/></lane></edge>'
        f'<edge id="bwd" from="b" to="a" numLanes="1" speed="50" width="3.5" '
        f'shape="{_arc(radius, length, True)}"><lane index="0"><neigh lane="fwd_0"/></lane>'
        "</edge></edges>",
    )
    (tmp_path / "arc.rou.xml").write_text(
        f'<routes><vType id="car" length="4.6" width="1.8" decel="9" sigma="0"/>'
        f'<vehicle id="stalled" type="car" depart="0" departPos="{pos}" departSpeed="0">'
        f'<route edges="fwd"/><stop lane="fwd_0" endPos="{pos + 5}" duration="1000"/></vehicle>'
        f'<vehicle id="beside" type="car" depart="0" departPos="{length - pos - 5}" '
        f'departSpeed="0"><route edges="bwd"/>'
        f'<stop lane="bwd_0" endPos="{length - pos}" duration="1000"/></vehicle>'
        '<vehicle id="ego" type="car" depart="0" departPos="100" departSpeed="30">'
        '<route edges="fwd"/></vehicle></routes>'
    )
    cfg = write_sumocfg(tmp_path / "arc.sumocfg", "arc.net.xml", "arc.rou.xml")
    summary = run_case(
        cfg,
        ScenarioOverrides(ego_speed_mps=130 / 3.6, mu=1.0),
        tmp_path / "run",
        RunSettings(max_time_s=20.0),
    )
    assert summary["collision_with"] == "none", summary["reason"]
    assert summary["min_gap_aro_m"] > 0.3
    assert summary["modes_visited"][:2] == [0, 1]
    assert summary["trigger_range_m"] > 99.0  # braked as soon as it was seen


@pytest.mark.parametrize(("lanes", "centre_m"), [([1, 2, 1], 1.75), ([2, 3], 5.25)])
def test_a_lane_added_on_the_right_does_not_pull_the_ego_over(tmp_path, lanes, centre_m):
    """SUMO numbers lanes from the right: where a lane is added on the right the ego's lane
    straight on has the next index, and netconvert may connect the ego's lane to the added
    one (2 -> 3 lanes: lane 0 to lane 0, 3.5 m to the right over 8 m). The centre line
    followed the same index or the connection: the ego swerved a lane over at 0.73 g in
    mode 0, "no manoeuvre needed" (with a car parked in the added lane, it spun)."""
    _straight_edges(tmp_path, "added", [3.5] * len(lanes), lanes)
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
    _straight_edges(tmp_path, "short", [3.5], [1])
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


def test_an_ego_far_off_the_road_ends_the_run(curve_scenario, tmp_path):
    """165 km/h on the 1500 m arc asks 1.4 m/s^2 of a mu 0.1 road (0.98 m/s^2): the ego slides
    off the outside of the curve. With nothing near it there, the run ends (it wandered on to
    the 40 s limit) and the outcome is the road departure's."""
    summary = run_case(
        curve_scenario,
        ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=0.1),
        tmp_path / "run",
        RunSettings(max_time_s=40.0),
    )
    assert summary["end_cause"] == "left_road"
    assert summary["sim_time_s"] < 30.0
    assert summary["outcome"] == "orange" and summary["left_road"] is True
    assert "left the road" in summary["reason"]


def test_an_ego_starting_on_a_curve_starts_turning_along_it(tmp_path):
    """A 400 m left arc at 120 km/h on mu 0.4 (2.78 of 3.92 m/s^2): the plant started straight
    with SUMO's angle (its 20 m chord's, 0.025 rad off the curve) and drifted 1.3 m in mode
    0. It now starts on the curve: the yaw rate v / R, along the road's heading."""
    radius, length = 400.0, 1200.0
    end = (radius * math.sin(length / radius), radius * (1 - math.cos(length / radius)))
    network(
        tmp_path,
        "arc",
        f'<nodes><node id="a" x="0" y="0"/><node id="b" x="{end[0]:.3f}" y="{end[1]:.3f}"/>'
        "</nodes>",
        f'<edges><edge id="fwd" from="a" to="b" numLanes="1" speed="50" width="3.5" '
        f'shape="{_arc(radius, length)}"/></edges>',
    )
    (tmp_path / "arc.rou.xml").write_text(
        '<routes><vType id="car" length="4.6" width="1.8" sigma="0"/>'
        '<vehicle id="ego" type="car" depart="0" departPos="100" departSpeed="30">'
        '<route edges="fwd"/></vehicle></routes>'
    )
    cfg = write_sumocfg(tmp_path / "arc.sumocfg", "arc.net.xml", "arc.rou.xml")
    out = tmp_path / "run"
    speed = 120 / 3.6
    summary = run_case(
        cfg, ScenarioOverrides(ego_speed_mps=speed, mu=0.4), out, RunSettings(max_time_s=15.0)
    )
    assert summary["outcome"] == "none"
    ts = pd.read_csv(out / "timeseries.csv")
    assert ts["yaw_rate_radps"].iloc[0] == pytest.approx(speed / radius, rel=0.02)
    assert abs(ts["heading_error_rad"].iloc[0]) < 0.002
    assert ts["lateral_offset_m"].abs().max() < 0.5


def _ramp(tmp_path, route: str, depart_lane: int) -> object:
    """A 2-lane motorway widening to 3 lanes, then an exit on the right and 2 lanes on."""
    from tests.builders import netconvert

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
    from tests.builders import netconvert

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
    from tests.builders import netconvert

    (tmp_path / "bus.con.xml").write_text(
        '<connections><connection from="e1" to="e2" fromLane="0" toLane="1"/>'
        '<connection from="e1" to="e2" fromLane="1" toLane="2"/></connections>'
    )
    netconvert(
        tmp_path,
        "bus",
        '<nodes><node id="A" x="0" y="0"/><node id="B" x="500" y="0"/>'
        '<node id="C" x="3000" y="0"/></nodes>',
        '<edges><edge id="e1" from="A" to="B" numLanes="2" speed="33.33" width="3.5"/>'
        '<edge id="e2" from="B" to="C" numLanes="3" speed="33.33" width="3.5">'
        '<lane index="2" allow="bus"/></edge></edges>',
        "--connection-files",
        str(tmp_path / "bus.con.xml"),
    )
    (tmp_path / "bus.rou.xml").write_text(
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
    cfg = tmp_path / "bus.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="bus.net.xml"/><route-files value="bus.rou.xml"/>'
        '</input><time><begin value="0"/><step-length value="0.01"/></time></configuration>'
    )
    summary = run_case(cfg, ScenarioOverrides(mu=0.3), tmp_path / "o")
    modes = summary["modes_visited"]
    assert 1 in modes or 3 in modes  # it met the obstacle in its lane
    assert 2 not in modes and 4 not in modes  # and did not evade through the bus lane
    assert summary["time_in_next_lane_s"] == 0.0


def test_a_lane_that_ends_beside_the_ego_is_no_way_out(tmp_path):
    """The lanes beside the ego were judged on its start edge: the left lane ends 130 m
    ahead, and the ego evaded into it and on beyond the road's edge (scored green). The side
    must now lie beside the ego along the manoeuvre's reach: it brakes in its lane."""
    from tests.builders import netconvert

    (tmp_path / "drop.con.xml").write_text(
        '<connections><connection from="e1" to="e2" fromLane="0" toLane="0"/></connections>'
    )
    netconvert(
        tmp_path,
        "drop",
        '<nodes><node id="A" x="0" y="0"/><node id="B" x="500" y="0"/>'
        '<node id="C" x="3000" y="0"/></nodes>',
        '<edges><edge id="e1" from="A" to="B" numLanes="2" speed="33.33" width="3.5"/>'
        '<edge id="e2" from="B" to="C" numLanes="1" speed="33.33" width="3.5" '
        'shape="500,-3.5 3000,-3.5"/></edges>',
        "--connection-files",
        str(tmp_path / "drop.con.xml"),
    )
    (tmp_path / "drop.rou.xml").write_text(
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
    cfg = tmp_path / "drop.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="drop.net.xml"/><route-files value="drop.rou.xml"/>'
        '</input><time><begin value="0"/><step-length value="0.01"/></time></configuration>'
    )
    summary = run_case(cfg, ScenarioOverrides(mu=0.3), tmp_path / "o")
    modes = summary["modes_visited"]
    assert 1 in modes or 3 in modes
    assert 2 not in modes and 4 not in modes
    assert summary["left_road"] is False
