"""What the SUMO scenario is written from: bodies, departure places and speeds, the ego."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from eoam_sumo.openscenario.xmltree import Node


@dataclass(frozen=True)
class Body:
    """An entity's footprint: ``centre_ahead_m`` is its box centre ahead of its reference
    point (OpenSCENARIO positions place the reference point, usually the rear axle)."""

    name: str
    length_m: float
    width_m: float
    centre_ahead_m: float
    category: str

    @property
    def front_ahead_m(self) -> float:
        """The front bumper ahead of the reference point."""
        return self.centre_ahead_m + self.length_m / 2

    @property
    def rear_ahead_m(self) -> float:
        """The rear bumper ahead of the reference point (negative: behind it)."""
        return self.centre_ahead_m - self.length_m / 2


@dataclass(frozen=True)
class Place:
    """A reference point on an OpenDRIVE lane: road, lane id, s along the road."""

    road: str
    lane: int
    s_m: float
    node: Node
    offset_m: float = 0.0  # from the lane's centre, left of the direction of s


@dataclass
class Plan:
    """Everything the SUMO scenario is written from."""

    bodies: dict[str, Body]
    ego: str
    places: dict[str, Place]
    speeds_mps: dict[str, float]
    notes: list[str] = field(default_factory=list)
    # Init actions the storyboard engine runs from time 0 (entity, the PrivateAction's child)
    init_actions: list[tuple[str, Node]] = field(default_factory=list)

    def sumo_ids(self) -> dict[str, str]:
        """Entity name -> its SUMO vehicle id: ``ego`` for the ego; for a target its name
        with anything but letters, digits, ``_ . -`` as ``_`` (a space, ``&`` or ``"``
        broke the SUMO files), made unique (a target named ``ego`` becomes ``ego_2``)."""
        ids = {self.ego: "ego"}
        taken = {"ego"}
        for name in self.bodies:
            if name == self.ego:
                continue
            base = re.sub(r"[^A-Za-z0-9_.\-]", "_", name) or "_"
            vid, k = base, 1
            while vid.lower() in taken:
                k += 1
                vid = f"{base}_{k}"
            ids[name] = vid
            taken.add(vid.lower())
        return ids
