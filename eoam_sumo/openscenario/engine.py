"""The storyboard run during the simulation: a step observer of the co-simulation.

After each co-simulation step (SUMO's time ``t``, scenario time ``t - DEPART_S``) it reads the
ego's place from SUMO, evaluates the triggers, starts what they fire, steps the running
actions to the end of the coming step and places every target there through SUMO
(:class:`~eoam_sumo.sim.session.puppets.Puppets`), as esmini steps its storyboard: triggers,
then actions, then the controllers (here the EOAM, in the next co-simulation step). The
storyboard's stop trigger ends the run (once a manoeuvre
of the EOAM under way has ended).
"""

from __future__ import annotations

import math

from eoam_sumo.openscenario.actors import Actor
from eoam_sumo.openscenario.geometry import LaneMap
from eoam_sumo.openscenario.model import Plan
from eoam_sumo.openscenario.motions import LateralMotion, SpeedMotion
from eoam_sumo.openscenario.story import (
    COMPLETE,
    RUNNING,
    STANDBY,
    Element,
    Trigger,
    build_all,
    resolve,
    state_holds,
    walk,
)
from eoam_sumo.openscenario.subset import refuse
from eoam_sumo.openscenario.sumofiles import DEPART_S
from eoam_sumo.openscenario.xmltree import Node
from eoam_sumo.sim.observers import StepObserver


class World:
    """What conditions and actions read: time, the actors, the lanes, values, states."""

    def __init__(self, plan: Plan, lanes: LaneMap, parameters: dict, variables: dict) -> None:
        self.lanes, self.parameters, self.variables = lanes, parameters, variables
        self.time_s, self.step = 0.0, 0
        self.actors = {
            n: Actor(n, b, plan.places[n].road, plan.places[n].lane, plan.places[n].s_m,
                     plan.places[n].offset_m, plan.speeds_mps.get(n, 0.0), n != plan.ego)
            for n, b in plan.bodies.items()
        }  # fmt: skip
        self.elements: dict[str, Element] = {}  # by qualified name (story::act::...)
        self._refs: dict[int, Element] = {}
        self.collided: set[str] = set()
        self.ego_xy = (0.0, 0.0)
        self.ego = plan.ego
        self.friction = lambda lane_id: 1.0
        self._base = {
            road: min(lane for r, lane in lanes.table if r == road) for road, _ in lanes.table
        }

    def element_state(self, node: Node) -> bool:
        """A ``StoryboardElementStateCondition`` now (its element resolved once)."""
        element = self._refs.get(id(node))
        if element is None:
            element = self._refs[id(node)] = resolve(self.elements, node)
        return state_holds(element, node.need("state"), self.step)

    def xy(self, actor: Actor) -> tuple[float, float]:
        if not actor.puppet:
            return self.ego_xy
        x, y, _ = self.lanes.point(actor.road, actor.lane, actor.s_m, actor.offset_m)
        return x, y

    def lateral_m(self, actor: Actor) -> float:
        """Left of the road's outermost right lane's centre, along s."""
        base = self._base[actor.road]
        return self.lanes.shift_m(actor.road, base, actor.lane, actor.s_m) + actor.offset_m

    def mu(self, actor: Actor) -> float:
        return self.friction(self.lanes.locate(actor.road, actor.lane, actor.s_m)[0])


class Storyboard(StepObserver):
    """The storyboard of a loaded scenario, stepped after each co-simulation step."""

    def __init__(self, root: Node, plan: Plan, lanes: LaneMap, parameters: dict) -> None:
        board = root.find("Storyboard")
        assert board is not None
        decls = root.find("VariableDeclarations")
        variables = {
            d.need("name"): d.need("value") for d in ([] if decls is None else decls.children)
        }
        self.world = World(plan, lanes, parameters, variables)
        self.world.elements = build_all(board)
        self.stories = [e for e in self.world.elements.values() if e.parent is None]
        self.plan, self.init_node = plan, board.find("Init") or board
        self.ids = plan.sumo_ids()  # entity name -> SUMO vehicle id
        stop = board.find("StopTrigger")
        self.stop = None if stop is None or not stop.children else Trigger(stop)
        self.ended_by_storyboard = False

    def start(self, sim) -> None:
        self.puppets = sim.session.puppets()
        self.world.friction = sim.session.lane_friction
        for actor in self.world.actors.values():
            if actor.puppet:
                self.puppets.take(self.ids[actor.name])
        self._start_init()
        self.after_step(sim)

    def _start_init(self) -> None:
        """The Init actions with a duration start at time 0 (a shaped speed change, a lane
        change or offset), stepped as one running action of the storyboard."""
        started = (start_private(self.world, n, a) for n, a in self.plan.init_actions)
        motions = [m for m in started if m is not None]
        if motions:
            init = Element("Action", "", self.init_node, [], None, None, path="Init")
            init.state, init.started_step, init.motions = RUNNING, 0, motions
            self.world.elements["Init"] = init

    def after_step(self, sim) -> None:
        world = self.world
        dt = sim.step_s
        world.time_s, world.step = sim.t - DEPART_S, world.step + 1
        self._read_ego(sim, dt)
        if sim.first_contact is not None:
            hit = sim.first_contact.body.vid
            world.collided |= {world.ego, next((n for n, v in self.ids.items() if v == hit), hit)}
        if self.stop is not None and self.stop.fired(world):
            self.ended_by_storyboard = True
        if self.ended_by_storyboard and (sim.ctrl.mode == 0 or sim.eoam_done()):
            sim.request_end("storyboard")  # ends now (a manoeuvre under way ends first)
        for story in self.stories:
            self._step_element(story)
        moved = self._step_actions(dt)
        for actor in world.actors.values():
            if actor.puppet:
                if actor.name not in moved:
                    actor.advance(actor.speed_mps, dt)
                self._place(actor)

    def _read_ego(self, sim, dt: float) -> None:
        ego = self.world.actors[self.world.ego]
        x = sim.x
        speed = max(float(x[3]), 0.0)
        lane_id, pos = self.puppets.ego_lane()
        found = self.world.lanes.road_position(lane_id, pos) if lane_id else None
        ego.advance(speed, dt)
        if found is not None:
            ego.road, ego.lane, front = found
            ego.s_m = front - ego.direction * ego.body.front_ahead_m
        self.world.ego_xy = (float(x[0]), float(x[1]))

    def _place(self, actor: Actor) -> None:
        """The actor's reference point where its lane position puts it, its heading along
        the chord from its rear to its front on the lane (as SUMO draws a vehicle on a curve:
        a long truck's rear does not swing out of its lane) turned by its lateral speed, and
        its front bumper ahead of the reference point along that heading."""
        lanes, body, d = self.world.lanes, actor.body, actor.direction
        x, y, _ = lanes.point(actor.road, actor.lane, actor.s_m, actor.offset_m)
        xf, yf, _ = lanes.point(actor.road, actor.lane, actor.front_s_m(), actor.offset_m)
        xr, yr, _ = lanes.point(actor.road, actor.lane, actor.rear_s_m(), actor.offset_m)
        yaw = math.atan2(yf - yr, xf - xr)
        yaw += math.atan2(actor.lat_speed_mps * d, max(actor.speed_mps, 0.1))
        front_x = x + body.front_ahead_m * math.cos(yaw)
        front_y = y + body.front_ahead_m * math.sin(yaw)
        nav = (90.0 - math.degrees(yaw)) % 360.0
        self.puppets.place(self.ids[actor.name], front_x, front_y, nav, actor.speed_mps)

    # ------------------------------------------------------------------ the state machines
    def _step_element(self, el: Element) -> None:
        """Start ``el`` when its trigger fires, stop it when its stop trigger does, then its
        children (an element with no start trigger starts with its parent)."""
        world = self.world
        standby = el.state == STANDBY  # a start trigger is evaluated while it can fire
        if standby and (el.start is None or el.start.fired(world)):
            if el.kind == "Event":
                self._start_event(el)
            else:
                el.state, el.started_step = RUNNING, world.step
        if el.state != RUNNING:
            return
        if el.stop is not None and el.stop.fired(world):
            self._end(el)
            return
        for child in el.children:
            if child.kind != "Action":
                self._step_element(child)

    def _start_event(self, ev: Element) -> None:
        world = self.world
        owner = ev.parent
        assert owner is not None  # an Event is in a Maneuver
        if ev.node.get("priority") == "skip" and any(e.state == RUNNING for e in owner.children):
            return
        if ev.node.get("priority") in ("override", "overwrite"):
            for other in owner.children:
                if other is not ev and other.state == RUNNING:
                    self._end(other)
        ev.state, ev.started_step = RUNNING, world.step
        for action in ev.children:
            action.state, action.started_step = RUNNING, world.step
            action.motions = start_action(world, action, ev.actors)

    def _end(self, el: Element) -> None:
        for e in walk(el):
            if e.state == RUNNING:
                e.state, e.ended_step = COMPLETE, self.world.step
                for actor, motion in e.motions:
                    _release(self.world.actors[actor], motion)
                e.motions = []

    def _step_actions(self, dt: float) -> set[str]:
        """Step every running action's motions; the actors whose speed an action set."""
        moved: set[str] = set()
        world = self.world
        for el in list(world.elements.values()):
            if el.kind != "Action" or el.state != RUNNING:
                continue
            left = []
            for name, motion in el.motions:
                actor = world.actors[name]
                overridden = motion is not actor.speed_busy and motion is not actor.lateral_busy
                if isinstance(motion, SpeedMotion) and not overridden:
                    moved.add(name)
                if not overridden and not motion.step(world, actor, dt):
                    left.append((name, motion))
                else:
                    _release(actor, motion)
            el.motions = left
            if not left:
                el.state, el.ended_step = COMPLETE, world.step
        for el in reversed(list(world.elements.values())):  # children before their parents
            self._complete_if_done(el)
        return moved

    def _complete_if_done(self, el: Element) -> None:
        done = el.children and all(c.state == COMPLETE for c in el.children)
        if el.kind != "Action" and el.state == RUNNING and done:
            el.state, el.ended_step = COMPLETE, self.world.step


def _release(actor: Actor, motion) -> None:
    if actor.speed_busy is motion:
        actor.speed_busy = None
    if actor.lateral_busy is motion:
        actor.lateral_busy = None


def start_action(world: World, action: Element, actors: tuple[str, ...]) -> list:
    """The motions of an action just started (placements and global actions take effect now)."""
    node = action.node.children[0]
    if node.tag == "GlobalAction":
        inner = node.children[0]
        if inner.tag == "VariableAction":
            _variable(world, inner)
        return []
    inner = node.children[0]
    started = (start_private(world, name, inner) for name in actors)
    return [m for m in started if m is not None]


def start_private(world: World, name: str, inner: Node) -> tuple[str, object] | None:
    """Start a private action of ``name`` (``inner``: the PrivateAction's child): its
    motion, or None for a placement (done now) or a controller action."""
    from eoam_sumo.openscenario.placing import place_now

    actor = world.actors[name]
    what = inner.children[0] if inner.children else inner
    if what.tag == "SpeedAction":
        motion: object = SpeedMotion(what)
        _take(actor, "speed_busy", motion)
    elif what.tag in ("LaneChangeAction", "LaneOffsetAction"):
        motion = LateralMotion(what)
        _take(actor, "lateral_busy", motion)
    else:
        place_now(world, actor, inner)
        return None
    motion.start(world, actor)  # type: ignore[attr-defined]
    return name, motion


def _take(actor: Actor, slot: str, motion) -> None:
    """A new motion of the same kind overrides the running one (it stops stepping)."""
    setattr(actor, slot, motion)


def _variable(world: World, node: Node) -> None:
    """A ``VariableAction`` now: ``SetAction`` value=, or ``ModifyAction`` > ``Rule`` >
    ``AddValue``/``MultiplyByValue`` value= (OpenSCENARIO 1.2 VariableModifyRule; the
    variable is numeric, :mod:`.checks`)."""
    name = node.need("variableRef")
    set_ = node.find("SetAction") or node.find("VariableSetAction")
    if set_ is not None:
        world.variables[name] = set_.need("value")
        return
    modify = node.find("ModifyAction")
    rule = None if modify is None else modify.find("Rule")
    what = None if rule is None or not rule.children else rule.children[0]
    if what is None or what.tag not in ("AddValue", "MultiplyByValue"):
        raise refuse(node, "a VariableAction sets (SetAction) or modifies (ModifyAction > Rule)")
    have = float(world.variables[name])
    new = have + what.num("value") if what.tag == "AddValue" else have * what.num("value")
    world.variables[name] = repr(new)
