"""Placements during the run: ``TeleportAction`` and a ``LongitudinalDistanceAction``
(the entity put at the distance or time gap ahead of the referenced one along the road, in
its own lane and lateral offset: a longitudinal action; continuous keeping of the distance
is refused by :mod:`.subset`)."""

from __future__ import annotations

from eoam_sumo.openscenario.actors import Actor, lane_plus, leading_s_m
from eoam_sumo.openscenario.xmltree import Node


def place_now(world, actor: Actor, action: Node) -> None:
    """Carry out a placement of ``actor`` (``action``: the PrivateAction's child); controller
    actions change nothing here (the ego is the EOAM's)."""
    if action.tag == "TeleportAction":
        pos = action.find("Position")
        where = pos.children[0]  # type: ignore[union-attr]
        offset = where.num("offset", 0.0)
        if where.tag == "LanePosition":
            actor.road, actor.lane, actor.s_m = (
                where.need("roadId"),
                int(where.num("laneId")),
                where.num("s"),
            )
            actor.direction = 1 if actor.lane < 0 else -1  # along its new lane
        else:
            ref = world.actors[where.need("entityRef")]
            actor.road, actor.lane = ref.road, lane_plus(ref.lane, int(where.num("dLane", 0.0)))
            actor.s_m = ref.s_m + where.num("ds")  # along the road's s (as compile._place)
            actor.direction = ref.direction
        actor.offset_m = offset
        return
    inner = action.children[0] if action.children else action
    if inner.tag != "LongitudinalDistanceAction":
        return
    ref = world.actors[inner.need("entityRef")]
    gap = (
        inner.num("distance")
        if inner.get("distance") is not None
        else inner.num("timeGap") * ref.speed_mps
    )
    if actor.road != ref.road:  # s is one road's: onto the reference's road and lane
        actor.road, actor.lane, actor.direction = ref.road, ref.lane, ref.direction
    actor.s_m = leading_s_m(ref, actor, gap, inner.get("freespace") in ("true", "1"))
