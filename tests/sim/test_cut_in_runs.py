"""A car cutting in ahead and driving on, real SUMO runs: the run finishes (the policy's
predictions are bounded when the two speeds match), and the EOAM follows the car instead of
braking to a standstill behind it on the motorway.

The road: two lanes eastwards, the left one closed to cars after 700 m (beyond the
reach within which the EOAM needs it open), so that a car
inserted in it at 85 km/h moves right at once (SUMO's own lane change), 20 m ahead of the ego
at 120 km/h."""

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
EGO_MPS, CUT_MPS = 120 / 3.6, 85 / 3.6


def cut_in_road(folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "m.nod.xml").write_text(
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="700" y="0"/>'
        '<node id="c" x="3000" y="0"/></nodes>'
    )
    (folder / "m.edg.xml").write_text(
        '<edges><edge id="e1" from="a" to="b" numLanes="2" speed="36.12" width="3.5"/>'
        '<edge id="e2" from="b" to="c" numLanes="2" speed="36.12" width="3.5">'
        '<lane index="1" disallow="passenger"/></edge></edges>'
    )
    netbuild.build_network(folder / "m.nod.xml")
    (folder / "r.rou.xml").write_text(
        '<routes><route id="r" edges="e1 e2"/>'
        '<vehicle id="ego" type="ego" route="r" depart="1.00" departLane="0" '
        f'departPos="100.00" departSpeed="{EGO_MPS:.3f}" insertionChecks="none">'
        '<param key="eoam.role" value="ego"/></vehicle>'
        '<vType id="cut" length="4.70" width="1.82" sigma="0" speedDev="0" '
        f'maxSpeed="{CUT_MPS:.3f}" lcAssertive="5" lcStrategic="10" lcSpeedGain="0" '
        'lcKeepRight="0"/>'
        '<vehicle id="cut" type="cut" route="r" depart="1.00" departLane="1" '
        f'departPos="125.00" departSpeed="{CUT_MPS:.3f}" insertionChecks="none"/></routes>'
    )
    cfg = folder / "m.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="m.net.xml"/><route-files value="r.rou.xml"/>'
        f'<additional-files value="{VTYPES}"/></input></configuration>'
    )
    return cfg


@pytest.mark.parametrize("mu", [0.5, 1.0])
def test_a_car_cutting_in_and_driving_on_is_followed_not_stopped_for(tmp_path, mu):
    cfg = cut_in_road(tmp_path / "road")
    settings = policy_settings(RunSettings(max_time_s=12.0), "safe")
    summary = run_case(cfg, ScenarioOverrides(mu=mu), tmp_path / "out", settings)
    ts = pd.read_csv(tmp_path / "out" / "timeseries.csv")
    assert summary["collision_with"] == "none", summary["reason"]
    modes = set(summary["modes_visited"])
    # braked in its lane: the lane change refused (mode 3), or never asked for where stopping
    # is shorter than clearing at the closing speed (mode 1 alone)
    assert modes & {1, 3} and not modes & {2, 4}
    assert ts["mode"].iloc[-1] == 0  # handed back once the car drove away
    assert ts["vx_mps"].min() > 0.5 * CUT_MPS  # never near a standstill
    assert "stopped" not in summary["reason"]
    assert summary["sight_needed_m"] is None or summary["sight_needed_m"] < 1000.0
