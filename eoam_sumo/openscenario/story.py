"""The storyboard as state machines stepped with the simulation (esmini's ``StoryBoard``).

Every Story, Act, ManeuverGroup, Maneuver, Event and Action is ``standby``, ``running`` or
``complete`` (OpenSCENARIO 1.2 sec. 7.3), each transition one step. A trigger's condition
groups are OR'ed, the conditions of a group AND'ed; a condition's ``conditionEdge`` is taken
on its value from step to step and its ``delay`` shifts its result (sec. 7.4.1). Each step
evaluates the triggers, then starts what they fire, then steps the running actions.
"""

from __future__ import annotations

from collections import Counter, deque
from dataclasses import dataclass, field

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.conditions import by_entity, by_value
from eoam_sumo.openscenario.subset import refuse
from eoam_sumo.openscenario.xmltree import Node

STANDBY, RUNNING, COMPLETE = "standby", "running", "complete"
KINDS = {"Story": "Act", "Act": "ManeuverGroup", "ManeuverGroup": "Maneuver",
         "Maneuver": "Event", "Event": "Action"}  # fmt: skip
# StoryboardElementStateCondition's storyboardElementType -> the element's tag
TYPES = {"story": "Story", "act": "Act", "maneuverGroup": "ManeuverGroup",
         "maneuver": "Maneuver", "event": "Event", "action": "Action"}  # fmt: skip
SEP = "::"  # a qualified name: the names of the element's parents and its own


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
    started. ``path`` is its qualified name (``Story::Act::...::Action``): names repeat
    across a storyboard (only the path is unique), so elements are kept by path."""

    kind: str
    name: str
    node: Node
    children: list[Element]
    start: Trigger | None
    stop: Trigger | None
    actors: tuple[str, ...] = ()
    path: str = ""
    parent: Element | None = None
    state: str = STANDBY
    started_step: int = -10
    ended_step: int = -10
    motions: list = field(default_factory=list)


def build(node: Node, actors: tuple[str, ...] = (), prefix: str = "", suffix: str = "") -> Element:
    """The element tree under ``node`` (a Story), each element's path its qualified name
    (a second sibling of one name: ``#2`` after its name, a third ``#3``)."""
    if node.tag == "ManeuverGroup":
        refs = node.find("Actors")
        actors = tuple(
            r.need("entityRef") for r in ([] if refs is None else refs.findall("EntityRef"))
        )
    path = prefix + node.need("name") + suffix
    child_tag = KINDS.get(node.tag)
    kids, seen = [], Counter[str]()
    for child in node.findall(child_tag) if child_tag else []:
        name = child.need("name")
        seen[name] += 1  # siblings of one name (esmini's acc-test): the path gets #2, #3
        suffix = "" if seen[name] == 1 else f"#{seen[name]}"
        kids.append(build(child, actors, path + SEP, suffix))
    start, stop = node.find("StartTrigger"), node.find("StopTrigger")
    element = Element(
        node.tag,
        node.need("name"),
        node,
        kids,
        None if start is None or not start.children else Trigger(start),
        None if stop is None or not stop.children else Trigger(stop),
        actors,
        path,
    )
    for kid in kids:
        kid.parent = element
    return element


def build_all(board: Node) -> dict[str, Element]:
    """Every element of the storyboard's stories by its qualified name, parents first."""
    elements: dict[str, Element] = {}
    seen = Counter[str]()
    for story in board.findall("Story"):
        seen[story.need("name")] += 1
        count = seen[story.need("name")]
        top = build(story, suffix="" if count == 1 else f"#{count}")
        elements |= {e.path: e for e in walk(top)}
    return elements


def _names(element: Element) -> list[str]:
    """The names of the element's parents and its own, outermost first."""
    out = []
    at: Element | None = element
    while at is not None:
        out.append(at.name)
        at = at.parent
    return out[::-1]


def resolve(elements: dict[str, Element], cond: Node) -> Element:
    """The element a ``StoryboardElementStateCondition`` names: its ``storyboardElementRef``
    is a name or a qualified name (parents' names first, ``::`` between) matching the end of
    exactly one element's path of its ``storyboardElementType`` (OpenSCENARIO 1.2 sec. 7.4.2,
    references by name); none or several: refused."""
    ref, kind = cond.need("storyboardElementRef"), cond.get("storyboardElementType")
    tag = TYPES.get(kind or "")
    if kind is not None and tag is None:
        raise refuse(cond, f"storyboardElementType={kind} is not an element type")
    parts = ref.split(SEP)
    hits = [
        e
        for e in elements.values()
        if (tag is None or e.kind == tag) and _names(e)[-len(parts) :] == parts
    ]
    if not hits:
        raise InputError(f"{cond.where()}: no {kind or 'storyboard element'} named {ref!r}")
    if len(hits) > 1:
        paths = ", ".join(e.path for e in hits)
        raise InputError(
            f"{cond.where()}: {ref!r} names {len(hits)} elements ({paths}): qualify it"
        )
    return hits[0]


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
