"""The private actions as motions of one actor, stepped with the simulation.

Each motion is started once (``start``: it reads what it needs of the world then) and then
stepped (``step``: the actor's state at the end of the coming step; True when complete), as
esmini's ``OSCPrivateAction``. Shapes (OpenSCENARIO 1.2 ``DynamicsShape``) as fractions of the
way: linear ``f = tau``, cubic ``3 tau^2 - 2 tau^3``, sinusoidal ``(1 - cos(pi tau)) / 2``,
step ``1``.
"""

from __future__ import annotations

import math
import sys

from eoam_sumo.openscenario.actors import Actor, lane_plus
from eoam_sumo.openscenario.subset import refuse
from eoam_sumo.openscenario.xmltree import Node
from eoam_sumo.params import G_MPS2

# a speed below this is a stop to standstill (Vector's CCRb brakes its target "to 2 km/h",
# 0.56 m/s, where Euro NCAP's protocol stops it: the protocol's own points stop it too)
STOP_MPS = 0.6
# peak slope of each shape over tau in [0, 1] (for a rate: the duration |delta| * peak / rate)
PEAK_SLOPE = {"linear": 1.0, "cubic": 1.5, "sinusoidal": math.pi / 2}
# peak second derivative (for a lateral acceleration limit: T = sqrt(|delta| * peak / a))
PEAK_CURVE = {"linear": 4.0, "cubic": 6.0, "sinusoidal": math.pi**2 / 2}


def shape_fraction(shape: str, tau: float) -> float:
    """How far along its way a shaped change is at ``tau`` in [0, 1]."""
    tau = min(max(tau, 0.0), 1.0)
    if shape == "linear":
        return tau
    if shape == "cubic":
        return tau * tau * (3.0 - 2.0 * tau)
    if shape == "sinusoidal":
        return 0.5 * (1.0 - math.cos(math.pi * tau))
    return 1.0  # step


class SpeedMotion:
    """``SpeedAction``: to an absolute or relative target speed, by step, rate or time.

    A deceleration is capped by the friction of the actor's lane (``mu g``), as the scripted
    stops of any run (docs/scenarios.md)."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.dyn = node.find("SpeedActionDynamics")
        target = node.find("SpeedActionTarget")
        assert self.dyn is not None and target is not None  # subset.py checked
        self.target = target.children[0]
        self.shape = self.dyn.need("dynamicsShape")
        self.dim = self.dyn.get("dynamicsDimension", "time")
        self.value = self.dyn.num("value", 0.0)
        self.said_negative = False

    def _target_mps(self, world) -> float:
        t = self.target
        if t.tag == "AbsoluteTargetSpeed":
            value = t.num("value")
            return 0.0 if value < STOP_MPS else value
        ref = world.actors[t.need("entityRef")].speed_mps
        if t.get("speedTargetValueType", "delta") == "factor":
            value = ref * t.num("value")
        else:
            value = ref + t.num("value")
        if value < 0.0 and not self.said_negative:  # said once (a continuous target: each step)
            self.said_negative = True
            print(f"eoam-sumo: {t.where()} at {world.time_s:.2f} s: target speed {value:.3g} m/s "
                  "run as a stop", file=sys.stderr)  # fmt: skip
        return max(value, 0.0)

    def start(self, world, actor: Actor) -> None:
        self.v0, self.t0 = actor.speed_mps, world.time_s
        self.goal = self._target_mps(world)
        self.continuous = self.target.get("continuous") in ("true", "1")
        delta = abs(self.goal - self.v0)
        self.duration = 0.0
        if self.shape != "step" and self.dim == "time":
            self.duration = self.value
        elif self.shape != "step" and self.dim == "rate" and self.value == 0 and delta > 1e-6:
            self.duration = math.inf  # never there: the speed kept (ALKS 4.4_1's "no change")
            print(f"eoam-sumo: {self.node.where()} at {world.time_s:.2f} s: a rate of 0 never "
                  f"reaches the target speed {self.goal:.3g} m/s: {actor.name} keeps "
                  f"{self.v0:.3g} m/s", file=sys.stderr)  # fmt: skip
        elif self.shape != "step" and self.dim == "rate":
            self.duration = (
                0.0 if self.value == 0 else delta * PEAK_SLOPE[self.shape] / abs(self.value)
            )
        elif self.shape != "step":
            raise refuse(self.node, f"dynamicsDimension={self.dim} is not supported for a speed")

    def step(self, world, actor: Actor, dt_s: float) -> bool:
        if self.continuous:
            self.goal = self._target_mps(world)
        if self.duration <= 0.0:
            want = self.goal
        elif math.isinf(self.duration):
            want = actor.speed_mps
        else:
            tau = (world.time_s + dt_s - self.t0) / self.duration
            want = self.v0 + (self.goal - self.v0) * shape_fraction(self.shape, tau)
        floor = actor.speed_mps - world.mu(actor) * G_MPS2 * dt_s
        actor.advance(max(want, floor, 0.0), dt_s)
        return not self.continuous and abs(actor.speed_mps - self.goal) < 1e-6


class LateralMotion:
    """``LaneChangeAction`` (to an absolute or relative target lane, its ``targetLaneOffset``;
    by time, distance or ``rate``, the peak lateral speed) and ``LaneOffsetAction`` (to an
    absolute or relative offset, its ``maxLateralAcc``)."""

    def __init__(self, node: Node) -> None:
        self.node = node

    def start(self, world, actor: Actor) -> None:
        node, lanes = self.node, world.lanes
        self.lane0, self.o0, self.t0, self.d0 = (
            actor.lane,
            actor.offset_m,
            world.time_s,
            actor.odometer_m,
        )
        self.lane1, offset1 = self._goal(world, actor)
        if not lanes.has(actor.road, self.lane1):  # no such lane: said, the actor keeps its own
            where = f"{node.where()} at {world.time_s:.2f} s"
            print(f"eoam-sumo: {where}: {actor.name} has no lane {self.lane1} to change to; "
                  "it keeps its lane", file=sys.stderr)  # fmt: skip
            self.lane1 = self.lane0
        shift = lanes.shift_m(actor.road, self.lane0, self.lane1, actor.s_m)  # left of s
        self.delta = shift + offset1 - self.o0
        self.offset1 = offset1
        dyn = node.children[0]
        self.shape = dyn.need("dynamicsShape")
        self.by_distance = dyn.get("dynamicsDimension") == "distance"
        if node.tag == "LaneOffsetAction":
            a = dyn.num("maxLateralAcc", 0.0)
            self.length = (
                0.0 if a <= 0 else math.sqrt(abs(self.delta) * PEAK_CURVE.get(self.shape, 0.0) / a)
            )
        elif dyn.get("dynamicsDimension") == "rate":
            self.length = abs(self.delta) * PEAK_SLOPE.get(self.shape, 0.0) / dyn.num("value")
        else:
            self.length = dyn.num("value")

    def _goal(self, world, actor: Actor) -> tuple[int, float]:
        node = self.node
        if node.tag == "LaneOffsetAction":
            target = node.find("LaneOffsetTarget").children[0]  # type: ignore[union-attr]
            if target.tag == "AbsoluteTargetLaneOffset":
                return actor.lane, target.num("value")
            return actor.lane, world.actors[target.need("entityRef")].offset_m + target.num("value")
        target = node.find("LaneChangeTarget").children[0]  # type: ignore[union-attr]
        offset = node.num("targetLaneOffset", 0.0)
        if target.tag == "AbsoluteTargetLane":
            return int(target.num("value")), offset
        ref = world.actors[target.need("entityRef")]
        return lane_plus(ref.lane, int(target.num("value")) * ref.direction), offset

    def step(self, world, actor: Actor, dt_s: float) -> bool:
        if self.length <= 0.0:
            tau = 1.0
        elif self.by_distance:
            tau = (actor.odometer_m + actor.speed_mps * dt_s - self.d0) / self.length
        else:
            tau = (world.time_s + dt_s - self.t0) / self.length
        before = actor.offset_m
        actor.offset_m = self.o0 + self.delta * shape_fraction(self.shape, tau)
        actor.lat_speed_mps = (actor.offset_m - before) / dt_s
        if tau < 1.0:
            return False
        if self.lane1 != self.lane0:
            actor.lane, actor.offset_m = self.lane1, self.offset1
        actor.lat_speed_mps = 0.0
        return self.node.tag != "LaneOffsetAction" or self.node.get("continuous") not in (
            "true",
            "1",
        )
