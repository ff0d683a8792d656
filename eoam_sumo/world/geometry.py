"""Oriented boxes of road users: overlap, distance and contact classification (ground truth).

SUMO does not report the remote-controlled ego's collisions reliably, so
the co-simulation tests the ego against every other body with these functions at every plant
step. They run in that loop, hence plain floats and the math module, and far pairs are
rejected by their bounding circles before the separating-axis test.

Frame: network coordinates, x east, y north, yaw counter-clockwise from +x (docs/architecture.md).
A box's own frame has x forward (towards its ``front`` face) and y to its ``left``.

Contact rules (the paper's colours, sec. 11, need the faces and the kind of the first contact):

* contact normal: the separating axis (one of the four box axes) that closed last, i.e. the
  axis whose penetration depth divided by the closing speed along it is smallest; an axis
  whose penetration is within the tolerance counts as closed just now, and without any
  closing speed (boxes placed overlapping) the axis of least penetration is used;
* face of each box: the face whose outward normal is closest to the direction towards the
  other box along that contact normal;
* kind: ``side`` when either face is ``left`` or ``right``; ``rear_end`` when a ``rear``
  face is involved (front-rear, or rear-rear); front against front is ``head_on`` when the
  headings are within ``HEAD_ON_MAX_ANGLE_RAD`` of opposite and the two front faces overlap
  laterally by at least ``HEAD_ON_MIN_OVERLAP`` of the narrower width (measured across the
  first box's heading), otherwise ``oblique`` (angled or offset frontal);
* impact speed: norm of the relative velocity of the box centres (yaw rates neglected);
  closing speed: its component along the contact normal;
* point: centroid of the overlap region of the two boxes.

``face_overlap`` measures how much of a face the other box covers (crash tests' overlap),
``time_to_contact`` how soon two boxes keeping their velocities would touch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from mypy_extensions import mypyc_attr

#: Boxes closer than this count as touching [m]: far below the 1 mm that tests resolve and far
#: above the rounding error of a rotation of road-scale coordinates (~1e-12 m).
CONTACT_TOLERANCE_M = 1e-6
#: Frontal contact counts as head-on within this angle of exactly opposite headings [rad].
HEAD_ON_MAX_ANGLE_RAD = math.radians(20.0)
#: ... and with at least this lateral overlap of the front faces, as a fraction of the
#: narrower width (offset frontal crash tests use 40 % and 25 % overlap; 50 % and more is
#: treated as a direct hit).
HEAD_ON_MIN_OVERLAP = 0.5
#: A lower bound of a gap (bounding circles, ``gap_lower_bound``) is lowered by this for
#: rounding before it rules a gap out [m].
GAP_ROUNDING_M = 1e-6

FACES = ("front", "rear", "left", "right")
CONTACT_KINDS = ("head_on", "rear_end", "side", "oblique")


class _BoxFields(NamedTuple):
    """OrientedBox's fields, typed so that compiled code reads them as floats (hypothesis'
    ``builds`` would ask for every field: build boxes with the constructor). The functions of
    the step loop unpack a box (``x, y, _, _, _, c, s, hl, hw, _ = box``): compiled code then
    reads the tuple's items directly, a field by name through Python's attribute lookup."""

    x_m: float
    y_m: float
    yaw_rad: float
    length_m: float
    width_m: float
    cos_yaw: float
    sin_yaw: float
    half_length_m: float
    half_width_m: float
    radius_m: float


@mypyc_attr(native_class=False)  # a tuple subclass: a Python class when compiled too
class OrientedBox(_BoxFields):
    """Rectangle footprint of a body: centre, heading and size (validated), with the cosine,
    sine, half sizes and bounding radius worked out once.

    ``OrientedBox(x_m, y_m, yaw_rad, length_m, width_m)``. An immutable tuple subclass: boxes
    are built for every moving body at every step, and this builds in a third of the time of
    a frozen dataclass with ``__post_init__``. Build boxes with the constructor: the tuple's
    ``_make``/``_replace`` would skip the validation and the derived values."""

    __slots__ = ()

    def __new__(cls, x_m: float, y_m: float, yaw_rad: float, length_m: float, width_m: float):
        isfinite = math.isfinite
        if not (
            isfinite(x_m)
            and isfinite(y_m)
            and isfinite(yaw_rad)
            and isfinite(length_m)
            and isfinite(width_m)
        ):
            for name, v in zip(_BoxFields._fields, (x_m, y_m, yaw_rad, length_m, width_m)):
                if not isfinite(v):
                    raise ValueError(f"OrientedBox.{name}={v!r} must be finite")
        if length_m <= 0.0 or width_m <= 0.0:
            raise ValueError(
                f"OrientedBox needs length_m > 0 and width_m > 0, got {length_m}, {width_m}"
            )
        hl, hw = 0.5 * length_m, 0.5 * width_m
        return tuple.__new__(
            cls,
            (
                x_m,
                y_m,
                yaw_rad,
                length_m,
                width_m,
                math.cos(yaw_rad),
                math.sin(yaw_rad),
                hl,
                hw,
                math.hypot(hl, hw),
            ),
        )

    def __getnewargs__(self):
        return self[:5]

    def __repr__(self) -> str:
        return (
            f"OrientedBox(x_m={self.x_m!r}, y_m={self.y_m!r}, yaw_rad={self.yaw_rad!r}, "
            f"length_m={self.length_m!r}, width_m={self.width_m!r})"
        )

    @classmethod
    def from_axis_point(
        cls,
        x_m: float,
        y_m: float,
        yaw_rad: float,
        length_m: float,
        width_m: float,
        to_front_m: float,
    ) -> OrientedBox:
        """Box of a body given a point on its centre line ``to_front_m`` behind its front face.

        ``to_front_m=0`` for SUMO's front-bumper position, the CG-to-front-bumper distance for
        the plant's CG.
        """
        back = to_front_m - 0.5 * length_m
        return cls(
            x_m + back * math.cos(yaw_rad),
            y_m + back * math.sin(yaw_rad),
            yaw_rad,
            length_m,
            width_m,
        )

    def corners(self) -> tuple[tuple[float, float], ...]:
        """Front-left, rear-left, rear-right, front-right corners (counter-clockwise)."""
        c, s = self.cos_yaw, self.sin_yaw
        fx, fy = c * self.half_length_m, s * self.half_length_m
        lx, ly = -s * self.half_width_m, c * self.half_width_m
        x, y = self.x_m, self.y_m
        return (
            (x + fx + lx, y + fy + ly),
            (x - fx + lx, y - fy + ly),
            (x - fx - lx, y - fy - ly),
            (x + fx - lx, y + fy - ly),
        )

    def to_local(self, x_m: float, y_m: float) -> tuple[float, float]:
        """A world point in this box's frame (x forward, y left, origin at the centre)."""
        dx, dy = x_m - self.x_m, y_m - self.y_m
        return self.cos_yaw * dx + self.sin_yaw * dy, -self.sin_yaw * dx + self.cos_yaw * dy

    def to_world(self, lx_m: float, ly_m: float) -> tuple[float, float]:
        """A point of this box's frame in world coordinates."""
        return (
            self.x_m + self.cos_yaw * lx_m - self.sin_yaw * ly_m,
            self.y_m + self.sin_yaw * lx_m + self.cos_yaw * ly_m,
        )

    def nearest_point(self, x_m: float, y_m: float) -> tuple[float, float]:
        """The point of the box (boundary or inside) closest to a world point."""
        return nearest_point(self, x_m, y_m)

    def distance_to_point(self, x_m: float, y_m: float) -> float:
        """Euclidean distance from a world point to the box (0 inside)."""
        lx, ly = self.to_local(x_m, y_m)
        return math.hypot(
            max(abs(lx) - self.half_length_m, 0.0), max(abs(ly) - self.half_width_m, 0.0)
        )


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True, slots=True)
class Contact:
    """First contact between box ``a`` and box ``b`` (faces as seen from each box)."""

    kind: str
    face_a: str
    face_b: str
    impact_speed_mps: float
    point: tuple[float, float]  # centroid of the overlap region, network frame [m]
    normal: tuple[float, float]  # unit contact normal, from a towards b
    closing_speed_mps: float  # relative velocity along the normal, positive closing


def _axes(a: OrientedBox, b: OrientedBox) -> tuple[tuple[float, float], ...]:
    _, _, _, _, _, ac, asin, _, _, _ = a
    _, _, _, _, _, bc, bsin, _, _, _ = b
    return ((ac, asin), (-asin, ac), (bc, bsin), (-bsin, bc))


def _half_extent(box: OrientedBox, nx: float, ny: float) -> float:
    """Half the length of the box's projection on the unit axis (nx, ny)."""
    _, _, _, _, _, c, s, hl, hw, _ = box
    return hl * abs(c * nx + s * ny) + hw * abs(-s * nx + c * ny)


def boxes_overlap(a: OrientedBox, b: OrientedBox, tol_m: float = CONTACT_TOLERANCE_M) -> bool:
    """True when the boxes overlap or touch (within ``tol_m``); separating-axis test."""
    ax, ay, _, _, _, _, _, _, _, a_radius = a
    bx, by, _, _, _, _, _, _, _, b_radius = b
    dx, dy = bx - ax, by - ay
    reach = a_radius + b_radius + tol_m
    if dx * dx + dy * dy > reach * reach:
        return False
    for nx, ny in _axes(a, b):
        if abs(dx * nx + dy * ny) - _half_extent(a, nx, ny) - _half_extent(b, nx, ny) > tol_m:
            return False
    return True


def gap_lower_bound(a: OrientedBox, b: OrientedBox) -> float:
    """A lower bound of the boxes' gap [m]: their largest separation along one of the four box
    axes (an axis separates the boxes by at most their distance; <= 0 when they overlap along
    every axis), equal to the gap for boxes end to end in one lane or side by side. The four
    projections of ``boxes_overlap`` written out, far cheaper than ``box_distance``."""
    ax, ay, _, _, _, ac, asin, ahl, ahw, _ = a
    bx, by, _, _, _, bc, bsin, bhl, bhw, _ = b
    dx, dy = bx - ax, by - ay
    c, s = abs(ac * bc + asin * bsin), abs(ac * bsin - asin * bc)  # b's yaw relative to a's
    return max(
        abs(dx * ac + dy * asin) - ahl - bhl * c - bhw * s,
        abs(dy * ac - dx * asin) - ahw - bhl * s - bhw * c,
        abs(dx * bc + dy * bsin) - bhl - ahl * c - ahw * s,
        abs(dy * bc - dx * bsin) - bhw - ahl * s - ahw * c,
    )


def nearest_point(box: OrientedBox, x_m: float, y_m: float) -> tuple[float, float]:
    """``OrientedBox.nearest_point`` as a module function: compiled code calls it directly
    (the method of a tuple subclass goes through Python's call)."""
    bx, by, _, _, _, c, s, hl, hw, _ = box
    return _nearest_point_of(bx, by, c, s, hl, hw, x_m, y_m)


def _nearest_point_of(
    bx: float, by: float, c: float, s: float, hl: float, hw: float, x_m: float, y_m: float
) -> tuple[float, float]:
    """``nearest_point`` of the box centred at (bx, by), heading (c, s), half sizes hl, hw."""
    dx, dy = x_m - bx, y_m - by
    lx, ly = c * dx + s * dy, -s * dx + c * dy  # to_local, to_world inlined (hot path)
    if lx > hl:  # clamp to the box (comparisons: min/max calls cost more here)
        lx = hl
    elif lx < -hl:
        lx = -hl
    if ly > hw:
        ly = hw
    elif ly < -hw:
        ly = -hw
    return bx + c * lx - s * ly, by + s * lx + c * ly


def _nearest_corner(src: OrientedBox, dst: OrientedBox) -> tuple[float, float, float, float, float]:
    """(distance, x, y of the corner, x, y of its nearest point of dst) of the first corner of
    ``src`` nearest to ``dst`` (distance inf, zeros if none is finite); ``corners`` written
    out, the same arithmetic: the margins and the contact check ask this every step."""
    x, y, _, _, _, c, s, hl, hw, _ = src
    dst_x, dst_y, _, _, _, dst_c, dst_s, dst_hl, dst_hw, _ = dst
    fx, fy = c * hl, s * hl
    lx, ly = -s * hw, c * hw
    best = (math.inf, 0.0, 0.0, 0.0, 0.0)
    for cx, cy in (
        (x + fx + lx, y + fy + ly),
        (x - fx + lx, y - fy + ly),
        (x - fx - lx, y - fy - ly),
        (x + fx - lx, y + fy - ly),
    ):
        px, py = _nearest_point_of(dst_x, dst_y, dst_c, dst_s, dst_hl, dst_hw, cx, cy)
        dist = math.hypot(cx - px, cy - py)
        if dist < best[0]:
            best = (dist, cx, cy, px, py)
    return best


def _closest_points(
    a: OrientedBox, b: OrientedBox
) -> tuple[float, tuple[float, float], tuple[float, float]]:
    """(distance, point on a, point on b) for disjoint boxes: attained at a corner of one box
    (a's corners first on a tie)."""
    dist, cx, cy, px, py = _nearest_corner(a, b)
    dist_b, bx, by, qx, qy = _nearest_corner(b, a)
    if dist_b < dist:
        return dist_b, (qx, qy), (bx, by)
    if dist < math.inf:
        return dist, (cx, cy), (px, py)
    return math.inf, (a.x_m, a.y_m), (b.x_m, b.y_m)


def box_distance(a: OrientedBox, b: OrientedBox, tol_m: float = CONTACT_TOLERANCE_M) -> float:
    """Euclidean gap between two boxes [m]; 0.0 when they overlap or touch."""
    if boxes_overlap(a, b, tol_m):
        return 0.0
    return min(_nearest_corner(a, b)[0], _nearest_corner(b, a)[0])


def _face(box: OrientedBox, nx: float, ny: float) -> str:
    """Face of ``box`` whose outward normal is closest to the world direction (nx, ny)."""
    lx = box.cos_yaw * nx + box.sin_yaw * ny
    ly = -box.sin_yaw * nx + box.cos_yaw * ny
    if abs(lx) >= abs(ly):
        return "front" if lx > 0.0 else "rear"
    return "left" if ly > 0.0 else "right"


def _clip(poly: list, index: int, sign: float, limit: float) -> list:
    """Sutherland-Hodgman: keep the part of ``poly`` where sign * p[index] <= limit."""
    out = []
    n = len(poly)
    for k in range(n):
        p, q = poly[k], poly[(k + 1) % n]
        fp, fq = sign * p[index] - limit, sign * q[index] - limit
        if fp <= 0.0:
            out.append(p)
        if (fp < 0.0 < fq) or (fq < 0.0 < fp):
            t = fp / (fp - fq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def _clip_local(a: OrientedBox, b: OrientedBox, grow_m: float) -> list:
    """a's outline clipped by b grown by ``grow_m`` on every side, in b's frame."""
    poly = [b.to_local(x, y) for x, y in a.corners()]
    hl, hw = b.half_length_m + grow_m, b.half_width_m + grow_m
    for index, sign, limit in ((0, 1.0, hl), (0, -1.0, hl), (1, 1.0, hw), (1, -1.0, hw)):
        poly = _clip(poly, index, sign, limit)
        if not poly:
            break
    return poly


def _overlap_centroid(a: OrientedBox, b: OrientedBox, tol_m: float) -> tuple[float, float]:
    """Centroid of the overlap region of a and b, network frame.

    Boxes that only touch (within ``tol_m``) have no overlap area: then the region where a
    meets b grown by ``tol_m``, or failing that the midpoint of the closest points.
    """
    poly = _clip_local(a, b, 0.0) or _clip_local(a, b, tol_m)
    if not poly:
        _, pa, pb = _closest_points(a, b)
        return 0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])
    area2 = cx = cy = 0.0
    n = len(poly)
    for k in range(n):
        (x0, y0), (x1, y1) = poly[k], poly[(k + 1) % n]
        cross = x0 * y1 - x1 * y0
        area2 += cross
        cx += (x0 + x1) * cross
        cy += (y0 + y1) * cross
    if abs(area2) > 1e-12:
        lx, ly = cx / (3.0 * area2), cy / (3.0 * area2)
    else:
        lx, ly = sum(p[0] for p in poly) / n, sum(p[1] for p in poly) / n
    return b.to_world(lx, ly)


def _frontal_kind(a: OrientedBox, b: OrientedBox) -> str:
    """``head_on`` for nearly opposite headings and a mostly overlapping front, else oblique."""
    dyaw = (b.yaw_rad - a.yaw_rad + math.pi) % (2.0 * math.pi) - math.pi
    if math.pi - abs(dyaw) > HEAD_ON_MAX_ANGLE_RAD:
        return "oblique"
    offset = a.to_local(b.x_m, b.y_m)[1]
    overlap = min(a.half_width_m, offset + b.half_width_m) - max(
        -a.half_width_m, offset - b.half_width_m
    )
    return "head_on" if overlap >= HEAD_ON_MIN_OVERLAP * min(a.width_m, b.width_m) else "oblique"


def contact(
    a: OrientedBox,
    b: OrientedBox,
    va: tuple[float, float],
    vb: tuple[float, float],
    tol_m: float = CONTACT_TOLERANCE_M,
) -> Contact | None:
    """Contact of two boxes moving at world velocities ``va``, ``vb`` [m/s], or None if apart.

    The rules (normal, faces, kind, impact speed, point) are in the module docstring.
    """
    if not boxes_overlap(a, b, tol_m):
        return None
    dx, dy = b.x_m - a.x_m, b.y_m - a.y_m
    rvx, rvy = vb[0] - va[0], vb[1] - va[1]
    best_key, normal = None, (1.0, 0.0)
    for ax, ay in _axes(a, b):
        nx, ny, proj = ax, ay, dx * ax + dy * ay
        if proj < 0.0:
            nx, ny, proj = -ax, -ay, -proj
        depth = _half_extent(a, nx, ny) + _half_extent(b, nx, ny) - proj
        closing_mps = -(rvx * nx + rvy * ny)
        if depth <= tol_m:
            since_s = 0.0
        elif closing_mps > 1e-9:
            since_s = depth / closing_mps
        else:
            since_s = math.inf
        key = (since_s, depth)
        if best_key is None or key < best_key:
            best_key, normal = key, (nx, ny)
    face_a = _face(a, normal[0], normal[1])
    face_b = _face(b, -normal[0], -normal[1])
    if face_a in ("left", "right") or face_b in ("left", "right"):
        kind = "side"
    elif face_a == "front" and face_b == "front":
        kind = _frontal_kind(a, b)
    else:
        kind = "rear_end"
    return Contact(
        kind=kind,
        face_a=face_a,
        face_b=face_b,
        impact_speed_mps=math.hypot(rvx, rvy),
        point=_overlap_centroid(a, b, tol_m),
        normal=normal,
        closing_speed_mps=-(rvx * normal[0] + rvy * normal[1]),
    )


def face_overlap(a: OrientedBox, b: OrientedBox, face_a: str) -> float:
    """Share (0-1) of ``face_a`` of box ``a`` that box ``b`` covers, measured along that face:
    across a's width for its front or rear (the overlap of frontal crash tests: the share of
    the vehicle's width in line with what it hits), along its length for a side. ``b`` is
    projected onto the face's line, so an angled body covers its whole shadow there."""
    if face_a in ("front", "rear"):
        ux, uy, half = -a.sin_yaw, a.cos_yaw, a.half_width_m
    else:
        ux, uy, half = a.cos_yaw, a.sin_yaw, a.half_length_m
    centre = (b.x_m - a.x_m) * ux + (b.y_m - a.y_m) * uy
    reach = _half_extent(b, ux, uy)
    covered = min(half, centre + reach) - max(-half, centre - reach)
    return min(max(covered / (2.0 * half), 0.0), 1.0)


def time_to_contact(
    a: OrientedBox,
    b: OrientedBox,
    va: tuple[float, float],
    vb: tuple[float, float],
    horizon_s: float = math.inf,
) -> float:
    """Time [s] until the boxes touch (within ``CONTACT_TOLERANCE_M``, as ``boxes_overlap``)
    if both keep their velocities (no turning): 0 when they overlap now, ``inf`` when they never
    touch within ``horizon_s``.

    Separating-axis test of the moving pair: on each of the four box axes the gap between
    the projections changes linearly with time; contact needs every axis closed at once."""
    ax, ay, _, _, _, ac, asn, ahl, ahw, _ = a
    bx, by, _, _, _, bc, bsn, bhl, bhw, _ = b
    dx, dy = bx - ax, by - ay
    rvx, rvy = vb[0] - va[0], vb[1] - va[1]
    # b's centre on each axis relative to a's, its rate, and the pair's reach on that axis
    # (``_axes`` and ``_half_extent`` written out, the same arithmetic)
    return slab_entry(
        [
            (
                dx * nx + dy * ny,
                rvx * nx + rvy * ny,
                ahl * abs(ac * nx + asn * ny)
                + ahw * abs(-asn * nx + ac * ny)
                + (bhl * abs(bc * nx + bsn * ny) + bhw * abs(-bsn * nx + bc * ny))
                + CONTACT_TOLERANCE_M,
            )
            for nx, ny in ((ac, asn), (-asn, ac), (bc, bsn), (-bsn, bc))
        ],
        horizon_s,
    )


def slab_entry(slabs, t_max: float) -> float:
    """First t in [0, t_max] at which every slab holds, or ``inf`` if none does.

    Each slab ``(o, u, h)`` holds while ``-h <= o + u t <= h`` (a point moving at rate u
    inside a slab of half-width h): the slab test of a ray against a box, or of two boxes'
    projections closing on a separating axis."""
    t_in, t_out = 0.0, t_max
    for o, u, h in slabs:
        if abs(u) < 1e-12:
            if abs(o) > h:
                return math.inf
            continue
        t1, t2 = (-h - o) / u, (h - o) / u
        if t1 > t2:
            t1, t2 = t2, t1
        t_in, t_out = max(t_in, t1), min(t_out, t2)
        if t_in > t_out:
            return math.inf
    return t_in
