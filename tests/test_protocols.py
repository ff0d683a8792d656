"""The protocols: scoring rules on hand-made rows (independent truth: the published bands of
Euro NCAP's rating code, copied by hand below), the test grids, and a tiny protocol run
twice (determinism)."""

from __future__ import annotations

import math
import subprocess
import sys

import pandas as pd
import pytest

from eoam_sumo.protocols import rules, scoring
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


def test_test_score_weights_the_ranges():
    # CCRs: 1.2 standard, 0.15 extended; two standard cells (1, 0.5), two extended (1, 0)
    score = rules.test_score("CCRs", [(1.0, False), (0.5, False), (1.0, True), (0.0, True)])
    assert score.standard == pytest.approx(1.2 * 0.75)
    assert score.extended == pytest.approx(0.15 * 0.5)
    assert score.max_total == pytest.approx(1.35)


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
        for p in protocol_points(PROTOCOLS[2], SEDAN_WIDTH_M, ())
        if p.test == test and p.ego_speed_kmh == ego_kmh
    )
    assert scoring.point_row(point, impact_kmh)["verdict"] == verdict


def test_failure_cause_names_the_never_triggered_head_on():
    row = {"status": "ok", "note": "", "modes_visited": "0", "test": "CCFhos", "reason": "x"}
    assert scoring.failure_cause(row) == f"{scoring.NO_TRIGGER_ONCOMING}; run: x"
    failed = {"status": "failed", "error": "boom", "test": "CCRs"}
    assert scoring.failure_cause(failed) == "the run failed: boom"


def test_abs_and_esc_are_switched_on_the_vehicle_and_carried_by_every_case(tmp_path):
    from eoam_sumo.batch.case import case_vehicle
    from eoam_sumo.protocols.command import vehicle_params
    from eoam_sumo.protocols.runner import _case

    assert vehicle_params("sedan").width_m == SEDAN_WIDTH_M
    params = vehicle_params("sedan", abs_mode="on", esc_mode="off")
    assert params.abs_fitted is True and params.esc_fitted is False
    point = protocol_points("unr152", SEDAN_WIDTH_M, ("paper",))[0]
    case = _case(point, tmp_path / "x.sumocfg", "paper", 1.0, 40.0, "sedan", params)
    assert case_vehicle(case) == params
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
    points = protocol_points("unr152", SEDAN_WIDTH_M, ("paper",))[:1]
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
        for p in protocol_points(PROTOCOLS[1], SEDAN_WIDTH_M, ("paper",))
        if p.test == "CCRm" and p.ego_speed_kmh == 60 and p.overlap == 50
    )
    row = scoring.point_row(point, 12.0)
    assert (row["colour"], row["points"]) == ("orange", 0.5)
    not_run = scoring.point_row(point, None, "why")
    assert (not_run["colour"], not_run["points"], not_run["note"]) == ("not_run", 0.0, "why")


def test_grids():
    p2026 = protocol_points(PROTOCOLS[1], SEDAN_WIDTH_M, ("paper", "safe"))
    count = {t: sum(p.test == t for p in p2026) for t in ("CCRs", "CCRm", "CCRb", "CCFhos")}
    assert count == {"CCRs": 8 * 7, "CCRm": 11 * 7, "CCRb": 11 * 7, "CCFhos": 2 * 8 * 4}
    assert len({p.point_id for p in p2026}) == len(p2026)
    p2023 = protocol_points(PROTOCOLS[0], SEDAN_WIDTH_M, ())
    assert sum(p.test == "CCRb" for p in p2023) == 4
    r152 = protocol_points(PROTOCOLS[2], SEDAN_WIDTH_M, ())
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
    assert list(first["status"]) == ["not_run", "ok", "ok"]
    assert (tmp_path / "a" / "scorecard.md").read_text().count("outside the design range") == 1
    assert not math.isnan(first["impact_speed_kmh"].iloc[1])
