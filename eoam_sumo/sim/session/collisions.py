"""SUMO-format collision records (``collision-output``) from the co-simulation's own contacts.

SUMO does not see the contacts of the ego it is told to move (``collision.action`` is none
and the ego is placed by moveToXY), so a scenario's ``collision-output`` would stay empty.
The session collects :class:`CollisionRecord`\\ s (``SumoSession.record_collision``) and, when
the sumocfg asks for a collision output, writes them into that file after SUMO has closed it,
beside any record SUMO wrote itself, in SUMO's format (``collision_file.xsd``): time (SUMO's
label of the step, its start), type, lane, pos, collider, victim, their types and speeds and
the centres of their front and rear bumpers.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from eoam_sumo.world.bodies import Body

ROOT_TAG = "collisions"


@dataclass(frozen=True)
class CollisionRecord:
    """One contact as SUMO's collision output has it (``collider`` hit ``victim``)."""

    time_s: float  # SUMO's label of the step of the contact (its start)
    lane: str  # the collider's lane ("" when it is on none)
    pos_m: float  # the collider's position along that lane
    collider: Body
    victim: Body
    collider_type: str
    victim_type: str
    kind: str = "collision"  # SUMO's collision type

    def attributes(self) -> dict:
        """The ``<collision>`` element's attributes, formatted as SUMO writes them."""
        return {
            "time": f"{self.time_s:.2f}",
            "type": self.kind,
            "lane": self.lane,
            "pos": f"{self.pos_m:.2f}",
            "collider": self.collider.vid,
            "victim": self.victim.vid,
            "colliderType": self.collider_type,
            "victimType": self.victim_type,
            "colliderSpeed": f"{self.collider.speed_mps:.2f}",
            "victimSpeed": f"{self.victim.speed_mps:.2f}",
            "colliderFront": _bumper(self.collider, 0.5),
            "colliderBack": _bumper(self.collider, -0.5),
            "victimFront": _bumper(self.victim, 0.5),
            "victimBack": _bumper(self.victim, -0.5),
        }


def _bumper(body: Body, along: float) -> str:
    """'x,y' of the centre of a body's front (along 0.5) or rear (-0.5) bumper."""
    reach = along * body.length_m
    return (
        f"{body.x_m + reach * math.cos(body.yaw_rad):.2f},"
        f"{body.y_m + reach * math.sin(body.yaw_rad):.2f}"
    )


def write_collision_output(path: Path, records: list[CollisionRecord]) -> None:
    """Add ``records`` to the collision output at ``path`` (SUMO's own records kept, all in
    time order). A file that is missing or that SUMO left unreadable is written anew."""
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
        if root.tag != ROOT_TAG:
            raise ET.ParseError(f"root <{root.tag}>")
    except (OSError, ET.ParseError):
        root = ET.Element(ROOT_TAG)
    elements = [*root.findall("collision")]
    for elem in elements:
        root.remove(elem)
    elements += [ET.Element("collision", rec.attributes()) for rec in records]
    elements.sort(key=lambda e: float(e.get("time", "0")))
    for elem in elements:
        root.append(elem)
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)
