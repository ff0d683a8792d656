"""Verdict rules and severity against closed forms: offset hits, unfinished runs, passing,
overlap, time to collision, delta-v from momentum exchange."""

from __future__ import annotations

import math

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from eoam_sumo.sim.outcome import DIRECT_HIT_MIN_OVERLAP, classify_outcome
from eoam_sumo.sim.severity import (
    BICYCLE_WITH_RIDER_KG,
    delta_v_mps,
    impact_angle_rad,
    road_user_mass_kg,
)
from eoam_sumo.world.geometry import Contact, OrientedBox, face_overlap, time_to_contact

LANE_M = 3.5
REAR_HIT = Contact("rear_end", "front", "rear", 20.0, (0.0, 0.0), (1.0, 0.0), 20.0)
BRAKED = [0, 1, 3]


def test_a_direct_rear_hit_after_limit_braking_is_yellow_an_offset_one_orange():
    direct = classify_outcome(
        BRAKED, 0.4, LANE_M, REAR_HIT, "aro", direct_overlap=DIRECT_HIT_MIN_OVERLAP
    )
    offset = classify_outcome(BRAKED, 0.4, LANE_M, REAR_HIT, "aro", direct_overlap=0.32)
    assert direct.colour == "yellow"
    assert offset.colour == "orange" and "offset front hit" in offset.reason
    assert "32 %" in offset.reason


@pytest.mark.parametrize(
    ("final_offset_m", "running", "colour"),
    [
        (2.4, False, "unfinished"),  # cut off 2.4 m into the opposite lane
        (0.1, True, "unfinished"),  # in lane, but the manoeuvre still under way
        (0.1, False, "green"),  # back in lane and done: the cut-off changed nothing
    ],
)
def test_a_run_cut_off_mid_manoeuvre_is_unfinished_never_green(final_offset_m, running, colour):
    out = classify_outcome(
        [0, 1, 2],
        3.6,
        LANE_M,
        final_offset_m=final_offset_m,
        final_speed_mps=30.0,
        cut_off="time limit",
        manoeuvre_running=running,
    )
    assert out.colour == colour
    if colour == "unfinished":
        assert "time limit" in out.reason and out.collision_with == "none"


def test_unfinished_needs_a_cut_off_and_a_manoeuvre():
    # the loop's own end (settled) is never unfinished; a run without any manoeuvre is none
    assert classify_outcome([0, 1, 2], 3.6, LANE_M, final_offset_m=2.4).colour == "green"
    assert (
        classify_outcome([0], 0.0, LANE_M, cut_off="time limit", manoeuvre_running=False).colour
        == "none"
    )


def test_returning_behind_the_obstacle_is_not_a_completed_lane_change():
    behind = classify_outcome(
        [0, 1, 2, 5], 3.6, LANE_M, final_offset_m=0.1, final_speed_mps=20.0, passed_obstacle=False
    )
    ahead = classify_outcome(
        [0, 1, 2, 5], 3.6, LANE_M, final_offset_m=0.1, final_speed_mps=20.0, passed_obstacle=True
    )
    assert behind.colour == "green" and "not completed" in behind.reason
    assert "behind the obstacle" in behind.reason
    assert ahead.reason == "lane change completed, returned to lane, no contact"


@pytest.mark.parametrize("passed", [True, False, None])
def test_a_stop_says_behind_the_obstacle_only_when_it_is(passed):
    """An aborted lane change ending stopped, in lane: "stopped behind the obstacle" unless
    the ego ended ahead of the obstacle it was avoiding (``passed_obstacle``: a person
    walking towards it who walked past, the ego past it)."""
    out = classify_outcome(
        [0, 1, 2, 3], 0.1, LANE_M, final_offset_m=0.0, final_speed_mps=0.0, passed_obstacle=passed
    )
    assert out.colour == "green"
    assert ("stopped behind the obstacle" in out.reason) == (passed is not True)
    assert ("past the obstacle" in out.reason) == (passed is True)


def _box(x, y, yaw=0.0, length=4.9, width=1.85):
    return OrientedBox(x, y, yaw, length, width)


@pytest.mark.parametrize(
    ("offset_m", "share"),
    [
        (0.0, 1.0),
        (0.925, 0.5),
        (0.5, (1.85 - 0.5) / 1.85),
        (-0.5, (1.85 - 0.5) / 1.85),
        (1.85, 0.0),
    ],
)
def test_front_overlap_is_the_share_of_the_ego_width_in_line(offset_m, share):
    ego = _box(0.0, 0.0)
    ahead = _box(4.9, offset_m)  # same width, rear touching the ego's front
    assert face_overlap(ego, ahead, "front") == pytest.approx(share, abs=1e-12)


def test_a_narrow_body_covers_its_width_of_the_ego_front():
    ego = _box(0.0, 0.0)
    person = OrientedBox(2.55, 0.0, math.pi, 0.215, 0.478)
    assert face_overlap(ego, person, "front") == pytest.approx(0.478 / 1.85)


def test_time_to_contact_of_a_head_on_is_gap_over_closing_speed():
    ego = _box(0.0, 0.0)
    onc = _box(104.9, 0.5, math.pi)  # 100 m between the fronts, half a width to the side
    ttc = time_to_contact(ego, onc, (30.0, 0.0), (-20.0, 0.0))
    assert ttc == pytest.approx(100.0 / 50.0)
    # in its own lane (3.5 m to the left) it never meets the ego
    beside = _box(104.9, 3.5, math.pi)
    assert time_to_contact(ego, beside, (30.0, 0.0), (-20.0, 0.0)) == math.inf
    assert time_to_contact(ego, _box(1.0, 0.0), (0.0, 0.0), (0.0, 0.0)) == 0.0
    assert time_to_contact(ego, onc, (30.0, 0.0), (-20.0, 0.0), horizon_s=1.0) == math.inf


@given(st.floats(0.5, 60.0), st.floats(-30.0, 30.0), st.floats(-3.0, 3.0))
@example(7.0, 0.0, 1.85)  # side by side, touching: within the contact tolerance on both sides
def test_time_to_contact_matches_stepping_the_boxes(closing, lateral_speed, offset_m):
    """Step both boxes in 1 ms steps: the first overlap is within one step of the TTC."""
    from eoam_sumo.world.geometry import boxes_overlap

    ego = _box(0.0, 0.0)
    other = _box(30.0, offset_m, math.pi)
    va, vb = (closing, lateral_speed * 0.1), (0.0, 0.0)
    ttc = time_to_contact(ego, other, va, vb)
    hit = next(
        (
            k * 1e-3
            for k in range(4000)
            if boxes_overlap(_box(va[0] * k * 1e-3, va[1] * k * 1e-3), other)
        ),
        math.inf,
    )
    if math.isinf(hit):
        assert ttc > 3.999 or math.isinf(ttc)
    else:
        assert ttc == pytest.approx(hit, abs=1.1e-3)


def test_delta_v_of_equal_masses_is_half_the_closing_speed():
    assert delta_v_mps(1500.0, 1500.0, 50.0) == pytest.approx(25.0)
    assert delta_v_mps(1723.0, 70.0, 20.0) == pytest.approx(20.0 * 70.0 / 1793.0)
    assert delta_v_mps(1723.0, 1500.0, -3.0) == 0.0  # separating: no exchange


@given(st.floats(50.0, 40000.0), st.floats(50.0, 40000.0), st.floats(0.0, 80.0))
def test_momentum_is_conserved_and_the_velocities_end_equal(m1, m2, v):
    dv1, dv2 = delta_v_mps(m1, m2, v), delta_v_mps(m2, m1, v)
    assert m1 * dv1 == pytest.approx(m2 * dv2, rel=1e-9)
    assert dv1 + dv2 == pytest.approx(v, rel=1e-9)  # plastic: no relative speed left


def test_impact_angle_and_masses():
    assert impact_angle_rad(0.0, math.pi) == pytest.approx(math.pi)
    assert impact_angle_rad(0.1, 0.1) == 0.0
    assert impact_angle_rad(3.0, -3.0) == pytest.approx(2 * math.pi - 6.0)
    assert road_user_mass_kg(10.0, "bicycle") == BICYCLE_WITH_RIDER_KG
    assert road_user_mass_kg(25.0, "bicycle") == 25.0  # a mass the vType sets is kept
    assert road_user_mass_kg(1500.0, "passenger") == 1500.0
    with pytest.raises(ValueError, match="masses"):
        delta_v_mps(0.0, 1.0, 1.0)


def test_a_direct_front_hit_after_a_lane_change_is_not_called_offset():
    """After a lane change a front hit is orange (rule 3) however squarely it lands; the
    reason called a 97 % hit "offset", which the docs keep for under 50 %."""
    lane_change = [0, 2]
    out = classify_outcome(lane_change, 2.0, LANE_M, REAR_HIT, "aro", direct_overlap=0.97)
    assert out.colour == "orange"
    assert "front hit the ARO (97 %" in out.reason and "offset" not in out.reason
