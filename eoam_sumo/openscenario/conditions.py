"""Conditions evaluated at run time (OpenSCENARIO 1.2 sec. 7.4), each a small function of the
world at the step's end: by value (time, parameters, variables, storyboard element states)
and by entity (distances, headway, time to collision, speeds, standstill, travelled
distance, reached positions, collisions), ``triggeringEntitiesRule`` any or all."""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from typing import Any

from eoam_sumo.openscenario.actors import (
    Actor,
    euclid,
    gap_rate_mps,
    lateral_gap_m,
    longitudinal_gap_m,
)
from eoam_sumo.openscenario.subset import refuse
from eoam_sumo.openscenario.xmltree import Node

RULES: dict[str, Callable[[float, float], bool]] = {
    "greaterThan": operator.gt,
    "lessThan": operator.lt,
    "equalTo": lambda a, b: abs(a - b) < 1e-9,
    "greaterOrEqual": operator.ge,
    "lessOrEqual": operator.le,
    "notEqualTo": lambda a, b: abs(a - b) >= 1e-9,
}


def compare(node: Node, have: float, key: str = "value") -> bool:
    rule = node.need("rule")
    if rule not in RULES:
        raise refuse(node, f"rule={rule} is not supported")
    return RULES[rule](have, node.num(key))


def _text_or_number(node: Node, have: str, want: str) -> bool:
    try:
        return RULES[node.need("rule")](float(have), float(want))
    except ValueError:
        same = have.strip().lower() == want.strip().lower()
        return same == (node.need("rule") != "notEqualTo")


def by_value(node: Node, world) -> bool:
    """A ``ByValueCondition``'s inner condition now."""
    tag = node.tag
    if tag == "SimulationTimeCondition":
        return compare(node, world.time_s)
    if tag == "ParameterCondition":
        have = node.parameters(world.parameters)[node.need("parameterRef")]
        return _text_or_number(node, have, node.need("value"))
    if tag == "VariableCondition":
        return _text_or_number(node, world.variables[node.need("variableRef")], node.need("value"))
    if tag == "StoryboardElementStateCondition":
        return world.element_state(node)
    raise refuse(node, f"{tag} is not supported at run time")


def by_entity(cond: Node) -> Callable[[Any], bool]:
    """A ``ByEntityCondition`` as a function of the world: its condition for each triggering
    entity, any or all (the nodes looked up once, not at every step)."""
    trig = cond.find("TriggeringEntities")
    inner = cond.find("EntityCondition").children[0]  # type: ignore[union-attr]
    assert trig is not None
    names = [r.need("entityRef") for r in trig.findall("EntityRef")]
    check = ENTITY.get(inner.tag)
    if check is None:
        raise refuse(inner, f"{inner.tag} is not supported at run time")
    if inner.tag == "RelativeSpeedCondition" and inner.get("direction") not in (
        None,
        "longitudinal",
    ):
        raise refuse(inner, "only direction=longitudinal (or none) is supported")
    combine = any if trig.get("triggeringEntitiesRule", "any") == "any" else all

    def holds(world) -> bool:
        return combine([check(inner, world, world.actors[n]) for n in names])

    return holds


def _free(node: Node) -> bool:
    return node.get("freespace") in ("true", "1")


def _relative_distance(node: Node, world, me: Actor) -> bool:
    other = world.actors[node.need("entityRef")]
    kind = node.get("relativeDistanceType", "cartesianDistance")
    if kind == "longitudinal":
        d = abs(longitudinal_gap_m(me, other, _free(node)))
    elif kind == "lateral":
        d = lateral_gap_m(world.lateral_m(me), world.lateral_m(other), me, other, _free(node))
    else:
        d = euclid(world.xy(me), world.xy(other))
        if _free(node):
            d = max(0.0, d - (me.body.length_m + other.body.length_m) / 2)
    return compare(node, d)


def _headway(node: Node, world, me: Actor) -> bool:
    gap = longitudinal_gap_m(me, world.actors[node.need("entityRef")], _free(node))
    return compare(node, gap / me.speed_mps if gap > 0 and me.speed_mps > 0 else math.inf)


def _ttc(node: Node, world, me: Actor) -> bool:
    """``TimeToCollisionCondition`` to an entity: the gap along ``me``'s direction (reference
    points, or freespace) over the speed it closes at, both velocities taken along that
    direction (heading towards each other: the sum of the speeds). Infinite while the gap
    opens (once they have passed), as esmini (``Object::TimeToCollision``: undefined when
    moving away); boxes overlapping (freespace 0) close or open by their reference points."""
    target = node.find("TimeToCollisionConditionTarget")
    ref = None if target is None else target.find("EntityRef")
    if ref is None:
        raise refuse(node, "only an entity as the time-to-collision target is supported")
    other = world.actors[ref.need("entityRef")]
    gap = longitudinal_gap_m(me, other, _free(node))
    side = gap if gap != 0.0 else longitudinal_gap_m(me, other, False)
    closing = -gap_rate_mps(me, other) * (1 if side >= 0 else -1)
    return compare(node, abs(gap) / closing if closing > 0 else math.inf)


def _reach(node: Node, world, me: Actor) -> bool:
    pos = node.find("Position")
    lane = None if pos is None else pos.find("LanePosition")
    if lane is None:
        raise refuse(node, "only a LanePosition is supported to reach")
    road, lane_id = lane.need("roadId"), int(lane.num("laneId"))
    x, y, _ = world.lanes.point(road, lane_id, lane.num("s"), lane.num("offset", 0.0))
    return euclid(world.xy(me), (x, y)) <= node.num("tolerance")


def _relative_speed(node: Node, world, me: Actor) -> bool:
    """``RelativeSpeedCondition``: "speed_rel = speed(triggering entity) - speed(reference
    entity)" (OpenSCENARIO 1.2), the speeds' difference whatever the headings (towards each
    other at 20 and 10 m/s: +10 m/s, not the approach); with ``direction="longitudinal"``
    the projection on that axis "with the triggering entity as the reference": its speed
    less the reference's velocity along its heading (towards each other: the sum)."""
    other = world.actors[node.need("entityRef")]
    if node.get("direction") == "longitudinal":
        return compare(node, -gap_rate_mps(me, other))
    return compare(node, me.speed_mps - other.speed_mps)


ENTITY: dict[str, Callable[[Node, Any, Actor], bool]] = {
    "RelativeDistanceCondition": _relative_distance,
    "TimeHeadwayCondition": _headway,
    "TimeToCollisionCondition": _ttc,
    "ReachPositionCondition": _reach,
    "RelativeSpeedCondition": _relative_speed,
    "SpeedCondition": lambda n, w, me: compare(n, me.speed_mps),
    "AccelerationCondition": lambda n, w, me: compare(n, me.accel_mps2),
    "StandStillCondition": lambda n, w, me: me.still_s >= n.num("duration"),
    "TraveledDistanceCondition": lambda n, w, me: me.odometer_m >= n.num("value"),
    "CollisionCondition": lambda n, w, me: me.name in w.collided,
}
