"""A coasted object (lost from view, predicted in the path) within the stopping distance
keeps the EOAM braking: no hand-back to NORMAL, no speeding up (docs/sensing.md)."""

import pytest

from eoam_sumo.decision import Mode
from eoam_sumo.eoam import EgoMeasurement, EoamController, EoamSettings, Perception
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import ego_e_class_sedan

P = ego_e_class_sedan()
DT = 0.01
MU = 1.0


@pytest.fixture(scope="module")
def tables():
    return LookupTables.load(default_tables_dir(), params=P)


def stopping_m(tables, v_mps: float) -> float:
    """The ego's limit-braking stopping distance (the brake limit the EOAM uses, on the car
    and its spinning wheels)."""
    decel = float(tables.limit_brake_decel_mps2(MU))
    return v_mps * v_mps / (2.0 * decel)


def step(ctrl: EoamController, t: float, v: float, perception: Perception):
    meas = EgoMeasurement(t, v, 0.0, 0.0, 0.0, 0.0, 100.0 + v * t, 0.0, 0.0, 0.0, MU, 3.5)
    return ctrl.step(meas, perception, DT)


@pytest.mark.parametrize("v_mps", [3.0, 8.0])
def test_normal_driving_brakes_for_a_coasted_object_within_the_stopping_distance(tables, v_mps):
    margin = EoamSettings().coasted_margin_m
    inside, outside = (
        (stopping_m(tables, v_mps) + margin) * 0.98,
        (stopping_m(tables, v_mps) + margin) * 1.02,
    )
    far = EoamController(P, tables)
    far.reset(v_mps)
    cmd = step(far, 0.0, v_mps, Perception(coasted_range_m=outside, coasted_range_rate_mps=-v_mps))
    assert far.mode is Mode.NORMAL and cmd.brake_force_cmd_n == 0.0
    near = EoamController(P, tables)
    near.reset(v_mps)
    cmd = step(near, 0.0, v_mps, Perception(coasted_range_m=inside, coasted_range_rate_mps=-v_mps))
    assert near.mode is Mode.UPDATE_BRAKE and cmd.fcw
    assert cmd.brake_force_cmd_n > 0.0 and cmd.drive_force_cmd_n == 0.0


def braking_for_a_person_lost_from_view(tables) -> EoamController:
    """Braking at 5 m/s for a person seen 3 m ahead (mode 1)."""
    ctrl = EoamController(P, tables)
    ctrl.reset(5.0)
    step(ctrl, 0.0, 5.0, Perception(3.0, -3.6))  # seen, closing
    assert ctrl.mode is Mode.UPDATE_BRAKE
    return ctrl


@pytest.mark.parametrize(
    ("coasted_m", "rate_mps", "hands_back"),
    [
        (None, 0.0, True),  # nothing in the path: the threat is gone
        (2.5, 1.4, False),  # pulling away, but within the 0.9 m stopping distance + 2 m
        (10.0, -1.0, False),  # far, but closing
        (10.0, 0.0, False),  # far, standing
        (10.0, 1.4, True),  # far, walking away
    ],
)
def test_no_hand_back_while_a_coasted_object_is_near_or_not_pulling_away(
    tables, coasted_m, rate_mps, hands_back
):
    """The person is lost from view (ego at 4 m/s): without a coasted track the threat is
    gone and the EOAM hands back; with one it brakes on unless the prediction pulls away
    (faster than the release speed) beyond the stopping distance plus the margin."""
    assert stopping_m(tables, 4.0) + EoamSettings().coasted_margin_m > 2.5
    ctrl = braking_for_a_person_lost_from_view(tables)
    cmd = step(
        ctrl, DT, 4.0, Perception(coasted_range_m=coasted_m, coasted_range_rate_mps=rate_mps)
    )
    assert (ctrl.mode is Mode.NORMAL) is hands_back
    if not hands_back:
        assert cmd.brake_force_cmd_n > 0.0 and cmd.drive_force_cmd_n == 0.0


def test_a_stopped_ego_hands_back_once_the_person_walks_on_beyond_the_margin(tables):
    ctrl = braking_for_a_person_lost_from_view(tables)
    step(ctrl, DT, 0.0, Perception(coasted_range_m=1.9, coasted_range_rate_mps=1.4))
    assert ctrl.mode is Mode.UPDATE_BRAKE
    step(ctrl, 2 * DT, 0.0, Perception(coasted_range_m=2.1, coasted_range_rate_mps=1.4))
    assert ctrl.mode is Mode.NORMAL


def test_a_person_walking_towards_the_ego_counts_at_the_closing_speed(tables):
    """At 3 m/s with a person coasted towards the ego at 1.4 m/s (closing 4.4 m/s), the
    stopping distance is that of the closing speed."""
    margin = EoamSettings().coasted_margin_m
    between = 0.5 * (stopping_m(tables, 3.0) + stopping_m(tables, 4.4)) + margin
    ctrl = EoamController(P, tables)
    ctrl.reset(3.0)
    step(ctrl, 0.0, 3.0, Perception(coasted_range_m=between, coasted_range_rate_mps=-4.4))
    assert ctrl.mode is Mode.UPDATE_BRAKE
