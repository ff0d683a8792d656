"""Placements during the run: ``TeleportAction`` and a ``LongitudinalDistanceAction``
(the entity put at the distance or time gap from the referenced one, in its lane; continuous
keeping of the distance is refused by :mod:`.subset`)."""

from __future__ import annotations

from eoam_sumo.openscenario.actors import Actor, lane_plus
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
    if inner.get("freespace") in ("true", "1"):
        gap += ref.body.front_ahead_m - actor.body.rear_ahead_m
    actor.road, actor.lane, actor.offset_m = ref.road, ref.lane, ref.offset_m
    actor.s_m = ref.s_m + ref.direction * gap
