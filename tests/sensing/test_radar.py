"""Radar model: coverage against closed-form geometry, measurements, classification."""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from eoam_sumo.sensing.radar import Radar, RadarSettings
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import OrientedBox

LANE_M = 3.5
ARO = (5.09, 1.99)
CAR = (4.70, 1.82)
PARKED = (4.30, 1.80)
PARKED_NEAR_SIDE_M = -(0.5 * LANE_M + 1.5)  # 1.5 m beyond the right lane marker
PARKED_D_M = PARKED_NEAR_SIDE_M - 0.5 * PARKED[1]
HALF_FOV = math.radians(9.0)
ROAD = RoadFrame([(-1000.0, 0.0), (5000.0, 0.0)])  # ego lane centre line, eastbound


def _ahead(rear_s_m, d_m, dims, speed_mps=0.0, reverse=False):
    """A target in the straight road frame, its rear (or front if ``reverse``) face at rear_s."""
    centre = rear_s_m + 0.5 * dims[0]
    return Body("t", "passenger", centre, d_m, math.pi if reverse else 0.0, speed_mps, *dims)


def _scan(targets, front=(0.0, 0.0), yaw=0.0, speed=30.0, radar=None, road=ROAD):
    return (radar or Radar()).scan(front, yaw, speed, road, targets, LANE_M)


# --- the paper's scenario ---------------------------------------------------------------------


def test_aro_at_120_m_is_out_of_range_at_90_m_in_path():
    far = _scan([_ahead(120.0, 0.0, ARO, 16.7)])
    assert far.in_path_range_m is None and far.in_path_range_rate_mps is None
    assert far.detections == () and not far.oncoming_detected
    near = _scan([_ahead(90.0, 0.0, ARO, 10.0)], speed=30.0)
    assert near.in_path_range_m == pytest.approx(90.0, abs=1e-9)
    assert near.in_path_range_rate_mps == pytest.approx(-20.0, abs=1e-9)
    assert near.in_path_index == 0
    (det,) = near.detections
    assert det.category == "in_path" and det.bearing_rad == pytest.approx(0.0, abs=1e-12)
    assert (det.s_m, det.d_m, det.road_speed_mps) == pytest.approx((1090.0 + 0.5 * ARO[0], 0, 10))


def test_range_limit():
    assert _scan([_ahead(99.99, 0.0, ARO)]).in_path_range_m == pytest.approx(99.99)
    assert _scan([_ahead(100.01, 0.0, ARO)]).in_path_range_m is None
    short = Radar(RadarSettings(range_m=60.0))
    assert _scan([_ahead(70.0, 0.0, ARO)], radar=short).in_path_range_m is None


def test_offset_aro_range_is_to_its_nearest_point():
    # ARO 0.4 m left of the lane centre: its rear face still crosses the boresight
    rep = _scan([_ahead(50.0, 0.4, ARO, 5.0)], speed=25.0)
    assert rep.in_path_range_m == pytest.approx(50.0, abs=1e-9)
    assert rep.in_path_range_rate_mps == pytest.approx(-20.0, abs=1e-9)
    # 1.2 m right: nearest point is the rear-left corner at d = -1.2 + 0.995
    rep = _scan([_ahead(50.0, -1.2, ARO, 5.0)], speed=25.0)
    r = math.hypot(50.0, 1.2 - 0.5 * ARO[1])
    assert rep.in_path_range_m == pytest.approx(r, abs=1e-9)
    assert rep.in_path_range_rate_mps == pytest.approx(-20.0 * 50.0 / r, abs=1e-9)


def _parked_visible_range(rear_s_m: float) -> float | None:
    """Closed form for a parked car right of the lane: its near side at y = PARKED_NEAR_SIDE_M."""
    y = -PARKED_NEAR_SIDE_M
    x_fov = y / math.tan(HALF_FOV)  # where the right edge of the field of view meets that side
    x_range = math.sqrt(100.0**2 - y * y)  # where the range circle meets it
    lo, hi = max(rear_s_m, x_fov), min(rear_s_m + PARKED[0], x_range)
    return math.hypot(lo, y) if lo <= hi else None


@pytest.mark.parametrize("rear_s_m", [5.0, 12.0, 17.0, 25.0, 40.0, 60.0, 80.0, 99.0, 99.9, 100.0])
def test_parked_cars_are_stationary_side_never_in_path(rear_s_m):
    rep = _scan([_ahead(rear_s_m, PARKED_D_M, PARKED)])
    expected = _parked_visible_range(rear_s_m)
    assert rep.in_path_range_m is None and not rep.oncoming_detected
    if expected is None:
        assert rep.detections == ()
    else:
        (det,) = rep.detections
        assert det.category == "stationary_side"
        assert det.range_m == pytest.approx(expected, abs=1e-9)
        assert det.range_rate_mps < 0.0  # closing on a stopped object


def test_parked_row_with_aro_ahead():
    parked = [_ahead(s, PARKED_D_M, PARKED) for s in range(10, 100, 8)]
    rep = _scan([*parked, _ahead(85.0, 0.0, ARO, 8.0)])
    assert rep.in_path_range_m == pytest.approx(85.0)
    assert rep.in_path_index == len(parked)
    assert {det.category for det in rep.detections} == {"stationary_side", "in_path"}
    ranges = [det.range_m for det in rep.detections]
    assert ranges == sorted(ranges)


@settings(max_examples=150, deadline=None, database=None)
@given(
    st.floats(-0.5, 3.8),
    st.floats(-12.0, 12.0),
    st.lists(st.floats(-5.0, 130.0), min_size=1, max_size=6),
)
def test_parked_cars_never_in_path_during_the_manoeuvre(ego_d_m, ego_yaw_deg, rear_s):
    """Whatever the ego's lateral position and heading while it steers, parked cars stay parked."""
    rep = _scan(
        [_ahead(s, PARKED_D_M, PARKED) for s in rear_s],
        front=(0.0, ego_d_m),
        yaw=math.radians(ego_yaw_deg),
    )
    assert rep.in_path_range_m is None and not rep.oncoming_detected
    assert all(det.category == "stationary_side" for det in rep.detections)


def test_oncoming_at_80_m_in_the_left_lane():
    onc = _ahead(80.0, LANE_M, CAR, 20.0, reverse=True)  # front face at 80 m, driving west
    rep = _scan([onc], speed=30.0)
    assert rep.oncoming_detected and rep.in_path_range_m is None
    (det,) = rep.detections
    r = math.hypot(80.0, LANE_M - 0.5 * CAR[1])
    assert det.category == "oncoming"
    assert det.range_m == pytest.approx(r, abs=1e-9)
    assert det.range_rate_mps == pytest.approx(-50.0 * 80.0 / r, abs=1e-9)
    assert det.road_speed_mps == pytest.approx(-20.0)
    both = _scan([onc, _ahead(60.0, 0.0, ARO, 0.0)], speed=30.0)
    assert both.oncoming_detected
    assert both.in_path_range_m == pytest.approx(60.0)
    assert both.in_path_range_rate_mps == pytest.approx(-30.0)


@pytest.mark.parametrize(
    ("target", "category"),
    [
        (_ahead(40.0, 0.0, CAR, 0.0), "in_path"),  # stopped in the lane
        (_ahead(40.0, 0.0, CAR, 15.0, reverse=True), "oncoming"),  # wrong-way in the ego lane
        (_ahead(40.0, LANE_M, CAR, 25.0), "other"),  # overtaking in the left lane
        (_ahead(40.0, LANE_M, CAR, 1.0, reverse=True), "oncoming"),  # creeping towards it
        (_ahead(40.0, 0.0, CAR, 1.5, reverse=True), "in_path"),  # backing up in the ego lane
        (_ahead(40.0, 0.0, (0.5, 0.6), 1.4, reverse=True), "in_path"),  # walking towards it
        (_ahead(40.0, LANE_M, CAR, 0.0), "in_next_lane"),  # stopped in the left lane
        (_ahead(40.0, 2.2 * LANE_M, CAR, 0.0), "stationary_side"),  # beyond the next lane
        (_ahead(40.0, -LANE_M, CAR, 0.0), "stationary_side"),  # parked on the right
        (_ahead(40.0, 0.5 * LANE_M + 0.4, CAR, 0.0), "in_path"),  # half on the marker
        (_ahead(40.0, 1.4 * LANE_M, CAR, 20.0, reverse=True), "oncoming"),  # the next lane
        (_ahead(40.0, 2.0 * LANE_M, CAR, 20.0, reverse=True), "other"),  # two lanes left
        (_ahead(80.0, 3.0 * LANE_M, (0.5, 0.6), 3.0, reverse=True), "other"),  # far pavement
    ],
)
def test_classification(target, category):
    (det,) = _scan([target]).detections
    assert det.category == category


def test_traffic_beyond_the_next_lane_is_not_oncoming():
    """A car against the road two lanes left (the other carriageway of a 2+2 road) is not in
    the way of a lane change: no oncoming flag, no oncoming object; one in the next lane is."""
    far = _scan([_ahead(60.0, 2.0 * LANE_M, CAR, 25.0, reverse=True)])
    assert far.detections and not far.oncoming_detected
    near = _scan([_ahead(60.0, LANE_M, CAR, 25.0, reverse=True)])
    assert near.oncoming_detected


# --- head-on: a wrong-way car in the ego's lane (Euro NCAP CCFhos) ----------------------------

EGO_W_M = 1.85  # the ego's width: a 50 % offset puts the other car's centre half of it aside


@pytest.mark.parametrize("offset_m", [0.0, 0.5 * EGO_W_M, -0.5 * EGO_W_M, 2.2])
def test_a_wrong_way_car_in_the_lane_is_the_in_path_obstacle_and_oncoming(offset_m):
    """Its front 60 m ahead, 50 km/h against the ego's 80: the in-path range is the distance
    to its front face (closed form), the range rate minus the closing speed projected on the
    line of sight, and the oncoming flag stays raised."""
    ego_mps, tgt_mps = 80 / 3.6, 50 / 3.6
    rep = _scan([_ahead(60.0, offset_m, CAR, tgt_mps, reverse=True)], speed=ego_mps)
    (det,) = rep.detections
    lateral = max(abs(offset_m) - 0.5 * CAR[1], 0.0)  # nearest point of its front face
    r = math.hypot(60.0, lateral)
    assert det.category == "oncoming" and det.head_on
    assert rep.oncoming_detected and rep.in_path is det and rep.in_path_index == 0
    assert rep.in_path_range_m == pytest.approx(r, abs=1e-9)
    assert rep.in_path_range_rate_mps == pytest.approx(-(ego_mps + tgt_mps) * 60.0 / r, abs=1e-9)


def test_head_on_nearest_in_path_target_wins():
    """The nearer of a wrong-way car and a stopped ARO in the lane is the in-path obstacle; a
    wrong-way car in the next lane or behind the ego's front is never in the path."""
    wrong_way = _ahead(40.0, 0.0, CAR, 14.0, reverse=True)
    far_aro, near_aro = _ahead(70.0, 0.0, ARO), _ahead(25.0, 0.0, ARO)
    rep = _scan([far_aro, wrong_way])
    assert rep.in_path_range_m == pytest.approx(40.0) and rep.in_path_index == 1
    rep = _scan([near_aro, wrong_way])
    assert rep.in_path_range_m == pytest.approx(25.0) and rep.oncoming_detected
    next_lane = _ahead(40.0, LANE_M, CAR, 14.0, reverse=True)
    rep = _scan([next_lane])
    assert rep.oncoming_detected and rep.in_path is None
    assert not rep.detections[0].head_on
    right_of_band = _ahead(40.0, -LANE_M, CAR, 14.0, reverse=True)  # wrong way on the right
    assert all(not d.head_on for d in _scan([right_of_band]).detections)
    radar = Radar()
    assert radar.head_on("oncoming", True, 0.0, 2.25)
    assert not radar.head_on("oncoming", False, 0.0, 2.25)  # its centre behind the bumper
    assert not radar.head_on("oncoming", True, 2.25, 2.25)
    assert not radar.head_on("in_path", True, 0.0, 2.25)


def test_in_path_is_relative_to_the_original_lane():
    """In the left lane after the lane change, the ARO in the original lane is still in path."""
    aro = _ahead(30.0, 0.0, ARO, 0.0)
    rep = _scan([aro], front=(0.0, LANE_M), speed=20.0)
    r = math.hypot(30.0, LANE_M - 0.5 * ARO[1])
    assert rep.in_path_range_m == pytest.approx(r, abs=1e-9)
    assert rep.detections[0].d_m == pytest.approx(0.0)
    assert rep.detections[0].bearing_rad == pytest.approx(-math.atan2(LANE_M - 0.5 * ARO[1], 30))


def test_targets_behind_or_beside_are_not_seen():
    behind = _ahead(-20.0, 0.0, CAR, 30.0)
    beside = _ahead(-2.0, LANE_M, CAR, 20.0, reverse=True)
    assert _scan([behind, beside]).detections == ()


# --- field-of-view edges ----------------------------------------------------------------------


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("fov_deg", [18.0, 40.0])
def test_field_of_view_edges(side, fov_deg):
    """A 1 m square ending at 50 m whose corner nearest the boresight is 1 cm outside or inside
    the edge ray."""
    half = math.radians(0.5 * fov_deg)
    radar = Radar(RadarSettings(fov_deg=fov_deg))
    edge_y = 50.0 * math.tan(half)
    for shift, seen in ((0.01, False), (-0.01, True)):
        near_y = edge_y + shift  # |y| of the square's face nearest the boresight
        target = Body("t", "passenger", 49.5, side * (near_y + 0.5), 0.0, 0.0, 1.0, 1.0)
        rep = _scan([target], radar=radar)
        assert (len(rep.detections) == 1) is seen
        if seen:
            det = rep.detections[0]
            # the visible sliver starts where the edge ray enters that face
            assert det.range_m == pytest.approx(near_y / math.sin(half), abs=1e-9)
            assert det.bearing_rad == pytest.approx(side * half, abs=1e-9)


def test_box_spanning_the_field_of_view_with_all_corners_outside():
    truck = Body("t", "truck", 30.0, 0.0, math.pi / 2, 5.0, 12.0, 2.0)  # crossing ahead, 12 m
    radar = Radar()
    assert all(abs(math.atan2(y, x)) > HALF_FOV for x, y in truck.box.corners())
    rep = _scan([truck], radar=radar)
    assert rep.in_path_range_m == pytest.approx(29.0)
    assert rep.detections[0].road_speed_mps == pytest.approx(0.0, abs=1e-12)


def test_box_seen_only_where_the_edge_ray_crosses_it():
    """Thin box across the left edge ray near the range limit: in-range corners lie outside the
    field of view, corners inside it are out of range, and so is the nearest point."""
    u_in = (math.cos(HALF_FOV - 0.02), math.sin(HALF_FOV - 0.02))
    u_out = (math.cos(HALF_FOV + 0.02), math.sin(HALF_FOV + 0.02))
    p_in = (100.6 * u_in[0], 100.6 * u_in[1])
    p_out = (99.0 * u_out[0], 99.0 * u_out[1])
    cx, cy = 0.5 * (p_in[0] + p_out[0]), 0.5 * (p_in[1] + p_out[1])
    length = math.hypot(p_in[0] - p_out[0], p_in[1] - p_out[1])
    yaw = math.atan2(p_in[1] - p_out[1], p_in[0] - p_out[0])
    target = Body("t", "passenger", cx, cy, yaw, 0.0, length, 0.05)
    box = target.box

    def sector(x, y):
        return math.hypot(x, y) <= 100.0 and abs(math.atan2(y, x)) <= HALF_FOV

    assert not any(sector(x, y) for x, y in box.corners())
    assert not sector(*box.nearest_point(0.0, 0.0))
    expected = _reference_range(box, (0.0, 0.0), 0.0, HALF_FOV)
    assert expected < 100.0
    rep = _scan([target])
    assert len(rep.detections) == 1
    assert rep.detections[0].range_m == pytest.approx(expected, abs=1e-9)


# --- exactness against an independent method: clip the box by the cone --------------------------


def _clip_halfplane(poly, nx, ny):
    """Keep the part of a polygon with nx*x + ny*y >= 0."""
    out = []
    for i, p in enumerate(poly):
        q = poly[(i + 1) % len(poly)]
        fp, fq = nx * p[0] + ny * p[1], nx * q[0] + ny * q[1]
        if fp >= 0.0:
            out.append(p)
        if fp * fq < 0.0:
            t = fp / (fp - fq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def _reference_range(box: OrientedBox, origin, yaw, half_fov) -> float:
    """Distance from the apex to box ∩ cone by polygon clipping (inf if empty)."""
    poly = [(x - origin[0], y - origin[1]) for x, y in box.corners()]
    left, right = yaw + half_fov, yaw - half_fov
    poly = _clip_halfplane(poly, math.sin(left), -math.cos(left))  # right of the left ray
    if poly:
        poly = _clip_halfplane(poly, -math.sin(right), math.cos(right))  # left of the right ray
    if not poly:
        return math.inf
    n = len(poly)
    inside = all(
        poly[i][0] * poly[(i + 1) % n][1] - poly[i][1] * poly[(i + 1) % n][0] >= 0.0
        for i in range(n)
    )
    if inside and n >= 3:
        return 0.0
    best = math.inf
    for i in range(n):
        (ax, ay), (bx, by) = poly[i], poly[(i + 1) % n]
        ux, uy = bx - ax, by - ay
        den = ux * ux + uy * uy
        t = 0.0 if den == 0.0 else min(max(-(ax * ux + ay * uy) / den, 0.0), 1.0)
        best = min(best, math.hypot(ax + t * ux, ay + t * uy))
    return best


@settings(max_examples=400, deadline=None, database=None)
@given(
    st.floats(-5.0, 115.0),
    st.floats(-25.0, 25.0),
    st.floats(-math.pi, math.pi),
    st.floats(0.3, 14.0),
    st.floats(0.3, 3.0),
    st.floats(-0.3, 0.3),
    st.floats(10.0, 60.0),
)
def test_detection_and_range_are_exact(x, y, yaw, length, width, ego_yaw, fov_deg):
    target = Body("t", "passenger", x, y, yaw, 0.0, length, width)
    radar = Radar(RadarSettings(fov_deg=fov_deg))
    ref = _reference_range(target.box, (0.0, 0.0), ego_yaw, math.radians(0.5 * fov_deg))
    assume(abs(ref - 100.0) > 1e-6)
    got = radar.visible_range_m((0.0, 0.0), ego_yaw, target.box)
    if math.isinf(ref):
        assert math.isinf(got)
    else:
        assert got == pytest.approx(ref, abs=1e-7)
    rep = radar.scan((0.0, 0.0), ego_yaw, 20.0, ROAD, [target], LANE_M)
    assert (len(rep.detections) == 1) == (ref <= 100.0)


# --- frame invariance -------------------------------------------------------------------------


def test_scene_rotated_and_moved_gives_the_same_report():
    rot, tx, ty = math.radians(30.0), 1234.0, -567.0
    c, s = math.cos(rot), math.sin(rot)

    def move(x, y):
        return c * x - s * y + tx, s * x + c * y + ty

    def moved(t: Body) -> Body:
        return Body(
            t.vid,
            t.vclass,
            *move(t.x_m, t.y_m),
            t.yaw_rad + rot,
            t.speed_mps,
            t.length_m,
            t.width_m,
        )

    scene = [
        _ahead(70.0, 0.2, ARO, 9.0),
        _ahead(85.0, LANE_M, CAR, 20.0, reverse=True),
        *(_ahead(sx, PARKED_D_M, PARKED) for sx in (35.0, 55.0, 90.0)),
    ]
    road = RoadFrame([move(-1000.0, 0.0), move(5000.0, 0.0)])
    base = _scan(scene, front=(0.0, 0.6), yaw=0.03, speed=28.0)
    turned = _scan(
        [moved(t) for t in scene], front=move(0.0, 0.6), yaw=0.03 + rot, speed=28.0, road=road
    )
    assert len(base.detections) == len(turned.detections) == 5
    for d0, d1 in zip(base.detections, turned.detections, strict=True):
        assert d0.target_index == d1.target_index and d0.category == d1.category
        assert (d1.range_m, d1.range_rate_mps, d1.bearing_rad, d1.d_m, d1.road_speed_mps) == (
            pytest.approx(
                (d0.range_m, d0.range_rate_mps, d0.bearing_rad, d0.d_m, d0.road_speed_mps), abs=1e-8
            )
        )
    assert turned.in_path_range_m == pytest.approx(base.in_path_range_m)
    assert turned.oncoming_detected and base.oncoming_detected


# --- validation -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs",
    [
        {"range_m": 0.0},
        {"range_m": math.nan},
        {"fov_deg": 0.0},
        {"fov_deg": 180.0},
        {"stationary_speed_mps": -0.1},
        {"lane_margin_m": math.inf},
        {"stationary_speed_mps": 3.0, "oncoming_speed_mps": 2.0},
    ],
)
def test_settings_validate(kwargs):
    with pytest.raises(ValueError, match="RadarSettings"):
        RadarSettings(**kwargs)


def test_bad_inputs():
    with pytest.raises(ValueError, match="speed_mps"):
        Body("t", "passenger", 0.0, 0.0, 0.0, math.nan, 4.0, 2.0)
    with pytest.raises(ValueError, match="length_m"):
        Body("t", "passenger", 0.0, 0.0, 0.0, 1.0, 0.0, 2.0)
    with pytest.raises(ValueError, match="lane_width_m"):
        Radar().scan((0.0, 0.0), 0.0, 10.0, ROAD, [], 0.0)


def test_the_nearest_standing_car_in_the_next_lane_is_reported():
    near, far = _ahead(50.0, LANE_M, CAR, 0.0), _ahead(70.0, LANE_M, CAR, 0.0)
    rep = _scan([far, _ahead(30.0, 0.0, ARO, 0.0), near], speed=30.0)
    assert rep.in_path_range_m == pytest.approx(30.0)
    assert rep.next_lane_range_m == min(
        d.range_m for d in rep.detections if d.category == "in_next_lane"
    )
    assert 50.0 <= rep.next_lane_range_m < 51.0
    assert _scan([_ahead(40.0, LANE_M, CAR, 25.0)]).next_lane_range_m is None  # moving


@pytest.mark.parametrize(
    ("vclass", "dims", "d_m", "in_path"),
    [
        ("pedestrian", (0.3, 0.6), -2.07, False),  # on the pavement, 0.03 m over the marker
        ("bicycle", (1.6, 0.65), -2.0, False),  # on a bike lane beside the ego's
        ("pedestrian", (0.3, 0.6), -1.5, True),  # 0.55 m into the lane
        ("passenger", CAR, -2.2, True),  # 0.46 m of the car in the lane: the margin's case
    ],
)
def test_a_narrow_road_user_is_in_the_path_only_as_far_into_the_lane_as_a_car(
    vclass, dims, d_m, in_path
):
    """The lane band (half a lane and 0.5 m) put a person walking on the pavement 2.07 m from
    the lane centre in the path: the ego braked from 120 km/h to a stop for people beside the
    road. A narrower road user now counts when it is as far into the lane as the 1.8 m car
    the margin is set for (0.4 m)."""
    person = Body("p", vclass, 60.0, d_m, math.pi, 1.2, *dims)
    det = _scan([person]).detections
    assert (det[0].category == "in_path") is in_path
