"""The supported subset of OpenSCENARIO 1.x: every element outside it refused by name.

Each element of a resolved scenario must be one of ``SUPPORTED`` and pass its value check;
the first one that does not is refused in one line naming the element, its file and line
(as CARLA's ScenarioRunner refuses an unsupported element at load time, never at run time).
Whether an event's start can be timed before the run is checked later (:mod:`.compile`).
"""

from __future__ import annotations

from collections.abc import Callable

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.xmltree import Node

STRUCTURE = frozenset(
    [
        "OpenSCENARIO",
        "FileHeader",
        "License",
        "Properties",
        "Property",
        "ParameterDeclarations",
        "ParameterDeclaration",
        "ConstraintGroup",
        "ValueConstraint",
        "VariableDeclarations",
        "VariableDeclaration",
        "CatalogLocations",
        "VehicleCatalog",
        "ControllerCatalog",
        "PedestrianCatalog",
        "MiscObjectCatalog",
        "ManeuverCatalog",
        "EnvironmentCatalog",
        "RouteCatalog",
        "TrajectoryCatalog",
        "Directory",
        "RoadNetwork",
        "LogicFile",
        "SceneGraphFile",
        "Entities",
        "ScenarioObject",
        "Vehicle",
        "BoundingBox",
        "Center",
        "Dimensions",
        "Performance",
        "Axles",
        "FrontAxle",
        "RearAxle",
        "AdditionalAxle",
        "TrailerHitch",
        "TrailerCoupler",
        "Trailer",
        "TrailerRef",
        "ObjectController",
        "Controller",
        "Storyboard",
        "Init",
        "Actions",
        "Private",
        "PrivateAction",
        "GlobalAction",
        "Story",
        "Act",
        "ManeuverGroup",
        "Actors",
        "EntityRef",
        "Maneuver",
        "Event",
        "Action",
        "StartTrigger",
        "StopTrigger",
        "ConditionGroup",
        "Condition",
        "ByValueCondition",
        "ByEntityCondition",
        "TriggeringEntities",
        "EntityCondition",
        "ParameterAssignments",
        "ParameterAssignment",
    ]
)
ACTIONS = frozenset(
    [
        "TeleportAction",
        "Position",
        "LanePosition",
        "RelativeLanePosition",
        "LongitudinalAction",
        "SpeedAction",
        "SpeedActionDynamics",
        "SpeedActionTarget",
        "AbsoluteTargetSpeed",
        "LongitudinalDistanceAction",
        "ControllerAction",
        "ActivateControllerAction",
        "VariableAction",
        "VariableSetAction",
        "SetAction",
        "ModifyAction",
        "Rule",
        "AddValue",
        "MultiplyByValue",
        "RelativeTargetSpeed",
        "LateralAction",
        "LaneChangeAction",
        "LaneChangeActionDynamics",
        "LaneChangeTarget",
        "RelativeTargetLane",
        "AbsoluteTargetLane",
        "LaneOffsetAction",
        "LaneOffsetActionDynamics",
        "LaneOffsetTarget",
        "AbsoluteTargetLaneOffset",
        "RelativeTargetLaneOffset",
        "Orientation",
        "EnvironmentAction",
        "Environment",
        "TimeOfDay",
        "Weather",
        "Sun",
        "Fog",
        "Precipitation",
        "Wind",
        "RoadCondition",
    ]
)
CONDITIONS = frozenset(
    [
        "SimulationTimeCondition",
        "StoryboardElementStateCondition",
        "ParameterCondition",
        "VariableCondition",
        "CollisionCondition",
        "SpeedCondition",
        "StandStillCondition",
        "RelativeSpeedCondition",
        "RelativeDistanceCondition",
        "TraveledDistanceCondition",
        "TimeHeadwayCondition",
        "TimeToCollisionCondition",
        "TimeToCollisionConditionTarget",
        "ReachPositionCondition",
        "AccelerationCondition",
    ]
)
SUPPORTED = STRUCTURE | ACTIONS | CONDITIONS
ZERO_M = 1e-6


def refuse(node: Node, why: str) -> InputError:
    """The one-line refusal of ``node``."""
    return InputError(f"{node.where()}: {why} (docs/openscenario.md lists the subset)")


def invalid(node: Node, why: str) -> InputError:
    """The one-line refusal of ``node`` for a value or structure the standard does not allow
    (not a matter of the subset)."""
    return InputError(f"{node.where()}: {why}")


SHAPES = ("step", "linear", "cubic", "sinusoidal")
# OpenSCENARIO 1.2 Rule: every condition's rule is one of these (sec. 7.4.3)
RULES = ("greaterThan", "lessThan", "equalTo", "greaterOrEqual", "lessOrEqual", "notEqualTo")


def _speed_dynamics(node: Node) -> None:
    shape, dim = node.get("dynamicsShape"), node.get("dynamicsDimension")
    if shape in SHAPES and (shape == "step" or dim in ("time", "rate")):
        return
    raise refuse(node, f"dynamicsShape={shape} dynamicsDimension={dim} is not supported")


def _lane_change_dynamics(node: Node) -> None:
    shape, dim = node.get("dynamicsShape"), node.get("dynamicsDimension")
    if shape not in SHAPES or dim not in ("time", "distance", "rate"):
        raise refuse(node, f"dynamicsShape={shape} dynamicsDimension={dim} is not supported")
    if shape != "step" and node.num("value") <= 0:
        raise refuse(node, f"value {node.get('value')} must be > 0")


def _orientation(node: Node) -> None:
    if node.get("type", "relative") != "relative" or abs(node.num("h", 0.0)) > ZERO_M:
        raise refuse(node, "only an orientation along the lane (relative, h=0) is supported")
    if abs(node.num("p", 0.0)) > ZERO_M or abs(node.num("r", 0.0)) > ZERO_M:
        raise refuse(node, "pitch and roll are not supported")


def _relative_lane(node: Node) -> None:
    if node.get("ds") is None:
        raise refuse(node, "only ds (not dsLane) is supported")
    _integer(node, "dLane")


def _lateral_target(node: Node) -> None:
    if node.tag == "LaneOffsetAction" and node.get("continuous") in ("true", "1"):
        raise refuse(node, "a continuous LaneOffsetAction is not supported")


def _distance(node: Node) -> None:
    if node.get("continuous") not in ("false", "0"):
        raise refuse(node, "a continuous LongitudinalDistanceAction is not supported")
    if node.get("displacement", "leadingReferencedEntity") != "leadingReferencedEntity":
        raise refuse(node, "only displacement=leadingReferencedEntity is supported")
    constraints = node.find("DynamicConstraints")
    if constraints is not None:
        raise refuse(constraints, "dynamic constraints are not supported")


# elements that are a choice of exactly one child (OpenSCENARIO 1.2 XSD xsd:choice)
ONE_CHILD = ("Condition", "ByValueCondition", "EntityCondition", "PrivateAction",
             "GlobalAction", "Position", "LongitudinalAction", "LateralAction",
             "SpeedActionTarget", "LaneChangeTarget", "LaneOffsetTarget", "Action",
             "VariableAction", "Rule")  # fmt: skip
# vehicleCategory values with a SUMO vehicle class (train, tram, trailers: none)
CATEGORIES = ("car", "van", "truck", "bus", "motorbike", "bicycle")


def _one_child(node: Node) -> None:
    kids = [c for c in node.children if c.tag != "ParameterDeclarations"]
    if len(kids) != 1:
        got = "is empty" if not kids else f"has {len(kids)} children"
        raise invalid(node, f"a <{node.tag}> holds exactly one element; this one {got}")


def _by_entity(node: Node) -> None:
    if node.find("TriggeringEntities") is None or node.find("EntityCondition") is None:
        raise invalid(node, "a ByEntityCondition needs TriggeringEntities and EntityCondition")


def _integer(node: Node, key: str) -> None:
    value = node.num(key, 0.0)
    if value != int(value):
        raise invalid(node, f"{key}={node.get(key)} is not an integer (a lane id or count)")


def _not_negative(node: Node, key: str, what: str) -> None:
    if node.num(key, 0.0) < 0:
        raise invalid(node, f"{key}={node.get(key)}: {what} cannot be negative")


def _dimensions(node: Node) -> None:
    for key in ("length", "width"):
        if node.num(key) <= 0:
            raise invalid(node, f"{key}={node.get(key)}: a bounding box's {key} must be > 0")


def _vehicle(node: Node) -> None:
    category = node.get("vehicleCategory", "car")
    if category not in CATEGORIES:
        raise refuse(node, f"vehicleCategory={category} is not supported ({', '.join(CATEGORIES)})")


def _trailer(node: Node) -> None:
    """A vehicle's ``Trailer`` (OpenSCENARIO 1.3: a ``Trailer`` entity or a ``TrailerRef``)
    that names no trailer (esmini's catalog cars: ``TrailerRef entityRef=""``) tows none;
    one that does is refused (a hitch point alone, ``TrailerHitch``, changes nothing)."""
    kids = node.children
    if all(k.tag == "TrailerRef" and not k.get("entityRef") for k in kids):
        return
    named = next((k.get("entityRef") or k.get("name") or k.tag for k in kids), "")
    raise refuse(node, f"a vehicle towing a trailer ({named}) is not supported")


def _reach(node: Node) -> None:
    pos = node.find("Position")
    if pos is None or pos.find("LanePosition") is None:
        raise refuse(node, "only a LanePosition is supported to reach")


CHECKS: dict[str, Callable[[Node], None]] = {
    "SpeedActionDynamics": _speed_dynamics,
    "LaneChangeActionDynamics": _lane_change_dynamics,
    "Orientation": _orientation,
    "RelativeLanePosition": _relative_lane,
    "LaneOffsetAction": _lateral_target,
    "LongitudinalDistanceAction": _distance,
    "ByEntityCondition": _by_entity,
    "Dimensions": _dimensions,
    "Vehicle": _vehicle,
    "Trailer": _trailer,
    "ReachPositionCondition": _reach,
    "AbsoluteTargetSpeed": lambda n: _not_negative(n, "value", "a target speed"),
    "LanePosition": lambda n: _integer(n, "laneId"),
    "AbsoluteTargetLane": lambda n: _integer(n, "value"),
    "RelativeTargetLane": lambda n: _integer(n, "value"),
    **dict.fromkeys(ONE_CHILD, _one_child),
}


def check_subset(root: Node) -> None:
    """InputError for the first element of ``root`` outside the subset."""
    for node in root.iter():
        if node.tag == "ParameterDeclarations":
            continue
        if node.tag not in SUPPORTED:
            raise refuse(node, f"{node.tag} is outside the supported subset")
        check = CHECKS.get(node.tag)
        if check is not None:
            check(node)
        if node.get("rule", RULES[0]) not in RULES:
            raise invalid(node, f"rule={node.get('rule')} is not a rule ({', '.join(RULES)})")
