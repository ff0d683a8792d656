"""The protocols: scoring rules on hand-made rows (independent truth: the published bands of
Euro NCAP's rating code and its own tests' worked examples, copied by hand below), the test
grids, and tiny protocol runs (determinism; the aeb system never steers)."""

from __future__ import annotations

import math
import subprocess
import sys

import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.protocols import rules, scoring
from eoam_sumo.protocols.impact import Measured, longitudinal_closing_mps, warning_lead_s
from eoam_sumo.protocols.points import (
    PROTOCOLS,
    offset_2023_m,
    offset_2026_m,
    protocol_points,
)

SEDAN_WIDTH_M = 1.85


@pytest.mark.parametrize(
    ("ego_kmh", "impact_kmh", "colour"),
    [
        (10, 0.0, "green"),
        (10, 0.1, "red"),
        (30, 0.0, "green"),
        (30, 10.0, "brown"),
        (30, 10.01, "red"),
        (40, 5.0, "orange"),
        (40, 20.0, "brown"),
        (40, 25.0, "red"),
        (50, 10.0, "yellow"),
        (80, 15.0, "orange"),
        (130, 30.0, "brown"),
        (130, 30.5, "red"),
    ],
)
def test_ccr_colour_bands(ego_kmh, impact_kmh, colour):
    assert rules.ncap_colour("CCRm", ego_kmh, impact_kmh) == colour


def test_points_by_colour_and_range():
    assert [rules.cell_points(c, extended=False) for c in rules.COLOURS] == [
        1.0,
        0.75,
        0.5,
        0.25,
        0.0,
    ]
    assert rules.cell_points("brown", extended=True) == 1.0
    assert rules.cell_points("red", extended=True) == 0.0
    assert rules.cell_points(rules.NOT_RUN, extended=False) == 0.0


def test_test_score_weights_the_ranges_and_bands_the_extended_one():
    # CCRs: 1.2 standard, 0.15 extended; two standard cells (1, 0.5), two extended (1, 0):
    # the extended mean 0.5 is exactly the 50 % band
    score = rules.test_score("CCRs", [(1.0, False), (0.5, False), (1.0, True), (0.0, True)])
    assert score.standard == pytest.approx(1.2 * 0.75)
    assert score.extended == pytest.approx(0.15 * 0.5)
    assert score.max_total == pytest.approx(1.5)  # the robustness layer's 0.15 included
    # three extended cells of four: 75 %; two of three: 66.7 % -> the 50 % band
    assert rules.test_score("CCRs", [(1.0, True)] * 3 + [(0.0, True)]).extended == pytest.approx(
        0.75 * 0.15
    )
    assert rules.test_score("CCRs", [(1.0, True)] * 2 + [(0.0, True)]).extended == pytest.approx(
        0.5 * 0.15
    )


# The rating code's own tests (Euro-NCAP/euroncap_rating_2026@94b1035,
# tests/crash_avoidance/test_band_gate_stability.py), restated: the real extended totals
# 0.25 (binary exact) and 0.15 (not), each edge exact and 1 ulp below, 1 ulp above the total.
@pytest.mark.parametrize("total", [0.25, 0.15])
def test_extended_band_as_the_rating_code_tests_it(total):
    assert rules.extended_band(0.0, total) == 0
    for share in (0.5, 0.75, 1.0):
        assert rules.extended_band(share * total, total) == share * total
        assert rules.extended_band(math.nextafter(share * total, 0), total) == share * total
    assert rules.extended_band(math.nextafter(total, 1), total) == total
    assert rules.extended_band(0.49 * total, total) == 0
    assert rules.extended_band(0.6 * total, total) == 0.5 * total
    assert rules.extended_band(0.9 * total, total) == 0.75 * total
    assert rules.extended_band(0, 0.0) == 0.0


def test_ccfhos_half_green_extended_snaps_to_half_its_total():
    # the same file: CCFhos, 14 extended cells, 7 green and 7 red -> 0.125
    cells = [(1.0, True)] * 7 + [(0.0, True)] * 7 + [(1.0, False)] * 18
    assert rules.test_score("CCFhos", cells).extended == 0.125


# tests/crash_avoidance/test_impact_speed_tolerance.py: the true colours (no tolerance) of
# FC v1.2 sec. 4.2.4's worked table, the 60 km/h matrix (green 0, yellow <= 10, orange
# <= 20, brown <= 30, red above), and the CCFhos reduction of 11 km/h: orange.
@pytest.mark.parametrize(
    ("value", "colour"),
    [
        (0.0, "green"),
        (1.9, "yellow"),
        (2.0, "yellow"),
        (8.0, "yellow"),
        (12.0, "orange"),
        (22.0, "brown"),
        (27.9, "brown"),
        (28.1, "brown"),
        (32.0, "red"),
        (40.0, "red"),
    ],
)
def test_true_colours_of_the_worked_table(value, colour):
    assert rules.ncap_colour("CCRm", 60, value) == colour


def test_ccfhos_reduction_of_11_is_orange():
    assert rules.ncap_colour("CCFhos", 50, 11.0) == "orange"


def test_round_half_up_as_excel():
    assert rules.round_half_up(0.075, 2) == 0.08  # binary 0.07499..., half-even gives 0.07
    assert rules.round_half_up(2.675, 2) == 2.68
    assert rules.round_half_up(0.4749999999999999, 3) == 0.475
    assert rules.round_half_up(-0.5, 0) == -1.0  # ties away from zero
    assert rules.round_half_up(10.004, 2) == 10.0


def test_impact_speed_rounded_to_001_before_banding():
    # 50 km/h row: yellow up to 10.00, orange above
    assert rules.ncap_colour("CCRm", 50, 10.004) == "yellow"  # 10.00
    assert rules.ncap_colour("CCRm", 50, 10.005) == "orange"  # 10.01


def test_fc_gate_every_standard_ccrs_cell_at_10_and_20_green():
    cells = [("CCRs", v, ext, "green", f"p{v}{ext}") for v in (10, 20, 30) for ext in (0, 1)]
    assert rules.fc_gate(cells) == (True, [])
    red_extended = [*cells, ("CCRs", 10, True, "red", "x")]
    assert rules.fc_gate(red_extended)[0]  # an extended cell does not count
    assert rules.fc_gate([*cells, ("CCRs", 30, False, "red", "y")]) == (True, [])  # 30 km/h
    not_run = [*cells, ("CCRs", 10, False, rules.NOT_RUN, "z")]
    assert rules.fc_gate(not_run) == (False, ["z"])


def test_the_car_target_fc_maximum_is_24_points():
    assert pytest.approx(24.0) == rules.CAR_FC_MAX
    assert sum(rules.weight_total(t) for t in ("CCRs", "CCRm", "CCRb", "CCFhos")) == (
        pytest.approx(9.0)
    )


@given(st.floats(0.0, 130.0), st.floats(0.0, 130.0))
def test_ccfhos_points_never_fall_as_the_reduction_grows(a, b):
    low, high = sorted((a, b))
    for extended in (False, True):
        before = rules.cell_points(rules.mitigation_colour(low), extended)
        assert rules.cell_points(rules.mitigation_colour(high), extended) >= before


def test_longitudinal_relative_impact_speed():
    # the CCRs_v30_o50 run: 5.356 m/s at 0.47 rad into a stationary target
    closing = longitudinal_closing_mps(5.356, 0.0, -0.47, 0.0, 0.0)
    assert closing * 3.6 == pytest.approx(5.356 * math.cos(0.47) * 3.6)
    assert 17.0 < closing * 3.6 < 17.5
    # behind a target at 20 km/h: the difference; head-on: the sum
    assert longitudinal_closing_mps(15.0, 0.0, 0.0, 5.0, 0.0) == pytest.approx(10.0)
    assert longitudinal_closing_mps(10.0, 0.0, 0.0, 8.0, math.pi) == pytest.approx(18.0)


def test_warning_lead_over_the_braking():
    times = [0.0, 0.1, 0.2, 0.3, 0.4]
    assert warning_lead_s(times, [0, 1, 1, 1, 1], [0, 0, 0, 1, 1]) == pytest.approx(0.2)
    assert warning_lead_s(times, [0] * 5, [0, 0, 0, 1, 1]) is None


# UN R152 00 series, para. 5.2.1.4, "Maximum relative impact speed (km/h) for M1 vehicles",
# copied by hand: relative speed -> (maximum mass / laden, mass in running order / unladen)
R152_BY_HAND = {40: (0, 0), 42: (10, 0), 45: (15, 15), 50: (25, 25), 55: (30, 30), 60: (35, 35)}


def test_r152_table_as_published():
    for rel, limits in R152_BY_HAND.items():
        assert rules.R152_M1_TABLE_KMH[float(rel)] == limits
    assert all(rules.R152_M1_TABLE_KMH[float(v)] == (0, 0) for v in range(10, 40, 5))
    assert rules.R152_LIMITS_KMH[("stationary", 42.0)] == 0.0  # the unladen column
    assert ("moving", 45.0) not in rules.R152_LIMITS_KMH  # subject 65 km/h: out of range


@pytest.mark.parametrize(
    ("test", "ego_kmh", "impact_kmh", "verdict"),
    [
        ("R152-stationary", 42, 0.0, "pass"),
        ("R152-stationary", 42, 4.0, "fail"),  # 10 allowed laden, 0 unladen
        ("R152-stationary", 45, 15.0, "pass"),
        ("R152-stationary", 60, 35.5, "fail"),
        ("R152-moving", 60, 0.0, "pass"),
        ("R152-moving", 60, 1.0, "fail"),
    ],
)
def test_r152_rows_from_impact_speeds(test, ego_kmh, impact_kmh, verdict):
    point = next(
        p
        for p in protocol_points(PROTOCOLS[2], SEDAN_WIDTH_M)
        if p.test == test and p.ego_speed_kmh == ego_kmh
    )
    facts = scoring.RunFacts(fcw_raised=True)
    assert scoring.point_row(point, _hit(impact_kmh), "", facts)["verdict"] == verdict


def _hit(impact_kmh: float, lead_s: float = 1.0) -> Measured:
    """A braking run that hit at ``impact_kmh`` (0: no contact), warned ``lead_s`` ahead."""
    return Measured(impact_kmh > 0, impact_kmh, None, lead_s, True)


def test_r152_a_run_that_leaves_its_lane_or_warns_late_fails():
    point = protocol_points(PROTOCOLS[2], SEDAN_WIDTH_M)[4]
    kept = scoring.point_row(point, _hit(0.0), "", scoring.RunFacts(fcw_raised=True))
    assert kept["verdict"] == "pass"
    left = scoring.RunFacts(left_lane=True, fcw_raised=True)
    assert scoring.point_row(point, _hit(0.0), "", left)["verdict"] == "fail"
    late = scoring.point_row(point, _hit(0.0, 0.5), "", scoring.RunFacts(fcw_raised=True))
    assert (late["verdict"], late["warning"]) == ("fail", "fail")
    silent = scoring.point_row(point, _hit(0.0), "", scoring.RunFacts())
    assert silent["warning"] == "fail"
    assert rules.left_lane(False, 0.9, 3.5, 1.85) and not rules.left_lane(False, 0.8, 3.5, 1.85)


def test_failure_cause_names_the_never_triggered_point():
    row = {"status": "ok", "note": "", "modes_visited": "0", "test": "CCFhos", "reason": "x"}
    assert scoring.failure_cause(row) == f"{scoring.NO_TRIGGER}; run: x"
    failed = {"status": "failed", "error": "boom", "test": "CCRs"}
    assert scoring.failure_cause(failed) == "the run failed: boom"


def test_abs_and_esc_are_switched_on_the_vehicle_and_carried_by_every_case(tmp_path):
    from eoam_sumo.batch.case import case_vehicle
    from eoam_sumo.protocols.command import vehicle_params
    from eoam_sumo.protocols.runner import _case

    assert vehicle_params("sedan").width_m == SEDAN_WIDTH_M
    params = vehicle_params("sedan", abs_mode="on", esc_mode="off")
    assert params.abs_fitted is True and params.esc_fitted is False
    point = protocol_points("unr152", SEDAN_WIDTH_M)[0]
    case = _case(point, tmp_path / "x.sumocfg", "paper", 1.0, 40.0, "sedan", params)
    assert case_vehicle(case) == params and case.steering_inhibited  # aeb by default
    eoam = _case(point, tmp_path / "x.sumocfg", "paper", 1.0, 40.0, "sedan", params, "eoam")
    assert not eoam.steering_inhibited
    suv = vehicle_params("suv", abs_mode="off")
    case = _case(point, tmp_path / "x.sumocfg", "paper", 1.0, 40.0, "suv", suv)
    assert case.vehicle == "suv" and case_vehicle(case) == suv and not suv.abs_fitted


def test_a_vut_whose_tables_are_missing_is_refused_in_one_line(tmp_path):
    """The paper's sedan with ABS needs tables of its own (tables/sedan-abs/): the ABS
    braking limit is the plant's; an empty tables folder has none."""
    import shutil

    from eoam_sumo.errors import InputError
    from eoam_sumo.offline.tables import default_tables_dir
    from eoam_sumo.protocols.command import vehicle_params
    from eoam_sumo.protocols.runner import run_protocol

    base = tmp_path / "tables"
    base.mkdir()
    for path in default_tables_dir().iterdir():
        if path.is_file():
            shutil.copy(path, base)
    points = protocol_points("unr152", SEDAN_WIDTH_M)[:1]
    with pytest.raises(InputError, match=r"sedan-abs: no lookup tables.*--abs on"):
        run_protocol(
            "unr152",
            points,
            tmp_path / "out",
            params=vehicle_params("sedan", "on"),
            tables_dir=base,
        )


def test_r152_verdicts():
    assert rules.r152_verdict(None, 0.0)[0] == "pass"
    assert rules.r152_verdict(None, 5.0)[0] == "undetermined"
    assert rules.r152_verdict(10.0, 5.0)[0] == "pass"
    assert rules.r152_verdict(10.0, 12.0)[0] == "fail"


def test_point_rows_from_impact_speeds():
    point = next(
        p
        for p in protocol_points(PROTOCOLS[1], SEDAN_WIDTH_M)
        if p.test == "CCRm" and p.ego_speed_kmh == 60 and p.overlap == 50
    )
    row = scoring.point_row(point, _hit(12.0))
    assert (row["colour"], row["points"], row["manoeuvre"]) == ("orange", 0.5, "B")
    steered = scoring.point_row(point, _hit(0.0), "", scoring.RunFacts(steered=True))
    assert (steered["colour"], steered["manoeuvre"]) == ("green", "S")
    not_run = scoring.point_row(point, None, "why")
    assert (not_run["colour"], not_run["points"], not_run["note"]) == ("not_run", 0.0, "why")
    head_on = next(p for p in protocol_points(PROTOCOLS[1], SEDAN_WIDTH_M) if p.head_on)
    stopped = Measured(True, head_on.target_speed_kmh, 0.0, 1.0, True)
    assert scoring.point_row(head_on, stopped)["colour"] == "green"  # a full stop
    unscored = scoring.point_row(protocol_points(PROTOCOLS[0], SEDAN_WIDTH_M)[0], _hit(5.0))
    assert unscored["colour"] == scoring.UNSCORED and math.isnan(unscored["points"])


def test_totals_of_one_system_and_policy_stay_within_the_maximum():
    points = protocol_points(PROTOCOLS[1], SEDAN_WIDTH_M)
    rows = [
        {**scoring.point_row(p, _hit(0.0)), "point_id": p.point_id}
        for p in points
        if p.ego_speed_kmh >= 20
    ]
    rows += [
        {**scoring.point_row(p, None, "below"), "point_id": p.point_id}
        for p in points
        if p.ego_speed_kmh < 20
    ]
    t = scoring.fc_totals(rows)
    assert t["max_run"] == pytest.approx(11.5) and t["max_protocol"] == pytest.approx(24.0)
    # every point run green: the robustness layer (1.375) is not assessed; the 10 km/h
    # CCRs row not run: 5 of 40 standard cells (-0.15), 2 of 16 extended (14/16 = 87.5 %,
    # banded to 75 %: -0.0375), and the gate fails
    assert t["points_before_gate"] == pytest.approx(10.35 - 0.15 - 0.0375)
    assert not t["gate_passed"] and t["points"] == 0.0


def test_grids():
    p2026 = protocol_points(PROTOCOLS[1], SEDAN_WIDTH_M)
    tests = ("CCRs", "CCRm", "CCRb", "CCFhos", "CCFhol")
    count = {t: sum(p.test == t for p in p2026) for t in tests}
    assert count == {"CCRs": 8 * 7, "CCRm": 11 * 7, "CCRb": 11 * 7, "CCFhos": 32, "CCFhol": 32}
    # the rating code's EXTENDED_RANGE_CELLS of CCFhos and CCFhol: the first column (100 %)
    # and the last two rows, 14 cells each
    for test in ("CCFhos", "CCFhol"):
        assert sum(p.extended for p in p2026 if p.test == test) == 14
    assert len({p.point_id for p in p2026}) == len(p2026)
    # CCFhos starts 8 s of closing apart (Vector's startupTime): 50/50 km/h -> 222.2 m
    assert next(p.gap_m for p in p2026 if p.test == "CCFhos" and p.ego_speed_kmh == 50) == (
        pytest.approx(8.0 * 100 / 3.6, abs=1e-3)
    )
    p2023 = protocol_points(PROTOCOLS[0], SEDAN_WIDTH_M)
    assert sum(p.test == "CCRb" for p in p2023) == 4
    # Vector's 2023 head-on variations: both cars at 50 or 70 km/h, the target centred
    for test in ("CCFhos", "CCFhol"):
        head_on = [(p.ego_speed_kmh, p.offset_m) for p in p2023 if p.test == test]
        assert head_on == [(50, 0.0), (70, 0.0)]
    r152 = protocol_points(PROTOCOLS[2], SEDAN_WIDTH_M)
    # the M1 table's 12 relative speeds against a stationary target; against a target at
    # 20 km/h those up to a subject speed of 60 km/h (para. 5.2.1.3): 10-40 km/h, 7 rows
    assert sum(p.test == "R152-stationary" for p in r152) == 12
    moving = [p.ego_speed_kmh for p in r152 if p.test == "R152-moving"]
    assert moving == [30, 35, 40, 45, 50, 55, 60]


def test_offsets():
    assert offset_2023_m(100, SEDAN_WIDTH_M) == 0.0
    assert offset_2023_m(-50, SEDAN_WIDTH_M) == pytest.approx(-1.712 / 2)
    assert offset_2026_m(50, SEDAN_WIDTH_M) == 0.0
    assert offset_2026_m(125, SEDAN_WIDTH_M) == pytest.approx(0.75 * SEDAN_WIDTH_M)


@pytest.mark.parametrize(
    ("option", "value", "named"),
    [("--vehicle", "truck", "truck"), ("--abs", "yes", "yes"), ("--esc", "maybe", "maybe")],
)
def test_bad_input_is_one_line_and_status_2(tmp_path, option, value, named):
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "eoam_sumo",
            "protocol",
            "unr152",
            "--out",
            str(tmp_path),
            option,
            value,
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and named.lower() in done.stderr.lower()


@pytest.mark.sumo
def test_the_same_protocol_twice_gives_the_same_results(tmp_path):
    def run(out):
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "eoam_sumo",
                "protocol",
                "unr152",
                "--out",
                str(out),
                "--points",
                "R152m(stationary_v(10|30)|moving_v50)",
                "--no-progress",
            ],
            capture_output=True,
            text=True,
            check=False,
        )
        assert done.returncode == 0, done.stderr
        frame = pd.read_csv(out / "results.csv")
        return frame.drop(columns=["wall_time_s", "realtime_factor"])

    first, second = run(tmp_path / "a"), run(tmp_path / "b")
    pd.testing.assert_frame_equal(first, second)
    assert list(first["status"]) == ["ok", "ok", "ok"]  # 10 km/h too: the design range's
    assert "Not run" not in (tmp_path / "a" / "scorecard.md").read_text()
    assert not math.isnan(first["impact_speed_kmh"].iloc[1])
    assert set(first["system"]) == {"aeb"}
    # the step each point ran at: the study default, as the batch's own rows say
    batch = pd.read_csv(tmp_path / "a" / "batch" / "results.csv")
    assert list(first["sumo_step_s"]) == [0.05] * 3 == list(batch["sumo_step_s"])


@pytest.mark.sumo
def test_aeb_brakes_in_lane_where_the_eoam_changes_lanes(tmp_path):
    """CCRs 60 km/h at 50 % (where limit braking needs more room than the lane change): the
    EOAM changes lanes (S); with --system aeb it brakes in its lane (B: no lane-change mode,
    no time in the next lane) and stops short."""

    def run(system):
        out = tmp_path / system
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "eoam_sumo",
                "protocol",
                "euroncap-aeb-c2c-2026",
                "--out",
                str(out),
                "--points",
                "^CCRs_v60_t0_o50_",
                "--system",
                system,
                "--no-progress",
            ],
            capture_output=True,
            text=True,
            check=False,
        )
        assert done.returncode == 0, done.stderr
        return pd.read_csv(out / "results.csv").iloc[0]

    aeb, eoam = run("aeb"), run("eoam")
    assert aeb["manoeuvre"] == "B" and aeb["time_in_next_lane_s"] == 0.0
    assert not {"2", "4"} & set(str(aeb["modes_visited"]).split("-"))
    assert eoam["manoeuvre"] == "S"


def test_run_facts_read_the_batch_text_columns():
    """The batch's results hold booleans as text: "False" is no departure, no warning."""
    from eoam_sumo.protocols.runner import _facts

    run = {
        "modes_visited": "0-1",
        "time_in_next_lane_s": 0.0,
        "left_road": "False",
        "max_lateral_offset_m": 0.0,
        "lane_width_m": 3.5,
        "fcw_raised": "False",
    }
    assert _facts(run, SEDAN_WIDTH_M) == scoring.RunFacts(False, False, False)
    run |= {"left_road": "True", "fcw_raised": "True", "modes_visited": "0-2"}
    assert _facts(run, SEDAN_WIDTH_M) == scoring.RunFacts(True, True, True)


def test_every_protocol_point_is_in_the_design_range_the_10_kmh_ones_included():
    """The design range starts at 5 km/h (``MIN_ENTRY_SPEED_KMH``): the runner's floor for the
    sedan is 5 km/h, below the tables' 20 km/h, so no point of any protocol is left not run,
    the 2026 CCRs cells at 10 km/h (the FC gate's) included."""
    from eoam_sumo.offline.tables import MIN_ENTRY_SPEED_KMH
    from eoam_sumo.params import ego_e_class_sedan
    from eoam_sumo.protocols.runner import _design_low_kmh
    from eoam_sumo.vehicle_files import DEFAULT_VEHICLE

    params = ego_e_class_sedan()
    low = _design_low_kmh(None, DEFAULT_VEHICLE, params)
    assert low == MIN_ENTRY_SPEED_KMH == 5.0
    for name in PROTOCOLS:
        speeds = [p.ego_speed_kmh for p in protocol_points(name, params.width_m)]
        assert min(speeds) >= low, name
    ccrs_10 = [
        p
        for p in protocol_points(PROTOCOLS[1], params.width_m)
        if p.test == "CCRs" and p.ego_speed_kmh == 10.0
    ]
    assert len(ccrs_10) == 7


@pytest.mark.sumo
def test_an_r152_run_that_leaves_its_lane_fails(tmp_path):
    """R152 at 50 km/h against a stopped car: the eoam system changes lanes and avoids it with
    its warning in time; leaving its lane alone makes the row fail (para. 5.2.1.4 is a speed
    reduction by braking demand)."""
    out = tmp_path / "r152"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "eoam_sumo",
            "protocol",
            "unr152",
            "--out",
            str(out),
            "--points",
            "^R152mstationary_v50_",
            "--system",
            "eoam",
            "--no-progress",
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    row = pd.read_csv(out / "results.csv").iloc[0]
    assert row["manoeuvre"] == "S" and row["impact_speed_kmh"] == 0.0
    assert row["warning"] == "pass"
    assert row["max_lateral_offset_m"] > (row["lane_width_m"] - SEDAN_WIDTH_M) / 2
    assert row["verdict"] == "fail" and "left its lane" in row["note"]
