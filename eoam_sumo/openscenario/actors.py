"""The entities as the storyboard moves them: lane position, speed, distance travelled.

Each target (a puppet) keeps its speed and its lane position unless an action moves it
(esmini's default controller); the ego's state is read from the co-simulation each step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from eoam_sumo.openscenario.model import Body


@dataclass
class Actor:
    """One entity: ``s_m`` of its reference point along the road, ``offset_m`` from its lane's
    centre (left of the direction of s), speed along its lane."""

    name: str
    body: Body
    road: str
    lane: int
    s_m: float
    offset_m: float
    speed_mps: float
    puppet: bool = True
    odometer_m: float = 0.0
    accel_mps2: float = 0.0
    lat_speed_mps: float = 0.0
    still_s: float = 0.0  # how long it has stood still
    speed_busy: object = None  # the running action that sets its speed
    lateral_busy: object = None  # the running action that moves it across
    direction: int = 0  # +1 along s, -1 against (0: its lane's, set at the start)

    def __post_init__(self) -> None:
        """The direction of travel is its starting lane's (negative ids run along s) and
        stays so: a lane change across the centre line (an overtake in the oncoming lane, as
        esmini drives it) does not turn the entity round."""
        if self.direction == 0:
            self.direction = 1 if self.lane < 0 else -1

    def front_s_m(self) -> float:
        return self.s_m + self.direction * self.body.front_ahead_m

    def rear_s_m(self) -> float:
        return self.s_m + self.direction * self.body.rear_ahead_m

    def advance(self, speed_mps: float, dt_s: float) -> None:
        """One step on at ``speed_mps`` (SUMO's Euler update: the new speed over the step)."""
        self.accel_mps2 = (speed_mps - self.speed_mps) / dt_s
        self.speed_mps = speed_mps
        self.s_m += self.direction * speed_mps * dt_s
        self.odometer_m += speed_mps * dt_s
        self.still_s = self.still_s + dt_s if speed_mps < 1e-3 else 0.0


def s_span_m(actor: Actor) -> tuple[float, float]:
    """The s of the actor's two box ends, the lower first, whatever its heading."""
    front, rear = actor.front_s_m(), actor.rear_s_m()
    return (front, rear) if front < rear else (rear, front)


def longitudinal_gap_m(me: Actor, other: Actor, freespace: bool) -> float:
    """``other`` ahead of ``me`` along ``me``'s direction (negative: behind), reference point
    to reference point or, with ``freespace``, between the nearer ends of the two boxes
    (0 when they overlap): OpenSCENARIO 1.2's freespace distance, "between the bounding
    boxes", so for an entity facing ``me`` its front, not its rear."""
    ds = (other.s_m - me.s_m) * me.direction
    if not freespace:
        return ds
    (me_lo, me_hi), (it_lo, it_hi) = s_span_m(me), s_span_m(other)
    if it_lo > me_hi:  # other wholly further along s
        return (it_lo - me_hi) * me.direction
    if it_hi < me_lo:
        return (it_hi - me_lo) * me.direction
    return 0.0


def gap_rate_mps(me: Actor, other: Actor) -> float:
    """How fast :func:`longitudinal_gap_m` grows: ``other``'s velocity along ``me``'s
    direction less ``me``'s speed (for entities heading opposite ways, minus the sum of
    their speeds)."""
    return other.speed_mps * other.direction * me.direction - me.speed_mps


def leading_s_m(ref: Actor, actor: Actor, gap_m: float, freespace: bool) -> float:
    """The s of ``actor``'s reference point ``gap_m`` ahead of ``ref`` along ``ref``'s
    direction (``LongitudinalDistanceAction``, displacement leadingReferencedEntity):
    reference point to reference point or, with ``freespace``, from ``ref``'s front to
    ``actor``'s nearer end (its rear when it heads as ``ref``, else its front)."""
    if not freespace:
        return ref.s_m + ref.direction * gap_m
    same = actor.direction == ref.direction
    near = actor.body.rear_ahead_m if same else -actor.body.front_ahead_m
    return ref.s_m + ref.direction * (ref.body.front_ahead_m + gap_m - near)


def lateral_gap_m(lat_me: float, lat_other: float, me: Actor, other: Actor, free: bool) -> float:
    """Lateral distance of two entities' centres (``lat_*`` left of s), or of their sides."""
    d = abs(lat_other - lat_me)
    return max(0.0, d - (me.body.width_m + other.body.width_m) / 2) if free else d


def lane_plus(lane: int, d: int) -> int:
    """OpenDRIVE lane id ``d`` lanes on (ids skip 0)."""
    out = lane + d
    if lane < 0 <= out or lane > 0 >= out:
        out += 1 if d > 0 else -1
    return out


def euclid(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])
