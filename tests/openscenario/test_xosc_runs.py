"""``eoam-sumo run FILE.xosc`` end to end on the shipped real files: Vector's CCRs/CCRm/CCRb
against the protocol's own generated points, openMSL's ALKS 4.3_2 against the speeds its file
writes, and a refusal before anything is written."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from eoam_sumo.cli import main
from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.reader import read_scenario

pytestmark = pytest.mark.sumo

DATA = Path(__file__).parents[1] / "data" / "openscenario"
ALKS = DATA / "alks"
NCAP_RUNS = (
    DATA / "ncap" / "OpenSCENARIO" / "NCAP" / "CA-FC_2026" / "Variations" / "SingleExecution"
)
POINTS = {  # the protocol's point of each file (impact location 50 %, 50 km/h)
    "CCRs": "CCRs_v50_t0_o50_g69p4",
    "CCRm": "CCRm_v50_t20_o50_g69p4",
    "CCRb": "CCRb_v50_t50_o50_g13p9_d4",
}


@pytest.fixture(autouse=True)
def _road_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))


def _summary(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


def _bumper_headway_s(xosc: Path) -> float:
    """Vector's CCRs/CCRm start the target 5 s ahead reference point to reference point, the
    protocol's points 5 s bumper to bumper: the headway that gives the protocol's gap."""
    plan = compile_plan(read_scenario(xosc))
    ego, tgt = plan.bodies["Ego"], plan.bodies["Target"]
    return 5.0 + (ego.front_ahead_m - tgt.rear_ahead_m) / (50 / 3.6)


def test_vector_ccr_files_match_the_protocol_points(tmp_path: Path) -> None:
    """On mu 0.1 the .xosc runs end as the protocol's own points do: the same partner and the
    impact speed within 0.5 km/h; CCRs at least is a real impact (AEB cannot stop from 50 km/h
    on ice within its gap), so the comparison is not one of zeros only."""
    pattern = "^(" + "|".join(POINTS.values()) + ")$"
    out = tmp_path / "protocol"
    argv = ["protocol", "euroncap-aeb-c2c-2026", "--points", pattern, "--mu", "0.1"]
    assert main([*argv, "--out", str(out), "--no-progress"]) == 0
    rows = {r["point_id"]: r for r in csv.DictReader((out / "results.csv").open())}
    for test, point in POINTS.items():
        run, xosc = tmp_path / test, NCAP_RUNS / f"{test}_50kph.xosc"
        argv = ["run", str(xosc), "--system", "aeb", "--mu", "0.1", "--out", str(run)]
        if test != "CCRb":  # CCRb's 1 s gap is bumper to bumper in both
            argv += ["--param", f"Ego_initTimeHeadway={_bumper_headway_s(xosc):.6f}"]
        assert main(argv) == 0
        ours, theirs = _summary(run), rows[point]
        assert abs(ours["impact_speed_mps"] * 3.6 - float(theirs["impact_speed_kmh"])) <= 0.5
        assert ours["collision_with"] == theirs["collision_with"]
    assert float(rows[POINTS["CCRs"]]["impact_speed_kmh"]) > 5.0


def test_alks_emergency_brake_runs_its_storyboard(tmp_path: Path) -> None:
    """4.3_2: the lead holds 60 km/h for 10 s after the start, then stops at 9.81 m/s^2."""
    path = ALKS / "alks_scenario_4_3_2_follow_lead_vehicle_emergency_brake_template.xosc"
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 0
    rows = [
        r
        for r in csv.DictReader((tmp_path / "o" / "traffic.csv").open())
        if r["id"] == "LeadVehicle"
    ]
    assert {r["y_m"] for r in rows} == {"-5.25"}  # lane -4 throughout: no lane change of SUMO's
    lead = [(float(r["time_s"]), float(r["speed_mps"])) for r in rows]
    depart = lead[0][0]
    assert all(v == pytest.approx(60 / 3.6, abs=0.01) for t, v in lead if t < depart + 9.99)
    stop_s = depart + 10.0 + (60 / 3.6) / 9.81
    assert all(v < 0.05 for t, v in lead if t > stop_s + 0.05)
    mid = next(v for t, v in lead if abs(t - (depart + 10.85)) < 0.006)
    assert mid == pytest.approx(60 / 3.6 - 9.81 * 0.85, abs=0.15)
    assert _summary(tmp_path / "o")["collision_with"] == "none"


def test_a_refused_file_writes_nothing(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    path = ALKS / "alks_scenario_4_2_1_fully_blocking_target_template.xosc"
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "<Pedestrian> at " in err and "pedestrian_catalog.xosc" in err
    assert not (tmp_path / "o").exists()


def test_alks_cut_in_runs_its_lane_change_when_the_gap_closes(tmp_path: Path) -> None:
    """4.4_1: the cut-in car (40 km/h, lane -5) starts its sinusoidal lane change (peak 2 m/s)
    when its freespace gap to the 60 km/h ego falls below 30 m, and reaches the ego's lane
    centre pi * 3.5 / (2 * 2) = 2.75 s later."""
    path = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
    out = tmp_path / "o"
    argv = ["run", str(path), "--system", "aeb", "--max-time-s", "16", "--out", str(out)]
    assert main(argv) == 0
    rows = [r for r in csv.DictReader((out / "traffic.csv").open()) if r["id"] == "CutInVehicle"]
    turned = [float(r["time_s"]) for r in rows if float(r["heading_rad"]) != 0.0]
    start, end = turned[0] - 0.01, turned[-1] + 0.01  # turned while it moves across
    assert end - start == pytest.approx(3.5 * 3.14159265 / 4, abs=0.02)
    assert float(rows[-1]["y_m"]) == pytest.approx(-5.25, abs=1e-3)  # on the ego's lane centre
    t0 = f"{start - 0.01:.2f}"  # the step the condition held: the gap of box centres less
    both = [r for r in csv.DictReader((out / "traffic.csv").open()) if r["time_s"] == t0]
    car, ego = sorted(both, key=lambda r: r["id"] == "ego")  # half lengths is the freespace gap
    gap = (
        float(car["x_m"])
        - float(ego["x_m"])
        - (float(car["length_m"]) + float(ego["length_m"])) / 2
    )
    assert gap == pytest.approx(30.0, abs=0.25)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--param", "novalue"], "expected NAME=VALUE"),
        (["--param", "Nope=1"], "--param Nope: no such parameter"),
        (["--speed-kmh", "50"], "--speed-kmh does not apply to an .xosc"),
        (["--ego", "Nobody"], "--ego Nobody: no such entity"),
    ],
)
def test_bad_xosc_options(tmp_path: Path, capsys: pytest.CaptureFixture, argv, needle) -> None:
    path = ALKS / "alks_scenario_4_1_1_free_driving_template.xosc"
    assert main(["run", str(path), *argv, "--out", str(tmp_path / "o")]) == 2
    assert needle in capsys.readouterr().err


def test_alks_free_driving_on_the_curved_road_starts_where_the_file_says(tmp_path: Path) -> None:
    """4.1_1 on its road of changing curvature: the ego departs at 60 km/h on lane -4 at
    s = 5 m (its front bumper 5 + 1.4 + 2.5 m along the SUMO lane)."""
    path = ALKS / "alks_scenario_4_1_1_free_driving_template.xosc"
    out = tmp_path / "o"
    assert main(["run", str(path), "--max-time-s", "2", "--out", str(out)]) == 0
    route = (out / "scenario" / "scenario.rou.xml").read_text()
    assert 'departPos="8.900"' in route and 'departSpeed="16.666667"' in route
    rows = list(csv.DictReader((out / "timeseries.csv").open()))
    assert float(rows[-1]["vx_mps"]) == pytest.approx(60 / 3.6, abs=0.3)


def test_a_stop_trigger_ends_the_run_and_says_so(tmp_path: Path) -> None:
    """The storyboard's StopTrigger (simulation time > 2 s, before the EOAM acts) ends the
    run: ``end_cause`` said ``time_limit`` though no time limit was reached."""
    from tests.openscenario.xosc_cases import STOP, write_case

    path = write_case(tmp_path, (STOP, STOP.replace('value="12"', 'value="2"')))
    assert main(["run", str(path), "--out", str(tmp_path / "o")]) == 0
    summary = _summary(tmp_path / "o")
    assert summary["storyboard_ended"] is True
    assert summary["end_cause"] == "storyboard"
    assert summary["sim_time_s"] == pytest.approx(2.0, abs=0.02)
