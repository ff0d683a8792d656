"""Real SUMO co-simulation runs of small scenarios."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.params import G_MPS2
from eoam_sumo.sim.cosim import run_case
from eoam_sumo.sim.runlog import COLUMNS
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import (
    BASELINE,
    PARKED_ONLY,
    baseline_variant,
    halted_car_scenario,
    netconvert,
    write_sumocfg,
)

CONTRACT_COLUMNS = [
    "time_s",
    "mode",
    "fcw",
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "ax_mps2",
    "ay_mps2",
    "steer_rad",
    "ax_target_mps2",
    "y_target_m",
    "aro_range_m",
    "aro_range_rate_mps",
]
SUMMARY_KEYS = [
    "outcome",
    "collision_with",
    "impact_speed_mps",
    "modes_visited",
    "fcw_raised",
    "mu",
    "min_gap_aro_m",
    "max_abs_lat_accel_mps2",
    "sim_time_s",
    "wall_time_s",
]


def _run(cfg, tmp_path, eoam=None, **over):
    settings = RunSettings(max_time_s=over.pop("max_time_s", 30.0), eoam=eoam or EoamSettings())
    out = tmp_path / "run"
    summary = run_case(cfg, ScenarioOverrides(**over), out, settings)
    return summary, out


@pytest.mark.sumo
def test_parked_cars_only_trigger_nothing(tmp_path):
    summary, out = _run(PARKED_ONLY, tmp_path, ego_speed_mps=120 / 3.6, mu=1.0, max_time_s=12.0)
    assert summary["outcome"] == "none"
    assert summary["collision_with"] == "none"
    assert summary["modes_visited"] == [0]
    assert summary["fcw_raised"] is False
    ts = pd.read_csv(out / "timeseries.csv")
    assert ts["aro_range_m"].isna().all(), "a parked car was reported in the ego's path"
    assert ts["mode"].dropna().eq(0).all()


@pytest.mark.sumo
def test_165_kmh_dry_no_oncoming_is_green_with_return_and_hand_back(tmp_path):
    # (at 120 km/h the ego now brakes to a stop: the obstacle's hard stop is seen early)
    summary, out = _run(BASELINE, tmp_path, ego_speed_mps=165 / 3.6, mu=1.0)
    assert summary["outcome"] == "green", summary["reason"]
    modes = summary["modes_visited"]
    assert 2 in modes and 5 in modes
    assert modes[0] == 0 and summary["fcw_raised"] is True
    ts = pd.read_csv(out / "timeseries.csv")
    # handed back: NORMAL again after RETURN, back in the own lane centre
    assert ts["mode"].dropna().iloc[-1] == 0
    assert abs(ts["lateral_offset_m"].iloc[-1]) < 0.3
    assert ts["lateral_offset_m"].max() > 3.0  # it really went into the next lane
    assert summary["max_abs_lat_accel_mps2"] <= 1.1 * 1.0 * G_MPS2
    # contract of the files
    for col in CONTRACT_COLUMNS:
        assert col in ts.columns
    assert list(ts.columns) == list(COLUMNS)
    saved = json.loads((out / "summary.json").read_text())
    for key in SUMMARY_KEYS:
        assert key in saved
    assert saved["mu"] == pytest.approx(1.0)
    assert saved["min_gap_aro_m"] > 0.0
    # loss-of-control measures of a normal lane change
    assert saved["left_road"] is False
    assert 0.05 < saved["max_abs_heading_error_rad"] < 0.3
    assert 15.0 < saved["min_speed_mps"] <= saved["final_speed_mps"]
    # one row per SUMO step of 10 ms
    assert ts["time_s"].diff().dropna().round(6).eq(0.01).all()


@pytest.mark.sumo
def test_120_kmh_dry_oncoming_300_m_is_not_red(tmp_path):
    summary, _ = _run(BASELINE, tmp_path, ego_speed_mps=120 / 3.6, mu=1.0, oncoming_start_m=300.0)
    assert summary["outcome"] in {"green", "yellow", "orange"}, summary["reason"]
    assert summary["outcome"] != "red"


def _write_user_scenario(folder: Path) -> Path:
    """A scenario unlike ours: other ids, 3.2 m lanes, friction in the net, a halted car."""
    netconvert(
        folder,
        "road",
        textwrap.dedent("""\
            <nodes>
              <node id="west" x="0" y="50"/>
              <node id="east" x="2500" y="50"/>
            </nodes>"""),
        textwrap.dedent("""\
            <edges>
              <edge id="main_fwd" from="west" to="east" numLanes="1" speed="40" width="3.2"
                    spreadType="right"/>
              <edge id="main_back" from="east" to="west" numLanes="1" speed="40" width="3.2"
                    spreadType="right"/>
            </edges>"""),
        "--opposites.guess",
        "true",
        "--no-turnarounds",
        "true",
    )
    (folder / "cars.rou.xml").write_text(
        textwrap.dedent("""\
        <routes>
          <vType id="sedan" length="4.8" width="1.8" accel="3" decel="9" sigma="0"/>
          <vType id="truck" length="8.0" width="2.4" accel="1" decel="6" sigma="0"/>
          <route id="r" edges="main_fwd"/>
          <vehicle id="broken_down" type="truck" route="r" depart="0" departPos="400"
                   departSpeed="0">
            <stop lane="main_fwd_0" endPos="408" duration="1000"/>
          </vehicle>
          <vehicle id="ego" type="sedan" route="r" depart="0" departPos="150"
                   departSpeed="25"/>
        </routes>""")
    )
    return write_sumocfg(
        folder / "user.sumocfg", "road.net.xml", "cars.rou.xml", step_length_s=0.01
    )


@pytest.mark.sumo
def test_user_scenario_with_halted_car_gets_a_sensible_outcome(tmp_path):
    cfg = _write_user_scenario(tmp_path)
    summary, out = _run(cfg, tmp_path, mu=0.7, max_time_s=30.0)
    # the halted truck is seen, a manoeuvre is made and nothing is hit at speed
    assert summary["fcw_raised"] is True
    assert summary["outcome"] in {"green", "yellow"}, summary["reason"]
    assert summary["modes_visited"][0] == 0 and len(summary["modes_visited"]) > 1
    ts = pd.read_csv(out / "timeseries.csv")
    assert ts["aro_range_m"].notna().any()
    assert summary["mu"] == pytest.approx(0.7)


@pytest.mark.sumo
def test_oncoming_seen_past_the_point_of_no_return_passes_the_aro_and_returns(tmp_path):
    """120 km/h, mu 0.3, oncoming car 420 m away, the point-of-no-return rule: seen after the
    point of no return (mode 4); the ego returns once past the ARO, long before the manoeuvre
    timer, and is back in its lane before the oncoming car arrives. (At 400 m the ego, which
    follows its lane-change plan closely, is seen further out and ends in a side contact with
    the oncoming car, docs/manoeuvre.md; by default the EOAM compares passing with aborting:
    tests/sim/test_oncoming_choice_runs.py.)"""
    summary, out = _run(
        BASELINE,
        tmp_path,
        EoamSettings(compare_outcomes=False),
        ego_speed_mps=120 / 3.6,
        mu=0.3,
        oncoming_start_m=420.0,
    )
    assert summary["modes_visited"] == [0, 1, 2, 4, 5], summary["reason"]
    assert summary["outcome"] == "green", summary["reason"]
    ts = pd.read_csv(out / "timeseries.csv")
    t2, t4, t5 = (ts.loc[ts["mode"] == m, "time_s"].iloc[0] for m in (2, 4, 5))
    assert t4 - t2 > 0.5 and t5 - t2 < 0.6 * 8.0
    assert ts["lateral_offset_m"].max() < 3.5 + 0.3


@pytest.mark.sumo
def test_radar_range_option_limits_what_is_sensed(tmp_path):
    """``--radar-range-m`` reaches the radar: the ARO is first reported near that range."""
    firsts = {}
    for rng in (60.0, 100.0):
        out = tmp_path / f"r{rng:.0f}"
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "eoam_sumo",
                "run",
                str(BASELINE),
                "--speed-kmh",
                "90",
                "--mu",
                "1.0",
                "--out",
                str(out),
                "--max-time-s",
                "6",
                "--radar-range-m",
                str(rng),
            ],
            check=False,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert proc.returncode == 0, proc.stderr
        ts = pd.read_csv(out / "timeseries.csv")
        firsts[rng] = ts["aro_range_m"].dropna().iloc[0]
    assert 60.0 - 1.0 < firsts[60.0] <= 60.0
    assert 100.0 - 1.0 < firsts[100.0] <= 100.0


@pytest.mark.sumo
def test_cli_run_prints_one_line_and_writes_files(tmp_path):
    out = tmp_path / "cli"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "eoam_sumo",
            "run",
            str(BASELINE),
            "--speed-kmh",
            "90",
            "--mu",
            "1.0",
            "--out",
            str(out),
            "--max-time-s",
            "25",
        ],
        check=False,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert len(proc.stdout.strip().splitlines()) == 1
    assert (out / "timeseries.csv").is_file() and (out / "summary.json").is_file()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["outcome"] in {"green", "yellow", "orange", "red", "none"}
    assert math.isfinite(summary["sim_time_s"])


@pytest.mark.parametrize(
    "args, needle",
    [
        (["run", "missing.sumocfg"], "missing.sumocfg"),
        (["run", str(BASELINE), "--mu", "1.5"], "1.5"),
        (["run", str(BASELINE), "--speed-kmh", "400"], "400"),
        (["run", str(BASELINE), "--oncoming-m", "-5"], "-5"),
        (["run", str(BASELINE), "--bogus"], "--bogus"),
        (["run", str(BASELINE), "--radar-range-m", "-5"], "--radar-range-m"),
    ],
)
def test_cli_bad_input_is_one_line_and_status_2(tmp_path, args, needle):
    proc = subprocess.run(
        [sys.executable, "-m", "eoam_sumo", *args, "--out", str(tmp_path / "o")],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    assert proc.returncode == 2
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and needle in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.sumo
def test_same_input_gives_identical_files(tmp_path):
    over = {"ego_speed_mps": 90 / 3.6, "mu": 0.7, "oncoming_start_m": 400.0}
    runs = []
    for name in ("a", "b"):
        out = tmp_path / name
        run_case(BASELINE, ScenarioOverrides(**over), out, RunSettings(max_time_s=20.0))
        summary = json.loads((out / "summary.json").read_text())
        for timing in ("wall_time_s", "realtime_factor"):
            summary.pop(timing)
        runs.append((summary, (out / "timeseries.csv").read_bytes()))
    assert runs[0][0] == runs[1][0]
    assert runs[0][1] == runs[1][1]


@pytest.mark.sumo
def test_traci_path_gives_the_libsumo_result(tmp_path):
    """The --gui loop runs through TraCI; checked here with the plain sumo binary."""
    over = ScenarioOverrides(ego_speed_mps=120 / 3.6, mu=1.0)
    fast = run_case(BASELINE, over, None, RunSettings(max_time_s=20.0))
    slow = run_case(BASELINE, over, None, RunSettings(max_time_s=20.0, use_traci=True))
    for key in ("outcome", "collision_with", "modes_visited", "fcw_raised", "sim_time_s"):
        assert fast[key] == slow[key]
    assert fast["max_abs_lat_accel_mps2"] == pytest.approx(slow["max_abs_lat_accel_mps2"], 1e-6)


@pytest.mark.sumo
def test_no_lane_to_the_left_means_braking_in_lane(tmp_path):
    cfg = halted_car_scenario(
        tmp_path,
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="1500" y="0"/></nodes>',
        '<edges><edge id="fwd" from="a" to="b" numLanes="1" speed="40"/></edges>',
        220.0,
    )
    summary, _ = _run(cfg, tmp_path, mu=1.0, max_time_s=25.0)
    assert summary["fcw_raised"] is True
    assert not {2, 4, 5} & set(summary["modes_visited"]), summary["modes_visited"]
    assert summary["max_lateral_offset_m"] < 0.5
    assert summary["outcome"] in {"green", "yellow"}, summary["reason"]


@pytest.mark.sumo
def test_curved_two_way_road(tmp_path):
    """A 400 m radius left-hand curve: the road frame follows it; a halted car is avoided."""
    shape = " ".join(
        f"{400 * math.sin(a):.3f},{400 * (1 - math.cos(a)):.3f}"
        for a in [i * 0.02 for i in range(101)]
    )
    end = f'x="{400 * math.sin(2.0):.3f}" y="{400 * (1 - math.cos(2.0)):.3f}"'
    cfg = halted_car_scenario(
        tmp_path,
        f'<nodes><node id="a" x="0" y="0"/><node id="b" {end}/></nodes>',
        f'<edges><edge id="fwd" from="a" to="b" numLanes="1" speed="40" spreadType="right" '
        f'shape="{shape}"/><edge id="back" from="b" to="a" numLanes="1" speed="40" '
        f'spreadType="right" shape="{" ".join(reversed(shape.split()))}"/></edges>',
        250.0,
        "--opposites.guess",
        "true",
    )
    summary, out = _run(cfg, tmp_path, mu=1.0, max_time_s=25.0)
    assert summary["fcw_raised"] is True
    assert summary["outcome"] in {"green", "yellow"}, summary["reason"]
    ts = pd.read_csv(out / "timeseries.csv")
    # before anything is seen, the ego keeps its lane on the curve
    calm = ts[ts["mode"] == 0].head(50)
    assert calm["lateral_offset_m"].abs().max() < 0.2


# a 120 m left curve from (200, 0) to (320, 120), a point every 10 degrees
ICE_CURVE = " ".join(
    f"{200 + 120 * math.sin(math.radians(a)):.2f},{120 * (1 - math.cos(math.radians(a))):.2f}"
    for a in range(0, 91, 10)
)


@pytest.mark.sumo
def test_ice_patch_road_departure_is_orange_not_green(tmp_path):
    """Dry road, then mu 0.05 on a 120 m left curve from x = 200 m: at 30 m/s (7.5 m/s^2 asked,
    0.5 given) the ego slides off the road to the right: orange, not green."""
    netconvert(
        tmp_path,
        "n",
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="200" y="0"/>'
        '<node id="c" x="320" y="120"/><node id="d" x="320" y="1500"/></nodes>',
        '<edges><edge id="dry" from="a" to="b" numLanes="2" speed="40"/>'
        '<edge id="ice" from="b" to="c" numLanes="2" speed="40" friction="0.05" '
        f'shape="{ICE_CURVE}"/>'
        '<edge id="end" from="c" to="d" numLanes="2" speed="40"/></edges>',
        "--no-turnarounds",
        "true",
    )
    (tmp_path / "r.rou.xml").write_text(
        textwrap.dedent("""\
        <routes>
          <vType id="car" length="4.6" width="1.8" decel="9" sigma="0"/>
          <route id="r" edges="dry ice end"/>
          <vehicle id="ego" type="car" route="r" depart="0" departPos="20" departSpeed="30"/>
        </routes>""")
    )
    cfg = write_sumocfg(tmp_path / "s.sumocfg", "n.net.xml", "r.rou.xml")
    summary, out = _run(cfg, tmp_path, max_time_s=20.0)
    assert summary["mu"] == pytest.approx(1.0)  # dry where the ego starts
    assert (summary["outcome"], summary["collision_with"]) == ("orange", "none"), summary
    assert summary["left_road"] is True
    assert "left the road" in summary["reason"] and "right edge" in summary["reason"]
    ts = pd.read_csv(out / "timeseries.csv")
    lane_width = 3.2  # netconvert's default
    assert ts["lateral_offset_m"].min() < -0.5 * lane_width - 0.5
    assert ts["mu"].min() == pytest.approx(0.05)
    # the summary's extremes agree with the logged steps
    e = (ts["heading_error_rad"] + math.pi) % math.tau - math.pi
    assert summary["max_abs_heading_error_rad"] == pytest.approx(e.abs().max(), abs=1e-6)
    assert summary["min_speed_mps"] == pytest.approx(ts["vx_mps"].min(), abs=1e-6)
    assert summary["max_lateral_offset_m"] == pytest.approx(
        ts["lateral_offset_m"].iloc[:-1].abs().max(), abs=1e-6
    )


def test_the_run_log_grows_to_its_limit_and_no_further():
    """A huge time limit costs nothing up front; rows past the limit are not kept."""
    from eoam_sumo.eoam import EgoMeasurement
    from eoam_sumo.sim.runlog import PREALLOCATED_ROWS, RunLog

    def meas(t):
        return EgoMeasurement(t, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 3.5)

    x = [0.0] * 19
    big = RunLog(10**12, (0.6, 0.4))
    for k in range(PREALLOCATED_ROWS + 5):
        big.add(meas(0.01 * k), x, None, None, 1.0)
    assert big.array().shape == (PREALLOCATED_ROWS + 5, len(COLUMNS))
    assert big.column("time_s")[-1] == pytest.approx(0.01 * (PREALLOCATED_ROWS + 4))
    small = RunLog(5, (0.6, 0.4))
    for k in range(8):
        small.add(meas(float(k)), x, None, None, 1.0)
    assert small.array().shape == (5, len(COLUMNS))


@pytest.mark.sumo
def test_a_car_standing_in_the_next_lane_turns_the_steer_into_braking(tmp_path):
    """Cars parked in the opposite lane just beyond the ARO: the lane change would end against
    them, so the EOAM brakes in lane (mode 3) instead of hitting them (orange)."""
    spaces = "".join(
        f'<space x="{x:.2f}" y="2.60" angle="270.00" length="4.30" width="1.80"/>'
        for x in (250.0, 262.0, 274.0)
    )
    (tmp_path / "park.add.xml").write_text(
        '<additional><parkingArea id="pa" lane="-E0_0" startPos="3500" endPos="3900" '
        f'roadsideCapacity="0" friendlyPos="true">{spaces}</parkingArea></additional>'
    )
    parked = "".join(
        f'<vehicle id="p{k}" type="parked" route="w" depart="0" departPos="stop" '
        'insertionChecks="none"><stop parkingArea="pa" parking="true" until="1000000"/>'
        "</vehicle>"
        for k in range(3)
    )
    cfg = baseline_variant(
        tmp_path,
        "<routes>",
        f'<routes><route id="w" edges="-E0"/>{parked}',
        extra_additional="park.add.xml",
    )
    summary, _ = _run(cfg, tmp_path, ego_speed_mps=120 / 3.6, mu=1.0)
    assert 3 in summary["modes_visited"] and 2 not in summary["modes_visited"]
    assert summary["collision_with"] in ("none", "aro")
    assert summary["outcome"] in ("green", "yellow")


@pytest.mark.sumo
def test_the_ego_may_be_a_vehicle_with_a_scripted_stop(tmp_path):
    """`--ego aro`: its stop parameters are ignored (the plant drives it), so it stays in the
    simulation."""
    out = tmp_path / "aro-ego"
    summary = run_case(
        BASELINE,
        ScenarioOverrides(ego_speed_mps=20.0, mu=1.0),
        out,
        RunSettings(max_time_s=3.0, ego_id="aro"),
    )
    assert summary["ego_initial_speed_mps"] == pytest.approx(20.0)
    assert summary["sim_time_s"] > 0.0


@pytest.mark.sumo
def test_a_second_manoeuvre_soon_after_a_hand_back_runs_to_its_end(tmp_path):
    """An ARO braking gently on a wet road (mu 0.3): the EOAM brakes, hands back, then has to
    change lanes; the run must not stop 2 s after the first hand-back, in the middle of the
    lane change. (With a plain cruise control after the hand-back: following the ARO, the ego
    never needs the second manoeuvre; ``test_after_a_hand_back_the_object_ahead_sets_the_speed``.
    On a dry road the second approach's closing speed is below where stopping is shorter than
    clearing, so the DMM brakes again: no lane change to cut short.)"""
    cfg = baseline_variant(
        tmp_path,
        '<param key="eoam.aro_decel_mps2" value="8.0"/>',
        '<param key="eoam.aro_decel_mps2" value="1.0"/>',
    )
    cruise = EoamSettings(follow_after_brake=False)
    summary, _ = _run(cfg, tmp_path, cruise, ego_speed_mps=120 / 3.6, mu=0.3, max_time_s=40.0)
    assert summary["modes_visited"][:3] == [0, 1, 2]
    assert abs(summary["final_lateral_offset_m"]) < 0.5
    assert "returned to lane" in summary["reason"]


@pytest.mark.sumo
def test_after_a_hand_back_the_object_ahead_sets_the_speed(tmp_path):
    """The same gently braking ARO with the default settings: after mode 1 hands back, the
    ego follows it (its speed target at most the ARO's plus the gap error) instead of
    speeding up towards its 120 km/h set speed and braking again."""
    cfg = baseline_variant(
        tmp_path,
        '<param key="eoam.aro_decel_mps2" value="8.0"/>',
        '<param key="eoam.aro_decel_mps2" value="1.0"/>',
    )
    summary, out = _run(cfg, tmp_path, ego_speed_mps=120 / 3.6, mu=1.0, max_time_s=40.0)
    assert summary["collision_with"] == "none", summary["reason"]
    assert summary["modes_visited"] == [0, 1]
    ts = pd.read_csv(out / "timeseries.csv")
    back = ts[(ts["mode"] == 0) & (ts["time_s"] > ts.loc[ts["mode"] == 1, "time_s"].max())]
    back = back.dropna(subset=["speed_target_mps", "aro_range_m"])  # the end row has none
    assert len(back) > 0
    # the ARO's speed from the radar: ego speed + range rate; never set above it by more
    # than the gap error closed in 3 s, and far below the set speed
    aro_speed = back["vx_mps"] + back["aro_range_rate_mps"]
    assert (back["speed_target_mps"] <= aro_speed + back["aro_range_m"] / 3.0 + 1e-6).all()
    assert back["speed_target_mps"].max() < 0.5 * 120 / 3.6


@pytest.mark.sumo
def test_a_vehicle_overlapping_the_ego_at_its_departure_is_bad_input(tmp_path):
    from eoam_sumo.errors import InputError

    cfg = baseline_variant(tmp_path, 'departPos="225.09"', 'departPos="102.00"')
    with pytest.raises(InputError, match="vehicle 'aro' overlaps the ego at its departure"):
        _run(cfg, tmp_path, ego_speed_mps=120 / 3.6, mu=1.0)


@pytest.mark.sumo
def test_at_10_kmh_the_eoam_brakes_to_a_stop_without_steering(tmp_path):
    """Below the tables' 20 km/h the design range's floor admits the run and the DMM only
    brakes (docs/design-choices.md, "Low speed"): a car halted 25 m ahead on a two-lane road,
    the ego at 10 km/h, stops short in its lane; no lane-change or return mode is visited."""
    cfg = halted_car_scenario(
        tmp_path,
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="400" y="0"/></nodes>',
        '<edges><edge id="fwd" from="a" to="b" numLanes="2" speed="30"/></edges>',
        50.0,
    )
    summary, _ = _run(cfg, tmp_path, ego_speed_mps=10.0 / 3.6, mu=1.0, max_time_s=20.0)
    assert summary["collision_with"] == "none", summary["reason"]
    assert 1 in summary["modes_visited"]
    assert not {2, 3, 4, 5} & set(summary["modes_visited"]), summary["modes_visited"]
    assert summary["max_lateral_offset_m"] < 0.2
    assert 0.0 < summary["min_gap_aro_m"] < 5.0  # stopped short, within about the 2 m buffer


@pytest.mark.sumo
@pytest.mark.parametrize("length_m", [None, 20.0])
def test_the_ego_starts_with_its_front_bumper_at_its_depart_pos(tmp_path, length_m):
    """SUMO departs a vehicle with its front at ``departPos`` (100 m on the baseline's
    straight east-bound edge from x = 0); the plant's centre of gravity starts
    ``cg_to_front_bumper_m`` behind it, whatever the length of the route file's vType (the
    box is resized to the plant's), so the gap to the obstacle is the scenario's."""
    from eoam_sumo.params import ego_e_class_sedan

    old, new = '<vehicle id="ego" type="ego"', '<vehicle id="ego" type="ego"'
    if length_m is not None:
        new = f'<vType id="ego_long" length="{length_m}"/>\n    <vehicle id="ego" type="ego_long"'
    cfg = baseline_variant(tmp_path, old, new)
    _summary, out = _run(cfg, tmp_path, ego_speed_mps=90 / 3.6, mu=1.0, max_time_s=0.05)
    first = pd.read_csv(out / "timeseries.csv").iloc[0]
    assert first["x_m"] + ego_e_class_sedan().cg_to_front_bumper_m == pytest.approx(100.0, abs=1e-6)
