"""Oriented boxes: overlap, distance and contact classification against independent geometry."""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from eoam_sumo.world.geometry import (
    CONTACT_TOLERANCE_M,
    OrientedBox,
    box_distance,
    boxes_overlap,
    contact,
    gap_lower_bound,
)

EGO = (4.92, 1.85)  # length, width [m]
ARO = (5.09, 1.99)
CAR = (4.30, 1.80)
ANGLES_DEG = (0.0, 30.0, 45.0, 90.0, 200.0)


# --- independent reference: brute-force convex polygon geometry (no separating axes) --------


def _orient(p, q, r) -> float:
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])


def _inside_or_on(pt, poly) -> bool:
    """Point in a counter-clockwise convex polygon, boundary included."""
    n = len(poly)
    return all(_orient(poly[i], poly[(i + 1) % n], pt) >= -1e-12 for i in range(n))


def _segments_cross(p1, p2, q1, q2) -> bool:
    d1, d2 = _orient(q1, q2, p1), _orient(q1, q2, p2)
    d3, d4 = _orient(p1, p2, q1), _orient(p1, p2, q2)
    return d1 * d2 < 0.0 and d3 * d4 < 0.0


def _point_segment(pt, a, b) -> float:
    ux, uy = b[0] - a[0], b[1] - a[1]
    t = ((pt[0] - a[0]) * ux + (pt[1] - a[1]) * uy) / (ux * ux + uy * uy)
    t = min(max(t, 0.0), 1.0)
    return math.hypot(pt[0] - a[0] - t * ux, pt[1] - a[1] - t * uy)


def _brute_distance(a: OrientedBox, b: OrientedBox) -> float:
    """0 if the polygons intersect (edge crossing or containment), else vertex-edge minimum."""
    pa, pb = a.corners(), b.corners()
    ea = [(pa[i], pa[(i + 1) % 4]) for i in range(4)]
    eb = [(pb[i], pb[(i + 1) % 4]) for i in range(4)]
    if any(_segments_cross(*e, *f) for e in ea for f in eb):
        return 0.0
    if any(_inside_or_on(p, pb) for p in pa) or any(_inside_or_on(p, pa) for p in pb):
        return 0.0
    return min(
        *(_point_segment(p, *f) for p in pa for f in eb),
        *(_point_segment(p, *e) for p in pb for e in ea),
    )


def _aabb_overlap(a: OrientedBox, b: OrientedBox) -> bool:
    xa = [p[0] for p in a.corners()]
    ya = [p[1] for p in a.corners()]
    xb = [p[0] for p in b.corners()]
    yb = [p[1] for p in b.corners()]
    return min(xa) <= max(xb) and min(xb) <= max(xa) and min(ya) <= max(yb) and min(yb) <= max(ya)


def _place(a: OrientedBox, local_xy, rel_yaw_rad, dims) -> OrientedBox:
    """A box whose centre sits at ``local_xy`` in a's frame, turned by ``rel_yaw_rad``."""
    x, y = a.to_world(*local_xy)
    return OrientedBox(x, y, a.yaw_rad + rel_yaw_rad, *dims)


# --- the box itself ---------------------------------------------------------------------------


def test_corners_counter_clockwise_from_front_left():
    box = OrientedBox(10.0, -5.0, math.pi / 2, 4.0, 2.0)  # facing north
    expected = ((9.0, -3.0), (9.0, -7.0), (11.0, -7.0), (11.0, -3.0))
    for got, exp in zip(box.corners(), expected, strict=True):
        assert got == pytest.approx(exp, abs=1e-12)


def test_from_axis_point_front_bumper_and_cg():
    yaw = math.radians(30.0)
    front = OrientedBox.from_axis_point(100.0, 50.0, yaw, 4.92, 1.85, to_front_m=0.0)
    assert front.x_m == pytest.approx(100.0 - 2.46 * math.cos(yaw))
    assert front.y_m == pytest.approx(50.0 - 2.46 * math.sin(yaw))
    # a point 2.092 m behind the front (CG of the ego): centre 0.368 m behind the CG
    cg = OrientedBox.from_axis_point(0.0, 0.0, 0.0, 4.92, 1.85, to_front_m=2.092)
    assert cg.x_m == pytest.approx(2.092 - 2.46)
    assert cg.y_m == pytest.approx(0.0)


def test_nearest_point_and_distance_to_point():
    box = OrientedBox(0.0, 0.0, math.pi / 4, 2.0 * math.sqrt(2.0), 2.0 * math.sqrt(2.0))
    # a diamond with vertices at (+-2, 0), (0, +-2): nearest point to (3, 0) is the vertex
    assert box.nearest_point(3.0, 0.0) == pytest.approx((2.0, 0.0), abs=1e-12)
    assert box.distance_to_point(3.0, 3.0) == pytest.approx(math.hypot(2.0, 2.0))
    assert box.distance_to_point(0.3, -0.2) == 0.0


@pytest.mark.parametrize(
    "kwargs",
    [
        {"length_m": 0.0},
        {"width_m": -1.0},
        {"x_m": math.nan},
        {"yaw_rad": math.inf},
    ],
)
def test_box_rejects_bad_values(kwargs):
    args = {"x_m": 0.0, "y_m": 0.0, "yaw_rad": 0.0, "length_m": 4.0, "width_m": 2.0, **kwargs}
    with pytest.raises(ValueError, match="OrientedBox"):
        OrientedBox(**args)


# --- touching and near misses, rotated ------------------------------------------------------


def _end_to_end(a, gap_m, rel_deg):
    """b ahead of a, turned by rel_deg, its rearmost corner gap_m in front of a's front face."""
    phi = math.radians(rel_deg)
    hl, hw = 0.5 * ARO[0], 0.5 * ARO[1]
    reach = hl * math.cos(phi) + hw * math.sin(phi)  # b's extent behind its centre along a's x
    corner_y = -hl * math.sin(phi) + hw * math.cos(phi)  # rear-left corner's lateral position
    return _place(a, (0.5 * EGO[0] + gap_m + reach, 0.3 - corner_y), phi, ARO)


def _side_by_side(a, gap_m):
    return _place(a, (0.7, 0.5 * EGO[1] + gap_m + 0.5 * CAR[1]), math.pi, CAR)


def _corner_to_corner(a, gap_m):
    """b turned -45 deg, its rear-right corner on a's front-left corner's diagonal, gap_m away.

    b's faces leave that corner at -45 and +45 deg, away from a: the gap is corner to corner.
    """
    phi = math.radians(-45.0)
    e = gap_m / math.sqrt(2.0)
    rx = math.cos(phi) * -0.5 * CAR[0] - math.sin(phi) * -0.5 * CAR[1]
    ry = math.sin(phi) * -0.5 * CAR[0] + math.cos(phi) * -0.5 * CAR[1]
    return _place(a, (0.5 * EGO[0] + e - rx, 0.5 * EGO[1] + e - ry), phi, CAR)


CONFIGS = {
    "end_to_end": lambda a, g: _end_to_end(a, g, 0.0),
    "end_to_end_turned_30": lambda a, g: _end_to_end(a, g, 30.0),
    "side_by_side": _side_by_side,
    "corner_to_corner": _corner_to_corner,
}


@pytest.mark.parametrize("angle_deg", ANGLES_DEG)
@pytest.mark.parametrize("config", sorted(CONFIGS))
def test_one_millimetre_gap_vs_overlap(config, angle_deg):
    a = OrientedBox(120.0, -35.0, math.radians(angle_deg), *EGO)
    apart = CONFIGS[config](a, 1e-3)
    into = CONFIGS[config](a, -1e-3)
    touching = CONFIGS[config](a, 0.0)
    # the construction is what it claims, by independent polygon geometry
    assert _brute_distance(a, apart) == pytest.approx(1e-3, abs=1e-9)
    assert _brute_distance(a, into) == 0.0
    assert not boxes_overlap(a, apart)
    assert not boxes_overlap(apart, a)
    assert boxes_overlap(a, into)
    assert boxes_overlap(a, touching)
    assert box_distance(a, apart) == pytest.approx(1e-3, abs=1e-9)
    assert box_distance(a, into) == 0.0
    assert contact(a, apart, (30.0, 0.0), (0.0, 0.0)) is None
    assert contact(a, into, (30.0, 0.0), (0.0, 0.0)) is not None


@pytest.mark.parametrize("angle_deg", (15.0, 30.0, 105.0, 120.0))
def test_corner_near_miss_with_overlapping_bounding_shapes(angle_deg):
    a = OrientedBox(0.0, 0.0, math.radians(angle_deg), *EGO)
    b = _corner_to_corner(a, 1e-3)
    # the cheap tests cannot tell: axis-aligned boxes and bounding circles both overlap
    assert _aabb_overlap(a, b)
    assert math.hypot(b.x_m - a.x_m, b.y_m - a.y_m) < a.radius_m + b.radius_m
    assert not boxes_overlap(a, b)
    assert box_distance(a, b) == pytest.approx(1e-3, abs=1e-9)


def test_far_apart_distance_is_closed_form():
    a = OrientedBox(0.0, 0.0, 0.0, 4.0, 2.0)
    b = OrientedBox(10.0, 0.0, 0.0, 4.0, 2.0)
    assert box_distance(a, b) == pytest.approx(6.0)
    c = OrientedBox(10.0, 10.0, 0.0, 4.0, 2.0)  # corner (2, 1) to corner (8, 9)
    assert box_distance(a, c) == pytest.approx(math.hypot(6.0, 8.0))


# --- properties -------------------------------------------------------------------------------

coord = st.floats(-8.0, 8.0, allow_nan=False)
yaw = st.floats(-math.pi, math.pi, allow_nan=False)
length = st.floats(0.5, 6.0, allow_nan=False)
width = st.floats(0.5, 2.5, allow_nan=False)
# built through the constructor (st.builds would ask for all ten typed tuple fields)
boxes = st.tuples(coord, coord, yaw, length, width).map(lambda a: OrientedBox(*a))


def _moved(box: OrientedBox, rot: float, tx: float, ty: float) -> OrientedBox:
    c, s = math.cos(rot), math.sin(rot)
    return OrientedBox(
        c * box.x_m - s * box.y_m + tx,
        s * box.x_m + c * box.y_m + ty,
        box.yaw_rad + rot,
        box.length_m,
        box.width_m,
    )


@settings(max_examples=300, deadline=None, database=None)
@given(boxes, boxes)
def test_overlap_agrees_with_brute_force_and_is_symmetric(a, b):
    ref = _brute_distance(a, b)
    assume(ref == 0.0 or ref > 10.0 * CONTACT_TOLERANCE_M)
    assert boxes_overlap(a, b) == (ref == 0.0)
    assert boxes_overlap(b, a) == boxes_overlap(a, b)
    assert box_distance(a, b) == pytest.approx(ref, abs=1e-9)
    assert box_distance(b, a) == pytest.approx(ref, abs=1e-9)


@settings(max_examples=300, deadline=None, database=None)
@given(boxes, boxes, yaw, st.floats(-5e3, 5e3), st.floats(-5e3, 5e3))
def test_overlap_invariant_under_common_rigid_motion(a, b, rot, tx, ty):
    ref = _brute_distance(a, b)
    assume(ref == 0.0 or ref > 10.0 * CONTACT_TOLERANCE_M)
    ma, mb = _moved(a, rot, tx, ty), _moved(b, rot, tx, ty)
    assert boxes_overlap(ma, mb) == boxes_overlap(a, b)
    assert box_distance(ma, mb) == pytest.approx(box_distance(a, b), abs=1e-8)


@settings(max_examples=300, deadline=None, database=None)
@given(boxes, boxes)
def test_distance_is_the_nearest_corner_bit_for_bit(a, b):
    """The inlined corner search gives exactly (same floating-point value) the least distance
    from a corner of either box to its nearest point of the other (``nearest_point``)."""
    assume(not boxes_overlap(a, b))
    corner_gaps = [
        math.hypot(cx - px, cy - py)
        for src, dst in ((a, b), (b, a))
        for cx, cy in src.corners()
        for px, py in [dst.nearest_point(cx, cy)]
    ]
    assert box_distance(a, b) == min(corner_gaps)


@settings(max_examples=300, deadline=None, database=None)
@given(boxes, boxes)
def test_gap_lower_bound_never_exceeds_the_gap(a, b):
    """The separating-axis bound that lets the contact check skip a gap is a lower bound of
    the brute-force gap (to rounding far below the check's 1e-6 m margin), <= 0 when the
    boxes overlap."""
    ref = _brute_distance(a, b)
    assert gap_lower_bound(a, b) <= ref + 1e-9
    if ref == 0.0:
        assert gap_lower_bound(a, b) <= CONTACT_TOLERANCE_M


def test_gap_lower_bound_is_the_gap_end_to_end_and_side_by_side():
    a = OrientedBox(0.0, 0.0, 0.3, *EGO)
    c, s = math.cos(0.3), math.sin(0.3)
    ahead = OrientedBox(10.0 * c, 10.0 * s, 0.3, *ARO)
    beside = OrientedBox(-3.0 * s, 3.0 * c, 0.3, *CAR)
    assert gap_lower_bound(a, ahead) == pytest.approx(10.0 - 0.5 * (EGO[0] + ARO[0]), abs=1e-12)
    assert gap_lower_bound(a, beside) == pytest.approx(3.0 - 0.5 * (EGO[1] + CAR[1]), abs=1e-12)
    assert gap_lower_bound(a, ahead) == pytest.approx(box_distance(a, ahead), abs=1e-12)


# --- contact classification -----------------------------------------------------------------


def _vel(box: OrientedBox, speed_mps: float, lateral_mps: float = 0.0):
    """World velocity of a body moving ``speed`` along and ``lateral`` across its heading."""
    return (
        speed_mps * box.cos_yaw - lateral_mps * box.sin_yaw,
        speed_mps * box.sin_yaw + lateral_mps * box.cos_yaw,
    )


@pytest.mark.parametrize("angle_deg", ANGLES_DEG)
def test_head_on(angle_deg):
    ego = OrientedBox(-40.0, 7.0, math.radians(angle_deg), *EGO)
    onc = _place(ego, (0.5 * EGO[0] + 0.5 * CAR[0] - 0.01, 0.2), math.pi, CAR)
    hit = contact(ego, onc, _vel(ego, 30.0), _vel(onc, 20.0))
    assert (hit.kind, hit.face_a, hit.face_b) == ("head_on", "front", "front")
    assert hit.impact_speed_mps == pytest.approx(50.0)
    # the overlap is the 1 cm strip between the two front faces
    px, py = ego.to_local(*hit.point)
    assert px == pytest.approx(0.5 * EGO[0] - 0.005, abs=1e-6)
    assert abs(py) < 0.5 * EGO[1]


@pytest.mark.parametrize("angle_deg", ANGLES_DEG)
def test_offset_and_angled_frontal_hits_are_oblique(angle_deg):
    ego = OrientedBox(3.0, 3.0, math.radians(angle_deg), *EGO)
    # 1.5 m lateral offset: the fronts overlap by 0.325 m, 18 % of the narrower width
    offset = _place(ego, (0.5 * EGO[0] + 0.5 * CAR[0] - 0.01, 1.5), math.pi, CAR)
    hit = contact(ego, offset, _vel(ego, 30.0), _vel(offset, 20.0))
    assert (hit.kind, hit.face_a, hit.face_b) == ("oblique", "front", "front")
    # 40 deg off opposite, front corner into front face
    phi = math.pi - math.radians(40.0)
    reach = 0.5 * CAR[0] * math.cos(math.radians(40.0)) + 0.5 * CAR[1] * math.sin(
        math.radians(40.0)
    )
    angled = _place(ego, (0.5 * EGO[0] + reach - 0.01, 0.0), phi, CAR)
    hit = contact(ego, angled, _vel(ego, 30.0), _vel(angled, 20.0))
    assert (hit.kind, hit.face_a, hit.face_b) == ("oblique", "front", "front")


@pytest.mark.parametrize("angle_deg", ANGLES_DEG)
def test_rear_end_both_orders(angle_deg):
    ego = OrientedBox(0.0, 0.0, math.radians(angle_deg), *EGO)
    aro = _place(ego, (0.5 * EGO[0] + 0.5 * ARO[0] - 0.02, 0.3), 0.0, ARO)
    hit = contact(ego, aro, _vel(ego, 30.0), _vel(aro, 10.0))
    assert (hit.kind, hit.face_a, hit.face_b) == ("rear_end", "front", "rear")
    assert hit.impact_speed_mps == pytest.approx(20.0)
    back = contact(aro, ego, _vel(aro, 10.0), _vel(ego, 30.0))
    assert (back.kind, back.face_a, back.face_b) == ("rear_end", "rear", "front")
    assert back.point == pytest.approx(hit.point, abs=1e-6)


@pytest.mark.parametrize("angle_deg", ANGLES_DEG)
def test_side_swipe_with_oncoming(angle_deg):
    """Ego drifting left into an oncoming car beside it: left face against its left face."""
    ego = OrientedBox(0.0, 0.0, math.radians(angle_deg), *EGO)
    onc = _place(ego, (0.4, 0.5 * EGO[1] + 0.5 * CAR[1] - 0.01), math.pi, CAR)
    hit = contact(ego, onc, _vel(ego, 30.0, lateral_mps=1.0), _vel(onc, 20.0))
    assert (hit.kind, hit.face_a, hit.face_b) == ("side", "left", "left")
    assert hit.impact_speed_mps == pytest.approx(math.hypot(50.0, 1.0))


def test_front_into_side_is_side():
    """Eastbound ego into a northbound car crossing ahead: its left (west) flank."""
    ego = OrientedBox(0.0, 0.0, 0.0, *EGO)
    crossing = _place(ego, (0.5 * EGO[0] + 0.5 * CAR[1] - 0.01, 0.0), math.pi / 2, CAR)
    hit = contact(ego, crossing, _vel(ego, 15.0), _vel(crossing, 10.0))
    assert (hit.kind, hit.face_a, hit.face_b) == ("side", "front", "left")
    mirrored = _place(ego, (0.5 * EGO[0] + 0.5 * CAR[1] - 0.01, 0.0), -math.pi / 2, CAR)
    hit = contact(ego, mirrored, _vel(ego, 15.0), _vel(mirrored, 10.0))
    assert (hit.kind, hit.face_a, hit.face_b) == ("side", "front", "right")


def test_cutting_back_in_clips_the_aro_with_the_right_side():
    """Returning (yaw -8 deg) too early: ego's right flank lands on the ARO's front-left corner."""
    yaw = math.radians(-8.0)
    aro = OrientedBox(0.0, 0.0, 0.0, *ARO)
    corner = (0.5 * ARO[0], 0.5 * ARO[1])
    lx, ly = -1.5, -0.5 * EGO[1] + 0.005  # the corner is 5 mm inside the ego's right face
    ex = corner[0] - (math.cos(yaw) * lx - math.sin(yaw) * ly)
    ey = corner[1] - (math.sin(yaw) * lx + math.cos(yaw) * ly)
    ego = OrientedBox(ex, ey, yaw, *EGO)
    hit = contact(ego, aro, _vel(ego, 25.0), _vel(aro, 5.0))
    assert (hit.kind, hit.face_a, hit.face_b) == ("side", "right", "left")
    assert ego.distance_to_point(*hit.point) == 0.0 and aro.distance_to_point(*hit.point) == 0.0


def test_placed_overlapping_without_motion_uses_least_penetration():
    a = OrientedBox(0.0, 0.0, 0.0, 4.0, 2.0)
    b = OrientedBox(3.9, 0.5, 0.0, 4.0, 2.0)  # 0.1 m deep along x, 1.5 m along y
    hit = contact(a, b, (0.0, 0.0), (0.0, 0.0))
    assert (hit.kind, hit.face_a, hit.face_b, hit.impact_speed_mps) == (
        "rear_end",
        "front",
        "rear",
        0.0,
    )
