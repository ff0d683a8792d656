"""A second car standing in the ego's lane beyond the paper's obstacle (an accident scene, a
queue): the return (mode 5) drove into it at 22.3 m/s, the DMM asking to brake for 1.8 s
(review D3). Now mode 3 brakes at the limit while the return ends on its path."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import straight_road

pytestmark = pytest.mark.sumo


def second_car_scenario(folder, beyond_m: float):
    """The paper's scenario on a one-way two-lane road (``straight_road``): the ego 120 m
    behind the obstacle (60 km/h, holds 2 s, stops at 8 m/s^2, its front then at 278 m), and
    a car standing in the ego's lane with its front ``beyond_m`` beyond that."""
    straight_road(folder, "second", [3.5, 3.5], [2, 2])
    front = 278.0 + beyond_m
    (folder / "second.rou.xml").write_text(
        '<routes><vType id="car" length="4.7" width="1.82" sigma="0"/>'
        '<vType id="van" length="5.09" width="1.99" sigma="0"/>'
        f'<vehicle id="S2" type="car" depart="0" departLane="0" departPos="{front}" '
        'departSpeed="0" insertionChecks="none"><route edges="e0 e1"/>'
        f'<stop lane="e0_0" endPos="{front}" duration="1000"/></vehicle>'
        '<vehicle id="ego" type="car" depart="1" departLane="0" departPos="100" '
        'departSpeed="38.89" insertionChecks="none"><route edges="e0 e1"/></vehicle>'
        '<vehicle id="aro" type="van" depart="1" departLane="0" departPos="225.09" '
        'departSpeed="16.67" insertionChecks="none"><route edges="e0 e1"/>'
        '<param key="eoam.role" value="aro"/><param key="eoam.aro_hold_s" value="2"/>'
        '<param key="eoam.aro_decel_mps2" value="8"/></vehicle></routes>'
    )
    return folder / "second.sumocfg"


@pytest.mark.parametrize("beyond_m", [60.0, 90.0])
def test_the_return_brakes_for_a_car_standing_beyond_the_obstacle(tmp_path, beyond_m):
    """140 km/h, mu 1.0: the lane change passes the obstacle, the return meets the second
    car at 22.3 m/s (60 m) or 18.9 m/s (90 m) without braking. Now the return turns into
    limit braking (mode 3) as the DMM asks, and the ego stops behind it in its own lane."""
    out = tmp_path / "run"
    summary = run_case(
        second_car_scenario(tmp_path, beyond_m),
        ScenarioOverrides(ego_speed_mps=140 / 3.6, mu=1.0),
        out,
        RunSettings(max_time_s=30.0),
    )
    assert summary["collision_with"] == "none", summary["reason"]
    assert summary["modes_visited"] == [0, 1, 2, 5, 3]
    assert summary["final_speed_mps"] == pytest.approx(0.0, abs=0.1)
    # stopped with its body in its own lane (3.5 m wide), on its own path back
    assert abs(summary["final_lateral_offset_m"]) + 0.5 * 1.85 < 0.5 * 3.5
    ts = pd.read_csv(out / "timeseries.csv")
    braking = ts[ts["mode"] == 3]
    assert braking["ax_mps2"].min() < -7.0  # at the limit, not a comfortable stop
    assert (ts["mode"].diff().fillna(0) != 0).sum() == 4  # 0-1-2-5-3, nothing else
