"""Generated scenarios: the same seed writes the same files, and they run."""

from __future__ import annotations

import json

import pytest

from eoam_sumo.cli import main
from eoam_sumo.traffic_levels.build import write_scenario
from eoam_sumo.traffic_levels.spec import TrafficSpec

pytestmark = pytest.mark.sumo


def _files(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def test_the_same_seed_writes_identical_files(tmp_path):
    spec = TrafficSpec("rural", "B", curve_radius_m=400.0, seed=7)
    write_scenario(spec, tmp_path / "one")
    write_scenario(spec, tmp_path / "two")
    one, two = _files(tmp_path / "one"), _files(tmp_path / "two")
    assert set(one) >= {"scenario.sumocfg", "scenario.rou.xml", "road.net.xml", "scenario.json"}
    assert one == two
    write_scenario(TrafficSpec("rural", "B", curve_radius_m=400.0, seed=8), tmp_path / "three")
    assert _files(tmp_path / "three")["scenario.rou.xml"] != one["scenario.rou.xml"]


@pytest.mark.parametrize(
    "args",
    [
        ["motorway", "--los", "C", "--lanes", "3"],
        ["rural", "--los", "B", "--curve-radius-m", "400"],
    ],
)
def test_a_generated_scenario_runs(tmp_path, args, capsys):
    assert main(["scenario", *args, "--out", str(tmp_path / "scn")]) == 0
    record = json.loads((tmp_path / "scn" / "scenario.json").read_text())
    assert record["measured"]["level"] == args[2]
    cfg = tmp_path / "scn" / "scenario.sumocfg"
    assert main(["run", str(cfg), "--out", str(tmp_path / "run"), "--max-time-s", "20"]) == 0
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["outcome"] in ("green", "yellow", "orange", "red", "unfinished")
    assert summary["ego_initial_speed_mps"] > 0.0
