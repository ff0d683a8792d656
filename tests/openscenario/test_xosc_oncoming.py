"""Entities heading opposite ways (the review's #13, #14, #16): time to collision and relative
speed from the velocities along the line between them, freespace gaps between the nearer
ends of the boxes, and a ``LongitudinalDistanceAction`` that keeps the entity's own lane and
lateral offset. Figures from the kinematics, not from the code's earlier runs."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.actors import Actor, longitudinal_gap_m
from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.conditions import ENTITY, by_entity
from eoam_sumo.openscenario.model import Body
from eoam_sumo.openscenario.placing import place_now
from eoam_sumo.openscenario.reader import read_scenario
from eoam_sumo.openscenario.xmltree import Node
from tests.openscenario.xosc_cases import STEP, VEHICLE, lane, road

CAR = Body("c", 4.0, 1.8, 1.5, "car")  # front 3.5 m ahead of the reference point, rear 0.5 behind
BOX = Body("v", 4.5, 1.8, 1.5, "car")  # the review's: front 3.75 m ahead, rear 0.75 m behind
NCAP = Path(__file__).parents[1] / "data/openscenario/ncap/OpenSCENARIO/NCAP/CA-FC_2026"
SINGLE = NCAP / "Variations" / "SingleExecution"


def _node(tag: str, attrib: dict, *children: Node) -> Node:
    return Node(tag, attrib, Path("-"), 1, list(children))


def _ttc(value: float, free: bool, target: str = "Ego") -> Node:
    ref = _node("TimeToCollisionConditionTarget", {}, _node("EntityRef", {"entityRef": target}))
    attrib = {"value": str(value), "rule": "lessThan", "freespace": str(free).lower()}
    return _node(
        "TimeToCollisionCondition", {**attrib, "relativeDistanceType": "longitudinal"}, ref
    )


def _fired(cond: Node, me: Actor, other: Actor, until_s: float) -> list[float]:
    """The times (each 0.01 s, after the step) at which ``cond`` of ``me`` holds."""
    world = SimpleNamespace(actors={me.name: me, other.name: other})
    check, out = ENTITY[cond.tag], []
    for k in range(1, round(until_s / 0.01) + 1):
        me.advance(me.speed_mps, 0.01)
        other.advance(other.speed_mps, 0.01)
        if check(cond, world, me):
            out.append(round(k * 0.01, 2))
    return out


def _oncoming() -> tuple[Actor, Actor]:
    """The review's s13b: Ego lane -1 at s 50, 20 m/s; O in lane 1 at s 400, 10 m/s."""
    return Actor("Ego", BOX, "1", -1, 50.0, 0.0, 20.0), Actor("O", BOX, "1", 1, 400.0, 0.0, 10.0)


def test_ttc_of_cars_driving_towards_each_other_uses_the_sum_of_their_speeds() -> None:
    """350 m apart closing at 30 m/s: TTC < 4 s once 350 - 30 t < 120, from 7.67 s, until
    they pass at 11.67 s; after that the gap opens: no time to collision."""
    ego, o = _oncoming()
    fired = _fired(_ttc(4, False), o, ego, 20.0)
    assert fired[0] == pytest.approx(7.67) and fired[-1] == pytest.approx(11.66)
    assert len(fired) == round((11.66 - 7.67) / 0.01) + 1  # every step between, none after
    ego, o = _oncoming()  # the other way round: the same
    assert _fired(_ttc(4, False, "O"), ego, o, 20.0)[0] == pytest.approx(7.67)


def test_ttc_freespace_between_cars_facing_each_other_is_between_their_fronts() -> None:
    """The fronts 400 - 3.75 - (50 + 3.75) = 342.5 m apart: TTC < 4 s from (342.5 - 120) / 30
    = 7.42 s."""
    ego, o = _oncoming()
    assert _fired(_ttc(4, True), o, ego, 20.0)[0] == pytest.approx(7.42)


def test_ttc_in_one_direction_closes_on_the_speed_difference() -> None:
    """Ego at 20 m/s 100 m behind L at 10 m/s: TTC < 2.995 s once 100 - 10 t < 29.95, from
    7.01 s; L's own TTC to the faster ego coming from behind is the same (as esmini's)."""
    ego, lead = (
        Actor("Ego", BOX, "1", -1, 50.0, 0.0, 20.0),
        Actor("L", BOX, "1", -2, 150.0, 0, 10.0),
    )
    assert _fired(_ttc(2.995, False, "L"), ego, lead, 9.0)[0] == pytest.approx(7.01)
    ego, lead = (
        Actor("Ego", BOX, "1", -1, 50.0, 0.0, 20.0),
        Actor("L", BOX, "1", -2, 150.0, 0, 10.0),
    )
    assert _fired(_ttc(2.995, False), lead, ego, 9.0)[0] == pytest.approx(7.01)


def _relative_speed(value: float, **attrib: str) -> Node:
    attrib = {"entityRef": "Ego", "value": str(value), "rule": "greaterThan", **attrib}
    return _node("RelativeSpeedCondition", attrib)


def test_relative_speed_is_the_standards_difference_and_longitudinal_projects_it() -> None:
    """OpenSCENARIO 1.2: speed_rel = speed(triggering) - speed(reference): O at 10 m/s to the
    ego at 20 m/s is -10 m/s whatever their headings; with direction="longitudinal" the
    ego's velocity along O's heading is -20 m/s: 10 - (-20) = +30 m/s."""
    ego, o = _oncoming()
    world = SimpleNamespace(actors={"Ego": ego, "O": o})
    check = ENTITY["RelativeSpeedCondition"]
    assert check(_relative_speed(-10.1), world, o) and not check(_relative_speed(-9.9), world, o)
    along = {"direction": "longitudinal"}
    assert check(_relative_speed(29.9, **along), world, o)
    assert not check(_relative_speed(30.1, **along), world, o)
    same = Actor("L", BOX, "1", -2, 150.0, 0.0, 10.0)  # one direction: both readings agree
    world.actors["L"] = same
    assert check(_relative_speed(-10.1, **along), world, same)
    assert not check(_relative_speed(-9.9, **along), world, same)


def test_relative_speed_lateral_is_refused_before_the_run() -> None:
    cond = _node(
        "ByEntityCondition",
        {},
        _node("TriggeringEntities", {}, _node("EntityRef", {"entityRef": "O"})),
        _node("EntityCondition", {}, _relative_speed(1.0, direction="lateral")),
    )
    with pytest.raises(InputError, match="only direction=longitudinal"):
        by_entity(cond)


def test_freespace_gap_of_cars_facing_each_other_is_front_to_front() -> None:
    """Front bumpers at 103.5 m and 196.5 m: 93 m, seen from either car; once past each other
    (O at s 50: its rear, now the nearer end, at 50.5) -49 m, each behind the other."""
    me = Actor("me", CAR, "0", -1, 100.0, 0.0, 10.0)
    other = Actor("o", CAR, "0", 1, 200.0, 0.0, 10.0)
    assert longitudinal_gap_m(me, other, True) == pytest.approx(93.0)
    assert longitudinal_gap_m(other, me, True) == pytest.approx(93.0)
    other.s_m = 50.0
    assert longitudinal_gap_m(me, other, True) == pytest.approx(50.5 - 99.5)
    assert longitudinal_gap_m(other, me, True) == pytest.approx(50.5 - 99.5)  # behind it


def _distance_action(**attrib: str) -> Node:
    inner = {"entityRef": "Ego", "freespace": "false", "continuous": "false", **attrib}
    return _node("LongitudinalAction", {}, _node("LongitudinalDistanceAction", inner))


def test_a_longitudinal_distance_keeps_the_entitys_lane_and_offset() -> None:
    """The review's s18: B in lane -1 (0.3 m off centre) 2 s ahead of the ego (lane -2,
    20 m/s): 40 m ahead, still in lane -1 and 0.3 m off its centre."""
    ego = Actor("Ego", CAR, "1", -2, 100.0, 0.0, 20.0)
    b = Actor("B", CAR, "1", -1, 80.0, 0.3, 20.0)
    place_now(SimpleNamespace(actors={"Ego": ego, "B": b}), b, _distance_action(timeGap="2"))
    assert (b.road, b.lane, b.offset_m, b.direction, b.s_m) == ("1", -1, 0.3, 1, 140.0)


def test_a_longitudinal_distance_to_an_oncoming_car_measures_to_its_front() -> None:
    """The review's s17: O oncoming in lane 2, 50 m ahead of the ego: it stays in lane 2,
    heading against s; freespace, its front (3.5 m before its reference point) is 50 m ahead
    of the ego's front (103.5 m): O at 157 m."""
    ego = Actor("Ego", CAR, "1", -1, 100.0, 0.0, 20.0)
    o = Actor("O", CAR, "1", 2, 300.0, 0.0, 10.0)
    world = SimpleNamespace(actors={"Ego": ego, "O": o})
    place_now(world, o, _distance_action(distance="50"))
    assert (o.lane, o.direction, o.s_m) == (2, -1, 150.0)
    place_now(world, o, _distance_action(distance="50", freespace="true"))
    assert (o.lane, o.s_m) == (2, 157.0)
    assert longitudinal_gap_m(ego, o, True) == pytest.approx(50.0)


@pytest.mark.parametrize("impact", ["0", "25", "100"])
def test_ccrb_keeps_the_impact_locations_offset_as_ccrs(impact: str) -> None:
    """Vector's CCRb places its target with CCRs's offset (ImpactLocation / 100 * Ego_width -
    Ego_width / 2), then sets its gap with a LongitudinalDistanceAction at time 0: the offset
    stays (it was the ego's, 0, at every impact location)."""
    params = {"ImpactLocation": impact}
    ccrb = compile_plan(read_scenario(SINGLE / "CCRb_50kph.xosc", params))
    ccrs = compile_plan(read_scenario(SINGLE / "CCRs_50kph.xosc", params))
    width = ccrb.bodies["Ego"].width_m
    want = float(impact) / 100 * width - width / 2
    assert ccrb.places["Target"].offset_m == pytest.approx(want)
    assert ccrs.places["Target"].offset_m == pytest.approx(want)
    assert ccrb.places["Target"].lane == ccrb.places["Ego"].lane


def _private(name: str, lane_id: int, s_m: float, speed: float) -> str:
    return (
        f'<Private entityRef="{name}"><PrivateAction><TeleportAction><Position><LanePosition '
        f'roadId="1" laneId="{lane_id}" offset="0" s="{s_m}"/></Position></TeleportAction>'
        f"</PrivateAction><PrivateAction><LongitudinalAction><SpeedAction>{STEP}"
        f'<SpeedActionTarget><AbsoluteTargetSpeed value="{speed}"/></SpeedActionTarget>'
        "</SpeedAction></LongitudinalAction></PrivateAction></Private>"
    )


def _event(actor: str, action: str, condition: str) -> str:
    return (
        f'<ManeuverGroup maximumExecutionCount="1" name="G{actor}"><Actors '
        f'selectTriggeringEntities="false"><EntityRef entityRef="{actor}"/></Actors><Maneuver '
        f'name="M{actor}"><Event name="E{actor}" priority="override"><Action name="A{actor}">'
        f"<PrivateAction><LongitudinalAction>{action}</LongitudinalAction></PrivateAction>"
        f'</Action><StartTrigger><ConditionGroup><Condition name="C{actor}" delay="0" '
        f'conditionEdge="rising">{condition}</Condition></ConditionGroup></StartTrigger>'
        "</Event></Maneuver></ManeuverGroup>"
    )


TO_30 = (
    f'<SpeedAction>{STEP}<SpeedActionTarget><AbsoluteTargetSpeed value="30"/>'
    "</SpeedActionTarget></SpeedAction>"
)


def _of_o(inner: str) -> str:
    return (
        '<ByEntityCondition><TriggeringEntities triggeringEntitiesRule="any"><EntityRef '
        f'entityRef="O"/></TriggeringEntities><EntityCondition>{inner}</EntityCondition>'
        "</ByEntityCondition>"
    )


def _oncoming_case(folder: Path) -> Path:
    """Ego lane -1 at s 50, 20 m/s; O oncoming in lane 1 at s 402, 10 m/s. P (lane -2) steps
    to 30 m/s on O's TTC to the ego < 4 s; Q (lane -2) on O's freespace distance < 100 m;
    B, oncoming in lane 2, is put 60 m (freespace) ahead of the ego at 1 s."""
    ttc = '<TimeToCollisionCondition value="4" freespace="false" rule="lessThan" '
    ttc += 'relativeDistanceType="longitudinal"><TimeToCollisionConditionTarget>'
    ttc += (
        '<EntityRef entityRef="Ego"/></TimeToCollisionConditionTarget></TimeToCollisionCondition>'
    )
    dist = '<RelativeDistanceCondition entityRef="Ego" relativeDistanceType="longitudinal" '
    dist += 'value="100" freespace="true" rule="lessThan"/>'
    at_1 = '<ByValueCondition><SimulationTimeCondition value="1" rule="greaterOrEqual"/>'
    place = '<LongitudinalDistanceAction entityRef="Ego" distance="60" freespace="true" '
    place += 'continuous="false" displacement="leadingReferencedEntity"/>'
    names = ("Ego", "O", "P", "Q", "B")
    entities = "".join(f'<ScenarioObject name="{n}">{VEHICLE}</ScenarioObject>' for n in names)
    inits = [("Ego", -1, 50, 20), ("O", 1, 402, 10), ("P", -2, 20, 10), ("Q", -2, 0, 10)]
    init = "".join(_private(*i) for i in [*inits, ("B", 2, 480, 10)])
    groups = _event("P", TO_30, _of_o(ttc)) + _event("Q", TO_30, _of_o(dist))
    groups += _event("B", place, at_1 + "</ByValueCondition>")
    text = f"""<?xml version="1.0" encoding="UTF-8"?>
<OpenSCENARIO><FileHeader revMajor="1" revMinor="2" date="2024-01-01T00:00:00" description="t"
 author="t"/><ParameterDeclarations/><CatalogLocations/>
<RoadNetwork><LogicFile filepath="road.xodr"/></RoadNetwork><Entities>{entities}</Entities>
<Storyboard><Init><Actions>{init}</Actions></Init><Story name="S"><Act name="A">{groups}
<StartTrigger><ConditionGroup><Condition name="C0" delay="0" conditionEdge="none">
<ByValueCondition><SimulationTimeCondition value="0" rule="greaterOrEqual"/></ByValueCondition>
</Condition></ConditionGroup></StartTrigger></Act></Story>
<StopTrigger><ConditionGroup><Condition name="Stop" delay="0" conditionEdge="rising">
<ByValueCondition><SimulationTimeCondition value="10" rule="greaterThan"/></ByValueCondition>
</Condition></ConditionGroup></StopTrigger></Storyboard></OpenSCENARIO>
"""
    both = road(left=lane(2) + lane(1), right=lane(-1) + lane(-2), length_m=1000.0)
    (folder / "road.xodr").write_text(both, encoding="utf-8")
    (folder / "case.xosc").write_text(text, encoding="utf-8")
    return folder / "case.xosc"


@pytest.mark.sumo
def test_oncoming_conditions_and_placement_in_a_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """In the co-simulation (fronts 3.8 m ahead of the reference points): P steps up once
    352 - 30 t < 120 (TTC < 4 s, from scenario time 7.74 s), Q once the fronts are 100 m
    apart (402 - 3.8 - 53.8 - 30 t < 100: 8.15 s), each at 30 m/s from the next step; B
    stays in its lane (y 5.25 m), its front 60 m before the ego's; nothing collides."""
    from eoam_sumo.cli import main

    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "o"
    argv = ["run", str(_oncoming_case(tmp_path)), "--system", "aeb", "--out", str(out)]
    assert main([*argv, "--max-time-s", "12"]) == 0
    rows = list(csv.DictReader((out / "traffic.csv").open()))

    def first_fast(vid: str) -> float:
        return min(
            float(r["time_s"]) for r in rows if r["id"] == vid and float(r["speed_mps"]) > 20
        )

    assert first_fast("P") - 1.0 == pytest.approx(7.74 + 0.01, abs=0.015)
    assert first_fast("Q") - 1.0 == pytest.approx(8.15 + 0.01, abs=0.015)
    at = {r["id"]: r for r in rows if r["time_s"] == "2.02"}  # just after B's placement
    b, ego = at["B"], at["ego"]
    assert float(b["y_m"]) == pytest.approx(5.25, abs=0.01)
    fronts = (
        float(b["x_m"]) - float(b["length_m"]) / 2 - float(ego["x_m"]) - float(ego["length_m"]) / 2
    )
    assert fronts == pytest.approx(60.0 - 30 * 0.02, abs=0.35)
    assert json.loads((out / "summary.json").read_text())["collision_with"] == "none"
