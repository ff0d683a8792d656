"""The side of a lane change: the mirrored road frame is its own inverse, and the lateral
travel to a target lane of another width is the centre-to-centre distance."""

import pytest

from eoam_sumo.eoam.sides import (
    lane_offset_m,
    mirrored_command,
    mirrored_measurement,
    mirrored_perception,
)
from eoam_sumo.eoam_messages import (
    Command,
    EgoMeasurement,
    NextLaneView,
    ObjectState,
    Perception,
)


def test_mirroring_twice_is_the_identity_on_the_geometry():
    meas = EgoMeasurement(1.0, 30.0, 0.2, 0.05, -3.0, 1.5, 100.0, -0.4, 0.01, 0.002, 0.8, 3.5)
    twice = mirrored_measurement(mirrored_measurement(meas))
    assert twice == meas._replace(left_lane_available=True)
    once = mirrored_measurement(meas)
    assert (once.d_m, once.e_yaw_rad, once.yaw_rate_radps) == (0.4, -0.01, -0.05)
    assert mirrored_measurement(meas).mu == 0.8  # no friction of its own for the right
    icy = meas._replace(mu_right=0.1)
    assert (mirrored_measurement(icy).mu, mirrored_measurement(icy).mu_right) == (0.1, 0.8)
    assert mirrored_measurement(mirrored_measurement(icy)) == icy._replace(left_lane_available=True)
    cmd = Command(0.02, 0.0, 100.0, 2, True, "D", -3.0, 1.2, 4.0, 0.1, 0.2, 0.01, 0.005, -0.003, 30)
    assert mirrored_command(mirrored_command(cmd)) == cmd
    assert mirrored_command(cmd).steer_cmd_rad == -0.02


def test_the_mirrored_perception_swaps_the_lanes_and_flips_the_obstacle():
    left = NextLaneView(
        True, 25.0, coverage=lambda: 50.0, nearest_ahead_m=30.0, nearest_ahead_speed_mps=-20.0
    )
    right = NextLaneView(
        False, 36.0, coverage=lambda: 80.0, ahead=((12.0, 0.0), (40.0, 30.0)), side=-1
    )
    obj = ObjectState(120.0, 0.3, 20.0, 4.7, 1.8)
    p = Perception(20.0, -5.0, True, obj, 33.0, left, right_lane=right)
    m = mirrored_perception(p)
    assert m.next_lane is right and m.right_lane is left
    assert m.aro_object.d_m == -0.3
    assert not m.oncoming_detected  # the oncoming car is in the left lane
    assert m.next_lane_obstacle_range_m == 12.0  # the standing one in the right lane


@pytest.mark.parametrize(
    ("target", "expected"), [(3.5, 0.0), (0.0, 0.0), (3.75, 3.625), (3.0, 3.25)]
)
def test_the_travel_is_centre_to_centre(target, expected):
    view = NextLaneView(False, 36.0, coverage=lambda: 80.0, lane_width_m=target)
    assert lane_offset_m(3.5, view) == expected
    assert lane_offset_m(3.5, None) == 0.0
