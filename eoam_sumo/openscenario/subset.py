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
    ]
)
SUPPORTED = STRUCTURE | ACTIONS | CONDITIONS
ZERO_M = 1e-6


def refuse(node: Node, why: str) -> InputError:
    """The one-line refusal of ``node``."""
    return InputError(f"{node.where()}: {why} (docs/openscenario.md lists the subset)")


def _speed_dynamics(node: Node) -> None:
    shape, dim = node.get("dynamicsShape"), node.get("dynamicsDimension")
    if shape == "step":
        return
    if shape == "linear" and dim == "rate":
        return
    raise refuse(node, f"dynamicsShape={shape} dynamicsDimension={dim} is not supported")


def _no_offset(node: Node) -> None:
    if abs(node.num("offset", 0.0)) > ZERO_M:
        raise refuse(node, f"a lateral offset ({node.get('offset')} m) is not supported")
    orientation = node.find("Orientation")
    if orientation is not None:
        raise refuse(orientation, "an orientation is not supported")


def _relative_lane(node: Node) -> None:
    _no_offset(node)
    if int(node.num("dLane", 0.0)) != 0:
        raise refuse(node, "only dLane=0 is supported")
    if node.get("ds") is None:
        raise refuse(node, "only ds (not dsLane) is supported")


def _distance(node: Node) -> None:
    if node.get("continuous") not in ("false", "0"):
        raise refuse(node, "a continuous LongitudinalDistanceAction is not supported")
    if node.get("displacement", "leadingReferencedEntity") != "leadingReferencedEntity":
        raise refuse(node, "only displacement=leadingReferencedEntity is supported")
    constraints = node.find("DynamicConstraints")
    if constraints is not None:
        raise refuse(constraints, "dynamic constraints are not supported")


CHECKS: dict[str, Callable[[Node], None]] = {
    "SpeedActionDynamics": _speed_dynamics,
    "LanePosition": _no_offset,
    "RelativeLanePosition": _relative_lane,
    "LongitudinalDistanceAction": _distance,
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
