"""Outcome colours (docs/outcomes.md) and ground-truth roles, one test per rule."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.sim.outcome import (
    COLOURS,
    LOST_CONTROL_HEADING_RAD,
    REVERSING_SPEED_MPS,
    ROAD_EDGE_MARGIN_M,
    Outcome,
    OutcomeSettings,
    classify_outcome,
    left_road,
    road_departure,
    role_of,
)
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import Contact, OrientedBox, contact

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
    return Contact(kind, face_a, face_b, speed, (0.0, 0.0), (1.0, 0.0), speed)


def _classify(modes, max_offset, contact_=None, role="none", final_offset=0.0, final_speed=0.0):
    return classify_outcome(
        modes_visited=modes,
        max_lateral_offset_m=max_offset,
        lane_width_m=LANE_M,
        contact=contact_,
        role=role,
        final_offset_m=final_offset,
        final_speed_mps=final_speed,
    )


# --- roles --------------------------------------------------------------------------------


def _body(s_m, d_m, yaw_rad, speed_mps, dims=CAR):
    return Body("t", "passenger", s_m, d_m, yaw_rad, speed_mps, *dims)


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
        # against the road's direction: oncoming whatever its speed (a van at 1.5 m/s, a car
        # halted in the opposite lane), unless SUMO has it parked
        (_body(80.0, LANE_M, math.pi, 1.5), "oncoming"),
        (_body(80.0, LANE_M, math.pi, 0.0), "oncoming"),
        (Body("t", "passenger", 80.0, -4.15, math.pi, 0.0, *CAR, parked=True), "parked"),
        (_body(80.0, 0.0, math.pi, 1.3, (0.215, 0.478)), "oncoming"),  # a person walking at us
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


def test_cross_traffic_in_the_ego_lane_is_not_the_obstacle_unless_it_was():
    """A car crossing the ego's lane from the side at a junction (heading 80 deg off the
    road, 15 m/s) is another road user, not the ARO; the ARO that swerves across its lane
    stays the ARO, and a person walking across at 1.4 m/s is still the obstacle."""
    crossing = _body(80.0, 0.0, math.radians(80.0), 15.0)
    assert role_of(crossing, ROAD, LANE_M) == "other"
    assert role_of(crossing, ROAD, LANE_M, was_obstacle=True) == "aro"
    assert role_of(crossing, ROAD, LANE_M, in_lane_at_start=True) == "aro"
    assert role_of(_body(80.0, 0.0, math.pi / 2, 1.4, (0.215, 0.478)), ROAD, LANE_M) == "aro"
    assert role_of(_body(80.0, 0.0, math.radians(30.0), 15.0), ROAD, LANE_M) == "aro"


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
        "lane change aborted for limit braking (next lane not free before the point of no "
        "return: oncoming traffic or a standing car), front hit the ARO at 7.2 m/s"
    )


def test_the_reason_names_a_lane_change_begun_after_braking():
    """Modes 0-1-2 hit head on before the point of no return began a lane
    change; the reason must not read as limit braking chosen by the DMM."""
    out = _classify([0, 1, 2], 0.2, _hit("rear_end", speed=17.9), "aro")
    assert out.reason.startswith("lane change started but the point of no return not reached")
    braked = _classify([0, 1, 3], 0.0, _hit("rear_end", speed=7.2), "aro")
    assert braked.reason.startswith("limit braking chosen (next lane not free")


def test_the_reason_names_braking_for_another_obstacle_after_the_return():
    """Mode 5 hands over to 3 for a second obstacle in the lane the ego returned to: the
    reason says so, not that the next lane was found closed before the point of no return."""
    out = _classify([0, 1, 2, 5, 3], 0.1, _hit("rear_end", speed=9.0), "aro")
    assert out.colour == "yellow"
    assert out.reason.startswith(
        "lane change and return, then limit braking for another obstacle in the lane"
    )


def test_yellow_limit_braking_by_the_dmm_and_without_intervention():
    out = _classify(BRAKE_ONLY, 0.0, _hit("rear_end", speed=11.0), "aro")
    assert out.colour == "yellow" and "by the DMM" in out.reason
    late = _classify([0], 0.0, _hit("rear_end", speed=25.0), "aro")
    assert late.colour == "yellow" and "no EOAM intervention" in late.reason
    # a frontal hit on a road user that is not the ARO (role other) is yellow, with "other"
    other = _classify(BRAKE_ONLY, 0.0, _hit("rear_end"), "other")
    assert (other.colour, other.collision_with) == ("yellow", "other")


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
        (_hit("rear_end", "rear", "front", 3.0), "other", "other"),  # hit from behind
    ],
)
def test_orange_any_other_contact_after_a_lane_change(hit, role, collision_with):
    out = _classify(LANE_CHANGE, 3.4, hit, role)
    assert (out.colour, out.collision_with, out.impact_speed_mps) == (
        "orange",
        collision_with,
        hit.impact_speed_mps,
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
    assert (
        classify_outcome(ONCOMING_ABORT, 1.5, LANE_M, hit, "aro", settings=loose).colour == "yellow"
    )


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
        assert out.collision_with == role
        assert out.impact_speed_mps == hit.impact_speed_mps
        assert (out.colour == "red") == (role == "oncoming" and hit.kind in ("head_on", "oblique"))
        if abs(max_offset) >= PONR_M and 3 not in modes:
            assert out.colour != "yellow"


def test_aborted_steer_that_drifts_past_the_ponr_is_still_limit_braking():
    """Mode 3 (oncoming seen before the PONR) then a front hit on the ARO: yellow."""
    hit = Contact("rear_end", "front", "rear", 9.0, (0.0, 0.0), (1.0, 0.0), 9.0)
    out = classify_outcome([0, 1, 2, 3], 1.6, 3.5, hit, "aro")
    assert out.colour == "yellow" and "limit braking" in out.reason


# --- loss of control and road departure without contact (rule 1) ---------------------------

RIGHT_EDGE_M = -0.5 * LANE_M  # road frame of the ego lane: its right marker
LEFT_EDGE_M = 1.5 * LANE_M  # with one lane to the left
DEFAULTS = OutcomeSettings()


def _motion(
    modes=LANE_CHANGE,
    max_offset=3.6,
    hit=None,
    role="none",
    final_offset=0.0,
    final_speed=25.0,
    heading=0.1,
    min_speed=20.0,
    min_offset=-0.2,
    max_offset_d=None,
    left_width=LANE_M,
    lane_width=LANE_M,
    settings=DEFAULTS,
):
    return classify_outcome(
        modes,
        max_offset,
        lane_width,
        hit,
        role,
        final_offset,
        final_speed,
        settings,
        max_abs_heading_error_rad=heading,
        min_speed_mps=min_speed,
        min_offset_m=min_offset,
        max_offset_m=max_offset if max_offset_d is None else max_offset_d,
        left_width_m=left_width,
    )


def test_orange_spin_on_ice_without_contact():
    """A spin on a 0.05 ice patch, heading 2.2 rad off, vx -8 m/s, d 6.4 m on a two-lane
    road: orange, not green "lane change completed, returned to lane"."""
    out = _motion(
        max_offset=6.4,
        final_offset=0.2,
        final_speed=-8.0,
        heading=2.2,
        min_speed=-8.0,
        min_offset=-0.3,
    )
    assert (out.colour, out.collision_with, out.impact_speed_mps) == ("orange", "none", 0.0)
    assert out.reason == (
        "lane change, no contact; lost control: heading 2.20 rad (126 deg) off the road; "
        "went backwards (vx down to -8.0 m/s); left the road: centre 1.2 m beyond its left edge"
    )


def test_orange_heading_alone():
    out = _motion(heading=1.3)
    assert (out.colour, out.collision_with) == ("orange", "none")
    assert out.reason == (
        "lane change, no contact; lost control: heading 1.30 rad (74 deg) off the road"
    )
    assert _motion(heading=-1.3) == out  # |heading| counts
    assert _motion(heading=LOST_CONTROL_HEADING_RAD).colour == "green"
    assert _motion(heading=LOST_CONTROL_HEADING_RAD + 1e-9).colour == "orange"


def test_orange_going_backwards_alone():
    out = _classify(BRAKE_ONLY, 0.0, final_speed=-1.0)  # without the motion measures: green
    assert out.colour == "green" and "stopped" in out.reason
    out = _motion(BRAKE_ONLY, 0.0, final_speed=-1.0, heading=0.0, min_speed=-1.0, min_offset=0.0)
    assert (out.colour, out.collision_with) == ("orange", "none")
    assert out.reason == (
        "limit braking chosen by the DMM, no contact; went backwards (vx down to -1.0 m/s)"
    )
    assert _motion(min_speed=REVERSING_SPEED_MPS).colour == "green"
    assert _motion(min_speed=REVERSING_SPEED_MPS - 1e-9).colour == "orange"


def test_orange_left_the_road_to_the_right():
    out = _motion(min_offset=RIGHT_EDGE_M - 4.1)
    assert (out.colour, out.collision_with) == ("orange", "none")
    assert out.reason == (
        "lane change, no contact; left the road: centre 4.1 m beyond its right edge"
    )
    assert _motion(min_offset=RIGHT_EDGE_M - ROAD_EDGE_MARGIN_M).colour == "green"
    assert _motion(min_offset=RIGHT_EDGE_M - ROAD_EDGE_MARGIN_M - 1e-9).colour == "orange"


def test_orange_not_none_for_a_car_that_left_the_road_without_any_manoeuvre():
    """43 m off the road with the EOAM never triggered: orange, not ``none``."""
    out = _motion(
        [0],
        44.75,
        final_offset=-44.75,
        heading=0.4,
        min_speed=25.0,
        min_offset=RIGHT_EDGE_M - 43.0,
        max_offset_d=0.0,
    )
    assert (out.colour, out.collision_with) == ("orange", "none")
    assert out.reason == (
        "no EOAM intervention, no contact; left the road: centre 43.0 m beyond its right edge"
    )


def test_orange_left_the_road_to_the_left_depends_on_the_lane_there():
    beyond = LEFT_EDGE_M + ROAD_EDGE_MARGIN_M
    assert _motion(max_offset=beyond).colour == "green"
    out = _motion(max_offset=beyond + 0.3)
    assert out.colour == "orange"
    assert out.reason.endswith("left the road: centre 0.8 m beyond its left edge")
    # no lane to the left: the road ends at the ego lane's left marker
    lone = _motion([0, 1], 0.5 * LANE_M + 0.6, left_width=0.0, min_offset=0.0)
    assert lone.colour == "orange" and "0.6 m beyond its left edge" in lone.reason


@pytest.mark.parametrize(
    ("lane_width", "modes", "max_offset", "min_offset", "heading", "min_speed", "final_speed"),
    [
        # Table 2 extremes (no contact): largest heading 0.33 rad (55 km/h, mu 1.0), largest
        # d 3.76 m (165 km/h, mu 0.1), return overshoot -0.33 m, stops at vx 0
        (3.5, LANE_CHANGE, 3.21, 0.0, 0.333, 8.4, 12.9),
        (3.5, LANE_CHANGE, 3.755, -0.128, 0.033, 39.96, 39.96),
        (3.5, LANE_CHANGE, 3.567, -0.328, 0.118, 35.4, 39.7),
        (3.5, PONR_PASSED, 3.62, -0.26, 0.11, 33.3, 36.5),
        (3.5, BRAKE_ONLY, 0.0, 0.0, 0.0, 0.0, 0.0),
        (3.5, ONCOMING_ABORT, 0.9, 0.0, 0.05, 0.0, 0.0),
        # low-speed lane changes at the tables' 20 km/h floor (halted car, mu 1.0)
        (3.5, LANE_CHANGE, 3.3, -0.1, 0.53, 3.1, 5.5),
        (5.0, LANE_CHANGE, 5.0, -0.1, 0.70, 3.1, 5.5),
    ],
)
def test_normal_runs_stay_green(
    lane_width, modes, max_offset, min_offset, heading, min_speed, final_speed
):
    final_offset = 0.05
    old = classify_outcome(modes, max_offset, lane_width, None, "none", final_offset, final_speed)
    new = _motion(
        modes,
        max_offset,
        final_offset=final_offset,
        final_speed=final_speed,
        heading=heading,
        min_speed=min_speed,
        min_offset=min_offset,
        left_width=lane_width,
        lane_width=lane_width,
    )
    assert new == old and new.colour == "green"


def test_contact_keeps_the_contact_rules_after_a_loss_of_control():
    spin = {"heading": 2.5, "min_speed": -3.0, "min_offset": RIGHT_EDGE_M - 2.0}
    hit = _hit("rear_end", speed=9.0)
    assert _motion(BRAKE_ONLY, 0.0, hit, "aro", **spin) == _classify(BRAKE_ONLY, 0.0, hit, "aro")
    side = _hit("side", "left", "right", 12.0)
    out = _motion(LANE_CHANGE, 3.4, side, "parked", **spin)
    assert out == _classify(LANE_CHANGE, 3.4, side, "parked")
    assert (out.colour, out.collision_with) == ("orange", "parked")


def test_settings_move_the_thresholds():
    loose = OutcomeSettings(
        lost_control_heading_rad=3.0, reversing_speed_mps=-10.0, road_edge_margin_m=50.0
    )
    out = _motion(heading=2.2, min_speed=-8.0, min_offset=RIGHT_EDGE_M - 43.0, settings=loose)
    assert out.colour == "green"
    for bad in (
        {"lost_control_heading_rad": 0.0},
        {"reversing_speed_mps": 0.0},
        {"road_edge_margin_m": -0.1},
        {"lost_control_heading_rad": math.inf},
    ):
        with pytest.raises(ValueError, match=next(iter(bad))):
            OutcomeSettings(**bad)


def test_motion_inputs_are_checked():
    for kwargs in (
        {"heading": math.nan},
        {"min_speed": -math.inf},
        {"min_offset": math.nan},
        {"max_offset_d": math.inf},
    ):
        with pytest.raises(ValueError, match="must be finite"):
            _motion(**kwargs)
    with pytest.raises(ValueError, match="left_width_m"):
        _motion(left_width=-1.0)


def test_road_departure_and_left_road():
    assert road_departure(0.0, 0.0, LANE_M) == ("right", pytest.approx(-1.75))
    assert road_departure(-0.2, 3.6, LANE_M, LANE_M) == ("right", pytest.approx(-1.55))
    assert road_departure(-0.2, 5.5, LANE_M, LANE_M) == ("left", pytest.approx(0.25))
    assert road_departure(-6.0, 5.5, LANE_M, LANE_M) == ("right", pytest.approx(4.25))
    assert road_departure(0.0, 2.0, LANE_M) == ("left", pytest.approx(0.25))
    assert not left_road(-2.25, 5.75, LANE_M, LANE_M)  # exactly the margin on both sides
    assert left_road(-2.26, 0.0, LANE_M, LANE_M)
    assert left_road(0.0, 2.26, LANE_M)  # no lane to the left
    assert not left_road(-40.0, 0.0, LANE_M, settings=OutcomeSettings(road_edge_margin_m=40.0))


@settings(max_examples=300, deadline=None, database=None)
@given(
    st.lists(st.integers(0, 5), min_size=1, max_size=6, unique=True),
    contacts,
    st.sampled_from(("aro", "oncoming", "parked", "other")),
    st.floats(-10.0, 0.0),
    st.floats(0.0, 10.0),
    st.floats(-4.0, 4.0),
    st.floats(-10.0, 50.0),
    st.sampled_from((0.0, LANE_M)),
)
def test_motion_rule_invariants(
    modes, hit, role, min_offset, max_offset, heading, min_speed, left_width
):
    role = role if hit else "none"
    max_abs = max(max_offset, -min_offset)
    old = classify_outcome(modes, max_abs, LANE_M, hit, role, 0.0, max(min_speed, 0.0))
    new = classify_outcome(
        modes,
        max_abs,
        LANE_M,
        hit,
        role,
        0.0,
        max(min_speed, 0.0),
        max_abs_heading_error_rad=heading,
        min_speed_mps=min_speed,
        min_offset_m=min_offset,
        max_offset_m=max_offset,
        left_width_m=left_width,
    )
    off_road = (
        min_offset < RIGHT_EDGE_M - ROAD_EDGE_MARGIN_M
        or max_offset > 0.5 * LANE_M + left_width + ROAD_EDGE_MARGIN_M
    )
    lost = abs(heading) > LOST_CONTROL_HEADING_RAD or min_speed < REVERSING_SPEED_MPS
    assert off_road == left_road(min_offset, max_offset, LANE_M, left_width)
    if hit is not None or not (off_road or lost):
        assert new == old
    else:
        assert (new.colour, new.collision_with, new.impact_speed_mps) == ("orange", "none", 0.0)
        assert ("lost control" in new.reason) == (abs(heading) > LOST_CONTROL_HEADING_RAD)
        assert ("went backwards" in new.reason) == (min_speed < REVERSING_SPEED_MPS)
        assert ("left the road" in new.reason) == off_road
