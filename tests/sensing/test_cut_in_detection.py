"""A car cutting in is in the path once it has moved more than the wandering threshold from
its lane's centre towards the ego's lane, still moves towards it, and the risk perception
time has passed since it crossed the threshold (at its lateral speed), before its centre
crosses the lane band (closed-form road geometry, no SUMO)."""

from __future__ import annotations

import math

from eoam_sumo.sensing.radar import CUT_IN_PERCEPTION_S, CUT_IN_WANDER_M, Radar, cutting_in
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body

LANE_M = 3.5
CAR = (4.70, 1.82)
ROAD = RoadFrame([(-1000.0, 0.0), (5000.0, 0.0)])
BAND_M = 0.5 * LANE_M + 0.5  # the radar's default lane band


def _car(d_m, heading_rad, speed_mps=23.6, rear_s_m=25.0):
    return Body("c", "passenger", rear_s_m + 0.5 * CAR[0], d_m, heading_rad, speed_mps, *CAR)


def _category(body):
    report = Radar().scan((0.0, 0.0), 0.0, 33.3, ROAD, [body], LANE_M)
    return report.detections[0].category if report.detections else None


def test_a_car_drifting_towards_the_ego_lane_past_the_threshold_is_in_the_path():
    towards = -math.radians(3.0)  # heading right, towards the ego's lane from the left lane
    lateral_mps = 23.6 * math.sin(-towards)
    # the threshold crossed the perception time ago at its lateral speed (and a little more)
    d_in = LANE_M - CUT_IN_WANDER_M - CUT_IN_PERCEPTION_S * lateral_mps - 0.02
    assert _category(_car(d_in, towards)) == "in_path"
    # past the threshold for less than the perception time, or moving away, or straight:
    # still in the next lane
    assert _category(_car(d_in + 0.05, towards)) == "other"
    assert _category(_car(LANE_M - CUT_IN_WANDER_M + 0.05, towards)) == "other"
    assert _category(_car(d_in, -towards)) == "other"
    assert _category(_car(d_in, 0.0)) == "other"
    # its centre still short of the band, where the old rule saw it in the path
    assert d_in > BAND_M + 0.2


def test_the_perception_time_is_the_time_since_the_threshold_at_the_lateral_speed():
    for lateral_mps in (0.3, 1.0, 1.5):
        crossed_m = LANE_M - CUT_IN_WANDER_M  # the centre's offset at the threshold
        t_s = CUT_IN_PERCEPTION_S
        assert cutting_in(crossed_m - lateral_mps * (t_s + 0.01), -lateral_mps, LANE_M, BAND_M)
        assert not cutting_in(crossed_m - lateral_mps * (t_s - 0.01), -lateral_mps, LANE_M, BAND_M)


def test_cutting_in_is_symmetric_and_limited_to_the_neighbouring_lanes():
    # 1 m from its lane's centre at 1 m/s: past the threshold for 0.625 s
    assert cutting_in(2.5, -1.0, LANE_M, BAND_M)  # from the left, moving right
    assert cutting_in(-2.5, 1.0, LANE_M, BAND_M)  # from the right, moving left
    assert not cutting_in(-2.5, -1.0, LANE_M, BAND_M)
    assert not cutting_in(2.5 + LANE_M, -1.0, LANE_M, BAND_M)  # two lanes away
    assert not cutting_in(2.0, -1.0, LANE_M, BAND_M)  # inside the band: in the path anyway
