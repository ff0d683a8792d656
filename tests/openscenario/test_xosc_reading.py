"""Reading OpenSCENARIO: expressions (by hand), parameters, the real files of openMSL's ALKS
set and Vector's NCAP set (tests/data/openscenario): what they compile to, checked against
the numbers written in the files, and every refusal naming its element, file and line."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.expressions import ExpressionError, evaluate, substitute
from eoam_sumo.openscenario.reader import read_scenario

DATA = Path(__file__).parents[1] / "data" / "openscenario"
ALKS = DATA / "alks"
NCAP_RUNS = (
    DATA / "ncap" / "OpenSCENARIO" / "NCAP" / "CA-FC_2026" / "Variations" / "SingleExecution"
)


def test_expressions_follow_the_standard_operators() -> None:
    values = {"a": "50", "w": "1.815", "flag": "true"}
    assert evaluate("$a / 100 * $w - $w / 2", values) == pytest.approx(0.0)
    assert evaluate("($a + 10) % 7 ** 1", values) == pytest.approx(4.0)
    assert evaluate("not $flag", values) is False
    assert evaluate("sign(-$a) * min(1.0, abs(-3))", values) == -1.0
    assert evaluate("round(2.5) + floor(-0.5) + ceil(0.2)", values) == 3.0
    assert substitute("$a", values) == "50"
    assert substitute("plain", values) == "plain"


@pytest.mark.parametrize(
    "expr", ["__import__('os').system('true')", "$a.real", "[1, 2]", "(lambda: 1)()", "$b + 1"]
)
def test_expressions_refuse_anything_else(expr: str) -> None:
    with pytest.raises(ExpressionError):
        evaluate(expr, {"a": "1"})


def test_ccrb_compiles_to_the_protocol_timeline() -> None:
    """CCRb 50 km/h: the target departs 1 s (13.89 m) bumper to bumper ahead (its
    LongitudinalDistanceAction at time 0 is a departure placement)."""
    plan = compile_plan(read_scenario(NCAP_RUNS / "CCRb_50kph.xosc"))
    assert plan.ego == "Ego"
    ego, tgt = plan.bodies["Ego"], plan.bodies["Target"]
    gap = (plan.places["Target"].s_m + tgt.rear_ahead_m) - (
        plan.places["Ego"].s_m + ego.front_ahead_m
    )
    assert gap == pytest.approx(50 / 3.6 * 1.0)
    assert plan.speeds_mps == pytest.approx({"Ego": 50 / 3.6, "Target": 50 / 3.6})


def test_alks_emergency_brake_compiles_its_start() -> None:
    """4.3_2: ego and lead depart at 60 km/h (the brake is the engine's, at run time)."""
    plan = compile_plan(
        read_scenario(
            ALKS / "alks_scenario_4_3_2_follow_lead_vehicle_emergency_brake_template.xosc"
        )
    )
    assert plan.ego == "Ego"  # the one with an ObjectController
    assert plan.speeds_mps == pytest.approx({"Ego": 60 / 3.6, "LeadVehicle": 60 / 3.6})


def test_a_blocking_target_given_as_a_car_by_its_parameters() -> None:
    """4.2_1's target is a pedestrian by default; its catalog parameters can name a car."""
    path = ALKS / "alks_scenario_4_2_1_fully_blocking_target_template.xosc"
    params = {"TargetBlocking_Catalog": "vehicle_catalog", "TargetBlocking_Model": "car"}
    plan = compile_plan(read_scenario(path, params))
    place = plan.places["TargetBlocking"]
    assert (place.lane, place.s_m) == (-4, 500.0)
    assert plan.speeds_mps.get("TargetBlocking", 0.0) == 0.0
    assert plan.bodies["TargetBlocking"].length_m == 5.0


def test_param_replaces_a_declared_value_and_refuses_an_undeclared_one() -> None:
    path = ALKS / "alks_scenario_4_3_2_follow_lead_vehicle_emergency_brake_template.xosc"
    plan = compile_plan(read_scenario(path, {"Ego_InitSpeed_Ve0_kph": "36"}))
    assert plan.speeds_mps["Ego"] == pytest.approx(10.0)
    with pytest.raises(InputError, match="--param Nope: no such parameter"):
        read_scenario(path, {"Nope": "1"})


@pytest.mark.parametrize(
    ("path", "element", "line", "why"),
    [
        (
            ALKS / "alks_scenario_4_2_1_fully_blocking_target_template.xosc",
            "Pedestrian",
            8,
            "outside",
        ),
        (NCAP_RUNS / "CCFhos_50kph_50kph.xosc", "RelativeRoadPosition", 112, "outside"),
    ],
)
def test_files_outside_the_subset_are_refused_by_element_file_and_line(
    path: Path, element: str, line: int, why: str
) -> None:
    with pytest.raises(InputError) as err:
        compile_plan(read_scenario(path))
    text = str(err.value)
    assert f"<{element}> at " in text and f":{line}" in text and why in text
    assert "\n" not in text


def test_a_continuous_lane_offset_is_refused(tmp_path: Path) -> None:
    """Outside the subset: refused by element, file and line, not ignored."""
    alks = shutil.copytree(ALKS, tmp_path / "alks")
    src = alks / "alks_scenario_4_3_2_follow_lead_vehicle_emergency_brake_template.xosc"
    text = src.read_text(encoding="utf-8-sig").replace(
        "<LongitudinalAction>",
        '<LateralAction><LaneOffsetAction continuous="true"><LaneOffsetActionDynamics '
        'maxLateralAcc="1" dynamicsShape="cubic"/><LaneOffsetTarget><AbsoluteTargetLaneOffset '
        'value="1"/></LaneOffsetTarget></LaneOffsetAction></LateralAction></PrivateAction>'
        "<PrivateAction><LongitudinalAction>",
        1,
    )
    assert "LaneOffsetAction" in text
    src.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=r"<LaneOffsetAction> at .*:\d+: a continuous"):
        compile_plan(read_scenario(src))


def test_a_variation_with_many_values_needs_them_picked() -> None:
    """Vector's CCRs standard range sweeps the speed 10-50 km/h and five impact locations:
    `run` refuses it naming the distribution, and runs the point --param picks."""
    path = NCAP_RUNS.parent / "StandardRange" / "CCRs.xosc"
    with pytest.raises(InputError, match=r"CCRs.xosc:28: Ego_speed_kph has many values"):
        read_scenario(path)
    plan = compile_plan(read_scenario(path, {"Ego_speed_kph": "30", "ImpactLocation": "50"}))
    assert plan.speeds_mps == pytest.approx({"Ego": 30 / 3.6, "Target": 0.0})
    # the target 5 s at 30 km/h ahead (Ego_initTimeHeadway, reference points) of s = 50 m
    assert plan.places["Target"].s_m == pytest.approx(50 + 5 * 30 / 3.6)


@pytest.mark.parametrize(
    ("name", "target", "lane", "speed_kmh"),
    [
        ("alks_scenario_4_4_1_cut_in_no_collision_template.xosc", "CutInVehicle", -5, 40.0),
        ("alks_scenario_4_1_2_swerving_lead_vehicle_template.xosc", "LeadVehicle", -4, 60.0),
    ],
)
def test_run_time_storyboards_compile_with_their_departures(
    name: str, target: str, lane: int, speed_kmh: float
) -> None:
    """Refused before the storyboard engine: a dLane, a RelativeTargetSpeed, a start on a
    distance, a LaneChangeAction or LaneOffsetAction. Now the departures come from Init
    (4.4_1: one lane right of the ego at the ego's speed - 20 km/h)."""
    plan = compile_plan(read_scenario(ALKS / name))
    assert plan.places[target].lane == lane
    assert plan.speeds_mps[target] == pytest.approx(speed_kmh / 3.6)
