"""Road users as ground truth: one :class:`Body` type, and SUMO's angle convention.

A :class:`Body` is any road user SUMO has (a vehicle of any vClass, a bicycle, a person) or a
test's hand-made one: its SUMO id and vClass (``pedestrian`` for persons), the centre of its
footprint, yaw counter-clockwise from +x, speed along the yaw, size, whether it is parked, and
its :class:`~eoam_sumo.world.geometry.OrientedBox`. The session builds one per road user per
step that its values changed, and the radar, the contact test and the outcome read it.

SUMO reports a road user's FRONT centre (for a person: the front in its walking direction;
checked with libsumo 1.28 here: a 0.2 m person walking behind a 5 m one on a one-stripe
sidewalk closes to 5.25 m, the leader's length plus minGap, between reported positions) and
its navigation angle (degrees clockwise from north); :func:`yaw_rad` and
:func:`nav_angle_deg` convert that angle.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from mypy_extensions import mypyc_attr

from eoam_sumo.world.geometry import OrientedBox

PEDESTRIAN = "pedestrian"  # SUMO's vClass of persons


class _BodyFields(NamedTuple):
    """Body's fields, typed so that compiled code reads them as floats (hypothesis' ``builds``
    would ask for every field: build bodies with the constructor). The functions of the step
    loop unpack a body (``vid, _, x, y, ... = b``): compiled code then reads the tuple's items
    directly, a field by name through Python's attribute lookup."""

    vid: str
    vclass: str
    x_m: float
    y_m: float
    yaw_rad: float
    speed_mps: float
    length_m: float
    width_m: float
    parked: bool
    box: OrientedBox


@mypyc_attr(native_class=False)  # a tuple subclass: a Python class when compiled too
class Body(_BodyFields):
    """A road user: SUMO id and vClass, centre (x_m, y_m), yaw CCW from +x, speed along it,
    footprint, parked flag and its oriented box.

    ``Body(vid, vclass, x_m, y_m, yaw_rad, speed_mps, length_m, width_m, parked=False)``; an
    immutable tuple subclass (built for every moving road user at every step that its values
    changed). Raises ValueError for a non-finite number or a size not above 0."""

    __slots__ = ()

    def __new__(
        cls,
        vid: str,
        vclass: str,
        x_m: float,
        y_m: float,
        yaw_rad: float,
        speed_mps: float,
        length_m: float,
        width_m: float,
        parked: bool = False,
    ):
        if not math.isfinite(speed_mps):
            raise ValueError(f"Body.speed_mps={speed_mps!r} must be finite")
        box = OrientedBox(x_m, y_m, yaw_rad, length_m, width_m)
        return tuple.__new__(
            cls, (vid, vclass, x_m, y_m, yaw_rad, speed_mps, length_m, width_m, parked, box)
        )

    def __getnewargs__(self):
        return self[:9]

    def __repr__(self) -> str:
        return (
            f"Body(vid={self.vid!r}, vclass={self.vclass!r}, x_m={self.x_m!r}, "
            f"y_m={self.y_m!r}, yaw_rad={self.yaw_rad!r}, speed_mps={self.speed_mps!r}, "
            f"length_m={self.length_m!r}, width_m={self.width_m!r}, "
            f"parked={self.parked!r})"
        )

    @classmethod
    def from_front(
        cls,
        vid: str,
        vclass: str,
        x_front_m: float,
        y_front_m: float,
        angle_nav_deg: float,
        speed_mps: float,
        length_m: float,
        width_m: float,
        parked: bool = False,
    ) -> Body:
        """The body of a road user from SUMO's front position and navigation angle."""
        yaw = yaw_rad(angle_nav_deg)
        half = 0.5 * length_m
        return cls(
            vid,
            vclass,
            x_front_m - half * math.cos(yaw),
            y_front_m - half * math.sin(yaw),
            yaw,
            speed_mps,
            length_m,
            width_m,
            parked,
        )


def nav_angle_deg(yaw_rad: float) -> float:
    """SUMO navigation angle (degrees clockwise from north) of a yaw (rad CCW from +x)."""
    return (90.0 - math.degrees(yaw_rad)) % 360.0


def yaw_rad(nav_angle_deg: float) -> float:
    """Yaw in (-pi, pi], CCW from +x, of a SUMO navigation angle."""
    yaw = math.remainder(math.radians(90.0 - nav_angle_deg), 2.0 * math.pi)
    return yaw + 2.0 * math.pi if yaw <= -math.pi else yaw
