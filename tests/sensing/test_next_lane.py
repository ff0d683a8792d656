"""Coverage of the next lane by the forward radar, the corner radars and V2X, and the road
users found in it, on a straight road (closed-form geometry; no SUMO)."""

import math
from collections import namedtuple

import pytest

from eoam_sumo.sensing.next_lane import (
    NextLaneSensing,
    cone_on_line,
    covered_from,
    shadow_on_line,
)
from eoam_sumo.sensing.v2x import V2XSettings
from eoam_sumo.sim.geometry import OrientedBox
from eoam_sumo.sim.radar import Radar, RadarSettings

LANE = 3.5
HALF_FOV = math.radians(9.0)


class Straight:
    """Road frame of a straight lane along +x centred on y = 0."""

    def project(self, x, y):
        return x, y, 0.0


class Body(namedtuple("Body", "vid x_m y_m yaw_rad speed_mps length_m width_m")):
    @property
    def box(self):
        return OrientedBox(self.x_m, self.y_m, self.yaw_rad, self.length_m, self.width_m)


def test_the_forward_cone_meets_a_side_line_between_its_edge_and_its_range():
    lo, hi = cone_on_line(3.5, 0.0, HALF_FOV, 100.0)
    assert lo == pytest.approx(3.5 / math.tan(HALF_FOV))
    assert hi == pytest.approx(math.sqrt(100.0**2 - 3.5**2))
    assert cone_on_line(120.0, 0.0, HALF_FOV, 100.0) is None
    lo, hi = cone_on_line(-3.5, 0.0, HALF_FOV, 100.0)  # mirror image on the right
    assert lo == pytest.approx(3.5 / math.tan(HALF_FOV))


def test_a_rear_looking_corner_cone_covers_behind():
    lo, hi = cone_on_line(2.0, math.radians(140.0), math.radians(40.0), 80.0)
    assert lo == pytest.approx(-math.sqrt(80.0**2 - 4.0))
    assert hi == pytest.approx(2.0 / math.tan(math.radians(100.0)))
    assert hi < 0.0


def test_a_box_ahead_shadows_the_side_line_beyond_the_ray_past_its_corner():
    box = (40.0, 45.0, -1.0, 1.0)  # 40 m ahead, 2 m wide, centred
    a, b = shadow_on_line(3.5, box)
    assert a == pytest.approx(3.5 * 40.0 / 1.0)  # the ray through the near left corner
    assert math.isinf(b)
    assert shadow_on_line(3.5, (40.0, 45.0, -4.0, -2.0)) is None  # a box on the right


def test_covered_length_stops_at_the_first_gap():
    assert covered_from([(0.0, 10.0), (9.0, 50.0), (60.0, 90.0)], 0.0) == 50.0
    assert covered_from([(1.0, 10.0)], 0.0) == 0.0


def _sensing(v2x=None, radar_range_m=100.0):
    return NextLaneSensing(opposing=True, speed_limit_mps=25.0, lane_width_m=LANE,
                           radar_range_m=radar_range_m, radar_fov_deg=18.0, ego_length_m=4.92,
                           ego_width_m=1.85, v2x=v2x)


def _view(sensing, bodies, t=0.0):
    radar = Radar(RadarSettings())
    report = radar.scan((0.0, 0.0), 0.0, 30.0, Straight(), bodies, LANE)
    return sensing.update(t, (0.0, 0.0), 0.0, Straight(), report, bodies)


def test_an_empty_road_is_known_free_to_the_radar_range_on_the_far_line():
    view = _view(_sensing(), [])
    far = 1.5 * LANE - 0.25
    assert view.coverage_ahead_m == pytest.approx(math.sqrt(100.0**2 - far**2))
    assert view.known_free_ahead_m == view.coverage_ahead_m
    assert view.nearest_ahead_m is None


def test_the_obstacle_ahead_hides_the_lane_beyond_its_shadow():
    aro = Body("aro", 42.5, 0.0, 0.0, 0.0, 5.0, 2.0)
    view = _view(_sensing(), [aro])
    near = 0.5 * LANE + 0.25  # the near line is hidden from x = 2.0 * 40 / 1.0 = 80 m
    assert view.coverage_ahead_m == pytest.approx(near * 40.0 / 1.0)
    assert view.nearest_ahead_m is None  # the in-path obstacle is not in the next lane


@pytest.mark.parametrize("speed", [-1.5, 0.0, 1.5, -20.0])
def test_any_road_user_in_the_next_lane_limits_the_free_length_whatever_its_speed(speed):
    yaw = math.pi if speed < 0 else 0.0
    van = Body("van", 62.5, LANE, yaw, abs(speed), 5.0, 2.0)
    view = _view(_sensing(), [van])
    assert view.nearest_ahead_m == pytest.approx(60.0)
    assert view.known_free_ahead_m == pytest.approx(60.0)
    assert view.nearest_ahead_speed_mps == pytest.approx(speed)


def test_a_person_beside_the_ego_is_found_by_the_corner_radar():
    walker = Body("p", -2.0, LANE, 0.0, 1.2, 0.5, 0.5)  # beside the ego's body
    view = _view(_sensing(), [walker])
    assert view.nearest_ahead_m == 0.0  # overlapping the ego's stations: blocks at once


def test_a_car_closing_from_behind_is_found_by_the_rear_corner_radar():
    car = Body("c", -40.0, LANE, 0.0, 40.0, 4.7, 1.8)
    view = _view(_sensing(), [car])
    assert view.nearest_behind_m == pytest.approx(40.0 - 4.92 - 2.35)
    assert view.nearest_behind_speed_mps == pytest.approx(40.0)
    assert _view(_sensing(), [Body("c", -90.0, LANE, 0.0, 40.0, 4.7, 1.8)]
                 ).nearest_behind_m is None  # beyond the corner radar's 80 m


def test_full_penetration_v2x_proves_the_range_free_less_its_blind_distance():
    v2x = V2XSettings(range_m=1000.0, latency_s=0.1)
    view = _view(_sensing(v2x), [])
    assert view.known_free_ahead_m == pytest.approx(1000.0 - 25.0 * 0.2)
    partial = V2XSettings(range_m=1000.0, penetration=0.9)
    assert _view(_sensing(partial), []).known_free_ahead_m < 100.0


def test_a_v2x_car_beyond_the_radar_limits_the_free_length_and_is_fused_when_seen():
    sensing = _sensing(V2XSettings(range_m=1000.0, latency_s=0.0))
    car = Body("c", 402.35, LANE, math.pi, 20.0, 4.7, 1.8)
    view = _view(sensing, [car])
    assert view.nearest_ahead_m == pytest.approx(400.0)
    assert view.known_free_ahead_m == pytest.approx(400.0)
    near = Body("c", 52.35, LANE, math.pi, 20.0, 4.7, 1.8)  # seen by radar and V2X: one
    view = _view(sensing, [near], t=0.1)
    assert view.nearest_ahead_m == pytest.approx(50.0)
