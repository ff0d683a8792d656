"""The third review of `run FILE.xosc` (its #3, #6, #7, #9, #11, #12, #18): departure speeds
and parameter types refused when the scenario is loaded, before anything is written; what
the run does not apply said on stderr; .xosp files; the road's netOffset in the summary.
Tiny hand-made files; the tests marked ``sumo`` convert the road or run it."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import pytest

from eoam_sumo.cli import main
from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.reader import read_scenario
from eoam_sumo.openscenario.story import COMPLETE, RUNNING
from tests.openscenario.test_xosc_review import _board, _distribution
from tests.openscenario.xosc_cases import BRAKE, STEP, TARGET_INIT_SPEED, write_case

DECLS = '<ParameterDeclaration name="TargetSpeed" parameterType="double" value="10"/>'
TYPED = (
    DECLS,
    DECLS + '<ParameterDeclaration name="Flag" parameterType="boolean" value="false"/>'
    '<ParameterDeclaration name="N" parameterType="int" value="2"/>'
    '<ParameterDeclaration name="U" parameterType="unsignedInt" value="2"/>'
    '<ParameterDeclaration name="F" parameterType="double" value="1"/>',
)


def _speed(target: str) -> str:
    return (
        f"<PrivateAction><LongitudinalAction><SpeedAction>{STEP}<SpeedActionTarget>{target}"
        "</SpeedActionTarget></SpeedAction></LongitudinalAction></PrivateAction>"
    )


# the target departs at F times the ego's speed (esmini's cut-in: TargetSpeedFactor)
RELATIVE = (
    '<RelativeTargetSpeed entityRef="Ego" value="$F" speedTargetValueType="factor" '
    'continuous="false"/>'
)
FACTOR_INIT = (TARGET_INIT_SPEED, _speed(RELATIVE))


def _line_of(path: Path, text: str) -> int:
    """The line of ``path`` that holds ``text`` (once)."""
    lines = [k for k, line in enumerate(path.read_text().splitlines(), 1) if text in line]
    assert len(lines) == 1
    return lines[0]


def _one_line_error(capsys: pytest.CaptureFixture) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


# ------------------------------------------------------------------ #18 the parameters' types
@pytest.mark.parametrize(
    ("given", "says"),
    [({"Flag": "maybe"}, "parameter Flag = 'maybe' is not a boolean"),
     ({"Flag": "ture"}, "parameter Flag = 'ture' is not a boolean"),
     ({"Flag": "TRUE"}, "parameter Flag = 'TRUE' is not a boolean"),
     ({"N": "1.5"}, "parameter N = '1.5' is not an integer"),
     ({"N": "abc"}, "parameter N = 'abc' is not an integer"),
     ({"U": "-3"}, "parameter U = '-3' is not an integer >= 0"),
     ({"F": "fast"}, "parameter F = 'fast' is not a number")],
)  # fmt: skip
def test_a_value_not_of_its_declared_type_is_refused_naming_the_parameter(
    tmp_path: Path, given: dict, says: str
) -> None:
    """`--param Flag=maybe` (or N=1.5, U=-3) ran silently, the condition on Flag false."""
    path = write_case(tmp_path, TYPED)
    with pytest.raises(InputError) as err:
        read_scenario(path, given)
    text = str(err.value)
    assert says in text and "\n" not in text and str(path) in text


def test_values_of_their_type_are_read(tmp_path: Path) -> None:
    """xsd:boolean's 1/0, an integer written 30.0 (a range's or a TOML sweep's value)."""
    path = write_case(tmp_path, TYPED)
    values = read_scenario(path, {"Flag": "0", "N": "30.0", "U": "4", "F": "1e1"}).parameters
    assert (values["N"], values["U"], values["F"]) == ("30.0", "4", "1e1")


def _flag_event(value: str) -> tuple[str, str]:
    """Target's brake event starts on ``Flag equalTo value`` (a parameter: known at time 0,
    so a step there is the target's departure speed)."""
    at_2s = '<SimulationTimeCondition value="2" rule="greaterThan"/>'
    return (
        "<ByValueCondition>" + at_2s,
        '<ByValueCondition><ParameterCondition parameterRef="Flag" rule="equalTo" '
        f'value="{value}"/>',
    )


@pytest.mark.parametrize(
    ("flag", "written", "departs"),
    [("1", "true", 0.0), ("true", "1", 0.0), ("0", "false", 0.0), ("0", "true", 10.0),
     ("false", "1", 10.0), ("true", "true", 0.0)],
)  # fmt: skip
def test_booleans_compare_as_booleans(tmp_path: Path, flag: str, written: str, departs) -> None:
    """`--param Flag=1` is true (xsd:boolean): the condition `Flag equalTo true` held false
    and the target kept its speed. The event's step to 0 at time 0 is the departure speed."""
    linear = 'dynamicsShape="linear" dynamicsDimension="rate" value="5"'
    step_brake = BRAKE.replace(linear, 'dynamicsShape="step" dynamicsDimension="time" value="0"')
    path = write_case(tmp_path, TYPED, (BRAKE, step_brake), _flag_event(written))
    plan = compile_plan(read_scenario(path, {"Flag": flag}))
    assert plan.speeds_mps["Target"] == departs


def test_a_distribution_value_is_checked_against_its_type(tmp_path: Path) -> None:
    write_case(tmp_path, TYPED)
    body = ('<Deterministic><DeterministicSingleParameterDistribution parameterName="N">'
            '<DistributionSet><Element value="2.5"/></DistributionSet>'
            "</DeterministicSingleParameterDistribution></Deterministic>")  # fmt: skip
    with pytest.raises(InputError, match=r"parameter N = '2\.5' is not an integer"):
        read_scenario(_distribution(tmp_path, body))


# ------------------------------------------------------------- #3 departure speeds at load
@pytest.mark.parametrize(
    ("factor", "says"),
    [("-1", "Target's departure speed -20 m/s is negative"),
     ("4", "Target's departure speed 80 m/s is above its Performance maxSpeed 70 m/s")],
)  # fmt: skip
def test_a_relative_departure_speed_out_of_range_is_refused_at_load(
    tmp_path: Path, factor: str, says: str
) -> None:
    """esmini's cut-in with TargetSpeedFactor=-1: SUMO refused the written route file
    ("Invalid departSpeed"), naming it, after overwriting an earlier run's scenario/."""
    from eoam_sumo.openscenario.runner import load

    path = write_case(tmp_path, TYPED, FACTOR_INIT)
    with pytest.raises(InputError) as err:
        load(path, {"F": factor})
    line = _line_of(path, "<RelativeTargetSpeed")
    assert str(err.value) == f"<RelativeTargetSpeed> at {path}:{line}: {says}"


def test_a_batch_refuses_such_a_case_before_any_runs(tmp_path: Path) -> None:
    """As `EgoSpeed = [60, -10]` is: it ran and failed in its worker (exit 1)."""
    from eoam_sumo.openscenario.batch import check_cases
    from eoam_sumo.openscenario.variations import XoscBatch

    path = write_case(tmp_path, TYPED, FACTOR_INIT)
    with pytest.raises(InputError, match=r"case00001 \(F=-1\): <RelativeTargetSpeed> at .* is neg"):
        check_cases(XoscBatch(path, [{"F": "1.2"}, {"F": "-1"}], 0))


@pytest.mark.parametrize("kmh", ["300", "3", "0"])
def test_the_ego_speed_outside_the_tables_is_refused_before_anything_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture, kmh: str
) -> None:
    """300 km/h was reported as SUMO's error on the target's speed; 3 km/h after
    DIR/scenario/ was written."""
    path = write_case(tmp_path)
    out = tmp_path / "out"
    args = ["run", str(path), "--param", f"EgoSpeed={float(kmh) / 3.6}", "--out", str(out)]
    assert main(args) == 2
    line = _line_of(path, '<AbsoluteTargetSpeed value="$EgoSpeed"/>')
    assert re.fullmatch(
        rf"eoam-sumo: error: <AbsoluteTargetSpeed> at {re.escape(str(path))}:{line}: the ego "
        rf"Ego's departure speed {float(kmh):.1f} km/h is outside the design range \[5, 175\] "
        r"km/h \(the lookup tables'\)",
        _one_line_error(capsys),
    )
    assert not out.exists()


@pytest.mark.sumo
def test_run_loaded_checks_the_ego_speed_before_writing_the_scenario(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An earlier run's DIR/scenario/ was overwritten before the session refused the speed."""
    from eoam_sumo.openscenario.runner import load, run_loaded
    from eoam_sumo.sim.settings import RunSettings

    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))
    loaded = load(write_case(tmp_path), {})
    loaded.plan.speeds_mps["Ego"] = 300 / 3.6
    earlier = tmp_path / "out" / "scenario" / "scenario.rou.xml"
    earlier.parent.mkdir(parents=True)
    earlier.write_text("the earlier run's routes", encoding="utf-8")
    with pytest.raises(InputError, match=r"the ego Ego's departure speed 300.0 km/h is outside"):
        run_loaded(loaded, tmp_path / "out", RunSettings())
    assert earlier.read_text(encoding="utf-8") == "the earlier run's routes"
    assert sorted(p.name for p in earlier.parent.iterdir()) == ["scenario.rou.xml"]


@pytest.mark.sumo
def test_a_departure_above_70_mps_is_within_its_sumo_type(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A target with Performance maxSpeed 100 departing at 80 m/s: its SUMO type's maxSpeed
    was 70 (SUMO: "Departure speed ... is too high for the vehicle type")."""
    import xml.etree.ElementTree as ET

    from eoam_sumo.openscenario.runner import load, write_scenario

    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))
    path = write_case(tmp_path, TYPED, FACTOR_INIT, ('maxSpeed="70"', 'maxSpeed="100"'))
    cfg = write_scenario(load(path, {"F": "4"}), tmp_path / "scenario")
    routes = ET.parse(cfg.parent / "scenario.rou.xml").getroot()
    types = ET.parse(cfg.parent / "scenario_vtypes.add.xml").getroot()
    target = next(v for v in routes.iter("vehicle") if v.get("id") == "Target")
    vtype = next(t for t in types.iter("vType") if t.get("id") == target.get("type"))
    assert float(target.get("departSpeed")) == pytest.approx(80.0)
    assert float(vtype.get("maxSpeed")) >= 80.0


# ----------------------------------------------------- #6, #11 speeds reached at run time
def _event_speed(target: str, dynamics: str = "") -> tuple[str, str]:
    """Target's event at 2 s: a SpeedAction to ``target`` (default dynamics: a step)."""
    action = _speed(target)
    if dynamics:
        action = action.replace(STEP, dynamics)
    return BRAKE, action


def _run_board(path: Path, seconds: float):
    board = _board(path)
    board.world.actors["Ego"].speed_mps = 20.0
    for k in range(int(seconds / 0.01)):
        board.world.time_s, board.world.step = 2.0 + k * 0.01, k + 1
        for story in board.stories:
            board._step_element(story)
        board._step_actions(0.01)
    return board


def test_a_negative_target_speed_at_run_time_is_said_and_run_as_a_stop(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """20 m/s - 30: the target braked to a standstill without a word, and its action never
    ended (its goal -10 m/s never reached)."""
    rel = RELATIVE.replace('value="$F" speedTargetValueType="factor"', 'value="-30"')
    path = write_case(tmp_path, _event_speed(rel))
    board = _run_board(path, 3.0)
    err = capsys.readouterr().err
    line = _line_of(path, "<RelativeTargetSpeed")
    assert err.count("run as a stop") == 1
    assert (
        f"<RelativeTargetSpeed> at {path}:{line} at 2.01 s: target speed -10 m/s run as a stop"
        in err
    )
    assert board.world.actors["Target"].speed_mps == 0.0
    action = board.world.elements["S::A::MG::M::E::Act1"]
    assert action.state == COMPLETE


@pytest.mark.parametrize(("goal", "said"), [("5", True), ("10", False)])
def test_a_rate_of_0_keeps_the_speed_and_says_so_when_it_cannot_reach_its_target(
    tmp_path: Path, capsys: pytest.CaptureFixture, goal: str, said: bool
) -> None:
    """A linear change at rate 0 never gets there: it did nothing, silently. openMSL's
    ALKS 4.4_1 writes rate 0 to keep the speed (its target then the speed it has)."""
    rate0 = '<SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="0"/>'
    path = write_case(tmp_path, _event_speed(f'<AbsoluteTargetSpeed value="{goal}"/>', rate0))
    board = _run_board(path, 1.0)
    err = capsys.readouterr().err
    assert ("a rate of 0 never reaches the target speed 5 m/s: Target keeps 10 m/s" in err) == said
    assert board.world.actors["Target"].speed_mps == 10.0
    action = board.world.elements["S::A::MG::M::E::Act1"]
    assert action.state == (RUNNING if said else COMPLETE)


# --------------------------------------------------------------- #7 .xosp and other names
@pytest.mark.parametrize("name", ["case.xosp", "case.xml", "case"])
def test_an_openscenario_file_of_another_name_is_read_as_one(
    tmp_path: Path, capsys: pytest.CaptureFixture, name: str
) -> None:
    """`run X.xosp` read it as a sumocfg (`--param ... apply to an .xosc scenario only`),
    `batch X.xosp` as a TOML matrix ("malformed TOML")."""
    path = write_case(tmp_path).rename(tmp_path / name)
    assert main(["run", str(path), "--param", "Nope=1", "--out", str(tmp_path / "o")]) == 2
    assert f"--param Nope: no such parameter declared in {path}" in _one_line_error(capsys)
    assert main(["batch", str(path), "--resume", "--out", str(tmp_path / "o")]) == 2
    assert "--resume does not apply to a batch over an .xosc" in _one_line_error(capsys)
    assert not (tmp_path / "o").exists()


# ------------------------------------------ #12 the ego's offset, #7 the time limit, #9
def _two_lanes_each_way() -> str:
    from tests.openscenario.xosc_cases import lane, road

    return road(left=lane(1) + lane(2), right=lane(-1) + lane(-2))


@pytest.mark.sumo
@pytest.mark.parametrize(
    ("offset", "note"),
    [("1.0", "lateral offset 1 m from lane -1 (line {line}) not applied: it starts on lane "
              "-1's centre"),
     ("-3.0", "lateral offset -3 m from lane -1 (line {line}) not applied: it starts on lane "
               "-2's centre, the lane nearest it"),
     ("0", None)],
)  # fmt: skip
def test_the_ego_offset_not_applied_is_noted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, offset: str, note: str | None
) -> None:
    """The plant starts on its departure lane's centre: the offset was dropped silently."""
    from eoam_sumo.openscenario.runner import load

    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))
    ego_lane = '<LanePosition roadId="1" laneId="-1" offset="0" s="50"/>'
    moved = ego_lane.replace('offset="0"', f'offset="{offset}"')
    path = write_case(tmp_path, (ego_lane, moved), xodr=_two_lanes_each_way())
    notes = [n for n in load(path, {}).plan.notes if "the ego Ego's lateral offset" in n]
    line = _line_of(path, f'offset="{offset}" s="50"')
    assert notes == ([] if note is None else [f"the ego Ego's {note.format(line=line)}"])


@pytest.mark.sumo
def test_a_run_cut_by_its_time_limit_says_so_and_gives_the_net_offset(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    """The storyboard (StopTrigger at 12 s) cut at --max-time-s 1 without a word; the
    outputs' x, y are the road's shifted by netconvert's netOffset (the road starts at
    x 100, y 50 here): the summary gives it, so that a target's place converts back."""
    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))
    xodr = _two_lanes_each_way().replace('x="0" y="0"', 'x="100" y="50"')
    path = write_case(tmp_path, xodr=xodr)
    out = tmp_path / "out"
    assert main(["run", str(path), "--max-time-s", "1", "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "case.xosc: stopped at --max-time-s 1 before the storyboard's end" in err
    summary = json.loads((out / "summary.json").read_text())
    dx, dy = summary["net_offset_m"]
    first = next(r for r in csv.DictReader((out / "traffic.csv").open()) if r["id"] == "Target")
    # Target at its departure (the first row, within a step of 0.1 m): reference point at
    # s 150 of lane -1 (y 50 - 1.75), its box's centre 1.4 m ahead of it
    back = (float(first["x_m"]) - dx, float(first["y_m"]) - dy)
    assert back == pytest.approx((100.0 + 150.0 + 1.4, 48.25), abs=0.11)
    ended = write_case(
        tmp_path, ('value="12" rule="greaterThan"', 'value="0.5" rule="greaterThan"')
    )
    assert main(["run", str(ended), "--max-time-s", "1", "--out", str(tmp_path / "o2")]) == 0
    assert "stopped at --max-time-s" not in capsys.readouterr().err
    assert json.loads((tmp_path / "o2" / "summary.json").read_text())["end_cause"] == "storyboard"
