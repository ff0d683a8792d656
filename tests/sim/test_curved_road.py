"""A curved road made of several edges, as users' networks are: the ego keeps its lane centre."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import network, straight_road, write_sumocfg

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


def test_lane_width_changes_along_the_route_do_not_throw_the_ego_off(tmp_path):
    """The lane centre shifts by up to 0.6 m at each junction: the ego follows it smoothly
    (not swerving into the next lane at the heading step seen 30 m ahead)."""
    straight_road(tmp_path, "widths", [3.5, 3.0, 4.0, 2.8, 3.5], [1] * 5)
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

    straight_road(tmp_path, "drop", [3.5, 3.5], [2, 1])  # the right lane ends
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


def _arc_road(folder, radius_m: float, length_m: float, two_way: bool = False) -> None:
    """``arc.net.xml``: a left arc of ``radius_m`` and ``length_m``, one 3.5 m lane (edge
    ``fwd``), and with ``two_way`` the opposite lane beside it (edge ``bwd``, ``<neigh>``)."""
    end_x, end_y = (
        radius_m * math.sin(length_m / radius_m),
        radius_m * (1 - math.cos(length_m / radius_m)),
    )
    nodes = f'<nodes><node id="a" x="0" y="0"/><node id="b" x="{end_x:.3f}" y="{end_y:.3f}"/>'
    edge = '<edge id="{}" from="{}" to="{}" numLanes="1" speed="50" width="3.5" shape="{}">'
    fwd = edge.format("fwd", "a", "b", _arc(radius_m, length_m))
    if not two_way:
        network(folder, "arc", nodes + "</nodes>", f"<edges>{fwd}</edge></edges>")
        return
    bwd = edge.format("bwd", "b", "a", _arc(radius_m, length_m, True))
    edges = (
        f'<edges>{fwd}<lane index="0"><neigh lane="bwd_0"/></lane></edge>'
        f'{bwd}<lane index="0"><neigh lane="fwd_0"/></lane></edge></edges>'
    )
    network(folder, "arc", nodes + "</nodes>", edges)


def test_a_queue_on_a_600_m_curve_at_130_kmh_is_stopped_for(tmp_path):
    """A 600 m left curve at 130 km/h on mu 1.0, a car halted in the ego's lane and one beside
    it in the opposite lane (no lane to change into): first seen at the radar's 100 m, which
    is inside the curve's braking boundary (the lateral 2.2 m/s^2 takes part of the friction
    ellipse and, without ABS, the inner wheels lock sooner: B0 x 1.07). The ego brakes at
    once and stops short; with the straight road's boundaries it braked 3 m later and hit at
    2.5 m/s."""
    radius, length, pos = 600.0, 1000.0, 600.0
    _arc_road(tmp_path, radius, length, two_way=True)
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
    _arc_road(tmp_path, radius, length)
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
