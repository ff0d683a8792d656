"""Margins along the lanes (``sim/margins.py``), on a hand-made run view: no SUMO."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from eoam_sumo.sim.margins import NEAR_MISS_TTC_S, Margins, follower_arriving
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import OrientedBox, time_to_contact

EGO_L, EGO_W = 4.92, 1.85
STEP_S = 0.01


class FakeRun:
    """What Margins reads of a run: the ego's state, the road users, the ego's lane."""

    def __init__(self, centreline: np.ndarray, lane_width_m: float = 3.5):
        self.step_s = STEP_S
        self.lane_width_m = lane_width_m
        self.left_lane = True
        self.right_width_m = 0.0  # no lane on the right the ego may use
        self.road = RoadFrame(centreline)
        self.session = SimpleNamespace(
            ego_lane_centreline=lambda: centreline, road_users=lambda: self.bodies
        )
        self.bodies: list[Body] = []
        self.bodies_before: list[Body] = []
        self.x = self.x_prev = [0.0] * 9
        self.meas = SimpleNamespace(d_m=0.0, e_yaw_rad=0.0)

    def place(self, x, y, yaw, speed, bodies):
        self.x_prev, self.x = self.x, [x, y, yaw, speed, 0.0, 0.0, 0.0, 0.0, 0.0]
        self.bodies_before, self.bodies = self.bodies, bodies


def arc(radius_m: float, from_rad: float, to_rad: float, centre=(0.0, 0.0)):
    """Points of a counter-clockwise circle (angles from the centre)."""
    a = np.linspace(from_rad, to_rad, 800)
    return np.column_stack((centre[0] + radius_m * np.cos(a), centre[1] + radius_m * np.sin(a)))


def on_circle(radius_m: float, angle: float, heading_sign: float):
    """(x, y, yaw) on a circle round the origin, moving counter-clockwise (+1) or not."""
    yaw = angle + heading_sign * 0.5 * math.pi
    return radius_m * math.cos(angle), radius_m * math.sin(angle), yaw


def test_passing_an_oncoming_car_on_a_300_m_curve_is_not_a_near_miss():
    # a right-hand curve: the ego's lane of radius 300 m, the oncoming one outside it, lane
    # centres 3.45 m apart (the boxes 1.6 m apart)
    radius, apart = 300.0, 3.45
    run = FakeRun(arc(radius, 1.0, -1.5))
    margins = Margins(EGO_L, EGO_W, 0.5 * EGO_L)  # the CG at the box centre
    ego_speed, car_speed = 33.3, 27.0
    ego_angle, car_angle = 0.5, 0.5 - 80.0 / radius  # the car 80 m ahead along the road
    straight_line_ttc = math.inf
    for step in range(400):
        ex, ey, eyaw = on_circle(radius, ego_angle, -1.0)
        cx, cy, cyaw = on_circle(radius + apart, car_angle, 1.0)
        car = Body("car", "passenger", cx, cy, cyaw, car_speed, 4.70, 1.82)
        run.place(ex, ey, eyaw, ego_speed, [car])
        if step == 0:
            margins.start(run)
        margins.after_step(run)
        # the straight-line extrapolation of both velocities, for comparison
        ve = (ego_speed * math.cos(eyaw), ego_speed * math.sin(eyaw))
        vc = (car_speed * math.cos(cyaw), car_speed * math.sin(cyaw))
        ego_box = OrientedBox(ex, ey, eyaw, EGO_L, EGO_W)
        straight_line_ttc = min(straight_line_ttc, time_to_contact(ego_box, car.box, ve, vc))
        ego_angle -= ego_speed * STEP_S / radius
        car_angle += car_speed * STEP_S / (radius + apart)
    assert straight_line_ttc < NEAR_MISS_TTC_S  # across the bend, a straight line meets
    assert margins.closest_gap_m > 0.5  # never within 0.5 m
    assert 1.55 < margins.min_gap_oncoming_m < 1.65
    assert margins.min_ttc_oncoming_s == math.inf  # along the lanes: never on a course
    assert not margins.near_miss()


def test_on_a_straight_road_the_lanes_are_the_straight_line():
    run = FakeRun(np.array([[0.0, 0.0], [1000.0, 0.0]]))
    margins = Margins(EGO_L, EGO_W, 0.5 * EGO_L)
    car = Body("car", "passenger", 100.0, 0.5, math.pi, 20.0, 4.70, 1.82)
    run.place(50.0, 0.0, 0.0, 25.0, [car])
    margins.start(run)
    margins.after_step(run)
    straight = time_to_contact(
        OrientedBox(50.0, 0.0, 0.0, EGO_L, EGO_W), car.box, (25.0, 0.0), (-20.0, 0.0)
    )
    assert math.isfinite(straight)
    assert abs(margins.min_ttc_oncoming_s - straight) < 1e-9
    assert margins.near_miss() is (straight < NEAR_MISS_TTC_S)


def test_a_follower_closing_in_gives_its_gap_drac_and_deceleration():
    run = FakeRun(np.array([[0.0, 0.0], [1000.0, 0.0]]))
    margins = Margins(EGO_L, EGO_W, 0.5 * EGO_L)
    # the ego at 20 m/s, a follower 22.0 m behind (centre to centre) at 30 m/s braking 5 m/s2
    follower = Body("f", "passenger", 78.0, 0.2, 0.0, 30.0, 4.70, 1.82)
    run.place(100.0, 0.0, 0.0, 20.0, [follower])
    margins.start(run)
    margins.after_step(run)
    braked = Body("f", "passenger", 78.3, 0.2, 0.0, 30.0 - 5.0 * STEP_S, 4.70, 1.82)
    run.place(100.2, 0.0, 0.0, 20.0, [braked])
    margins.after_step(run)
    gap = 100.2 - 0.5 * EGO_L - (78.3 + 0.5 * 4.70)
    assert abs(margins.min_gap_rear_m - gap) < 1e-9
    closing = 30.0 - 5.0 * STEP_S - 20.0
    first_gap = 100.0 - 0.5 * EGO_L - (78.0 + 2.35)
    assert abs(margins.max_drac_rear_mps2 - 10.0**2 / (2 * first_gap)) < 1e-9
    assert closing**2 / (2 * gap) < margins.max_drac_rear_mps2 + 1.0
    assert abs(margins.max_follower_decel_mps2 - 5.0) < 1e-6
    assert margins.follower_decel_id == "f"
    assert margins.min_ttc_rear_s < (first_gap / 10.0) + 0.05
    assert not margins.near_miss()  # 5 m/s2 is a heavy reaction, not an emergency


def test_a_stopped_ego_waits_for_its_nearest_follower_only():
    """The run of a stopped ego waits while the nearest road user behind it in its lane still
    moves towards it, not while a queue forms further back (or in the next lane)."""
    road = RoadFrame(np.array([[0.0, 0.0], [1000.0, 0.0]]))
    ego = [500.0, 0.0, 0.0, 0.0]
    rear = -0.5 * EGO_L

    def car(x, speed, y=0.0):
        return Body(f"c{x:g}", "passenger", x, y, 0.0, speed, 4.70, 1.82)

    stopped, arriving = car(490.0, 0.0), car(440.0, 12.0)
    assert not follower_arriving(ego, rear, road, 3.5, [stopped, arriving])
    assert follower_arriving(ego, rear, road, 3.5, [car(490.0, 3.0), car(440.0, 0.0)])
    assert not follower_arriving(ego, rear, road, 3.5, [car(490.0, 20.0, y=3.5)])  # next lane
    assert not follower_arriving(ego, rear, road, 3.5, [car(300.0, 20.0)])  # beyond the reach


def test_a_pair_judged_apart_never_touches_within_the_horizon():
    """The shortcut that skips the time to contact (``_apart``: bounding circles apart on a
    frame axis by more than the closing rate covers) never skips a pair that the
    separating-axis time to contact finds touching within the horizon, opening pairs and an
    infinite horizon included; and it does skip most pairs far apart."""
    from eoam_sumo.sim.margins import _apart

    rng = np.random.default_rng(43)
    skipped = 0
    for _ in range(4000):
        a = OrientedBox(0.0, 0.0, rng.uniform(-0.3, 0.3), EGO_L, EGO_W)
        yaw = rng.uniform(-math.pi, math.pi)
        b = OrientedBox(rng.uniform(-60, 60), rng.uniform(-8, 8), yaw, 4.5, 1.8)
        va, vb = tuple(rng.uniform(-40, 40, 2)), tuple(rng.uniform(-40, 40, 2))
        if rng.random() < 0.2:
            vb = (vb[0], va[1])  # lateral rates equal: apart for ever on that axis
        horizon = math.inf if rng.random() < 0.5 else rng.uniform(0.0, 10.0)
        if _apart(a, b.x_m, b.y_m, b.radius_m, va, vb, horizon):
            skipped += 1
            assert time_to_contact(a, b, va, vb, horizon) == math.inf
    assert skipped > 1000
