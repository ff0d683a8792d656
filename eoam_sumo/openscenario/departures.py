"""The departure speeds, checked when the scenario is loaded (before anything is written).

A departure speed comes from a step ``SpeedAction`` of the Init or of an event at time 0
(:mod:`.compile`), an absolute one or one relative to another entity's (``RelativeTargetSpeed``
delta or factor): the value is known only once the plan is compiled. Each must be one the run
can have: the ego's within the lookup tables' design range (``LookupTables.check_run``), a
target's not negative and not above its ``Performance maxSpeed``; otherwise one line naming
the element that set it, its file and line (SUMO refused the written files before, naming
them, or the session the ego's speed after ``DIR/scenario/`` was written).
"""

from __future__ import annotations

from eoam_sumo.openscenario.model import Plan
from eoam_sumo.openscenario.subset import invalid
from eoam_sumo.openscenario.xmltree import Node

TOLERANCE_MPS = 1e-9


def max_speeds_mps(root: Node) -> dict[str, float]:
    """Entity name -> its vehicle's ``Performance maxSpeed`` [m/s] (when it has one)."""
    entities = root.find("Entities")
    out = {}
    for obj in [] if entities is None else entities.findall("ScenarioObject"):
        vehicle = obj.find("Vehicle")
        perf = None if vehicle is None else vehicle.find("Performance")
        if perf is not None and perf.get("maxSpeed") is not None:
            out[obj.need("name")] = perf.num("maxSpeed")
    return out


def check_departures(
    root: Node, plan: Plan, ego_range_mps: tuple[float, float] | None = None
) -> None:
    """InputError naming the element that set a departure speed the run cannot have: the
    ego's outside ``ego_range_mps`` (the tables' design range; None: only not negative), a
    target's negative or above its ``Performance maxSpeed``. The ego first: its speed
    usually sets the others' (esmini's cut-in: ``EgoSpeed`` x 1.2)."""
    ego = plan.ego
    speed = plan.speeds_mps.get(ego, 0.0)
    low, top = ego_range_mps or (0.0, float("inf"))
    if not low - TOLERANCE_MPS <= speed <= top + TOLERANCE_MPS:
        raise invalid(
            speed_source(root, plan, ego),
            f"the ego {ego}'s departure speed {speed * 3.6:.1f} km/h is outside the design "
            f"range [{low * 3.6:.0f}, {top * 3.6:.0f}] km/h (the lookup tables')",
        )
    limits = max_speeds_mps(root)
    for name in plan.bodies:
        speed = plan.speeds_mps.get(name, 0.0)
        if name == ego or 0.0 <= speed <= limits.get(name, speed) + TOLERANCE_MPS:
            continue
        why = (
            "is negative"
            if speed < 0.0
            else f"is above its Performance maxSpeed {limits[name]:g} m/s"
        )
        raise invalid(
            speed_source(root, plan, name), f"{name}'s departure speed {speed:g} m/s {why}"
        )


def speed_source(root: Node, plan: Plan, name: str) -> Node:
    """The speed target that set ``name``'s departure speed: the last of its step speed
    actions (Init first, then its maneuver groups') whose value is that speed; else the last
    one in its Init; else the element that placed it."""
    board = root.find("Storyboard")
    nodes = [] if board is None else _speed_targets(board, name)
    want = plan.speeds_mps.get(name, 0.0)
    hits = [n for n, init in nodes if abs(_value(n, plan) - want) <= 1e-6]
    inits = [n for n, init in nodes if init]
    if hits or inits:
        return (hits or inits)[-1]
    return plan.places[name].node if name in plan.places else root


def _speed_targets(board: Node, name: str) -> list[tuple[Node, bool]]:
    """(speed target, whether in the Init) of every SpeedAction that may move ``name``."""
    out: list[tuple[Node, bool]] = []
    init = board.find("Init")
    for node in [] if init is None else init.iter():
        if node.tag == "Private" and node.get("entityRef") == name:
            out += [(t, True) for t in _targets(node)]
    for group in board.iter():
        actors = group.find("Actors") if group.tag == "ManeuverGroup" else None
        refs = [] if actors is None else actors.findall("EntityRef")
        if any(r.get("entityRef") == name for r in refs):
            out += [(t, False) for t in _targets(group)]
    return out


def _targets(node: Node) -> list[Node]:
    return [
        t
        for n in node.iter()
        if n.tag == "SpeedActionTarget"
        for t in n.children
        if t.tag in ("AbsoluteTargetSpeed", "RelativeTargetSpeed")
    ]


def _value(target: Node, plan: Plan) -> float:
    """The speed a target gives (a relative one: from the reference's departure speed)."""
    if target.tag == "AbsoluteTargetSpeed":
        return target.num("value")
    ref = plan.speeds_mps.get(target.need("entityRef"), 0.0)
    if target.get("speedTargetValueType", "delta") == "factor":
        return ref * target.num("value")
    return ref + target.num("value")
