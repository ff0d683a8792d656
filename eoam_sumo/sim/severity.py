"""The first contact of a run and its severity: overlap, impact angle, and the ego's change of
velocity (delta-v); the contact test at the plant's sub-steps.

Delta-v from the exchange of momentum of a fully plastic impact of two free bodies along the
contact normal (the box axis that closed last, ``geometry.contact``): both end with the same
velocity along the normal, so the ego's velocity changes by

    delta_v_ego = m_other / (m_ego + m_other) * v_closing

with ``v_closing`` the relative velocity along the normal (Brach and Brach, *Vehicle Accident
Analysis and Reconstruction Methods*, 2011, ch. 5; the ``delta-V`` of crash reconstruction).
Two equal masses share the closing speed equally (0.5 each). Sliding along the contact face
and rotation are neglected: for an offset hit this overstates the ego's delta-v.

Masses: the ego's from its vehicle parameters; another road user's from SUMO
(``getMass``: its vType's ``mass``, or SUMO's default for its vClass when the vType sets none:
1500 kg for a passenger car, 200 kg motorcycle, 4500 kg truck, 5000 kg delivery, 12000 kg
bus, 70 kg pedestrian). A bicycle is the exception: SUMO's default, 10 kg, is the bicycle
without its rider, so a bicycle reported at that mass counts as ``BICYCLE_WITH_RIDER_KG``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mypy_extensions import mypyc_attr

from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import Contact, OrientedBox, contact, face_overlap

#: SUMO's default mass of a bicycle vType without a ``mass`` attribute [kg] (SUMO 1.28).
SUMO_BICYCLE_DEFAULT_KG = 10.0
#: A bicycle with its rider [kg]: 10 kg bicycle + 75 kg adult (assumed).
BICYCLE_WITH_RIDER_KG = 85.0


def road_user_mass_kg(sumo_mass_kg: float, vclass: str) -> float:
    """The mass that takes part in a collision, from SUMO's reported mass and vClass."""
    if vclass == "bicycle" and sumo_mass_kg == SUMO_BICYCLE_DEFAULT_KG:
        return BICYCLE_WITH_RIDER_KG
    return sumo_mass_kg


def delta_v_mps(m_self_kg: float, m_other_kg: float, closing_speed_mps: float) -> float:
    """Change of velocity [m/s] of the body of mass ``m_self_kg`` in a plastic impact with one
    of ``m_other_kg`` closing at ``closing_speed_mps`` along the contact normal."""
    if not (m_self_kg > 0.0 and m_other_kg > 0.0):
        raise ValueError(f"masses must be > 0, got {m_self_kg} and {m_other_kg}")
    return m_other_kg / (m_self_kg + m_other_kg) * max(closing_speed_mps, 0.0)


def impact_angle_rad(yaw_self_rad: float, yaw_other_rad: float) -> float:
    """Angle [rad] between the two headings at the impact, in [0, pi]: 0 for a hit from
    behind or into the rear of a body going the same way, pi for a head-on."""
    return abs(math.remainder(yaw_other_rad - yaw_self_rad, math.tau))


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class ContactRecord:
    """The first contact of a run: the contact, the role of the road user hit, when, the road
    user (as SUMO reported it at the end of the step) and both boxes at the first plant
    sub-step in contact."""

    contact: Contact
    role: str
    time_s: float
    body: Body
    ego_box: OrientedBox
    other_box: OrientedBox


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class Severity:
    """How hard and how squarely the ego hit: ``overlap`` the share of the ego's face hit that
    the other body covers (its width for the front or rear, as crash tests define offset; its
    length for a side), ``direct_overlap`` the covered width over the narrower of the two
    widths (direct or offset hit), the impact angle, the masses and the ego's delta-v."""

    overlap: float
    direct_overlap: float
    impact_angle_rad: float
    other_mass_kg: float
    delta_v_ego_mps: float


def contact_severity(
    record: ContactRecord, ego_mass_kg: float, other_sumo_mass_kg: float
) -> Severity:
    """The severity of a contact, the other's mass from SUMO (``road_user_mass_kg``)."""
    hit, ego, other = record.contact, record.ego_box, record.other_box
    overlap = face_overlap(ego, other, hit.face_a)
    if hit.face_a in ("front", "rear"):
        narrower = min(ego.width_m, other.width_m)
        direct = min(overlap * ego.width_m / narrower, 1.0)
    else:
        direct = overlap
    mass = road_user_mass_kg(other_sumo_mass_kg, record.body.vclass)
    return Severity(
        overlap,
        direct,
        impact_angle_rad(ego.yaw_rad, other.yaw_rad),
        mass,
        delta_v_mps(ego_mass_kg, mass, hit.closing_speed_mps),
    )


def substep_contact(
    x_prev,
    x_next,
    body: Body,
    b0: Body,
    length_m: float,
    width_m: float,
    cg_to_front_m: float,
    substeps: int,
) -> tuple[Contact, OrientedBox, OrientedBox] | None:
    """First contact at any plant sub-step between the ego (plant states ``x_prev`` and
    ``x_next``, its box ``length_m`` x ``width_m`` with the CG ``cg_to_front_m`` behind the
    front) and ``body`` (``b0`` its pose at the start of the step), both poses interpolated
    linearly over the step; the contact with both boxes then, or None."""
    for k in range(1, substeps + 1):
        w = k / substeps
        ex = x_prev[0] + w * (x_next[0] - x_prev[0])
        ey = x_prev[1] + w * (x_next[1] - x_prev[1])
        eyaw = x_prev[2] + w * (x_next[2] - x_prev[2])
        bx = b0.x_m + w * (body.x_m - b0.x_m)
        by = b0.y_m + w * (body.y_m - b0.y_m)
        byaw = body.yaw_rad
        ebox = OrientedBox.from_axis_point(ex, ey, eyaw, length_m, width_m, cg_to_front_m)
        obox = OrientedBox(bx, by, byaw, body.length_m, body.width_m)
        vx = x_prev[3] + w * (x_next[3] - x_prev[3])
        vy = x_prev[4] + w * (x_next[4] - x_prev[4])
        ce, se = math.cos(eyaw), math.sin(eyaw)
        ve = (vx * ce - vy * se, vx * se + vy * ce)
        vb = (body.speed_mps * math.cos(byaw), body.speed_mps * math.sin(byaw))
        hit = contact(ebox, obox, ve, vb)
        if hit is not None:
            return hit, ebox, obox
    return None
