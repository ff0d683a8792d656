"""The review's defects, each on a tiny hand-made .xosc (no SUMO): duplicate storyboard
names, refusals in one line before the run, values never coerced silently."""

from __future__ import annotations

import itertools
from pathlib import Path
from types import SimpleNamespace
from typing import ClassVar

import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.engine import Storyboard
from eoam_sumo.openscenario.reader import read_scenario
from eoam_sumo.openscenario.story import RUNNING
from tests.openscenario.xosc_cases import GROUP, TARGET_INIT_SPEED, VEHICLE, write_case

TARGET2 = (
    '<ScenarioObject name="Target">',
    f'<ScenarioObject name="Target2">{VEHICLE}</ScenarioObject>\n'
    '    <ScenarioObject name="Target">',
)
TARGET2_INIT = (
    '<Private entityRef="Target">',
    '<Private entityRef="Target2"><PrivateAction><TeleportAction><Position><LanePosition '
    'roadId="1" laneId="-1" offset="0" s="300"/></Position></TeleportAction></PrivateAction>'
    f"{TARGET_INIT_SPEED}</Private>\n"
    '      <Private entityRef="Target">',
)


def _second_group(**names: str) -> tuple[str, str]:
    """A second maneuver group braking Target2 (its names replaced by ``names``)."""
    group = GROUP.replace('entityRef="Target"', 'entityRef="Target2"')
    for old, new in names.items():
        group = group.replace(f'name="{old}"', f'name="{new}"')
    return GROUP, GROUP + "\n" + group


def _refusal(path: Path, **params: str) -> str:
    with pytest.raises(InputError) as err:
        compile_plan(read_scenario(path, params))
    text = str(err.value)
    assert "\n" not in text
    return text


def _board(path: Path) -> Storyboard:
    scenario = read_scenario(path)
    plan = compile_plan(scenario)
    lanes = SimpleNamespace(
        table={("1", -1): None, ("1", 1): None},
        locate=lambda road, lane, s: ("1_0", s),
        has=lambda road, lane: lane in (-1, 1),
        shift_m=lambda road, lane_from, lane_to, s: 3.5 * (lane_to - lane_from),
    )
    return Storyboard(scenario.root, plan, lanes, scenario.parameters)  # type: ignore[arg-type]


def test_actions_of_one_name_in_two_groups_both_run(tmp_path: Path) -> None:
    """Names repeat across a storyboard (esmini's car_walk, acc-test): every action is kept
    by its path, so Target's brake runs beside Target2's (only the last one ran)."""
    path = write_case(tmp_path, TARGET2, TARGET2_INIT, _second_group(MG="MG2", M="M2", E="E2"))
    board = _board(path)
    actions = [e for e in board.world.elements.values() if e.kind == "Action"]
    assert [a.path for a in actions] == ["S::A::MG::M::E::Act1", "S::A::MG2::M2::E2::Act1"]
    board.world.time_s, board.world.step = 2.5, 1
    for story in board.stories:
        board._step_element(story)
    assert all(a.state == RUNNING for a in actions)
    board._step_actions(0.01)
    speeds = {n: a.speed_mps for n, a in board.world.actors.items()}
    assert speeds["Target"] == speeds["Target2"] == pytest.approx(10.0 - 5 * 0.01)


def test_whole_groups_of_one_name_run_their_own_events(tmp_path: Path) -> None:
    """Maneuver, event and action names all repeated in another group (a StopIteration
    traceback before): each event starts in its own maneuver."""
    path = write_case(tmp_path, TARGET2, TARGET2_INIT, _second_group(MG="MG2"))
    board = _board(path)
    board.world.time_s, board.world.step = 2.5, 1
    for story in board.stories:
        board._step_element(story)
    events = [e for e in board.world.elements.values() if e.kind == "Event"]
    assert [e.path for e in events] == ["S::A::MG::M::E", "S::A::MG2::M::E"]
    assert all(e.state == RUNNING for e in events)


def _state_condition(ref: str, kind: str = "event") -> tuple[str, str]:
    """Act1 of the second group starts when ``ref`` ends."""
    cond = (
        '<Condition name="C1" delay="0" conditionEdge="none"><ByValueCondition>'
        f'<StoryboardElementStateCondition storyboardElementType="{kind}" '
        f'storyboardElementRef="{ref}" state="endTransition"/></ByValueCondition></Condition>'
    )
    old, new = _second_group(MG="MG2")
    head, _, tail = new.rpartition('<Condition name="C1"')
    tail = tail[tail.index("</Condition>") + len("</Condition>") :]
    return old, head + cond + tail


def test_a_state_condition_on_a_repeated_name_must_be_qualified(tmp_path: Path) -> None:
    """Two events named E: "E" alone is ambiguous (refused in one line), "MG::M::E" is one."""
    path = write_case(tmp_path, TARGET2, TARGET2_INIT, _state_condition("E"))
    text = _refusal(path)
    assert "'E' names 2 elements" in text and "S::A::MG::M::E" in text
    path = write_case(tmp_path, TARGET2, TARGET2_INIT, _state_condition("MG::M::E"))
    compile_plan(read_scenario(path))


def test_a_state_condition_on_a_missing_element_says_so(tmp_path: Path) -> None:
    """Not "(a cycle)": the element named is not in the storyboard."""
    path = write_case(tmp_path, TARGET2, TARGET2_INIT, _state_condition("NoSuchEvent"))
    text = _refusal(path)
    assert "<StoryboardElementStateCondition> at" in text and "no event named 'NoSuchEvent'" in text


def test_two_sibling_events_of_one_name_are_both_kept(tmp_path: Path) -> None:
    """esmini's acc-test has two events named EgoSpeedEvent in one maneuver: both run (the
    second's path marked #2); a state condition naming them could not tell them apart."""
    event = GROUP[GROUP.index("<Event") : GROUP.index("</Maneuver>")]
    path = write_case(tmp_path, (event, event + event))
    events = [e.path for e in _board(path).world.elements.values() if e.kind == "Event"]
    assert events == ["S::A::MG::M::E", "S::A::MG::M::E#2"]
    cond = _state_condition("MG::M::E")[1]
    path = write_case(tmp_path, TARGET2, TARGET2_INIT, (GROUP, cond), (event, event + event))
    assert "'MG::M::E' names 2 elements (S::A::MG::M::E, S::A::MG::M::E#2)" in _refusal(path)


BRAKE_AT_2S = '<SimulationTimeCondition value="2" rule="greaterThan"/>'


@pytest.mark.parametrize(
    ("edit", "says"),
    [
        (('<EntityRef entityRef="Target"/></Actors>', '<EntityRef entityRef="Tagret"/></Actors>'),
         "<EntityRef> at .*: entity 'Tagret' is not declared"),
        ((f"<ByValueCondition>{BRAKE_AT_2S}</ByValueCondition>",
          '<ByEntityCondition><TriggeringEntities triggeringEntitiesRule="any"><EntityRef '
          'entityRef="Eg0"/></TriggeringEntities><EntityCondition><SpeedCondition value="5" '
          'rule="greaterThan"/></EntityCondition></ByEntityCondition>'),
         "<EntityRef> at .*: entity 'Eg0' is not declared"),
        ((BRAKE_AT_2S, '<VariableCondition variableRef="NoSuchVar" value="1" rule="equalTo"/>'),
         "<VariableCondition> at .*: variable 'NoSuchVar' is not declared"),
        (('<SimulationTimeCondition value="12" rule="greaterThan"/>',
          '<ParameterCondition parameterRef="Nope" value="1" rule="equalTo"/>'),
         "<ParameterCondition> at .*: parameter 'Nope' is not declared"),
        ((f"<ByValueCondition>{BRAKE_AT_2S}</ByValueCondition>", ""),
         "<Condition> at .*: a <Condition> holds exactly one element; this one is empty"),
        (('<Private entityRef="Target">', '<Private entityRef="Target"><PrivateAction/>'),
         "<PrivateAction> at .*: a <PrivateAction> holds exactly one element"),
        (('value="150"', 'value="${pow(10, 400)}"'),
         r"\${pow\(10, 400\)}: the result is too large"),
        (('value="150"', 'value="${10 ** 400}"'), r"\${10 \*\* 400}: the result is too large"),
        (('length="4.8"', 'length="nan"'), "<Dimensions> at .*: length='nan' is not a finite"),
        (('length="4.8"', 'length="0"'), "<Dimensions> at .*: length=0: a bounding box's length"),
        (('width="1.9"', 'width="-1.9"'), "<Dimensions> at .*: width=-1.9: a bounding box's"),
        (('<AbsoluteTargetSpeed value="0"/>', '<AbsoluteTargetSpeed value="-5"/>'),
         "<AbsoluteTargetSpeed> at .*: value=-5: a target speed cannot be negative"),
        (('laneId="-1" offset="0" s="50"', 'laneId="-1.5" offset="0" s="50"'),
         "<LanePosition> at .*: laneId=-1.5 is not an integer"),
        (('vehicleCategory="car"', 'vehicleCategory="train"'),
         "<Vehicle> at .*: vehicleCategory=train is not supported"),
        ((BRAKE_AT_2S.join(["<ByValueCondition>", "</ByValueCondition>"]),
          '<ByEntityCondition><TriggeringEntities triggeringEntitiesRule="any"><EntityRef '
          'entityRef="Ego"/></TriggeringEntities><EntityCondition><ReachPositionCondition '
          'tolerance="2"><Position><RelativeLanePosition entityRef="Target" dLane="0" ds="-30"/>'
          "</Position></ReachPositionCondition></EntityCondition></ByEntityCondition>"),
         "<ReachPositionCondition> at .*: only a LanePosition is supported to reach"),
    ],
)  # fmt: skip
def test_bad_input_is_refused_in_one_line_before_the_run(
    tmp_path: Path, edit: tuple[str, str], says: str
) -> None:
    """Each a traceback (KeyError, StopIteration, OverflowError) at run time, or a value
    read silently (nan, a zero-length box, laneId -1.5 as -1, a train as a car) before."""
    import re

    assert re.search(says, _refusal(write_case(tmp_path, edit)))


def _distribution(folder: Path, body: str) -> Path:
    """``folder/dist.xosc``: a parameter value distribution over ``case.xosc`` holding
    ``body`` beside its ScenarioFile."""
    dist = folder / "dist.xosc"
    dist.write_text(
        '<OpenSCENARIO><FileHeader revMajor="1" revMinor="2" date="" description="" author=""/>'
        f'<ParameterValueDistribution><ScenarioFile filepath="case.xosc"/>{body}'
        "</ParameterValueDistribution></OpenSCENARIO>",
        encoding="utf-8",
    )
    return dist


def test_nan_given_to_a_parameter_is_refused_naming_it(tmp_path: Path) -> None:
    text = _refusal(write_case(tmp_path), TargetSpeed="nan")
    assert "parameter TargetSpeed = 'nan' is not a finite number" in text


def test_a_distribution_with_only_its_scenario_file_is_refused(tmp_path: Path) -> None:
    from eoam_sumo.openscenario.variations import load_batch

    write_case(tmp_path)
    dist = _distribution(tmp_path, "")
    for read in (read_scenario, load_batch):
        with pytest.raises(InputError, match=r"no distribution .Deterministic. beside"):
            read(dist)


def _lanes(length_m: float = 500.0) -> SimpleNamespace:
    """Road 1's lanes -1 and 1 as the lane table has them (no netconvert)."""
    from eoam_sumo.openscenario.road import SumoLane

    ends = (0.0, length_m)
    table = {
        ("1", -1): [SumoLane("-1", 0, *ends, length_m, True, ends, ends)],
        ("1", 1): [SumoLane("1", 0, *ends, length_m, False, ends, ends[::-1])],
    }
    return SimpleNamespace(table=table, has=lambda road, lane: (road, lane) in table)


def _places_refusal(path: Path) -> str:
    from eoam_sumo.openscenario.checks import check_places

    scenario = read_scenario(path)
    plan = compile_plan(scenario)
    with pytest.raises(InputError) as err:
        check_places(scenario.root, plan.places, _lanes())
    return str(err.value)


def test_a_place_off_the_road_and_a_lane_change_to_no_lane_are_refused(tmp_path: Path) -> None:
    """s beyond the road's 500 m, a lane change to lane -4 (ignored silently before)."""
    text = _places_refusal(write_case(tmp_path, ('value="150"', 'value="600"')))
    assert "<LanePosition> at" in text and "s=600 m is off road 1 lane -1" in text
    lane_change = (
        "<PrivateAction><LateralAction><LaneChangeAction><LaneChangeActionDynamics "
        'dynamicsShape="sinusoidal" dynamicsDimension="time" value="3"/><LaneChangeTarget>'
        '<AbsoluteTargetLane value="-4"/></LaneChangeTarget></LaneChangeAction></LateralAction>'
        "</PrivateAction>"
    )
    from tests.openscenario.xosc_cases import BRAKE

    text = _places_refusal(write_case(tmp_path, (BRAKE, lane_change)))
    assert "<AbsoluteTargetLane> at" in text and "lane -4 is not a drivable lane" in text
    relative = lane_change.replace(
        '<AbsoluteTargetLane value="-4"/>', '<RelativeTargetLane entityRef="Target" value="-1"/>'
    )
    text = _places_refusal(write_case(tmp_path, (BRAKE, relative)))
    assert "<RelativeTargetLane> at" in text and "-1 lanes from Target's lane -1 is lane -2" in text


class _TwoWayLanes:
    """A straight two-way road: lanes -1, 1, 2 (3.5 m each), t of each centre left of s."""

    CENTRE: ClassVar[dict[int, float]] = {-1: -1.75, 1: 1.75, 2: 5.25}

    def shift_m(self, road: str, lane_from: int, lane_to: int, s_m: float) -> float:
        return self.CENTRE[lane_to] - self.CENTRE[lane_from]

    def has(self, road: str, lane: int) -> bool:
        return lane in self.CENTRE


def _lane_change(actor, lane: int, folder: Path) -> list[tuple[float, float]]:
    """(s, t) of ``actor`` at each step of a 3 s sinusoidal change to ``lane``, then 1 s on."""
    from eoam_sumo.openscenario.motions import LateralMotion
    from eoam_sumo.openscenario.xmltree import parse

    xml = folder / "lc.xml"
    xml.write_text(
        '<LaneChangeAction><LaneChangeActionDynamics dynamicsShape="sinusoidal" value="3" '
        f'dynamicsDimension="time"/><LaneChangeTarget><AbsoluteTargetLane value="{lane}"/>'
        "</LaneChangeTarget></LaneChangeAction>",
        encoding="utf-8",
    )
    node = parse(xml)
    lanes = _TwoWayLanes()
    world = SimpleNamespace(time_s=0.0, lanes=lanes, actors={})
    motion, done, out = LateralMotion(node), False, []
    motion.start(world, actor)
    for _ in range(400):
        if not done:
            done = motion.step(world, actor, 0.01)
        actor.advance(actor.speed_mps, 0.01)
        world.time_s = round(world.time_s + 0.01, 10)
        out.append((actor.s_m, lanes.CENTRE[actor.lane] + actor.offset_m))
    return out


def test_a_lane_change_across_the_centre_line_keeps_the_direction_of_travel(
    tmp_path: Path,
) -> None:
    """An overtake in the oncoming lane (esmini's): the target goes on along s in lane 1
    (it turned round when it reached lane +1, its direction taken from the lane's sign)."""
    from eoam_sumo.openscenario.actors import Actor
    from eoam_sumo.openscenario.model import Body

    actor = Actor("c", Body("c", 4.0, 1.8, 1.5, "car"), "1", -1, 100.0, 0.0, 10.0)
    path = _lane_change(actor, 1, tmp_path)
    assert (actor.lane, actor.direction) == (1, 1)
    assert all(b[0] > a[0] for a, b in itertools.pairwise(path))  # on along s
    assert path[-1] == pytest.approx((140.0, 1.75))
    assert max(abs(b[1] - a[1]) for a, b in itertools.pairwise(path)) < 0.02


def test_a_lane_change_against_s_moves_towards_its_target_lane(tmp_path: Path) -> None:
    """A target in lane 1 (against s) to lane 2: the offset (left of s) grows to +3.5 m, no
    jump at the end (it went to -3.5 m and jumped 7 m)."""
    from eoam_sumo.openscenario.actors import Actor
    from eoam_sumo.openscenario.model import Body

    actor = Actor("c", Body("c", 4.0, 1.8, 1.5, "car"), "1", 1, 300.0, 0.0, 10.0)
    path = _lane_change(actor, 2, tmp_path)
    assert (actor.lane, actor.direction) == (2, -1)
    assert path[-1] == pytest.approx((260.0, 5.25))
    assert max(abs(b[1] - a[1]) for a, b in itertools.pairwise(path)) < 0.02


def _init_target(action: str) -> tuple[str, str]:
    """The target's Init speed step replaced by ``action`` (a PrivateAction's child)."""
    from tests.openscenario.xosc_cases import TARGET_INIT_SPEED

    return TARGET_INIT_SPEED, f"<PrivateAction>{action}</PrivateAction>"


LINEAR_TO_25 = (
    '<LongitudinalAction><SpeedAction><SpeedActionDynamics dynamicsShape="linear" '
    'dynamicsDimension="rate" value="2"/><SpeedActionTarget><AbsoluteTargetSpeed value="25"/>'
    "</SpeedActionTarget></SpeedAction></LongitudinalAction>"
)


def test_an_init_speed_change_with_a_shape_runs_from_time_0(tmp_path: Path) -> None:
    """Init actions execute at time 0; a linear one runs over its duration (2 m/s^2 from
    standstill to 25 m/s): the target stayed at 0 (dropped silently)."""
    board = _board(write_case(tmp_path, _init_target(LINEAR_TO_25)))
    assert board.plan.speeds_mps.get("Target", 0.0) == 0.0
    board._start_init()
    for k in range(1, 201):
        board.world.time_s = round((k - 1) * 0.01, 10)
        board._step_actions(0.01)
    assert board.world.actors["Target"].speed_mps == pytest.approx(4.0)


def test_an_init_lane_offset_runs_from_time_0(tmp_path: Path) -> None:
    offset = (
        '<LateralAction><LaneOffsetAction continuous="false"><LaneOffsetActionDynamics '
        'dynamicsShape="sinusoidal" maxLateralAcc="1"/><LaneOffsetTarget>'
        '<AbsoluteTargetLaneOffset value="1.0"/></LaneOffsetTarget></LaneOffsetAction>'
        "</LateralAction>"
    )
    from tests.openscenario.xosc_cases import TARGET_INIT_SPEED

    edit = (TARGET_INIT_SPEED, f"{TARGET_INIT_SPEED}<PrivateAction>{offset}</PrivateAction>")
    board = _board(write_case(tmp_path, edit))
    board._start_init()
    for k in range(1, 401):
        board.world.time_s = round((k - 1) * 0.01, 10)
        board._step_actions(0.01)
    target = board.world.actors["Target"]
    assert (target.offset_m, target.speed_mps) == (pytest.approx(1.0), 10.0)


def test_the_ego_init_speed_over_no_time_is_a_step_and_a_ramp_is_refused(tmp_path: Path) -> None:
    """esmini's override_bb: the ego's Init speed 'linear' over time 0 is its departure
    speed; a ramp of the ego's speed (the EOAM's to drive) is refused in one line."""
    from tests.openscenario.xosc_cases import STEP

    over_0 = STEP.replace('"step"', '"linear"')
    plan = compile_plan(read_scenario(write_case(tmp_path, (STEP, over_0))))
    assert plan.speeds_mps == {"Ego": 20.0, "Target": 10.0} and plan.init_actions == []
    ego_speed = '<SpeedActionTarget><AbsoluteTargetSpeed value="$EgoSpeed"/>'
    linear = '<SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="2"/>'
    ramp = (STEP + ego_speed, linear + ego_speed)
    text = _refusal(write_case(tmp_path, ramp))
    assert "<LongitudinalAction> at" in text and "the ego Ego's Init must" in text


def test_left_hand_traffic_is_refused_and_wide_lanes_noted(tmp_path: Path) -> None:
    """rule="LHT" was ignored (esmini's left-hand-traffic_using_road_rule ended after 0.01 s,
    exit 0); Vector's NCAP road has one 28 m lane each way (a note says so)."""
    from eoam_sumo.openscenario import road as od
    from tests.openscenario.xosc_cases import lane, road

    lht = tmp_path / "lht.xodr"
    lht.write_text(road(rule="LHT"), encoding="utf-8")
    with pytest.raises(InputError, match=r'lht.xodr: road 1 has rule="LHT": left-hand traffic'):
        od.check_road(lht)
    wide = tmp_path / "wide.xodr"
    wide.write_text(road(lane(1, 28.0), lane(-1, 28.0) + lane(-2, 3.5)), encoding="utf-8")
    od.check_road(wide)
    assert od.wide_lanes(wide) == [
        "driving lanes wider than 6 m (road 1 lane 1: 28 m, road 1 lane -1: 28 m): the EOAM "
        "may swerve within one"
    ]
    assert od.wide_lanes(lht) == []


def test_parameters_declared_in_a_story_are_in_scope_there(tmp_path: Path) -> None:
    """esmini's cut-in declares $owner in its Story (18 of its files were refused with
    "$owner is not declared")."""
    story = (
        '<Story name="S">',
        '<Story name="S"><ParameterDeclarations><ParameterDeclaration name="owner" '
        'parameterType="string" value="Target"/></ParameterDeclarations>',
    )
    actors = (
        '<EntityRef entityRef="Target"/></Actors>',
        '<EntityRef entityRef="$owner"/></Actors>',
    )
    path = write_case(tmp_path, story, actors)
    board = _board(path)
    assert [e.actors for e in board.world.elements.values() if e.kind == "Event"] == [("Target",)]


def _catalog(folder: Path) -> tuple[str, str]:
    """Target's vehicle from a catalog entry declaring Length (an edit of the case)."""
    (folder / "cat").mkdir()
    entry = VEHICLE.replace('length="4.8"', 'length="$Length"').replace(
        "<BoundingBox>",
        '<ParameterDeclarations><ParameterDeclaration name="Length" parameterType="double" '
        'value="4.8"/></ParameterDeclarations><BoundingBox>',
    )
    (folder / "cat" / "vehicles.xosc").write_text(
        f'<OpenSCENARIO><Catalog name="VehicleCatalog">{entry}</Catalog></OpenSCENARIO>',
        encoding="utf-8",
    )
    return (f'<ScenarioObject name="Target">{VEHICLE}', '<ScenarioObject name="Target">'
            '<CatalogReference catalogName="VehicleCatalog" entryName="car">'
            '<ParameterAssignments><ParameterAssignment parameterRef="REF" value="5.5"/>'
            "</ParameterAssignments></CatalogReference>")  # fmt: skip


def test_a_catalog_assignment_names_what_is_wrong(tmp_path: Path) -> None:
    """A catalog entry's undeclared parameter was reported as "--param X: no such parameter
    declared"; esmini's "$Name" form of parameterRef is read as Name."""
    locations = ("<CatalogLocations/>", '<CatalogLocations><VehicleCatalog><Directory path="cat"/>'
                 "</VehicleCatalog></CatalogLocations>")  # fmt: skip
    old, new = _catalog(tmp_path)
    path = write_case(tmp_path, locations, (old, new.replace("REF", "$Length")))
    assert compile_plan(read_scenario(path)).bodies["Target"].length_m == 5.5
    path = write_case(tmp_path, locations, (old, new.replace("REF", "Lenght")))
    text = _refusal(path)
    assert "<ParameterAssignment> at" in text and "VehicleCatalog/car declares no parameter" in text
    assert "--param" not in text


def test_a_distribution_setting_an_undeclared_parameter_says_so(tmp_path: Path) -> None:
    write_case(tmp_path)
    dist = _distribution(
        tmp_path,
        '<Deterministic><DeterministicSingleParameterDistribution parameterName="Speeed">'
        '<DistributionSet><Element value="3"/></DistributionSet>'
        "</DeterministicSingleParameterDistribution></Deterministic>",
    )
    with pytest.raises(InputError, match=r"dist.xosc:1: sets parameter Speeed, which .*case"):
        read_scenario(dist)


def test_sumo_ids_are_safe_and_unique_and_the_vtypes_well_formed() -> None:
    """Names with &, ", a space broke the SUMO files; a target named ego beside --ego Ego
    gave a duplicate route id."""
    import xml.etree.ElementTree as ET

    from eoam_sumo.openscenario.model import Body, Plan
    from eoam_sumo.openscenario.sumofiles import _vtype

    names = ["Ego", "A&B", "A_B", 'Tar"get', "Target car 1", "ego"]
    bodies = {n: Body(n, 4.8, 1.9, 1.4, "car") for n in names}
    ids = Plan(bodies, "Ego", {}, {}).sumo_ids()
    assert ids == {"Ego": "ego", "A&B": "A_B", "A_B": "A_B_2", 'Tar"get': "Tar_get",
                   "Target car 1": "Target_car_1", "ego": "ego_2"}  # fmt: skip
    for name in names[1:]:
        assert ET.fromstring(_vtype(bodies[name], ids[name])).get("id") == f"t_{ids[name]}"


def test_an_act_may_start_on_its_story_running(tmp_path: Path) -> None:
    """esmini's follow_ghost starts its Act when the Story runs: "never timed (a cycle)"."""
    from tests.openscenario.xosc_cases import ACT_START

    story_runs = ACT_START.replace(
        '<SimulationTimeCondition value="0" rule="greaterOrEqual"/>',
        '<StoryboardElementStateCondition storyboardElementType="story" '
        'storyboardElementRef="S" state="runningState"/>',
    )
    compile_plan(read_scenario(write_case(tmp_path, (ACT_START, story_runs))))


NET = """<net>
<edge id="-1#0" from="a" to="b" priority="1">
 <lane id="-1#0_0" index="0" length="97" shape="0,-1.75 97,-1.75">
  <param key="origId" value="1_-1"/></lane></edge>
<edge id="-1#1" from="b" to="c" priority="1">
 <lane id="-1#1_0" index="0" length="97" shape="103,-5.25 200,-5.25">
  <param key="origId" value="1_-2"/></lane>
 <lane id="-1#1_1" index="1" length="97" shape="103,-1.75 200,-1.75">
  <param key="origId" value="1_-1"/></lane></edge>
<junction id="a" x="0" y="0"/><junction id="b" x="100" y="0"/><junction id="c" x="200" y="0"/>
</net>
"""


def test_a_lane_from_a_later_section_starts_where_its_section_starts(tmp_path: Path) -> None:
    """A 2+1 road's lane -2 exists from s = 100 m (the second edge): s = 150 m is 50 m into
    it, at x = 150 (it was scaled over the whole road: x = 175 for 100 m of lane); s = 50 m
    is refused (there is no lane -2 there); s in the junction gap moves on continuously."""
    from eoam_sumo.openscenario.lanetable import lane_table
    from eoam_sumo.openscenario.road import locate
    from tests.openscenario.xosc_cases import road

    (tmp_path / "n.net.xml").write_text(NET, encoding="utf-8")
    (tmp_path / "r.xodr").write_text(road(length_m=200.0), encoding="utf-8")
    table = lane_table(tmp_path / "n.net.xml", tmp_path / "r.xodr")
    lane, pos = locate(table, "1", -2, 150.0, "w")
    assert (lane.edge, pos) == ("-1#1", pytest.approx(47.0))  # its shape starts at x = 103
    assert lane.s_m(pos) == pytest.approx(150.0)
    with pytest.raises(InputError, match="s=50 m is off road 1 lane -2"):
        locate(table, "1", -2, 50.0, "w")
    gap = [locate(table, "1", -1, s, "w") for s in (96.0, 99.0, 101.0, 104.0)]
    assert [(sl.edge, round(p, 6)) for sl, p in gap] == [
        ("-1#0", 96.0),
        ("-1#0", 99.0),
        ("-1#1", -2.0),
        ("-1#1", 1.0),
    ]


@pytest.mark.sumo
def test_batch_checks_every_case_on_its_road_before_any_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A case's lane change to a lane the road does not have: refused before the batch
    runs (it failed in its worker, after the output folder was written)."""
    from eoam_sumo.openscenario.batch import check_cases
    from eoam_sumo.openscenario.variations import XoscBatch
    from tests.openscenario.xosc_cases import BRAKE

    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))
    lane_change = (
        "<PrivateAction><LateralAction><LaneChangeAction><LaneChangeActionDynamics "
        'dynamicsShape="sinusoidal" dynamicsDimension="time" value="3"/><LaneChangeTarget>'
        '<AbsoluteTargetLane value="-4"/></LaneChangeTarget></LaneChangeAction></LateralAction>'
        "</PrivateAction>"
    )
    path = write_case(tmp_path, (BRAKE, lane_change))
    with pytest.raises(InputError, match=r"case00000 \(TargetSpeed=5\): <AbsoluteTargetLane>"):
        check_cases(XoscBatch(path, [{"TargetSpeed": "5"}], 0))
