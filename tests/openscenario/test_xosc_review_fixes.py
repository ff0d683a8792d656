"""The second review of `run FILE.xosc`: variable modify rules, every rule of a simulation
time condition, catalog vehicles with a trailer hitch, RelativeLanePosition ds along the
road's s, a ParameterCondition on a Story's parameter. Tiny hand-made files, no SUMO."""

from __future__ import annotations

from pathlib import Path

import pytest

from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.placing import place_now
from eoam_sumo.openscenario.reader import read_scenario
from eoam_sumo.openscenario.story import RUNNING, STANDBY
from eoam_sumo.openscenario.timing import DYNAMIC, NEVER, Clock
from eoam_sumo.openscenario.xmltree import Node
from tests.openscenario.test_xosc_review import _board, _refusal
from tests.openscenario.xosc_cases import AT_2S, VEHICLE, write_case


def _variables(var_type: str = "double", value: str = "1") -> tuple[str, str]:
    decl = f'name="Counter" variableType="{var_type}" value="{value}"'
    return ("<CatalogLocations/>", f"<VariableDeclarations><VariableDeclaration {decl}/>"
            "</VariableDeclarations><CatalogLocations/>")  # fmt: skip


def _modify(rule: str, value: str, name: str) -> str:
    return (f'<Action name="{name}"><GlobalAction><VariableAction variableRef="Counter">'
            f'<ModifyAction><Rule><{rule} value="{value}"/></Rule></ModifyAction>'
            "</VariableAction></GlobalAction></Action>")  # fmt: skip


def _start_at(board, time_s: float) -> None:
    board.world.time_s, board.world.step = time_s, board.world.step + 1
    for story in board.stories:
        board._step_element(story)


def test_variable_add_and_multiply_run_as_the_standard_writes_them(tmp_path: Path) -> None:
    """OpenSCENARIO 1.2 VariableModifyAction > Rule > AddValue/MultiplyByValue: ModifyAction
    was refused, and the engine looked for AddValue where Rule is (a silent no-op)."""
    actions = ('<Action name="Act1">',
               _modify("AddValue", "2", "Add") + _modify("MultiplyByValue", "3", "Mul")
               + '<Action name="Act1">')  # fmt: skip
    board = _board(write_case(tmp_path, _variables(), actions))
    _start_at(board, 2.5)
    assert float(board.world.variables["Counter"]) == 9.0


def test_a_modify_rule_on_a_text_variable_is_refused_in_one_line(tmp_path: Path) -> None:
    actions = ('<Action name="Act1">', _modify("AddValue", "2", "Add") + '<Action name="Act1">')
    text = _refusal(write_case(tmp_path, _variables("string", "abc"), actions))
    assert "<VariableAction> at" in text and "'Counter' is a string" in text


@pytest.mark.parametrize(
    ("rule", "value", "expect"),
    [("greaterThan", 2, 2.0), ("greaterOrEqual", 2, 2.0), ("equalTo", 2, 2.0),
     ("lessThan", 2, 0.0), ("lessOrEqual", 2, 0.0), ("notEqualTo", 2, 0.0),
     ("lessThan", 0, NEVER), ("lessOrEqual", -1, NEVER), ("equalTo", -1, NEVER),
     ("greaterThan", -1, 0.0)],
)  # fmt: skip
def test_every_simulation_time_rule_is_timed(rule: str, value: float, expect: float) -> None:
    """OpenSCENARIO 1.2 sec. 7.4.3 Rule: all six (lessThan was refused): the first time >= 0
    the rule holds."""
    node = Node("SimulationTimeCondition", {"value": str(value), "rule": rule}, Path("f"), 1)
    assert Clock({}, lambda n: "")._value_time(node) == expect


def test_a_time_condition_less_than_runs_from_the_start(tmp_path: Path) -> None:
    """hand/v19_time_lessthan.xosc was refused: its event now starts at the first step."""
    path = write_case(tmp_path, ('rule="greaterThan"/></ByValueCondition></Condition>'
                                 "</ConditionGroup></StartTrigger></Event>",
                                 'rule="lessThan"/></ByValueCondition></Condition>'
                                 "</ConditionGroup></StartTrigger></Event>"))  # fmt: skip
    board = _board(path)
    _start_at(board, 0.0)
    assert [e.state for e in board.world.elements.values() if e.kind == "Event"] == [RUNNING]


def test_a_time_condition_true_from_the_start_with_an_edge_is_left_to_the_run() -> None:
    """lessThan with a rising edge never fires (it only falls): not timed at 0."""
    cond = Node(
        "Condition",
        {"conditionEdge": "rising"},
        Path("f"),
        1,
        [
            Node(
                "ByValueCondition",
                {},
                Path("f"),
                1,
                [Node("SimulationTimeCondition", {"value": "2", "rule": "lessThan"}, Path("f"), 1)],
            )
        ],
    )
    assert Clock({}, lambda n: "")._condition(cond) == DYNAMIC  # fmt: skip


def _trailer_catalog(folder: Path, trailer: str) -> tuple[tuple[str, str], tuple[str, str]]:
    """Target from a catalog entry with a hitch and ``trailer`` (esmini's VehicleCatalog)."""
    (folder / "cat").mkdir(exist_ok=True)
    entry = VEHICLE.replace("<Properties/>", f'<TrailerHitch dx="-1.2"/>{trailer}<Properties/>')
    other = '<Vehicle name="semi"><Unknown/></Vehicle>'  # never referenced
    (folder / "cat" / "vehicles.xosc").write_text(
        f'<OpenSCENARIO><Catalog name="VehicleCatalog">{entry}{other}</Catalog></OpenSCENARIO>',
        encoding="utf-8",
    )
    locations = ("<CatalogLocations/>", '<CatalogLocations><VehicleCatalog><Directory '
                 'path="cat"/></VehicleCatalog></CatalogLocations>')  # fmt: skip
    target = (f'<ScenarioObject name="Target">{VEHICLE}', '<ScenarioObject name="Target">'
              '<CatalogReference catalogName="VehicleCatalog" entryName="car"/>')  # fmt: skip
    return locations, target


def test_a_catalog_vehicle_with_a_hitch_and_no_trailer_runs(tmp_path: Path) -> None:
    """esmini's VehicleCatalog gives car_white a TrailerHitch and an empty TrailerRef: every
    scenario using it (cut-in, pedestrian) was refused on TrailerHitch."""
    edits = _trailer_catalog(tmp_path, '<Trailer><TrailerRef entityRef=""/></Trailer>')
    plan = compile_plan(read_scenario(write_case(tmp_path, *edits)))
    assert plan.bodies["Target"].length_m == 4.8


def test_a_vehicle_towing_a_trailer_is_refused_in_one_line(tmp_path: Path) -> None:
    edits = _trailer_catalog(tmp_path, '<Trailer><TrailerRef entityRef="Target2"/></Trailer>')
    text = _refusal(write_case(tmp_path, *edits))
    assert "<Trailer> at" in text and "towing a trailer (Target2) is not supported" in text


def test_relative_lane_position_ds_is_along_the_roads_s(tmp_path: Path) -> None:
    """OpenSCENARIO 1.2 RelativeLanePosition ds: "relative offset in the road's s
    coordinate" (esmini: ROAD_DIRECTION); it was turned by the reference's direction."""
    ego_left = ('laneId="-1" offset="0" s="50"', 'laneId="1" offset="0" s="50"')
    target = ('<LanePosition roadId="1" laneId="-1" offset="0" s="$TargetS"/>',
              '<RelativeLanePosition entityRef="Ego" dLane="0" ds="20"/>')  # fmt: skip
    path = write_case(tmp_path, ego_left, target)
    assert compile_plan(read_scenario(path)).places["Target"].s_m == 70.0
    board = _board(path)
    world = board.world
    teleport = Node("TeleportAction", {}, Path("f"), 1, [Node("Position", {}, Path("f"), 1, [
        Node("RelativeLanePosition", {"entityRef": "Ego", "dLane": "0", "ds": "-10"},
             Path("f"), 1)])])  # fmt: skip
    place_now(world, world.actors["Target"], teleport)
    assert world.actors["Target"].s_m == 40.0


def _story_parameter(name: str, value: str) -> tuple[str, str]:
    decl = f'name="{name}" parameterType="string" value="{value}"'
    return ('<Story name="S">', '<Story name="S"><ParameterDeclarations>'
            f"<ParameterDeclaration {decl}/></ParameterDeclarations>")  # fmt: skip


def _on_parameter(name: str, value: str) -> tuple[str, str]:
    return (AT_2S, '<Condition name="C1" delay="0" conditionEdge="none"><ByValueCondition>'
            f'<ParameterCondition parameterRef="{name}" value="{value}" rule="equalTo"/>'
            "</ByValueCondition></Condition>")  # fmt: skip


def test_a_parameter_condition_sees_the_story_scope_it_is_declared_in(tmp_path: Path) -> None:
    """OpenSCENARIO 1.2 sec. 8.4.1: a Story's declarations are in scope in it (one declared
    only there was refused as undeclared); a Story's value hides the scenario's."""
    path = write_case(tmp_path, _story_parameter("Go", "yes"), _on_parameter("Go", "yes"))
    board = _board(path)
    _start_at(board, 0.0)
    assert [e.state for e in board.world.elements.values() if e.kind == "Event"] == [RUNNING]
    path = write_case(tmp_path, _story_parameter("TargetSpeed", "3"),
                      _on_parameter("TargetSpeed", "10"))  # fmt: skip
    board = _board(path)
    _start_at(board, 0.0)
    assert [e.state for e in board.world.elements.values() if e.kind == "Event"] == [STANDBY]


def test_a_rule_outside_the_standards_six_is_refused_before_the_run(tmp_path: Path) -> None:
    """A by-entity condition's rule was only checked at run time (after files were written)."""
    edit = (AT_2S, '<Condition name="C1" delay="0" conditionEdge="none"><ByEntityCondition>'
            '<TriggeringEntities triggeringEntitiesRule="any"><EntityRef entityRef="Ego"/>'
            '</TriggeringEntities><EntityCondition><SpeedCondition value="5" rule="bigger"/>'
            "</EntityCondition></ByEntityCondition></Condition>")  # fmt: skip
    text = _refusal(write_case(tmp_path, edit))
    assert "<SpeedCondition> at" in text and "rule=bigger is not a rule" in text


def test_a_broken_or_binary_road_file_is_one_line(tmp_path: Path) -> None:
    """A malformed .xodr (a tag missing) or one of bytes that are no text crashed the run with
    a ParseError traceback after netconvert had accepted it."""
    from eoam_sumo.errors import InputError
    from eoam_sumo.openscenario import road as od
    from tests.openscenario.xosc_cases import road

    broken = tmp_path / "broken.xodr"
    broken.write_text(road().replace("</lanes>", ""), encoding="utf-8")
    binary = tmp_path / "binary.xodr"
    binary.write_bytes(b"\xff\xfe" + road().encode("utf-8"))
    for bad in (broken, binary):
        for read in (od.check_road, od.wide_lanes, od.road_lengths):
            with pytest.raises(InputError, match=rf"{bad.name}: not well-formed XML"):
                read(bad)


def test_a_lane_that_widens_along_the_road_is_noted_wide(tmp_path: Path) -> None:
    """Only the width polynomial's constant term was read: a lane of 3 m + 0.01 m per m over
    500 m (8 m at its end, OpenDRIVE 1.6 sec. 9.5.1) was not noted."""
    from eoam_sumo.openscenario import road as od
    from tests.openscenario.xosc_cases import lane, road

    widening = lane(-1, 3.0).replace('b="0"', 'b="0.01"')
    xodr = tmp_path / "widening.xodr"
    xodr.write_text(road(right=widening), encoding="utf-8")
    assert od.wide_lanes(xodr) == [
        "driving lanes wider than 6 m (road 1 lane -1: 8 m): the EOAM may swerve within one"
    ]


def test_a_catalog_entry_is_found_by_its_files_name_as_esmini_finds_it(tmp_path: Path) -> None:
    """esmini's EnvironmentCatalog.xosc declares ``<Catalog name="VehicleCatalog">``: its
    entries were "not found" though listed under the reference's catalog directory."""
    from eoam_sumo.openscenario.reader import find_entry

    (tmp_path / "EnvironmentCatalog.xosc").write_text(
        '<OpenSCENARIO><Catalog name="VehicleCatalog"><Environment name="winter"/>'
        "</Catalog></OpenSCENARIO>",
        encoding="utf-8",
    )
    found = find_entry("EnvironmentCatalog", "winter", [tmp_path])
    assert found is not None and found.tag == "Environment"
    assert find_entry("VehicleCatalog", "winter", [tmp_path]) is not None  # its declared name
    assert find_entry("EnvironmentCatalog", "summer", [tmp_path]) is None
