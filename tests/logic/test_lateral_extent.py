"""The lane change clears the obstacle's real lateral extent: to the target lane's centre, or
farther within the target lane when the obstacle reaches into it, else braking in lane
(closed-form geometry)."""

from __future__ import annotations

import pytest

from eoam_sumo.decision.obstacle import ObstacleTrack
from eoam_sumo.eoam import EgoMeasurement
from eoam_sumo.eoam.shifts import lane_change_height_m, yawed_body_reach_m
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.params import ego_e_class_sedan

P = ego_e_class_sedan()
ST = EoamSettings()
LANE = 3.5


def _meas():
    return EgoMeasurement(0.0, 30.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, LANE)


def _reach():
    """The yawed body's reach beyond half its width (``shifts.yawed_body_reach_m``)."""
    return yawed_body_reach_m(P, _meas())


def _truck(over_line_m):
    """A stopped truck whose left side is ``over_line_m`` past the ego lane's left marker."""
    return ObstacleTrack(0.0, 50.0, 0.0, 0.5 * LANE + over_line_m, 0.0, 12.0)


def test_an_obstacle_inside_its_lane_is_passed_at_the_target_lane_centre():
    assert lane_change_height_m(P, ST, _truck(-0.5), _meas()) == pytest.approx(LANE)
    assert lane_change_height_m(P, ST, None, _meas()) == pytest.approx(LANE)


@pytest.mark.parametrize("over_m", [0.37, 0.82, 0.84])
def test_a_truck_over_the_line_is_cleared_by_the_side_clearance_within_the_lane(over_m):
    height = lane_change_height_m(P, ST, _truck(over_m), _meas())
    clearance = height - 0.5 * P.width_m - _reach() - (0.5 * LANE + over_m)
    if height > LANE:  # moved over: exactly the clearance
        assert clearance == pytest.approx(ST.side_clearance_m)
    assert clearance >= ST.side_clearance_m - 1e-9
    # the body, its yawed corners included, within the target lane
    assert height + 0.5 * P.width_m + _reach() <= 1.5 * LANE + 1e-9


def test_a_truck_reaching_too_far_into_the_target_lane_makes_the_ego_brake():
    # the body cannot both clear it (its yawed corner by the side clearance) and stay in the
    # target lane (its other yawed corner as far out)
    too_far = 1.5 * LANE - P.width_m - 2.0 * _reach() - ST.side_clearance_m - 0.5 * LANE + 0.05
    assert lane_change_height_m(P, ST, _truck(too_far), _meas()) is None
    assert lane_change_height_m(P, ST, _truck(too_far - 0.1), _meas()) is not None


def test_the_yawed_body_reaches_farther_on_more_friction():
    """The rear axle's slip at its friction grows with mu; for the paper's sedan on mu 1.0
    it is near the 0.05-0.07 rad of sideslip its 165 km/h lane changes reach (docs/control.md),
    its corner, half a length out, then 0.12-0.17 m nearer."""
    reaches = [
        yawed_body_reach_m(P, EgoMeasurement(0.0, 30.0, 0, 0, 0, 0, 0, 0, 0, 0, mu, LANE))
        for mu in (0.1, 0.3, 0.7, 1.0)
    ]
    assert reaches == sorted(reaches) and reaches[0] > 0.0
    assert 0.5 * P.length_m * 0.05 < reaches[-1] < 0.5 * P.length_m * 0.07


@pytest.mark.parametrize("own_m, target_offset_m", [(28.0, 0.0), (3.5, 15.75), (7.0, 0.0)])
def test_a_lane_wider_than_two_cars_is_swerved_into_not_crossed(own_m, target_offset_m):
    """From or into a lane wider than WIDE_LANE_M (Vector's NCAP road: one 28 m lane each way)
    the lateral travel is the tables' 3.5 m, not the far lane's centre (28 m, 15.75 m); an
    obstacle that sticks out farther is cleared by the side clearance, as in a normal lane."""
    meas = _meas()._replace(lane_width_m=own_m)
    assert lane_change_height_m(P, ST, None, meas, target_offset_m) == pytest.approx(3.5)
    truck = ObstacleTrack(0.0, 50.0, 0.0, 3.0, 0.0, 12.0)  # its left side 3.0 m left of centre
    height = lane_change_height_m(P, ST, truck, meas, target_offset_m)
    clearance = height - 0.5 * P.width_m - yawed_body_reach_m(P, meas) - 3.0
    assert clearance == pytest.approx(ST.side_clearance_m)


def test_lanes_up_to_two_cars_wide_are_crossed_to_the_target_lane_centre():
    meas = _meas()._replace(lane_width_m=6.0)
    assert lane_change_height_m(P, ST, None, meas) == pytest.approx(6.0)
