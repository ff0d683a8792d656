"""The paper policy's commit check and the radar's classes of the target lane meet: a road
user there is judged by the radar's rules (oncoming, standing) or by the commit check (moving
the ego's way), none by neither (no SUMO; the real lookup tables)."""

from __future__ import annotations

import math

import pytest

from eoam_sumo.decision.policy import PolicySettings, SafePolicy
from eoam_sumo.eoam import EgoMeasurement, EoamSettings, ObjectState, Perception
from eoam_sumo.eoam_messages import (
    NEXT_LANE_STANDING_MPS,
    ONCOMING,
    STANDING,
    WITH,
    NextLaneView,
    next_lane_motion,
)
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.sensing.radar import Radar, RadarSettings
from eoam_sumo.world.bodies import Body

P = ego_e_class_sedan()
LANE_M = 3.5
BOUNDARY_MPS = (-20.0, -2.0, -1.5, -0.6, -0.5, -0.4, 0.0, 0.4, 0.5, 0.6, 20.0)


@pytest.fixture(scope="module")
def tables():
    return LookupTables.load(default_tables_dir(), params=P)


def _commit_reason(tables, speed_mps: float, gap_m: float = 30.0) -> str:
    """The paper policy's check at a commit, the ego at 33.3 m/s 40 m behind the obstacle,
    one road user ``gap_m`` ahead in the target lane at ``speed_mps``."""
    pol = SafePolicy(P, tables, EoamSettings(), PolicySettings(name="paper"))
    meas = EgoMeasurement(0.0, 33.3, 0.0, 0.0, 0.0, 0.0, 100.0, 0.0, 0.0, 0.0, 1.0, LANE_M)
    view = NextLaneView(True, 27.0, coverage_ahead_m=0.0, ahead=((gap_m, speed_mps),))
    seen = Perception(40.0, -33.3, False, ObjectState(150.0, 0.0, 0.0, 5.09, 1.99), None, view)
    return pol.occupied_reason(meas, seen, view)


class _Straight:
    """The road frame of a straight lane along +x centred on y = 0."""

    def project(self, x, y):
        return x, y, 0.0


def _radar_class(speed_mps: float) -> str:
    """The radar's class of a car centred in the next lane 40 m ahead at ``speed_mps``."""
    yaw = math.pi if speed_mps < 0.0 else 0.0
    car = Body("t", "passenger", 42.35, LANE_M, yaw, abs(speed_mps), 4.7, 1.82)
    (det,) = Radar().scan((0.0, 0.0), 0.0, 33.3, _Straight(), [car], LANE_M).detections
    return det.category


@pytest.mark.parametrize("speed_mps", BOUNDARY_MPS)
def test_each_road_user_ahead_in_the_target_lane_is_judged_once(tables, speed_mps):
    """Oncoming or standing for the radar (the paper's rules), or else refused by the commit
    check when the ego would catch it up: a van creeping towards the ego at 0.5-2 m/s was
    neither (the commit check left out everything slower than 0.5 m/s the ego's way)."""
    radar = _radar_class(speed_mps)
    reason = _commit_reason(tables, speed_mps)
    judged_by_radar = radar in ("oncoming", "in_next_lane")
    assert judged_by_radar != bool(reason), (radar, reason)
    if reason:
        assert reason == "a road user ahead in the target lane"


def test_the_classes_meet_at_the_radar_s_standing_speed():
    """Towards the ego at 0.5 m/s or more oncoming, slower either way standing, else the ego's
    way: one function for the radar and the EOAM (``eoam_messages.next_lane_motion``), at the
    radar's default standing speed."""
    assert next_lane_motion(-0.5) == ONCOMING
    assert next_lane_motion(-0.4999999) == STANDING
    assert next_lane_motion(0.4999999) == STANDING
    assert next_lane_motion(0.5) == WITH
    assert RadarSettings().stationary_speed_mps == NEXT_LANE_STANDING_MPS
