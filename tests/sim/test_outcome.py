"""Outcome colours (design.md sec. 3.4) and ground-truth roles, one test per rule."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.sim.geometry import Contact, OrientedBox, contact
from eoam_sumo.sim.outcome import (
    COLOURS,
    Outcome,
    OutcomeSettings,
    classify_outcome,
    role_of,
)
from eoam_sumo.sim.radar import Target
from eoam_sumo.sim.roadframe import RoadFrame

LANE_M = 3.5
PONR_M = 0.3 * LANE_M  # 1.05 m, paper sec. 8.1
ROAD = RoadFrame([(-1000.0, 0.0), (5000.0, 0.0)])
EGO = (4.92, 1.85)
ARO = (5.09, 1.99)
CAR = (4.70, 1.82)

BRAKE_ONLY = [0, 1]
ONCOMING_ABORT = [0, 1, 2, 3]
LANE_CHANGE = [0, 1, 2, 5, 0]
PONR_PASSED = [0, 1, 2, 4, 5, 0]


def _hit(kind, face_a="front", face_b="rear", speed=7.2):
    return Contact(kind, face_a, face_b, speed, (0.0, 0.0))


def _classify(modes, max_offset, contact_=None, role="none", final_offset=0.0, final_speed=0.0):
    return classify_outcome(
        modes_visited=modes, max_lateral_offset_m=max_offset, lane_width_m=LANE_M,
        contact=contact_, role=role, final_offset_m=final_offset, final_speed_mps=final_speed,
    )


# --- roles --------------------------------------------------------------------------------


def _body(s_m, d_m, yaw_rad, speed_mps, dims=CAR):
    return Target(s_m, d_m, yaw_rad, speed_mps, *dims)


@pytest.mark.parametrize(
    ("body", "role"),
    [
        (_body(80.0, 0.0, 0.0, 16.7, ARO), "aro"),  # the ARO before its stop
        (_body(80.0, 0.3, 0.0, 0.0, ARO), "aro"),  # the ARO stopped
        (_body(80.0, -1.9, 0.0, 0.0, ARO), "aro"),  # straddling the right marker, still in band
        (_body(80.0, LANE_M, math.pi, 20.0), "oncoming"),
        (_body(80.0, 0.0, math.pi, 20.0), "oncoming"),  # wrong-way in the ego lane
        (_body(80.0, LANE_M, math.pi - 0.2, 20.0), "oncoming"),  # swerving oncoming car
        (_body(80.0, -4.15, 0.0, 0.0, (4.3, 1.8)), "parked"),  # 1.5 m beyond the marker
        (_body(80.0, LANE_M, 0.0, 0.0), "parked"),  # stopped outside the ego lane band
        (_body(80.0, LANE_M, 0.0, 30.0), "other"),  # overtaking in the left lane
        (_body(80.0, LANE_M, math.pi, 1.0), "other"),  # creeping backwards, not oncoming
    ],
)
def test_role_of(body, role):
    assert role_of(body, ROAD, LANE_M) == role


def test_role_of_uses_the_start_lane_flag_and_the_road_heading():
    overtaking = _body(80.0, LANE_M, 0.0, 30.0)
    assert role_of(overtaking, ROAD, LANE_M, in_lane_at_start=True) == "aro"
    # the same oncoming car on a road running north: heading south is against the road
    north = RoadFrame([(0.0, -1000.0), (0.0, 5000.0)])
    onc = _body(-LANE_M, 80.0, -math.pi / 2, 20.0)
    assert role_of(onc, north, LANE_M) == "oncoming"
    aro = _body(0.0, 80.0, math.pi / 2, 10.0)
    assert role_of(aro, north, LANE_M) == "aro"
    with pytest.raises(ValueError, match="lane_width_m"):
        role_of(aro, north, 0.0)


# --- colours: one test per rule -----------------------------------------------------------


def test_none_no_manoeuvre_no_contact():
    out = _classify([0], 0.0, final_speed=30.0)
    assert out == Outcome("none", "none", 0.0, out.reason)
    assert "no manoeuvre" in out.reason


def test_green_lane_change_and_return():
    out = _classify(LANE_CHANGE, 3.6, final_offset=0.1, final_speed=28.0)
    assert (out.colour, out.collision_with, out.impact_speed_mps) == ("green", "none", 0.0)
    assert out.reason == "lane change completed, returned to lane, no contact"


def test_green_stop_behind_the_obstacle():
    out = _classify(BRAKE_ONLY, 0.0, final_speed=0.0)
    assert (out.colour, out.collision_with) == ("green", "none")
    assert "stopped behind the obstacle" in out.reason
    aborted = _classify(ONCOMING_ABORT, 0.8, final_offset=0.7, final_speed=0.0)
    assert aborted.colour == "green" and "stopped" in aborted.reason


def test_green_corner_cases_say_what_was_unfinished():
    away = _classify(PONR_PASSED, 3.5, final_offset=3.4, final_speed=25.0)
    assert away.colour == "green" and "not back in lane" in away.reason
    rolling = _classify(BRAKE_ONLY, 0.0, final_speed=4.0)
    assert rolling.colour == "green" and "still moving" in rolling.reason


def test_yellow_oncoming_seen_before_the_point_of_no_return():
    out = _classify(ONCOMING_ABORT, 0.6, _hit("rear_end", speed=7.2), "aro")
    assert (out.colour, out.collision_with, out.impact_speed_mps) == ("yellow", "aro", 7.2)
    assert out.reason == (
        "limit braking chosen (oncoming seen before the point of no return), "
        "front hit the ARO at 7.2 m/s"
    )


def test_yellow_limit_braking_by_the_dmm_and_without_intervention():
    out = _classify(BRAKE_ONLY, 0.0, _hit("rear_end", speed=11.0), "aro")
    assert out.colour == "yellow" and "by the DMM" in out.reason
    late = _classify([0], 0.0, _hit("rear_end", speed=25.0), "aro")
    assert late.colour == "yellow" and "no EOAM intervention" in late.reason
    # a frontal hit on an in-lane obstacle that is not the ARO (role other) counts as aro
    other = _classify(BRAKE_ONLY, 0.0, _hit("rear_end"), "other")
    assert (other.colour, other.collision_with) == ("yellow", "aro")


def test_red_head_on_or_oblique_with_oncoming_after_lane_change():
    out = _classify(PONR_PASSED, 3.3, _hit("head_on", "front", "front", 31.0), "oncoming")
    assert (out.colour, out.collision_with, out.impact_speed_mps) == ("red", "oncoming", 31.0)
    assert out.reason == "lane change, head-on with the oncoming vehicle at 31.0 m/s"
    oblique = _classify(PONR_PASSED, 2.4, _hit("oblique", "front", "front", 40.0), "oncoming")
    assert oblique.colour == "red" and "offset/oblique" in oblique.reason


def test_red_frontal_hit_on_oncoming_without_lane_change():
    out = _classify(ONCOMING_ABORT, 0.9, _hit("oblique", "front", "front", 35.0), "oncoming")
    assert (out.colour, out.collision_with) == ("red", "oncoming")


@pytest.mark.parametrize(
    ("hit", "role", "collision_with"),
    [
        (_hit("side", "left", "left", 50.0), "oncoming", "oncoming"),  # side swipe
        (_hit("side", "right", "left", 20.0), "aro", "aro"),  # cut back in too early
        (_hit("rear_end", "front", "rear", 6.0), "aro", "aro"),  # offset rear hit, lane change
        (_hit("side", "right", "left", 30.0), "parked", "parked"),
        (_hit("rear_end", "rear", "front", 3.0), "other", "aro"),  # hit from behind
    ],
)
def test_orange_any_other_contact_after_a_lane_change(hit, role, collision_with):
    out = _classify(LANE_CHANGE, 3.4, hit, role)
    assert (out.colour, out.collision_with, out.impact_speed_mps) == (
        "orange", collision_with, hit.impact_speed_mps,
    )
    assert out.reason.startswith("lane change, ")


def test_orange_side_contact_without_lane_change():
    out = _classify(ONCOMING_ABORT, 0.9, _hit("side", "left", "rear", 5.0), "aro")
    assert (out.colour, out.collision_with) == ("orange", "aro")
    back = _classify(BRAKE_ONLY, 0.0, _hit("rear_end", "rear", "front", 4.0), "other")
    assert back.colour == "orange"  # the ego hit from behind is not a frontal hit


def test_point_of_no_return_threshold_separates_yellow_from_orange():
    hit = _hit("rear_end", speed=9.0)
    assert _classify(ONCOMING_ABORT, PONR_M - 1e-6, hit, "aro").colour == "yellow"
    assert _classify(PONR_PASSED, PONR_M, hit, "aro").colour == "orange"
    assert _classify(PONR_PASSED, -PONR_M, hit, "aro").colour == "orange"  # |d| counts
    loose = OutcomeSettings(point_of_no_return_fraction=0.5)
    assert classify_outcome(
        ONCOMING_ABORT, 1.5, LANE_M, hit, "aro", settings=loose
    ).colour == "yellow"


# --- from real box geometry to a colour ---------------------------------------------------


def test_contacts_from_geometry():
    ego = OrientedBox(0.0, 0.0, 0.0, *EGO)
    aro = OrientedBox(0.5 * EGO[0] + 0.5 * ARO[0] - 0.01, 0.2, 0.0, *ARO)
    rear = contact(ego, aro, (12.0, 0.0), (0.0, 0.0))
    out = _classify(ONCOMING_ABORT, 0.4, rear, role_of(_body(aro.x_m, aro.y_m, 0, 0), ROAD, 3.5))
    assert (out.colour, out.collision_with, out.impact_speed_mps) == ("yellow", "aro", 12.0)

    ego_left = OrientedBox(0.0, LANE_M, 0.05, *EGO)
    onc = OrientedBox(0.5 * EGO[0] + 0.5 * CAR[0] - 0.01, LANE_M, math.pi, *CAR)
    head_on = contact(ego_left, onc, (25.0, 0.0), (-20.0, 0.0))
    role = role_of(_body(onc.x_m, onc.y_m, onc.yaw_rad, 20.0), ROAD, LANE_M)
    out = _classify(PONR_PASSED, 3.5, head_on, role)
    assert (out.colour, out.collision_with) == ("red", "oncoming")
    assert out.impact_speed_mps == pytest.approx(45.0)


# --- validation and invariants ------------------------------------------------------------


def test_bad_inputs():
    with pytest.raises(ValueError, match="modes_visited"):
        _classify([0, 7], 0.0)
    with pytest.raises(ValueError, match="role"):
        _classify(BRAKE_ONLY, 0.0, _hit("rear_end"), "none")
    with pytest.raises(ValueError, match="max_lateral_offset_m"):
        _classify(BRAKE_ONLY, math.nan)
    with pytest.raises(ValueError, match="lane_width_m"):
        classify_outcome([0], 0.0, 0.0)
    with pytest.raises(ValueError, match="point_of_no_return_fraction"):
        OutcomeSettings(point_of_no_return_fraction=0.0)
    with pytest.raises(ValueError, match="in_lane_tolerance_m"):
        OutcomeSettings(in_lane_tolerance_m=-1.0)


contacts = st.one_of(
    st.none(),
    st.builds(
        Contact,
        st.sampled_from(("head_on", "rear_end", "side", "oblique")),
        st.sampled_from(("front", "rear", "left", "right")),
        st.sampled_from(("front", "rear", "left", "right")),
        st.floats(0.0, 80.0),
        st.just((0.0, 0.0)),
    ),
)


@settings(max_examples=300, deadline=None, database=None)
@given(
    st.lists(st.integers(0, 5), min_size=1, max_size=6, unique=True),
    st.floats(-5.0, 5.0),
    contacts,
    st.sampled_from(("aro", "oncoming", "parked", "other")),
    st.floats(-5.0, 5.0),
    st.floats(0.0, 50.0),
)
def test_invariants(modes, max_offset, hit, role, final_offset, final_speed):
    out = _classify(modes, max_offset, hit, role if hit else "none", final_offset, final_speed)
    assert out.colour in COLOURS and out.reason
    if hit is None:
        assert out.collision_with == "none" and out.impact_speed_mps == 0.0
        assert out.colour == ("none" if set(modes) == {0} else "green")
    else:
        assert out.colour in ("yellow", "orange", "red")
        assert out.collision_with == ("aro" if role == "other" else role)
        assert out.impact_speed_mps == hit.impact_speed_mps
        assert (out.colour == "red") == (role == "oncoming" and hit.kind in ("head_on", "oblique"))
        if abs(max_offset) >= PONR_M and 3 not in modes:
            assert out.colour != "yellow"


def test_aborted_steer_that_drifts_past_the_ponr_is_still_limit_braking():
    """Mode 3 (oncoming seen before the PONR) then a front hit on the ARO: yellow."""
    hit = Contact("rear_end", "front", "rear", 9.0, (0.0, 0.0))
    out = classify_outcome([0, 1, 2, 3], 1.6, 3.5, hit, "aro")
    assert out.colour == "yellow" and "limit braking" in out.reason

