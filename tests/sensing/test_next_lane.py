"""Coverage of the next lane by the forward radar, the corner radars and V2X, and the road
users found in it, on a straight road (closed-form geometry; no SUMO)."""

import math

import pytest

from eoam_sumo.sensing.next_lane import COVERAGE_STEP_M, NextLaneSensing, hides, sees
from eoam_sumo.sensing.radar import Radar, RadarSettings
from eoam_sumo.sensing.v2x import V2XSettings
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import OrientedBox
from tests.builders import right_lane_sensing

LANE = 3.5
HALF_FOV = math.radians(9.0)


class Straight:
    """Road frame of a straight lane along +x centred on y = 0."""

    def project(self, x, y):
        return x, y, 0.0

    def point_at(self, s, d=0.0):
        return s, d, 0.0


class LeftCurve:
    """Road frame of a lane turning left on a circle of ``radius`` m from the origin."""

    def __init__(self, radius):
        self.r = radius

    def point_at(self, s, d=0.0):
        a = s / self.r
        return (self.r - d) * math.sin(a), self.r - (self.r - d) * math.cos(a), a

    def project(self, x, y):
        a = math.atan2(x, self.r - y)
        return self.r * a, self.r - math.hypot(x, self.r - y), a


def _body(vid, x_m, y_m, yaw_rad, speed_mps, length_m, width_m):
    return Body(vid, "passenger", x_m, y_m, yaw_rad, speed_mps, length_m, width_m)


def test_a_sensor_sees_within_its_range_and_field_of_view():
    assert sees(0.0, 0.0, 0.0, HALF_FOV, 100.0, 99.0, 3.5)
    assert not sees(0.0, 0.0, 0.0, HALF_FOV, 100.0, 20.0, 3.5)  # 9.9 deg off the boresight
    assert not sees(0.0, 0.0, 0.0, HALF_FOV, 100.0, 100.0, 3.5)  # beyond the range
    assert sees(0.0, 0.0, math.pi, 0.1, 50.0, -40.0, 0.0)  # looking backward


def test_a_box_hides_only_what_lies_behind_it():
    box = OrientedBox(42.5, 0.0, 0.0, 5.0, 2.0)
    assert hides(box, 0.0, 0.0, 90.0, 1.75)  # line of sight passes through the box
    assert not hides(box, 0.0, 0.0, 60.0, 1.75)  # at x = 40 the line is at y = 1.17
    assert not hides(box, 0.0, 0.0, 30.0, 0.0)  # in front of the box
    assert not hides(box, 0.0, 0.0, 90.0, 5.0)


def _sensing(v2x=None, radar_range_m=100.0):
    return NextLaneSensing(
        opposing=True,
        speed_limit_mps=25.0,
        lane_width_m=LANE,
        radar_range_m=radar_range_m,
        radar_fov_deg=18.0,
        ego_length_m=4.92,
        ego_width_m=1.85,
        v2x=v2x,
    )


def _view(sensing, bodies, t=0.0, road=None):
    road = road or Straight()
    radar = Radar(RadarSettings())
    report = radar.scan((0.0, 0.0), 0.0, 30.0, road, bodies, LANE)
    return sensing.update(t, (0.0, 0.0), 0.0, road, report, bodies)


def test_an_empty_road_is_known_free_to_the_radar_range_on_the_far_line():
    view = _view(_sensing(), [])
    far = 1.5 * LANE - 0.25
    assert view.coverage_ahead_m == pytest.approx(math.sqrt(100.0**2 - far**2), abs=COVERAGE_STEP_M)
    assert view.known_free_ahead_m == view.coverage_ahead_m
    assert view.nearest_ahead_m is None


def test_on_a_left_curve_the_lane_leaves_the_forward_radars_field_sooner():
    straight = _view(_sensing(), []).coverage_ahead_m
    curve = _view(_sensing(), [], road=LeftCurve(300.0)).coverage_ahead_m
    # the lane bends out of the forward radar's 9 deg half field after about 50 m; beyond it
    # the front corner radar (80 m, 40 deg outward) still sees it, to its range
    assert curve == pytest.approx(80.0, abs=COVERAGE_STEP_M) and straight > 95.0


def test_the_obstacle_ahead_hides_the_lane_beyond_its_shadow():
    aro = _body("aro", 42.5, 0.0, 0.0, 0.0, 5.0, 2.0)
    view = _view(_sensing(), [aro])
    near = 0.5 * LANE + 0.25  # the near line is hidden from x = 2.0 * 40 / 1.0 = 80 m
    assert view.coverage_ahead_m == pytest.approx(near * 40.0 / 1.0, abs=COVERAGE_STEP_M)
    assert view.nearest_ahead_m is None  # the in-path obstacle is not in the next lane


@pytest.mark.parametrize("speed", [-1.5, 0.0, 1.5, -20.0])
def test_any_road_user_in_the_next_lane_limits_the_free_length_whatever_its_speed(speed):
    yaw = math.pi if speed < 0 else 0.0
    van = _body("van", 62.5, LANE, yaw, abs(speed), 5.0, 2.0)
    view = _view(_sensing(), [van])
    assert view.nearest_ahead_m == pytest.approx(60.0)
    assert view.known_free_ahead_m == pytest.approx(60.0)
    assert view.nearest_ahead_speed_mps == pytest.approx(speed)


def test_a_person_beside_the_ego_is_found_by_the_corner_radar():
    walker = _body("p", -2.0, LANE, 0.0, 1.2, 0.5, 0.5)  # beside the ego's body
    view = _view(_sensing(), [walker])
    assert view.nearest_ahead_m == 0.0  # overlapping the ego's stations: blocks at once


def test_a_car_closing_from_behind_is_found_by_the_rear_corner_radar():
    car = _body("c", -40.0, LANE, 0.0, 40.0, 4.7, 1.8)
    view = _view(_sensing(), [car])
    assert view.nearest_behind_m == pytest.approx(40.0 - 4.92 - 2.35)
    assert view.nearest_behind_speed_mps == pytest.approx(40.0)
    assert (
        _view(_sensing(), [_body("c", -90.0, LANE, 0.0, 40.0, 4.7, 1.8)]).nearest_behind_m is None
    )  # beyond the corner radar's 80 m


def test_full_penetration_v2x_proves_the_range_free_less_its_blind_distance():
    v2x = V2XSettings(range_m=1000.0, latency_s=0.1)
    view = _view(_sensing(v2x), [])
    assert view.known_free_ahead_m == pytest.approx(1000.0 - 25.0 * 0.2)
    partial = V2XSettings(range_m=1000.0, penetration=0.9)
    assert _view(_sensing(partial), []).known_free_ahead_m < 100.0


def test_a_v2x_car_beyond_the_radar_limits_the_free_length_and_is_fused_when_seen():
    sensing = _sensing(V2XSettings(range_m=1000.0, latency_s=0.0))
    car = _body("c", 402.35, LANE, math.pi, 20.0, 4.7, 1.8)
    view = _view(sensing, [car])
    assert view.nearest_ahead_m == pytest.approx(400.0)
    assert view.known_free_ahead_m == pytest.approx(400.0)
    near = _body("c", 52.35, LANE, math.pi, 20.0, 4.7, 1.8)  # seen by radar and V2X: one
    view = _view(sensing, [near], t=0.1)
    assert view.nearest_ahead_m == pytest.approx(50.0)


def _right_sensing(target_width_m=LANE):
    return right_lane_sensing(LANE, target_width_m)


def test_the_right_lane_is_sensed_as_the_left_one_mirrored():
    car = _body("c", -40.0, -LANE, 0.0, 40.0, 4.7, 1.8)  # behind, in the right lane
    view = _view(_right_sensing(), [car])
    assert view.side == -1
    assert view.nearest_behind_m == pytest.approx(40.0 - 4.92 - 2.35)
    assert (
        _view(_right_sensing(), [_body("c", -40.0, LANE, 0.0, 40.0, 4.7, 1.8)]).nearest_behind_m
        is None
    )
    left = _view(_sensing(), [])
    right = _view(_right_sensing(), [])
    assert right.coverage_ahead_m == pytest.approx(left.coverage_ahead_m)


def test_a_wider_right_lane_reaches_further_out():
    sensing = _right_sensing(target_width_m=4.0)
    assert sensing.band_m == pytest.approx((-(0.5 * LANE + 4.0), -0.5 * LANE))
    van = _body("van", 62.5, -(0.5 * LANE + 3.7), 0.0, 10.0, 5.0, 1.0)  # in its outer half
    view = _view(sensing, [van])
    assert view.nearest_ahead_m == pytest.approx(60.0)
    assert view.lane_width_m == 4.0


def test_a_road_users_acceleration_is_its_speed_change_over_the_baseline():
    sensing = _sensing()
    speeds = [30.0 - 4.0 * 0.1 * k for k in range(8)]  # braking at 4 m/s^2, every 0.1 s
    x = 60.0
    views = []
    for k, v in enumerate(speeds):
        car = _body("c", x, LANE, 0.0, v, 4.7, 1.8)
        views.append(_view(sensing, [car], t=0.1 * k))
        x += v * 0.1
    assert views[0].users_ahead_accel()[0][2] == 0.0  # not followed long enough yet
    assert views[-1].users_ahead_accel()[0][2] == pytest.approx(-4.0)
