"""Run plots drawn from the scenario, on a real run of a road with 3.0 m lanes, a friction
patch of 0.2 from x = 150 m and an oncoming car of the route file: the friction is the
patch's, the lane change's lines are those of 3.0 m lanes, the traffic is named."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from matplotlib.figure import Figure

from eoam_sumo import netbuild
from eoam_sumo.plotting.batch_plots import _CaseFacts, _panel
from eoam_sumo.plotting.run_plots import load_run, plot_run, run_title
from eoam_sumo.plotting.runfacts import manoeuvre_mu
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.sim.trafficlog import read_traffic

pytestmark = pytest.mark.sumo
SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
LANE_M, PATCH_MU = 3.0, 0.2


def _patch_scenario(folder: Path) -> Path:
    (folder / "patch.nod.xml").write_text(
        '<nodes><node id="w" x="0" y="0"/><node id="m" x="150" y="0"/>'
        '<node id="e" x="3000" y="0"/></nodes>'
    )
    edges = []
    for eid, frm, to, mu in (("E0a", "w", "m", 1.0), ("E0b", "m", "e", PATCH_MU)):
        edges.append(
            f'<edge id="{eid}" from="{frm}" to="{to}" numLanes="1" speed="50" '
            f'width="{LANE_M}"><lane index="0" friction="{mu}">'
            f'<neigh lane="-{eid}_0"/></lane></edge>'
            f'<edge id="-{eid}" from="{to}" to="{frm}" numLanes="1" speed="50" '
            f'width="{LANE_M}"><lane index="0" friction="{mu}">'
            f'<neigh lane="{eid}_0"/></lane></edge>'
        )
    (folder / "patch.edg.xml").write_text(f"<edges>{''.join(edges)}</edges>")
    netbuild.build_all(folder)
    (folder / "patch.rou.xml").write_text(
        '<routes><vehicle id="ego" type="ego" depart="0" departLane="0" departPos="100" '
        'departSpeed="25" insertionChecks="none"><route edges="E0a E0b"/></vehicle>'
        '<vehicle id="aro" type="aro" depart="0" departLane="0" departPos="75.09" '
        'departSpeed="16.666667" insertionChecks="none"><route edges="E0b"/>'
        '<param key="eoam.role" value="aro"/><param key="eoam.aro_hold_s" value="1.0"/>'
        '<param key="eoam.aro_decel_mps2" value="8.0"/></vehicle>'
        '<vehicle id="westbound" type="oncoming" depart="0" departLane="0" departPos="2500" '
        'departSpeed="20" insertionChecks="none"><route edges="-E0b -E0a"/></vehicle>'
        "</routes>"
    )
    cfg = folder / "patch.sumocfg"
    cfg.write_text(
        f'<configuration><input><net-file value="patch.net.xml"/>'
        f'<route-files value="patch.rou.xml"/><additional-files value="'
        f'{SCENARIOS / "vtypes.add.xml"}"/></input></configuration>'
    )
    return cfg


@pytest.fixture(scope="module")
def patch_run(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("patch")
    cfg = _patch_scenario(folder)
    run_case(cfg, ScenarioOverrides(), folder / "run", RunSettings(max_time_s=12.0))
    return folder / "run"


def test_the_contact_point_lies_between_the_ego_and_the_obstacle(patch_run):
    summary, _ = load_run(patch_run)
    assert summary["collision_with"] == "aro"
    traffic = read_traffic(patch_run / "traffic.csv")
    at = traffic[traffic["time_s"] == traffic["time_s"].max()].set_index("id")
    ego, aro = at.loc["ego"], at.loc["aro"]
    # a rear-end hit: the point is at the ego's front and the obstacle's back
    assert summary["contact_x_m"] == pytest.approx(ego["x_m"] + 0.5 * ego["length_m"], abs=0.2)
    assert summary["contact_x_m"] == pytest.approx(aro["x_m"] - 0.5 * aro["length_m"], abs=0.2)
    assert abs(summary["contact_y_m"] - ego["y_m"]) < 0.5 * ego["width_m"]


def test_plots_use_the_friction_the_manoeuvre_ran_on(patch_run, tmp_path):
    summary, ts = load_run(patch_run)
    assert summary["mu"] == 1.0  # under the ego at its departure
    assert manoeuvre_mu(summary, ts) == (PATCH_MU, "under the ego when the manoeuvre began")
    title = run_title(summary, ts, patch_run)
    assert title.startswith(f"90 km/h, μ = {PATCH_MU}, oncoming traffic:")
    pngs = plot_run(patch_run, tmp_path)
    assert sorted(p.name for p in pngs) == [
        "dynamics.png",
        "gg.png",
        "phase_trace.png",
        "steering.png",
    ]


def test_lateral_offset_lines_are_those_of_the_run_lanes(patch_run):
    summary, _ = load_run(patch_run)
    assert summary["lane_width_m"] == pytest.approx(LANE_M)
    rows = pd.DataFrame({"status": ["ok"], "case_dir": [patch_run.name], "outcome": ["x"]})
    ax = Figure().add_subplot()
    _panel(ax, patch_run.parent, rows, lambda r: "run", "Blues", _CaseFacts(patch_run.parent))
    levels = sorted(line.get_ydata()[0] for line in ax.lines[2:])  # after the run and its end
    assert levels == pytest.approx([0.3 * LANE_M, LANE_M])
    texts = [t.get_text() for t in ax.texts]
    assert " next lane centre (3.00 m lane)" in texts
    assert " point of no return (0.3 x 3.00 m)" in texts
