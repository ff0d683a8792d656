"""When each storyboard element starts and ends, known before the run.

The subset runs storyboards whose timing does not depend on the run: a start trigger is a
``SimulationTimeCondition``, a ``ParameterCondition`` (fixed once parameters are resolved) or
a ``StoryboardElementStateCondition`` on another element, each with its ``delay``; condition
groups are OR'ed, conditions within a group AND'ed (OpenSCENARIO 1.2 sec. 7.4.1). A trigger
that depends on the run (distances, speeds, collisions) is "dynamic": :mod:`.compile` refuses
it unless the event only sets variables.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from eoam_sumo.openscenario.subset import refuse
from eoam_sumo.openscenario.xmltree import Node

NEVER = math.inf
DYNAMIC = "dynamic"
STATE_TYPES = ("story", "act", "maneuverGroup", "maneuver", "event", "action")
START_STATES = ("startTransition", "runningState")
END_STATES = ("completeState", "endTransition", "stopTransition")


# SimulationTimeCondition rules that hold from time 0 (for a value above 0)
FROM_START = ("lessThan", "lessOrEqual", "notEqualTo")


def _first_time(node: Node) -> float:
    """The first time >= 0 a ``SimulationTimeCondition`` holds, NEVER if none: every Rule
    of OpenSCENARIO 1.2 (greaterThan, lessThan, equalTo, greaterOrEqual, lessOrEqual,
    notEqualTo), as :func:`.conditions.compare` evaluates them during the run."""
    rule, value = node.need("rule"), node.num("value")
    if rule in ("greaterThan", "greaterOrEqual"):
        return max(value, 0.0)
    if rule == "equalTo":
        return value if value >= 0.0 else NEVER
    if rule == "lessThan":
        return 0.0 if value > 0.0 else NEVER
    if rule == "lessOrEqual":
        return 0.0 if value >= 0.0 else NEVER
    if rule == "notEqualTo":
        return 0.0
    raise refuse(node, f"rule={rule} is not a rule (OpenSCENARIO 1.2 Rule)")


class NotYet(Exception):
    """A state condition on an element not timed yet (the caller retries after others)."""

    def __init__(self, node: Node) -> None:
        super().__init__(node.where())
        self.node = node


class Clock:
    """Start and end times of the elements by qualified name (``ends`` filled as actions
    are timed); ``resolve`` gives the qualified name a state condition refers to."""

    def __init__(self, parameters: dict[str, str], resolve: Callable[[Node], str]) -> None:
        self.parameters, self.resolve = parameters, resolve
        self.starts: dict[str, float] = {}
        self.ends: dict[str, float] = {}

    def trigger_time(self, trigger: Node | None, default: float) -> float | str:
        """Earliest time the trigger fires (``default`` without one), NEVER, or DYNAMIC."""
        if trigger is None or not trigger.children:
            return default
        times = [self._group(g) for g in trigger.findall("ConditionGroup")]
        if DYNAMIC in times:
            return DYNAMIC
        return min(float(t) for t in times)

    def _group(self, group: Node) -> float | str:
        times = [self._condition(c) for c in group.findall("Condition")]
        if DYNAMIC in times:
            return DYNAMIC
        return max(float(t) for t in times) if times else NEVER

    def _condition(self, cond: Node) -> float | str:
        delay = cond.num("delay", 0.0)
        inner = cond.children[0].children[0] if cond.children[0].children else cond
        rule = inner.get("rule") if inner.tag == "SimulationTimeCondition" else None
        if rule in FROM_START and cond.get("conditionEdge", "none") != "none":
            return DYNAMIC  # true from the start: its edges are the run's (the engine's)
        t = self._value_time(inner)
        return t if t == DYNAMIC else float(t) + delay

    def _value_time(self, node: Node) -> float | str:
        if node.tag == "SimulationTimeCondition":
            return _first_time(node)
        if node.tag == "ParameterCondition":
            return 0.0 if self._parameter_true(node) else NEVER
        if node.tag == "StoryboardElementStateCondition":
            return self._state_time(node)
        return DYNAMIC

    def _parameter_true(self, node: Node) -> bool:
        ref, rule, want = node.need("parameterRef"), node.need("rule"), node.need("value")
        scope = node.parameters(self.parameters)  # the Story's, if declared there
        if ref not in scope:
            raise refuse(node, f"parameter {ref} is not declared")
        have = scope[ref]
        try:
            a, b = float(have), float(want)
        except ValueError:  # text: equal or not
            same = have.strip().lower() == want.strip().lower()
            if rule not in ("equalTo", "notEqualTo"):
                raise refuse(node, f"rule={rule} on text {have!r}") from None
            return same == (rule == "equalTo")
        ops = {
            "equalTo": a == b,
            "notEqualTo": a != b,
            "greaterThan": a > b,
            "lessThan": a < b,
            "greaterOrEqual": a >= b,
            "lessOrEqual": a <= b,
        }
        if rule not in ops:
            raise refuse(node, f"rule={rule} is not supported")
        return ops[rule]

    def _state_time(self, node: Node) -> float:
        ref, state = self.resolve(node), node.need("state")
        if node.get("storyboardElementType") not in STATE_TYPES:
            raise refuse(node, f"element type {node.get('storyboardElementType')} unsupported")
        table = self.starts if state in START_STATES else self.ends
        if state not in START_STATES + END_STATES:
            raise refuse(node, f"state={state} is not supported")
        if ref not in table:
            raise NotYet(node)
        return table[ref]
