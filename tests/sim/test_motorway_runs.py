"""The EOAM on a 3-lane one-way motorway at 130 km/h, real SUMO runs: a car 20 m
ahead brakes at 10 m/s^2; the safe policy passes it when the left lane is known free, and
keeps out of the way of a faster car coming up the left lane from behind."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo import netbuild
from eoam_sumo.sim.cosim import policy_settings, run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings

pytestmark = pytest.mark.sumo

ROOT = Path(__file__).resolve().parents[2]
VTYPES = ROOT / "scenarios" / "vtypes.add.xml"
SPEED_MPS = 130 / 3.6
NODES = '<nodes><node id="a" x="0" y="0"/><node id="b" x="3000" y="0"/></nodes>'
EDGES = '<edges><edge id="mw" from="a" to="b" numLanes="3" speed="36.12" width="3.5"/></edges>'


def motorway(folder: Path, ego_lane: int = 1, others: str = "", edges: str = EDGES) -> Path:
    """The motorway (built by netbuild), the ego at 130 km/h in lane ``ego_lane``, 100 m from
    the start; the ARO 20 m ahead at the same speed, braking at 10 m/s^2 after 0.5 s;
    ``others``: more vehicles (route ``r``)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "m.nod.xml").write_text(NODES)
    (folder / "m.edg.xml").write_text(edges)
    netbuild.build_network(folder / "m.nod.xml")
    v = f"{SPEED_MPS:.4f}"
    (folder / "r.rou.xml").write_text(
        f'<routes><route id="r" edges="mw"/>'
        f'<vehicle id="ego" type="ego" route="r" depart="1.00" departLane="{ego_lane}" '
        f'departPos="100.00" departSpeed="{v}" insertionChecks="none">'
        '<param key="eoam.role" value="ego"/></vehicle>'
        f'<vehicle id="aro" type="aro" route="r" depart="1.00" departLane="{ego_lane}" '
        f'departPos="125.09" departSpeed="{v}" insertionChecks="none">'
        '<param key="eoam.role" value="aro"/><param key="eoam.aro_hold_s" value="0.5"/>'
        '<param key="eoam.aro_decel_mps2" value="10.0"/></vehicle>'
        f"{others}</routes>"
    )
    cfg = folder / "m.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="m.net.xml"/><route-files value="r.rou.xml"/>'
        f'<additional-files value="{VTYPES}"/></input></configuration>'
    )
    return cfg


def car(vid: str, lane: int, front_pos_m: float, speed_mps: float) -> str:
    """A car that keeps its lane and speed (no lane changes)."""
    return (
        f'<vType id="t_{vid}" length="4.70" width="1.82" sigma="0" speedDev="0" maxSpeed="60" '
        'lcStrategic="-1" lcKeepRight="0" lcSpeedGain="0" lcCooperative="-1"/>'
        f'<vehicle id="{vid}" type="t_{vid}" route="r" depart="1.00" departLane="{lane}" '
        f'departPos="{front_pos_m}" departSpeed="{speed_mps}" insertionChecks="none"/>'
    )


def run(cfg: Path, out: Path, policy: str, v2x_m: float = 0.0) -> tuple[dict, pd.DataFrame]:
    settings = policy_settings(RunSettings(max_time_s=20.0), policy, v2x_m)
    summary = run_case(cfg, ScenarioOverrides(), out, settings)
    return summary, pd.read_csv(out / "timeseries.csv")


@pytest.mark.parametrize("v2x_m", [0.0, 1000.0])
def test_the_safe_policy_passes_a_car_braking_hard_20_m_ahead(tmp_path, v2x_m):
    cfg = motorway(tmp_path / "road")
    safe, ts = run(cfg, tmp_path / "safe", "safe", v2x_m)
    assert safe["sight_gate"] == "passed", safe["reason"]
    assert 2 in safe["modes_visited"] and 3 not in safe["modes_visited"]
    assert safe["collision_with"] == "none" and safe["outcome"] == "green", safe["reason"]
    assert ts["lateral_offset_m"].max() > 2.5  # into the left lane and past


def test_a_faster_car_coming_up_the_left_lane_is_never_touched_and_named(tmp_path):
    # its front 11 m behind the ego's rear, at 40 m/s; the ego in the right lane (no lane on
    # its right to evade into)
    behind = car("fast", 1, 100.0 - 4.92 - 11.0, 40.0)
    cfg = motorway(tmp_path / "road", ego_lane=0, others=behind)
    for v2x_m in (0.0, 1000.0):
        safe, _ = run(cfg, tmp_path / f"safe{v2x_m:g}", "safe", v2x_m)
        assert safe["collision_with"] in ("none", "aro"), safe["reason"]
        assert safe["sight_gate"] == "refused"
        # the ego braking in mode 1, the car has come alongside by the commit
        assert "a road user beside the ego in the target lane" in safe["reason"]
        assert "oncoming" not in safe["reason"]


LEFT_CARS = {
    "alongside": car("left", 2, 100.0, SPEED_MPS),  # its front beside the ego's, as fast
    "coming up": car("left", 2, 100.0 - 4.92 - 11.0, 40.0),  # 11 m behind, faster
}


@pytest.mark.parametrize("left", sorted(LEFT_CARS))
@pytest.mark.parametrize(("policy", "v2x_m"), [("paper", 0.0), ("safe", 0.0), ("safe", 1000.0)])
def test_with_the_left_lane_taken_the_eoam_evades_right_and_passes(tmp_path, policy, v2x_m, left):
    cfg = motorway(tmp_path / "road", others=LEFT_CARS[left])
    summary, ts = run(cfg, tmp_path / policy, policy, v2x_m)
    assert summary["collision_with"] == "none", summary["reason"]
    assert summary["outcome"] == "green", summary["reason"]
    assert 2 in summary["modes_visited"] and 3 not in summary["modes_visited"]
    assert ts["lateral_offset_m"].min() < -2.5  # into the right lane and past
    assert ts["lateral_offset_m"].max() < 0.5  # never towards the car on the left
    assert not summary["left_road"]


def test_a_right_lane_the_ego_may_not_use_is_never_chosen(tmp_path):
    closed = EDGES.replace(
        'width="3.5"/>', 'width="3.5"><lane index="0" disallow="passenger"/></edge>'
    )
    cfg = motorway(tmp_path / "road", others=LEFT_CARS["alongside"], edges=closed)
    summary, ts = run(cfg, tmp_path / "safe", "safe", 1000.0)
    assert ts["lateral_offset_m"].min() > -0.5  # not into the right lane
    assert summary["sight_gate"] == "refused"
    assert "a road user" in summary["reason"] and "in the target lane" in summary["reason"]
