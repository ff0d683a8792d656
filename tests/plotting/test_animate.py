"""traffic.csv and ``eoam-sumo animate`` on a real run: the baseline scenario with a person
walking along the ego's lane ahead and an oncoming car; SUMO's own fcd-output of the same
run is the independent record the traffic log is checked against."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from eoam_sumo.cli import main
from eoam_sumo.plotting.animate import ROLE_COLOURS, animate_run
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.sim.trafficlog import TRAFFIC_COLUMNS, read_traffic

pytestmark = pytest.mark.sumo
ROOT = Path(__file__).resolve().parents[2]
STEP_S = 0.01
WALKER = (
    '<person id="walker" depart="1.00" departPos="260"><walk edges="E0" arrivalPos="400"/></person>'
)


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("walker")
    scenarios = ROOT / "scenarios"
    routes = (scenarios / "baseline.rou.xml").read_text().replace("</routes>", WALKER + "</routes>")
    (folder / "walker.rou.xml").write_text(routes)
    (folder / "walker.sumocfg").write_text(
        f'<configuration><input><net-file value="{ROOT / "networks" / "highway.net.xml"}"/>'
        f'<route-files value="{scenarios / "parked.rou.xml"},walker.rou.xml"/>'
        f'<additional-files value="{scenarios / "vtypes.add.xml"},'
        f'{ROOT / "networks" / "highway_parking.add.xml"}"/></input>'
        f'<output><fcd-output value="fcd.xml"/><precision value="6"/></output>'
        "</configuration>"
    )
    run_case(
        folder / "walker.sumocfg",
        ScenarioOverrides(ego_speed_mps=90 / 3.6, oncoming_start_m=300.0),
        folder / "run",
        RunSettings(max_time_s=3.0),
    )
    return folder / "run"


def test_traffic_csv_holds_the_ego_the_parked_cars_and_the_walker(run_dir):
    traffic = read_traffic(run_dir / "traffic.csv")
    assert tuple(traffic.columns) == TRAFFIC_COLUMNS
    ts = pd.read_csv(run_dir / "timeseries.csv")
    ego = traffic[traffic["id"] == "ego"]
    np.testing.assert_array_equal(ego["time_s"].to_numpy(), ts["time_s"].round(6).to_numpy())
    assert set(ego["role"]) == {"ego"}
    parked = traffic[traffic["id"].str.startswith("parked_")]
    assert set(parked["role"]) == {"parked"} and set(parked["speed_mps"]) == {0.0}
    assert parked["id"].nunique() >= 3  # the ones within 250 m of the ego
    walker = traffic[traffic["id"] == "walker"]
    assert len(walker) == len(ego)  # on the road, ahead, in the log at every step
    assert set(walker["vclass"]) == {"pedestrian"}
    assert set(walker["role"]) == {"aro"}  # in the ego's lane, ahead of it
    assert walker["speed_mps"].iloc[1:].between(0.5, 2.0).all()  # walking (from rest)
    assert (np.diff(walker["x_m"]) >= 0.0).all() and walker["x_m"].iloc[-1] > 262.0
    assert set(traffic.loc[traffic["id"] == "aro", "role"]) == {"aro"}
    assert set(traffic.loc[traffic["id"] == "oncoming", "role"]) == {"oncoming"}


def _fcd(path: Path) -> pd.DataFrame:
    rows = [
        (
            round(float(step.get("time")), 3),
            user.get("id"),
            float(user.get("x")),
            float(user.get("y")),
        )
        for step in ET.parse(path).getroot().iter("timestep")
        for user in step
    ]
    return pd.DataFrame(rows, columns=["time_s", "id", "fx", "fy"])


def test_traffic_csv_at_t_is_sumos_fcd_output_at_t_minus_one_step(run_dir):
    """SUMO writes each step's result under the time the step began, the co-simulation logs
    it under SUMO's clock after the step: the front of every road user in traffic.csv at
    t is where fcd-output puts it at t - 0.01 s (the ego's first row aside: the plant starts
    its centre of gravity where SUMO had the body's centre)."""
    traffic = read_traffic(run_dir / "traffic.csv")
    traffic["fx"] = traffic["x_m"] + 0.5 * traffic["length_m"] * np.cos(traffic["heading_rad"])
    traffic["fy"] = traffic["y_m"] + 0.5 * traffic["length_m"] * np.sin(traffic["heading_rad"])
    traffic["time_s"] = traffic["time_s"].round(3)
    fcd = _fcd(run_dir.parent / "fcd.xml")
    first = traffic["time_s"].min()
    for shift, close in ((-STEP_S, True), (0.0, False)):
        at = fcd.assign(time_s=(fcd["time_s"] - shift).round(3))
        both = traffic.merge(at, on=["time_s", "id"], suffixes=("", "_fcd"))
        both = both[~((both["id"] == "ego") & (both["time_s"] == first))]
        gap = np.hypot(both["fx"] - both["fx_fcd"], both["fy"] - both["fy_fcd"])
        assert set(both["id"]) >= {"ego", "aro", "oncoming", "walker", "parked_0"}
        assert (gap.max() < 1e-3) == close, (shift, gap.max())


def test_animate_writes_a_gif_that_follows_the_ego(run_dir, tmp_path):
    out, frames = animate_run(run_dir, tmp_path / "a.gif", fps=8, size_in=(6.0, 2.4), dpi=60)
    assert frames >= 20
    with Image.open(out) as gif:
        assert gif.n_frames == frames
        first = np.asarray(gif.convert("RGB"))
        gif.seek(gif.n_frames - 1)
        last = np.asarray(gif.convert("RGB"))
    blue = np.array([int(ROLE_COLOURS["ego"][k : k + 2], 16) for k in (1, 3, 5)])
    for image in (first, last):  # the ego's box is in every frame
        assert (np.abs(image.astype(int) - blue).sum(axis=2) < 40).sum() > 20
    assert not np.array_equal(first, last)


def test_animate_cli_bad_run_dir_is_one_line_and_exit_2(tmp_path, capsys):
    assert main(["animate", str(tmp_path / "nowhere")]) == 2
    assert main(["animate", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"eoam-sumo: error: {tmp_path / 'nowhere'}: no such run folder",
        f"eoam-sumo: error: {tmp_path}: not a run folder (no summary.json)",
    ]
