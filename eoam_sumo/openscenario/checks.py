"""References checked before the run: every entity, variable and parameter a storyboard
names must be declared (OpenSCENARIO 1.2 sec. 7.1, 8.4), else one line naming the element.

Run by :mod:`.compile` once the entities are known, so that nothing fails at run time on a
misspelt name (a KeyError deep in a condition after the output folder is written).
"""

from __future__ import annotations

from eoam_sumo.openscenario.actors import lane_plus
from eoam_sumo.openscenario.road import locate
from eoam_sumo.openscenario.subset import invalid
from eoam_sumo.openscenario.xmltree import Node


def check_references(root: Node, entities: set[str], parameters: dict[str, str]) -> None:
    """InputError for the first reference to an undeclared entity, variable or parameter."""
    board = root.find("Storyboard")
    decls = root.find("VariableDeclarations")
    variables = {d.need("name"): d for d in ([] if decls is None else decls.children)}
    for node in [] if board is None else board.iter():
        name = node.get("entityRef")
        if name is not None and name not in entities:
            raise invalid(node, f"entity {name!r} is not declared in <Entities>")
        if node.tag in ("VariableCondition", "VariableAction"):
            ref = node.need("variableRef")
            if ref not in variables:
                raise invalid(node, f"variable {ref!r} is not declared (VariableDeclarations)")
            if node.tag == "VariableAction":
                _variable_action(node, variables[ref])
        ref = node.need("parameterRef") if node.tag == "ParameterCondition" else ""
        if ref and ref not in node.parameters(parameters):
            why = "the scenario's or an enclosing element's ParameterDeclarations"
            raise invalid(node, f"parameter {ref!r} is not declared in its scope ({why})")


# VariableDeclaration variableType values that are numbers (OpenSCENARIO 1.2 ParameterType)
NUMERIC = ("int", "double", "unsignedInt", "unsignedShort")


def _variable_action(node: Node, decl: Node) -> None:
    """A ``ModifyAction`` (``Rule`` > ``AddValue``/``MultiplyByValue``, OpenSCENARIO 1.2
    VariableModifyAction) adds to or multiplies a number: its variable is numeric; a
    ``SetAction`` gives a numeric variable a number (else a ValueError at run time)."""
    kind, ref = decl.get("variableType", "string"), node.need("variableRef")
    modify = node.find("ModifyAction")
    rule = None if modify is None else modify.find("Rule")
    what = None if rule is None or not rule.children else rule.children[0].tag
    if modify is not None and what not in ("AddValue", "MultiplyByValue"):
        raise invalid(modify, "a ModifyAction holds a Rule of AddValue or MultiplyByValue")
    if modify is not None and kind not in NUMERIC:
        raise invalid(node, f"variable {ref!r} is a {kind}: AddValue and MultiplyByValue "
                      "apply to a number (int, double, unsignedInt, unsignedShort)")  # fmt: skip
    given = ("SetAction", "AddValue", "MultiplyByValue")
    values = [decl] + [n for n in node.iter() if n.tag in given]
    for value in values if kind in NUMERIC else []:
        value.num("value")  # InputError naming the element when not a number


def check_places(root: Node, places: dict, lanes) -> None:
    """Every departure place and every ``LanePosition`` of the storyboard on a drivable lane
    of its road, its ``s`` within that lane (InputError before anything is written)."""
    for name, place in places.items():
        _on_lane(lanes, place.road, place.lane, place.s_m, place.node, f"{name}'s ")
    board = root.find("Storyboard")
    for node in [] if board is None else board.iter():
        if node.tag == "LanePosition":
            road, lane = node.need("roadId"), int(node.num("laneId"))
            _on_lane(lanes, road, lane, node.num("s"), node, "")
        if node.tag == "AbsoluteTargetLane":
            lane = int(node.num("value"))
            if not any(k == lane for _, k in lanes.table):
                raise invalid(node, f"lane {lane} is not a drivable lane of the road")
    _relative_lanes(board, places, lanes)


def _relative_lanes(board: Node | None, places: dict, lanes) -> None:
    """A lane change to a ``RelativeTargetLane`` counted from an entity in its Init lane
    then (no other lane change moves it; each action runs once): its target lane is known
    before the run and must exist (counted to the left in the entity's direction)."""
    changes: dict[str, list[Node]] = {}
    for group in [] if board is None else board.iter():
        if group.tag == "ManeuverGroup":
            found = [n for n in group.iter() if n.tag == "LaneChangeAction"]
            actors = group.find("Actors")
            for r in [] if actors is None else actors.findall("EntityRef"):
                changes.setdefault(r.need("entityRef"), []).extend(found)
    for change in [] if board is None else board.iter():
        target = change.find("LaneChangeTarget") if change.tag == "LaneChangeAction" else None
        node = None if target is None else target.find("RelativeTargetLane")
        ref = "" if node is None else node.need("entityRef")
        if node is None or ref not in places or changes.get(ref, []) not in ([], [change]):
            continue
        place = places[ref]
        lane = lane_plus(place.lane, int(node.num("value")) * (1 if place.lane < 0 else -1))
        if not lanes.has(place.road, lane):
            raise invalid(node, f"{node.get('value')} lanes from {ref}'s lane {place.lane} is "
                          f"lane {lane}, not a drivable lane of road {place.road}")  # fmt: skip


def _on_lane(lanes, road: str, lane: int, s_m: float, node: Node, whose: str) -> None:
    if not lanes.has(road, lane):
        raise invalid(node, f"{whose}road {road} lane {lane} is not a drivable SUMO lane")
    locate(lanes.table, road, lane, s_m, node.where())
