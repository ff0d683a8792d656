"""traffic.png on real runs: a car halted in the ego's lane and an oncoming car, on a straight
road running south and on a road turning 120 degrees left; and a contact on a straight road
running east. The road users must land in the ego's road frame where the run's own measures
put them: the obstacle's rear the radar's range ahead of the ego's front, the oncoming car a
lane width left, the smallest gaps those of summary.json, the contact at the ego's front."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from eoam_sumo.cli import main
from eoam_sumo.errors import InputError
from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.plotting.roadtracks import ego_road, project_traffic
from eoam_sumo.plotting.run_plots import load_run
from eoam_sumo.plotting.traffic_plots import TRAFFIC_PNG, plot_traffic, read_scene
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.runlog import ROAD_FILE
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.sim.trafficlog import read_traffic
from tests.builders import halted_car_scenario

pytestmark = pytest.mark.sumo
LANE_M = 3.5
CG_TO_FRONT_M = ego_e_class_sedan().cg_to_front_bumper_m


def _two_way(points: list[tuple[float, float]]) -> tuple[str, str]:
    """Nodes and edges of a two-way road of one 3.5 m lane each way along ``points``."""
    shape = " ".join(f"{x:.3f},{y:.3f}" for x, y in points)
    back = " ".join(reversed(shape.split()))
    (x0, y0), (x1, y1) = points[0], points[-1]
    nodes = (
        f'<nodes><node id="a" x="{x0:.3f}" y="{y0:.3f}"/>'
        f'<node id="b" x="{x1:.3f}" y="{y1:.3f}"/></nodes>'
    )
    common = f'numLanes="1" speed="40" spreadType="right" width="{LANE_M}"'
    edges = (
        f'<edges><edge id="fwd" from="a" to="b" {common} shape="{shape}"/>'
        f'<edge id="back" from="b" to="a" {common} shape="{back}"/></edges>'
    )
    return nodes, edges


def _left_turn(radius_m: float, turn_deg: int) -> list[tuple[float, float]]:
    """100 m east, a left arc of ``radius_m`` through ``turn_deg`` (3 degree chords), 300 m on."""
    points = [(0.0, 0.0)]
    for a in range(0, turn_deg + 1, 3):
        r = math.radians(a)
        points.append((100.0 + radius_m * math.sin(r), radius_m * (1.0 - math.cos(r))))
    r = math.radians(turn_deg)
    x, y = points[-1]
    return [*points, (x + 300.0 * math.cos(r), y + 300.0 * math.sin(r))]


def _run(folder: Path, points, obstacle_m, speed_mps, oncoming_m, mu=1.0) -> Path:
    nodes, edges = _two_way(points)
    cfg = halted_car_scenario(folder, nodes, edges, obstacle_m, "--opposites.guess", "true")
    overrides = ScenarioOverrides(ego_speed_mps=speed_mps, oncoming_start_m=oncoming_m, mu=mu)
    run_case(cfg, overrides, folder / "run", RunSettings(max_time_s=20.0))
    return folder / "run"


@pytest.fixture(scope="module")
def southbound(tmp_path_factory) -> Path:
    return _run(tmp_path_factory.mktemp("south"), [(0.0, 0.0), (0.0, -1500.0)], 220.0, 25.0, 250.0)


@pytest.fixture(scope="module")
def curved(tmp_path_factory) -> Path:
    return _run(tmp_path_factory.mktemp("curve"), _left_turn(120.0, 120), 330.0, 20.0, 250.0)


@pytest.fixture(scope="module")
def contact(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("hit")
    return _run(folder, [(0.0, 0.0), (1500.0, 0.0)], 150.0, 30.0, 150.0, mu=0.3)


def _projected(run_dir: Path) -> tuple[dict, pd.DataFrame, pd.DataFrame]:
    summary, ts = load_run(run_dir)
    traffic = project_traffic(read_traffic(run_dir / "traffic.csv"), ego_road(run_dir, ts))
    return summary, ts, traffic


@pytest.mark.parametrize("which", ["southbound", "curved"])
def test_the_obstacle_stands_the_radar_range_ahead_of_the_egos_front(which, request):
    run_dir = request.getfixturevalue(which)
    summary, ts, traffic = _projected(run_dir)
    assert summary["contact_time_s"] is None and summary["final_speed_mps"] < 0.1
    last = ts.dropna(subset=["aro_range_m"]).iloc[-1]
    rows = traffic[(traffic["id"] == "stalled") & np.isclose(traffic["time_s"], last["time_s"])]
    (rear_s,) = rows["s_m"] - 0.5 * rows["length_m"]
    assert rear_s - (last["s_m"] + CG_TO_FRONT_M) == pytest.approx(last["aro_range_m"], abs=0.15)
    assert abs(rows["d_m"].iloc[0]) < 0.3
    if which == "curved":  # the ego has turned through more than 90 degrees by then
        assert last["yaw_rad"] - ts["yaw_rad"].iloc[0] > math.radians(95.0)


@pytest.mark.parametrize("which", ["southbound", "curved"])
def test_the_oncoming_car_runs_one_lane_width_left(which, request):
    _, ts, traffic = _projected(request.getfixturevalue(which))
    onc = traffic[traffic["role"] == "oncoming"]
    ego_s = ts.set_index(ts["time_s"].round(6))["s_m"]
    near = onc[(onc["s_m"] - ego_s.loc[onc["time_s"].round(6)].to_numpy()).abs() < 60.0]
    assert len(near) > 100
    assert near["d_m"].to_numpy() == pytest.approx(LANE_M, abs=0.25)
    assert near["id"].unique().tolist() == ["oncoming"]


@pytest.mark.parametrize("which", ["southbound", "curved"])
def test_the_smallest_gaps_are_the_runs(which, request):
    run_dir = request.getfixturevalue(which)
    summary, ts = load_run(run_dir)
    scene = read_scene(run_dir, summary, ts)
    assert scene.closest["aro"].gap_m == pytest.approx(summary["min_gap_aro_m"], abs=0.01)
    assert scene.closest["oncoming"].gap_m == pytest.approx(summary["min_gap_oncoming_m"], abs=0.01)
    # the halted car pulls up by its type's decel (9 m/s^2 in builders.halted_car_scenario)
    assert [b.vid for b in scene.braking] == ["stalled"]
    assert scene.braking[0].peak_mps2 == pytest.approx(9.0, abs=0.5)


def test_the_road_frame_from_the_egos_samples_agrees_on_the_curve(curved, tmp_path):
    copy = tmp_path / "run"
    shutil.copytree(curved, copy)
    (copy / ROAD_FILE).unlink()
    _, ts, from_file = _projected(curved)
    _, _, from_ego = _projected(copy)
    driven = from_file["s_m"].between(ts["s_m"].min(), ts["s_m"].max())
    cols = ["s_m", "d_m"]
    diff = (from_file[cols] - from_ego[cols])[driven].abs().max()
    assert diff["s_m"] < 0.25 and diff["d_m"] < 0.05


def test_the_contact_point_lies_at_the_egos_front(contact):
    summary, ts = load_run(contact)
    assert summary["collision_with_id"] == "stalled", summary["reason"]
    scene = read_scene(contact, summary, ts)
    s, d = scene.road.project_path(np.array([[summary["contact_x_m"], summary["contact_y_m"]]]))[0]
    at = ts.iloc[(ts["time_s"] - summary["contact_time_s"]).abs().argmin()]
    assert s == pytest.approx(at["s_m"] + CG_TO_FRONT_M, abs=0.5)
    assert abs(d) < 1.0
    assert "aro" not in scene.closest  # the contact is marked as such


def test_eoam_sumo_plot_writes_traffic_png(southbound, curved, contact, tmp_path, capsys):
    assert main(["plot", str(southbound), "--out", str(tmp_path / "cli")]) == 0
    assert str(tmp_path / "cli" / TRAFFIC_PNG) in capsys.readouterr().out.splitlines()
    for k, run_dir in enumerate((southbound, curved, contact)):
        with Image.open(plot_traffic(run_dir, tmp_path / str(k))) as image:
            assert image.size[0] > 1000 and image.size[1] > 1000


@pytest.mark.parametrize(
    "traffic", [None, "", "time_s,id,vclass,role,x_m,y_m,heading_rad,speed_mps,length_m,width_m\n"]
)
def test_without_traffic_the_ego_is_drawn_alone(southbound, tmp_path, traffic):
    copy = tmp_path / "run"
    shutil.copytree(southbound, copy)
    if traffic is None:
        (copy / "traffic.csv").unlink()
    else:
        (copy / "traffic.csv").write_text(traffic)
    summary, ts = load_run(copy)
    scene = read_scene(copy, summary, ts)
    assert set(scene.traffic["role"]) <= {"ego"} and not scene.closest
    assert any("the ego alone" in note for note in scene.notes)
    assert plot_traffic(copy, tmp_path).is_file()


def test_a_damaged_traffic_csv_is_one_line_and_exit_2(southbound, tmp_path, capsys):
    copy = tmp_path / "run"
    shutil.copytree(southbound, copy)
    (copy / "traffic.csv").write_text("time_s,id\n1.0,ego\n")
    with pytest.raises(InputError, match=r"traffic\.csv"):
        plot_traffic(copy, tmp_path)
    assert main(["plot", str(copy), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert "traffic.csv" in err and "\n" not in err


def test_a_row_without_a_whole_footprint_is_left_out(southbound, tmp_path):
    copy = tmp_path / "run"
    shutil.copytree(southbound, copy)
    with (copy / "traffic.csv").open("a") as f:
        f.write(
            "5.0,ghost,passenger,other,10,-50,nan,1,4.5,1.8\n5.0,flat,passenger,other,1,-40,0,1,0,1.8\n"
        )
    summary, ts = load_run(copy)
    scene = read_scene(copy, summary, ts)
    assert not {"ghost", "flat"} & set(scene.traffic["id"])
    assert plot_traffic(copy, tmp_path).is_file()
