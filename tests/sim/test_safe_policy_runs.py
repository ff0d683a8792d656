"""The safe policy in real SUMO runs: oncoming cars seen too late, slow road users in the
opposite lane, and the gate opening only when the lane is known free."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.params import LANE_CHANGE_HEIGHT_M, PONR_FRACTION
from eoam_sumo.sim.cosim import RunSettings, policy_settings, run_case
from eoam_sumo.sim.scenario import ScenarioOverrides

pytestmark = pytest.mark.sumo

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "scenarios"
BASELINE = SCENARIOS / "baseline.sumocfg"
PONR_M = PONR_FRACTION * LANE_CHANGE_HEIGHT_M  # the point of no return on 3.5 m lanes
SAFE_OUTCOMES = ("green", "yellow")
#: A van creeping west at 1.5 m/s in the opposite lane beside where the ARO stops.
VAN = ('<vType id="van" vClass="delivery" length="5.50" width="2.00" maxSpeed="1.50" '
       'sigma="0" speedDev="0"/><route id="west" edges="-E0"/>'
       '<vehicle id="van" type="van" route="west" depart="1.00" departPos="{pos}" '
       'departSpeed="1.50" insertionChecks="none"/>')


def _scenario(tmp_path: Path, *, van_x_m: float | None = None,
              speed_limit_mps: float | None = None) -> Path:
    """The baseline scenario, optionally with the van (front bumper at x = ``van_x_m``) and
    the road's speed limit changed."""
    net = ROOT / "networks" / "highway.net.xml"
    if speed_limit_mps is not None:
        text = net.read_text().replace('speed="50.00"', f'speed="{speed_limit_mps:.2f}"')
        net = tmp_path / "road.net.xml"
        net.write_text(text)
    routes = (SCENARIOS / "baseline.rou.xml").read_text()
    if van_x_m is not None:
        routes = routes.replace("<routes>", "<routes>" + VAN.format(pos=4000.0 - van_x_m), 1)
    (tmp_path / "r.rou.xml").write_text(routes)
    cfg = tmp_path / "s.sumocfg"
    cfg.write_text(
        f'<configuration><input><net-file value="{net}"/><route-files value="'
        f'{SCENARIOS / "parked.rou.xml"},r.rou.xml"/><additional-files value="'
        f'{SCENARIOS / "vtypes.add.xml"},{ROOT / "networks" / "highway_parking.add.xml"}"/>'
        '</input></configuration>')
    return cfg


def _run(cfg, tmp_path, name, policy="paper", v2x_range_m=0.0, **over):
    settings = policy_settings(RunSettings(max_time_s=30.0), policy, v2x_range_m)
    out = tmp_path / name
    summary = run_case(cfg, ScenarioOverrides(**over), out, settings)
    return summary, pd.read_csv(out / "timeseries.csv")


def test_an_oncoming_car_first_seen_past_the_point_of_no_return_on_mu_03(tmp_path):
    over = {"ego_speed_mps": 165 / 3.6, "mu": 0.3, "oncoming_start_m": 400.0}
    paper, ts = _run(BASELINE, tmp_path, "paper", **over)
    seen = ts[ts["oncoming_detected"].astype(bool)]
    assert 2 in paper["modes_visited"] and len(seen)
    assert seen["lateral_offset_m"].iloc[0] > PONR_M  # the radar saw it too late
    for v2x in (0.0, 500.0):
        safe, ts = _run(BASELINE, tmp_path, f"safe{v2x:g}", "safe", v2x, **over)
        assert safe["outcome"] in SAFE_OUTCOMES, safe["reason"]
        assert safe["collision_with"] in ("none", "aro")
        assert 2 not in safe["modes_visited"] and 3 in safe["modes_visited"]
        assert safe["sight_gate"] == "refused"
        assert safe["sight_needed_m"] > safe["sight_known_free_m"]
        assert ts["lateral_offset_m"].abs().max() < PONR_M  # braked in its lane


@pytest.mark.parametrize("mu", [1.0, 0.3])
def test_a_van_creeping_in_the_opposite_lane_beside_the_obstacle_is_not_hit(tmp_path, mu):
    cfg = _scenario(tmp_path, van_x_m=300.0)
    over = {"ego_speed_mps": 120 / 3.6, "mu": mu}
    _paper, ts = _run(cfg, tmp_path, "paper", **over)
    assert not ts["oncoming_detected"].any()  # neither standing nor oncoming for the radar
    for v2x in (0.0, 500.0):
        safe, _ = _run(cfg, tmp_path, f"safe{v2x:g}", "safe", v2x, **over)
        assert safe["outcome"] in SAFE_OUTCOMES, safe["reason"]
        assert safe["collision_with"] in ("none", "aro")
        assert 2 not in safe["modes_visited"]


def test_v2x_opens_the_gate_on_a_free_road_and_a_slow_van_closes_it(tmp_path):
    """A 90 km/h road (25 m/s limit), the ego at 120 km/h: with every road user equipped and
    a 1000 m range the lane is known free far enough for the lane change; a van at 1.5 m/s
    in the opposite lane 260 m ahead of the ego blocks it, by the length it leaves free."""
    over = {"ego_speed_mps": 120 / 3.6, "mu": 1.0}
    free, _ = _run(_scenario(tmp_path, speed_limit_mps=25.0), tmp_path, "free", "safe",
                   1000.0, **over)
    assert free["sight_gate"] == "passed"
    assert free["sight_known_free_m"] >= free["sight_needed_m"]
    assert 2 in free["modes_visited"] and free["outcome"] == "green"
    van_dir = tmp_path / "van"
    van_dir.mkdir()
    cfg = _scenario(van_dir, van_x_m=360.0, speed_limit_mps=25.0)
    blocked, _ = _run(cfg, tmp_path, "blocked", "safe", 1000.0, **over)
    assert blocked["sight_gate"] == "refused"
    assert blocked["sight_known_free_m"] < blocked["sight_needed_m"]
    assert blocked["sight_known_free_m"] < 260.0  # limited by the van, not by the range
    assert 2 not in blocked["modes_visited"]
    assert blocked["collision_with"] in ("none", "aro")
