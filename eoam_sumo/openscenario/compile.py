"""A resolved scenario's start: who is where at what speed, the ego, a stop time if fixed.

Init places each entity (``LanePosition``, ``RelativeLanePosition``, a non-continuous
``LongitudinalDistanceAction``) and sets its speed (a step ``SpeedAction`` to an absolute or
relative target). Story events whose start is known before the run (:mod:`.timing`) and
falls at time 0 may place entities too (Vector's NCAP files do): their placements are the
SUMO departures. Everything after the start, and every start that depends on the run, is the
storyboard engine's (:mod:`.engine`), which runs all events again during the simulation.
"""

from __future__ import annotations

from dataclasses import dataclass

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.actors import Actor, lane_plus, leading_s_m
from eoam_sumo.openscenario.checks import check_references
from eoam_sumo.openscenario.model import Body, Place, Plan
from eoam_sumo.openscenario.reader import Scenario
from eoam_sumo.openscenario.story import Element, build_all, resolve
from eoam_sumo.openscenario.subset import refuse
from eoam_sumo.openscenario.timing import DYNAMIC, NEVER, Clock, NotYet
from eoam_sumo.openscenario.xmltree import Node


@dataclass(frozen=True)
class _Event:
    """An event of the storyboard's element tree (:func:`.story.build_all`): its node, its
    owners' nodes and their qualified names (names repeat across a storyboard, paths not)."""

    element: Element

    def owner(self, key: str) -> Element:
        """The story, act, group or maneuver the event is in (``event``: itself)."""
        kinds = {"story": "Story", "act": "Act", "group": "ManeuverGroup", "maneuver": "Maneuver"}
        kind = kinds.get(key, "Event")
        at = self.element
        while at.kind != kind:
            assert at.parent is not None
            at = at.parent
        return at

    def path(self, key: str) -> str:
        return self.owner(key).path

    @property
    def actors(self) -> tuple[str, ...]:
        return self.element.actors

    @property
    def act(self) -> Node:
        return self.owner("act").node

    @property
    def event(self) -> Node:
        return self.element.node


def compile_plan(scenario: Scenario, ego: str | None = None) -> Plan:
    """The plan of ``scenario``; ``ego`` names the ego entity (default: the one handed to a
    controller, else the one named Ego)."""
    board = scenario.root.find("Storyboard")
    assert board is not None  # the reader checked
    bodies = _bodies(scenario.root)
    check_references(scenario.root, set(bodies), scenario.parameters)
    plan = Plan(bodies, "", {}, {})
    init = board.find("Init")
    for private in [] if init is None else _privates(init):
        _init_private(plan, private)
    elements = build_all(board)
    clock = Clock(scenario.parameters, lambda cond: resolve(elements, cond).path)
    events = [_Event(e) for e in elements.values() if e.kind == "Event"]
    controlled = _time_events(plan, clock, events)
    plan.ego = _choose_ego(plan, controlled, ego, scenario.root)
    _check_ego_actions(plan.ego, events)
    for name, action in plan.init_actions:
        if name == plan.ego:
            raise refuse(action, f"the ego {name}'s Init must place it and set its speed at "
                         "once (a step): the EOAM drives it from there")  # fmt: skip
    plan.notes += _not_applied(board)
    missing = sorted(set(bodies) - set(plan.places))
    if missing:
        raise InputError(f"{scenario.path}: entity {missing[0]} is never placed (no Init)")
    return plan


def _bodies(root: Node) -> dict[str, Body]:
    bodies = {}
    entities = root.find("Entities")
    for obj in [] if entities is None else entities.findall("ScenarioObject"):
        veh = obj.find("Vehicle")
        if veh is None:
            other = next((c for c in obj.children if c.tag != "ObjectController"), obj)
            raise refuse(other, "only vehicles are supported as entities")
        box = veh.find("BoundingBox")
        dims = None if box is None else box.find("Dimensions")
        centre = None if box is None else box.find("Center")
        if dims is None or centre is None:
            raise refuse(veh, "a vehicle needs a BoundingBox with Center and Dimensions")
        name = obj.need("name")
        bodies[name] = Body(
            name,
            dims.num("length"),
            dims.num("width"),
            centre.num("x"),
            veh.get("vehicleCategory", "car") or "car",
        )
    return bodies


def _privates(init: Node) -> list[Node]:
    actions = init.find("Actions")
    return [] if actions is None else actions.findall("Private")


def _init_private(plan: Plan, private: Node) -> None:
    name = private.need("entityRef")
    if name not in plan.bodies:
        raise refuse(private, f"entity {name} is not declared")
    for pa in private.findall("PrivateAction"):
        action = pa.children[0]
        if _runs_from_start(action):
            plan.init_actions.append((name, action))
        else:
            _private_action(plan, name, action, 0.0)


def _runs_from_start(action: Node) -> bool:
    """An Init action with a duration: a shaped speed change, a lane change or offset.
    Init actions execute at time 0 (OpenSCENARIO 1.2 sec. 7.3.1); one with a duration runs
    on from there, so the storyboard engine runs it from the first step."""
    what = action.children[0] if action.children else action
    if what.tag in ("LaneChangeAction", "LaneOffsetAction"):
        return True
    return what.tag == "SpeedAction" and not _is_step(what)


def _is_step(speed: Node) -> bool:
    """A SpeedAction that sets its speed at once: a step, or any shape over no time."""
    dyn = speed.find("SpeedActionDynamics")
    if dyn is None:
        raise refuse(speed, "a SpeedAction needs its dynamics and a target")
    if dyn.need("dynamicsShape") == "step":
        return True
    return dyn.get("dynamicsDimension") == "time" and dyn.num("value", 0.0) == 0.0


def _private_action(plan: Plan, name: str, action: Node, t_s: float) -> float:
    """Apply one private action of ``name`` starting at ``t_s``; its end time."""
    inner = action.children[0] if action.children else action
    if t_s > 0.0:  # the engine's, at run time
        return t_s
    if action.tag == "TeleportAction" or inner.tag == "LongitudinalDistanceAction":
        place = _place(plan, name, action if action.tag == "TeleportAction" else inner)
        plan.places[name] = place
        return t_s
    if inner.tag == "SpeedAction":
        return _speed(plan, name, inner, t_s)
    return t_s


def _place(plan: Plan, name: str, node: Node) -> Place:
    """A ``LanePosition``, or a ``RelativeLanePosition``: ``dLane`` lanes on from the
    reference's lane (ids counted along the road's t, as esmini), ``ds`` along the road's s
    whatever the reference's direction (OpenSCENARIO 1.2: "relative offset in the road's
    s coordinate"; esmini moves it in ROAD_DIRECTION)."""
    if node.tag == "LongitudinalDistanceAction":
        return _distance_place(plan, name, node)
    pos = node.find("Position")
    where = None if pos is None or not pos.children else pos.children[0]
    if where is None:
        raise refuse(node, "a TeleportAction needs a Position")
    offset = where.num("offset", 0.0)
    if where.tag == "LanePosition":
        return Place(where.need("roadId"), int(where.num("laneId")), where.num("s"), where, offset)
    ref = _placed(plan, where.need("entityRef"), where)
    lane = lane_plus(ref.lane, int(where.num("dLane", 0.0)))
    return Place(ref.road, lane, ref.s_m + where.num("ds"), where, offset)  # ds: along s


def _placed(plan: Plan, name: str, node: Node) -> Place:
    if name not in plan.places:
        raise refuse(node, f"{name} is not placed before this position refers to it")
    return plan.places[name]


def _distance_place(plan: Plan, name: str, node: Node) -> Place:
    """``name`` ahead of the referenced entity by the distance or time gap (freespace: from
    the reference's front to ``name``'s nearer end; otherwise reference point to reference
    point), along the road in ``name``'s own lane and lateral offset: a longitudinal action
    (OpenSCENARIO 1.2 ``LongitudinalDistanceAction``; esmini moves the entity along s).
    An entity not placed before, or on another road, takes the reference's lane."""
    other = node.need("entityRef")
    ref = _placed(plan, other, node)
    if node.get("distance") is not None:
        gap = node.num("distance")
    else:
        gap = node.num("timeGap") * plan.speeds_mps.get(other, 0.0)
    own = plan.places.get(name)
    at = own if own is not None and own.road == ref.road else ref
    it = Actor(other, plan.bodies[other], ref.road, ref.lane, ref.s_m, ref.offset_m, 0.0)
    me = Actor(name, plan.bodies[name], at.road, at.lane, at.s_m, at.offset_m, 0.0)
    s_m = leading_s_m(it, me, gap, node.get("freespace") in ("true", "1"))
    return Place(at.road, at.lane, s_m, node, at.offset_m)


def _speed(plan: Plan, name: str, node: Node, t_s: float) -> float:
    """A step to a speed at the start is the entity's departure speed (the rest: the engine)."""
    dyn, target = node.find("SpeedActionDynamics"), node.find("SpeedActionTarget")
    if dyn is None or target is None or not target.children:
        raise refuse(node, "a SpeedAction needs its dynamics and a target")
    if not _is_step(node):
        return t_s
    goal = target.children[0]
    if goal.tag == "AbsoluteTargetSpeed":
        plan.speeds_mps[name] = goal.num("value")
        return t_s
    ref = plan.speeds_mps.get(goal.need("entityRef"), 0.0)
    factor = goal.get("speedTargetValueType", "delta") == "factor"
    plan.speeds_mps[name] = ref * goal.num("value") if factor else ref + goal.num("value")
    return t_s


def _time_events(plan: Plan, clock: Clock, events: list[_Event]) -> set[str]:
    """Time every event (in as many passes as state conditions need); the entities handed to
    a controller."""
    controlled: set[str] = set()
    waiting = list(events)
    while waiting:
        later = []
        for ev in waiting:
            try:
                controlled |= _time_event(plan, clock, ev)
            except NotYet as exc:
                later.append((ev, exc))
        if len(later) == len(waiting):
            raise refuse(later[0][1].node, "refers to an element that is never timed (a cycle)")
        waiting = [ev for ev, _ in later]
        _close(clock, events)
    _close(clock, events)
    return controlled


def _start(clock: Clock, node: Node, default: float) -> float:
    """When ``node`` starts, if known before the run (NEVER when it depends on the run: the
    engine starts it)."""
    t = clock.trigger_time(node.find("StartTrigger"), default)
    return NEVER if t == DYNAMIC else max(float(t), default)


def _time_event(plan: Plan, clock: Clock, ev: _Event) -> set[str]:
    clock.starts.setdefault(ev.path("story"), 0.0)  # a Story starts with the storyboard
    act_path = ev.path("act")
    if act_path not in clock.starts:
        clock.starts[act_path] = _start(clock, ev.act, 0.0)
    t_act = clock.starts[act_path]
    for key in ("group", "maneuver"):
        clock.starts.setdefault(ev.path(key), t_act)
    t_ev = _start(clock, ev.event, t_act) if t_act < NEVER else NEVER
    clock.starts[ev.path("event")] = t_ev
    return _run_actions(plan, clock, ev, ev.element.children, t_ev)


def _run_actions(
    plan: Plan, clock: Clock, ev: _Event, actions: list[Element], t_ev: float
) -> set[str]:
    controlled: set[str] = set()
    end = t_ev
    for element in actions:
        action, name = element.node, element.path
        clock.starts[name] = t_ev
        t_end = t_ev
        if t_ev < NEVER and action.find("PrivateAction") is not None:
            inner = action.find("PrivateAction").children[0]  # type: ignore[union-attr]
            for actor in ev.actors:
                t_end = max(t_end, _private_action(plan, actor, inner, t_ev))
            if inner.children and inner.children[0].tag == "ActivateControllerAction":
                controlled |= set(ev.actors)
        clock.ends[name] = t_end
        end = max(end, t_end)
    clock.ends[ev.path("event")] = end
    return controlled


def _close(clock: Clock, events: list[_Event]) -> None:
    """The end of every maneuver, group and act whose events are all timed."""
    for key in ("maneuver", "group", "act", "story"):
        owners: dict[str, list[str]] = {}
        for ev in events:
            owners.setdefault(ev.path(key), []).append(ev.path("event"))
        for owner, names in owners.items():
            if all(n in clock.ends for n in names):
                ends = [clock.ends[n] for n in names if clock.ends[n] < NEVER]
                clock.ends[owner] = max(ends, default=NEVER)


def _choose_ego(plan: Plan, controlled: set[str], ego: str | None, root: Node) -> str:
    if ego is not None:
        if ego not in plan.bodies:
            raise InputError(f"--ego {ego}: no such entity (have {', '.join(plan.bodies)})")
        return ego
    entities = root.find("Entities")
    for obj in [] if entities is None else entities.findall("ScenarioObject"):
        if obj.find("ObjectController") is not None:
            controlled.add(obj.need("name"))
    if len(controlled) == 1:
        return next(iter(controlled))
    named = [n for n in plan.bodies if n.lower() == "ego"]
    if not controlled and len(named) == 1:
        plan.notes.append(f"no entity is handed to a controller: the ego is {named[0]}")
        return named[0]
    raise InputError(f"{root.file}: cannot tell the ego (name it with --ego)")


def _not_applied(board: Node) -> list[str]:
    """What is read but not applied, one note each (said on stderr: nothing dropped silently)."""
    notes = []
    for node in board.iter():
        if node.tag == "EnvironmentAction":
            notes.append(
                f"EnvironmentAction at line {node.line} not applied (friction: the road's, --mu)"
            )
        if node.tag == "ManeuverGroup" and node.num("maximumExecutionCount", 1.0) > 1:
            times = node.get("maximumExecutionCount")
            notes.append(f"ManeuverGroup {node.get('name')} runs once, not {times} times")
    return notes


def _check_ego_actions(ego: str, events: list[_Event]) -> None:
    """The ego is the EOAM's after its Init: no storyboard action may move it."""
    for ev in events:
        if ego not in ev.actors:
            continue
        for action in ev.event.findall("Action"):
            private = action.find("PrivateAction")
            inner = None if private is None else private.children[0]
            if inner is not None and inner.tag in (
                "LongitudinalAction",
                "LateralAction",
                "TeleportAction",
            ):
                raise refuse(inner, f"the ego {ego} is driven by the EOAM, not by the storyboard")
