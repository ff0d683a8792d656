"""The return only behind and clear of the road user passed: its box predicted over the return,
the ego at its own acceleration (no return alongside it, none in front of a car it has only
just passed while braking), and in mode 2 only once it keeps its distance behind the ego by
the car-behind rule, against closed-form kinematics."""

import math
from types import SimpleNamespace

from eoam_sumo.decision.modes import ONCOMING_STEER_BRAKE, UPDATE_STEER_BRAKE
from eoam_sumo.decision.obstacle import ObstacleTrack
from eoam_sumo.decision.policy import FOLLOWER_HEADWAY_S
from eoam_sumo.eoam import EgoMeasurement
from eoam_sumo.eoam.strategies import OffsetPonr, PonrCommit, beside_obstacle, return_time_s
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.params import G_MPS2, ego_e_class_sedan

P = ego_e_class_sedan()
ST = EoamSettings()
LANE = 3.5


def _meas(s_m, v, ax=0.0, d=3.5, mu=1.0):
    return EgoMeasurement(10.0, v, 0.0, 0.0, ax, 0.0, s_m, d, 0.0, 0.0, mu, LANE)


def _track(front_s_m, v, decel=0.0, length=4.7):
    return ObstacleTrack(10.0, front_s_m, v, 0.9, decel, length)


def test_the_return_takes_the_quintic_time_at_its_lateral_limit():
    t = return_time_s(ST, _meas(0.0, 30.0, mu=0.5))
    peak = 10.0 * math.sqrt(3.0) / 3.0 * 3.5 / t**2
    assert abs(peak - ST.return_lateral_g * 0.5 * G_MPS2) < 1e-9


def _passed(meas, track, mode=UPDATE_STEER_BRAKE):
    commit = PonrCommit(P, ST, OffsetPonr(ST))
    return commit.passed(SimpleNamespace(mode=mode), meas, track)


def test_a_stopped_obstacle_is_passed_once_the_rear_is_the_margin_past_it():
    rear = P.cg_to_rear_bumper_m
    front = 100.0
    assert _passed(_meas(front + rear + ST.pass_margin_m + 0.01, 20.0, ax=-8.0), _track(front, 0))
    assert not _passed(_meas(front + rear + ST.pass_margin_m - 0.01, 20.0), _track(front, 0))


def test_a_braking_ego_does_not_return_in_front_of_a_car_it_just_passed():
    # 1.5 m ahead of a car at 25 m/s, the ego at 27 m/s braking at 6 m/s2: within the return
    # (about 1.4 s at mu 1) the car is level again; holding 27 m/s, it is clear
    rear = P.cg_to_rear_bumper_m
    front = 100.0
    meas = _meas(front + rear + 1.5, 27.0, ax=-6.0)
    t = return_time_s(ST, meas)
    gap_end = 1.5 + (27.0 - 25.0) * t - 0.5 * 6.0 * t * t
    assert gap_end < ST.pass_margin_m  # the truth the rule must follow
    assert not _passed(meas, _track(front, 25.0))
    assert not _passed(meas, _track(front, 25.0), ONCOMING_STEER_BRAKE)
    # holding 27 m/s it stays clear lengthwise: mode 4 (oncoming traffic) returns at once
    assert _passed(_meas(front + rear + 1.5, 27.0), _track(front, 25.0), ONCOMING_STEER_BRAKE)


def test_in_mode_2_the_car_passed_must_keep_its_distance_behind_the_ego():
    # the car at 25 m/s, the ego holding 30 m/s: the gap only grows (5 m/s), the car needs no
    # braking, so the rule is its 1 s of travel (25 m) from the start
    rear = P.cg_to_rear_bumper_m
    need_m = FOLLOWER_HEADWAY_S * 25.0
    assert _passed(_meas(100.0 + rear + need_m, 30.0), _track(100.0, 25.0))
    assert not _passed(_meas(100.0 + rear + need_m - 1.0, 30.0), _track(100.0, 25.0))


def test_no_return_begins_alongside_the_obstacle():
    state = SimpleNamespace(obstacle=_track(100.0, 0.0))
    front, rear = P.cg_to_front_bumper_m, P.cg_to_rear_bumper_m
    assert beside_obstacle(ST, P, state, _meas(100.0 - 2.0, 20.0))  # centre level with it
    assert beside_obstacle(ST, P, state, _meas(100.0 + rear + 0.5, 20.0))  # within the margin
    assert not beside_obstacle(ST, P, state, _meas(100.0 + rear + 1.5, 20.0))  # past it
    assert not beside_obstacle(ST, P, state, _meas(100.0 - 4.7 - front - 1.5, 20.0))  # behind
    assert not beside_obstacle(ST, P, SimpleNamespace(obstacle=None), _meas(100.0, 20.0))
    # a car at 20 m/s 1.5 m behind the ego's rear, as fast: too close to return in front of
    moving = SimpleNamespace(obstacle=_track(100.0, 20.0))
    assert beside_obstacle(ST, P, moving, _meas(100.0 + rear + 1.5, 20.0))
    assert not beside_obstacle(ST, P, moving, _meas(100.0 + rear + 20.0 * FOLLOWER_HEADWAY_S, 20.0))
