"""Road frame: projection onto the lane centre line inverts point_at (closed-form checks)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.sim.roadframe import RoadFrame

ARC_POINTS = [
    (200 * math.sin(a), 200 * (1 - math.cos(a))) for a in [i * 0.01 for i in range(101)]
]  # left-hand arc, radius 200 m, ~200 m long
ARC = RoadFrame(ARC_POINTS)


def test_straight_road_is_plain_coordinates():
    road = RoadFrame([(0.0, -1.75), (4000.0, -1.75)])
    assert road.project(120.0, 0.5) == pytest.approx((120.0, 2.25, 0.0))
    assert road.point_at(120.0, 2.25) == pytest.approx((120.0, 0.5, 0.0))
    assert road.curvature_at(100.0) == 0.0
    assert road.length_m == pytest.approx(4000.0)


@settings(max_examples=200, deadline=None, database=None)
@given(st.floats(1.0, 195.0), st.floats(-6.0, 6.0), st.sampled_from([0, 50, 99]))
def test_project_inverts_point_at_from_any_starting_hint(s_m, d_m, hint):
    ARC._hint = hint
    x, y, yaw = ARC.point_at(s_m, d_m)
    s2, d2, yaw2 = ARC.project(x, y)
    # chords of a 200 m arc every 2 m: the polyline differs from the circle by < 3 mm; next to
    # a vertex (heading change 0.01 rad) an offset point may project onto either neighbouring
    # segment, which moves s by at most |d| x 0.01
    assert s2 == pytest.approx(s_m, abs=0.01 + abs(d_m) * 0.011)
    assert d2 == pytest.approx(d_m, abs=0.01)
    if 15.0 <= s_m <= ARC.length_m - 15.0:  # the end halves of the 10 m heading chords hold
        assert yaw2 == pytest.approx(yaw, abs=0.011)


def test_curvature_of_the_arc():
    assert ARC.curvature_at(100.0) == pytest.approx(1 / 200.0, rel=0.01)


def test_needs_two_distinct_points():
    with pytest.raises(ValueError, match="two distinct points"):
        RoadFrame([(1.0, 1.0), (1.0, 1.0)])


@settings(max_examples=200, deadline=None, database=None)
@given(st.floats(-20.0, 220.0), st.floats(-20.0, 220.0))
def test_curvature_does_not_depend_on_the_last_lookup(s_m, before_m):
    """The walk from the last answer is only a shortcut: the curvature at s is the same
    whatever was asked before, and the arc's own between the first and last midpoints."""
    ARC.curvature_at(before_m)
    k = ARC.curvature_at(s_m)
    assert k == RoadFrame(ARC_POINTS).curvature_at(s_m)
    if 10.0 <= s_m <= ARC.length_m - 10.0:
        assert k == pytest.approx(1 / 200.0, rel=0.02)


def _arc_with_junction_chords(radius=1500.0, chord_m=25.0, edge_m=1000.0, gap_m=0.3):
    """Points of a left arc as SUMO gives consecutive edges' lane shapes: 25 m chords, and at
    every edge end a short chord across the junction."""
    pts, s_m = [], 0.0
    while s_m <= 3 * edge_m:
        pts.append((radius * math.sin(s_m / radius), radius * (1 - math.cos(s_m / radius))))
        nxt = s_m + chord_m
        if int(nxt // edge_m) > int(s_m // edge_m):  # an edge ends: stop short, then the gap
            end = (int(nxt // edge_m)) * edge_m
            pts.append((radius * math.sin(end / radius), radius * (1 - math.cos(end / radius))))
            nxt = end + gap_m
        s_m = nxt
    return pts


def test_heading_and_curvature_of_a_curve_ignore_junction_chords():
    """Heading follows the true tangent within a fraction of a chord's turn (no steps at the
    vertices) and the curvature stays the road's at the short chords between edges."""
    radius = 1500.0
    road = RoadFrame(_arc_with_junction_chords(radius))
    for s_m in [30.0 + 7.3 * k for k in range(400)]:  # from past the first chord
        x, y = radius * math.sin(s_m / radius), radius * (1 - math.cos(s_m / radius))
        s2, _, yaw = road.project(x, y)
        assert yaw == pytest.approx(s2 / radius, abs=0.1 * 25.0 / radius)
        if 30.0 < s2 < road.length_m - 30.0:
            assert road.curvature_at(s2) == pytest.approx(1.0 / radius, rel=0.1)


def test_a_straight_edge_stays_straight_up_to_the_curve_it_meets():
    """A 1000 m straight (one segment) then a 500 m left curve of 25 m chords: heading 0 and
    no curvature along the straight until 12.5 m before the curve, the curve's own after."""
    radius, chord = 500.0, 25.0
    pts = [(0.0, 0.0), (1000.0, 0.0)]
    pts += [
        (
            1000.0 + radius * math.sin(k * chord / radius),
            radius * (1 - math.cos(k * chord / radius)),
        )
        for k in range(1, 25)
    ]
    road = RoadFrame(pts)
    for x in [1.0, 100.0, 500.0, 900.0, 985.0]:
        s_m, _, yaw = road.project(x, 0.0)
        assert yaw == 0.0 and road.curvature_at(s_m) == 0.0
    for k in range(2, 22):  # chord midpoints of the curve: the tangent there
        a = (k + 0.5) * chord / radius
        s_m, _, yaw = road.project(1000.0 + radius * math.sin(a), radius * (1 - math.cos(a)))
        assert yaw == pytest.approx(a, abs=1e-3)
        assert road.curvature_at(s_m) == pytest.approx(1.0 / radius, rel=0.02)


def test_locate_starts_the_walk_on_the_return_leg_of_a_hairpin():
    """1000 m east, a 300 m half circle, 1000 m back west 600 m north of the first leg: a
    point on the return leg lies level with the first straight; ``locate`` finds its own."""
    radius = 300.0
    pts = [(0.0, 0.0), (1000.0, 0.0)]
    pts += [
        (1000.0 + radius * math.sin(a), radius * (1 - math.cos(a)))
        for a in [k * math.pi / 60 for k in range(1, 60)]
    ]
    pts += [(1000.0, 2 * radius), (0.0, 2 * radius)]
    road = RoadFrame(pts)
    assert road.project(500.0, 2 * radius)[1] == pytest.approx(2 * radius)  # the first leg's
    road.locate(500.0, 2 * radius)
    s_m, d_m, yaw = road.project(500.0, 2 * radius)
    assert d_m == pytest.approx(0.0, abs=1e-9)
    assert s_m == pytest.approx(1000.0 + math.pi * radius + 500.0, abs=1.0)
    assert math.cos(yaw) == pytest.approx(-1.0, abs=1e-6)  # heading west


@pytest.mark.parametrize("hint", [0, 50, 99])
def test_beyond_its_ends_the_heading_is_held(hint):
    """Before its start and past its end the road runs straight on: the heading of a point
    there is the one at the end it is beyond, however far out and wherever the walk began
    (the arc's first heading chord, 10 m, points 0.025 rad left; its last, 10-20 m long
    to the end at 1 rad, between 0.95 and 0.975 rad)."""
    length = ARC.length_m
    yaws = []
    for s_m in (-30.0, -0.5, length + 0.5, length + 30.0):
        ARC._hint = hint
        x, y, _ = ARC.point_at(s_m, 1.0)
        s2, _d, yaw = ARC.project(x, y)
        assert (s2 < 0.0) == (s_m < 0.0) and (s2 > length) == (s_m > length)
        yaws.append(yaw)
    assert yaws[0] == yaws[1] == pytest.approx(0.025, abs=0.01)
    assert yaws[2] == yaws[3]
    assert 0.95 - 1e-9 <= yaws[2] <= 0.975 + 1e-9
