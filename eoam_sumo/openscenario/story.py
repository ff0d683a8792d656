"""The storyboard as state machines stepped with the simulation (esmini's ``StoryBoard``).

Every Story, Act, ManeuverGroup, Maneuver, Event and Action is ``standby``, ``running`` or
``complete`` (OpenSCENARIO 1.2 sec. 7.3), each transition one step. A trigger's condition
groups are OR'ed, the conditions of a group AND'ed; a condition's ``conditionEdge`` is taken
on its value from step to step and its ``delay`` shifts its result (sec. 7.4.1). Each step
evaluates the triggers, then starts what they fire, then steps the running actions.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from eoam_sumo.openscenario.conditions import by_entity, by_value
from eoam_sumo.openscenario.xmltree import Node

STANDBY, RUNNING, COMPLETE = "standby", "running", "complete"
KINDS = {"Story": "Act", "Act": "ManeuverGroup", "ManeuverGroup": "Maneuver",
         "Maneuver": "Event", "Event": "Action"}  # fmt: skip


class Condition:
    """One condition: its value each step, its edge, its delay."""

    def __init__(self, node: Node) -> None:
        self.node, self.inner = node, node.children[0]
        self.edge = node.get("conditionEdge", "none")
        self.delay_s = node.num("delay", 0.0)
        self._last: bool | None = None
        self._seen: deque[tuple[float, bool]] = deque()
        inner = self.inner
        if inner.tag == "ByValueCondition":
            value = inner.children[0]
            self._holds = lambda world: by_value(value, world)
        else:
            self._holds = by_entity(inner)

    def value(self, world) -> bool:
        raw = self._holds(world)
        last, self._last = self._last, raw
        if self.edge == "none":
            edged = raw
        elif last is None:
            edged = False
        elif self.edge == "rising":
            edged = raw and not last
        elif self.edge == "falling":
            edged = last and not raw
        else:
            edged = raw != last
        if self.delay_s <= 0.0:
            return edged
        self._seen.append((world.time_s, edged))
        out = False
        while self._seen and self._seen[0][0] <= world.time_s - self.delay_s + 1e-9:
            out = self._seen.popleft()[1]
        return out


class Trigger:
    """A start or stop trigger (no condition group: never fires)."""

    def __init__(self, node: Node) -> None:
        self.groups = [
            [Condition(c) for c in g.findall("Condition")] for g in node.findall("ConditionGroup")
        ]

    def fired(self, world) -> bool:
        results = [[c.value(world) for c in group] for group in self.groups]  # every one, edges
        return any(all(r) and r for r in results)


@dataclass(eq=False)
class Element:
    """A storyboard element and its state; an Action's ``motions`` (actor, motion) once
    started."""

    kind: str
    name: str
    node: Node
    children: list[Element]
    start: Trigger | None
    stop: Trigger | None
    actors: tuple[str, ...] = ()
    state: str = STANDBY
    started_step: int = -10
    ended_step: int = -10
    motions: list = field(default_factory=list)


def build(node: Node, actors: tuple[str, ...] = ()) -> Element:
    """The element tree under ``node`` (a Story)."""
    if node.tag == "ManeuverGroup":
        refs = node.find("Actors")
        actors = tuple(
            r.need("entityRef") for r in ([] if refs is None else refs.findall("EntityRef"))
        )
    child_tag = KINDS.get(node.tag)
    kids = [build(c, actors) for c in node.findall(child_tag)] if child_tag else []
    start, stop = node.find("StartTrigger"), node.find("StopTrigger")
    return Element(
        node.tag,
        node.need("name"),
        node,
        kids,
        None if start is None or not start.children else Trigger(start),
        None if stop is None or not stop.children else Trigger(stop),
        actors,
    )


def walk(element: Element):
    yield element
    for child in element.children:
        yield from walk(child)


def state_holds(element: Element, state: str, step: int) -> bool:
    """``StoryboardElementStateCondition``'s state of ``element`` at ``step`` (a transition
    holds in the step it happened and the next, whichever order the elements are stepped)."""
    if state == "startTransition":
        return element.started_step >= step - 1
    if state in ("endTransition", "stopTransition"):
        return element.ended_step >= step - 1
    if state == "runningState":
        return element.state == RUNNING
    if state == "completeState":
        return element.state == COMPLETE
    return element.state == STANDBY
