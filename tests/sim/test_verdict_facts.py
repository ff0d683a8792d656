"""The verdict as a pure function of a run's facts, built by hand (no SUMO): the colour, the
severity of the contact and the summary's fields."""

from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import replace

import pytest

from eoam_sumo.sim.facts import RunFacts, RunInfo
from eoam_sumo.sim.severity import ContactRecord
from eoam_sumo.sim.summary import FIELDS
from eoam_sumo.sim.verdict import outcome_of, severity_of, summarise
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import OrientedBox, contact

LANE_M = 3.5
EGO_MASS_KG = 1723.0
EGO = (4.92, 1.85)  # length, width [m]
LIMIT_BRAKING = (0, 1, 3)
LANE_CHANGE = (0, 1, 2, 5, 0)
POLICY = {
    "policy": "paper",
    "v2x_range_m": 0.0,
    "v2x_latency_s": 0.1,
    "v2x_loss": 0.0,
    "v2x_penetration": 1.0,
    "sight_gate": "",
    "sight_needed_m": None,
    "sight_known_free_m": None,
    "sight_time_s": None,
    "tie_break": "",
}
INFO = RunInfo(
    mu_belief="known",
    driver="eoam",
    policy_record=POLICY,
    radar_model="ideal",
    seed=0,
    vehicle="E-class sedan",
    abs_fitted=False,
    esc_fitted=False,
    radar_range_m=100.0,
    radar_fov_deg=18.0,
    net_file="/tmp/road.net.xml",
    sumo_overrides={},
    wall_time_s=2.0,
    loop_wall_s=0.5,
)


def _facts(**kw) -> RunFacts:
    return RunFacts(
        lane_width_m=LANE_M,
        left_lane=True,
        ego_mass_kg=EGO_MASS_KG,
        **{"modes_visited": (0,), **kw},
    )


def _record(other: Body, role: str, ego_speed_mps: float, ego_yaw_rad: float = 0.0):
    """The contact of the ego (centre at the origin, heading ``ego_yaw_rad``) with ``other``."""
    ego = OrientedBox(0.0, 0.0, ego_yaw_rad, *EGO)
    ve = (ego_speed_mps * math.cos(ego_yaw_rad), ego_speed_mps * math.sin(ego_yaw_rad))
    vb = (other.speed_mps * math.cos(other.yaw_rad), other.speed_mps * math.sin(other.yaw_rad))
    hit = contact(ego, other.box, ve, vb)
    assert hit is not None
    return ContactRecord(hit, role, 12.5, other, ego, other.box)


def _ahead(dx_m: float, dy_m: float = 0.0, yaw_rad: float = 0.0, speed_mps: float = 0.0) -> Body:
    """A 4.7 x 1.8 m car whose centre is ``dx_m`` ahead of the ego's and ``dy_m`` left."""
    return Body("car", "passenger", dx_m, dy_m, yaw_rad, speed_mps, 4.7, 1.8)


TOUCHING_M = 0.5 * (EGO[0] + 4.7) - 0.01  # centres this far apart: the boxes overlap by 1 cm


def test_a_square_hit_on_the_aro_after_limit_braking_is_yellow_with_its_delta_v():
    record = _record(_ahead(TOUCHING_M), "aro", ego_speed_mps=8.0)
    facts = _facts(
        modes_visited=LIMIT_BRAKING,
        max_abs_offset_m=0.2,
        contact=record,
        contact_sumo_mass_kg=1500.0,
        end_cause="contact",
    )
    severity = severity_of(facts)
    assert severity is not None and severity.direct_overlap == 1.0
    assert outcome_of(facts).colour == "yellow"
    summary = summarise(facts, INFO)
    assert (summary.outcome, summary.collision_with, summary.contact_kind) == (
        "yellow",
        "aro",
        "rear_end",
    )
    # plastic impact: the ego loses m_other / (m_ego + m_other) of the closing speed
    assert summary.delta_v_ego_mps == pytest.approx(8.0 * 1500.0 / (1500.0 + EGO_MASS_KG))
    assert summary.collision_with_mass_kg == 1500.0 and summary.contact_time_s == 12.5
    assert summary.near_miss is False  # a contact is never a near miss


def test_a_reference_driver_s_braking_is_named_for_the_driver_not_the_dmm():
    record = _record(_ahead(TOUCHING_M), "aro", ego_speed_mps=8.0)
    facts = _facts(
        modes_visited=(0, 1),
        contact=record,
        contact_sumo_mass_kg=1500.0,
        end_cause="contact",
    )
    eoam = summarise(facts, INFO)
    careful = summarise(facts, replace(INFO, driver="r157-cc"))
    assert "chosen by the DMM" in eoam.reason and eoam.driver == "eoam"
    assert careful.driver == "r157-cc" and "DMM" not in careful.reason
    assert "braking by the r157-cc reference driver" in careful.reason
    assert careful.outcome == eoam.outcome == "yellow"  # the same facts, the same colour
    idle = summarise(replace(facts, modes_visited=(0,)), replace(INFO, driver="rss"))
    assert idle.reason.startswith("no intervention by the rss reference driver")


def test_an_offset_hit_on_the_aro_after_limit_braking_is_orange():
    # 1.5 m to the left: the car's right side at 0.6 m, the ego's left at 0.925 m
    record = _record(_ahead(TOUCHING_M, 1.5), "aro", ego_speed_mps=8.0)
    facts = _facts(modes_visited=LIMIT_BRAKING, contact=record, contact_sumo_mass_kg=1500.0)
    severity = severity_of(facts)
    assert severity is not None
    assert severity.direct_overlap == pytest.approx(0.325 / 1.8)  # of the narrower width
    out = outcome_of(facts)
    assert out.colour == "orange" and "offset front hit" in out.reason


def test_a_lane_change_ending_head_on_with_oncoming_traffic_is_red():
    oncoming = _ahead(TOUCHING_M, yaw_rad=math.pi, speed_mps=20.0)
    facts = _facts(
        modes_visited=(0, 1, 2, 4),
        max_abs_offset_m=LANE_M,
        max_offset_m=LANE_M,
        final_offset_m=LANE_M,
        contact=_record(oncoming, "oncoming", ego_speed_mps=25.0),
        contact_sumo_mass_kg=1500.0,
        end_cause="contact",
    )
    out = outcome_of(facts)
    assert (out.colour, out.collision_with) == ("red", "oncoming")
    assert out.impact_speed_mps == pytest.approx(45.0)
    assert summarise(facts, INFO).impact_angle_rad == pytest.approx(math.pi)


def test_a_completed_lane_change_without_contact_is_green():
    facts = _facts(
        modes_visited=LANE_CHANGE,
        max_abs_offset_m=3.6,
        max_offset_m=3.6,
        final_offset_m=0.1,
        final_speed_mps=30.0,
        passed_obstacle=True,
    )
    summary = summarise(facts, INFO)
    assert summary.outcome == "green" and summary.collision_with == "none"
    assert summary.reason == "lane change completed, returned to lane, no contact"
    assert summary.contact_kind == "none" and summary.delta_v_ego_mps is None
    # returning behind the obstacle: green, but not a completed lane change
    behind = summarise(replace(facts, passed_obstacle=False), INFO)
    assert behind.outcome == "green" and "not completed" in behind.reason


def test_leaving_the_road_without_contact_is_orange():
    # the centre 3 m right of the lane centre: 1.25 m beyond the right edge of a 3.5 m lane
    facts = _facts(modes_visited=(0, 1), min_offset_m=-3.0, max_abs_offset_m=3.0)
    summary = summarise(facts, INFO)
    assert summary.outcome == "orange" and summary.left_road is True
    assert "left the road" in summary.reason and "right edge" in summary.reason
    # the same offset to the left stays on a road with a lane there, not on one without
    left = _facts(modes_visited=(0, 1), max_offset_m=3.0, max_abs_offset_m=3.0)
    assert summarise(left, INFO).left_road is False
    assert summarise(replace(left, left_lane=False), INFO).outcome == "orange"


def test_a_run_cut_off_in_the_other_lane_is_unfinished():
    facts = _facts(
        modes_visited=(0, 1, 2),
        max_abs_offset_m=3.6,
        final_offset_m=2.4,
        manoeuvre_running=True,
        end_cause="time_limit",
    )
    out = outcome_of(facts)
    assert out.colour == "unfinished" and "time limit" in out.reason
    assert outcome_of(replace(facts, end_cause="road_end")).reason.endswith(
        "end of the road with the ego +2.4 m from its lane centre and a manoeuvre still running"
    )


def test_no_manoeuvre_is_none_and_the_summary_has_every_field_in_order():
    facts = _facts(near_miss_margins=True, sim_time_s=3.0, min_gap_oncoming_m=4.25)
    summary = summarise(facts, INFO)
    assert summary.outcome == "none" and summary.near_miss is True
    assert tuple(summary.as_dict()) == FIELDS
    assert summary.min_gap_aro_m is None and summary.min_gap_oncoming_m == 4.25
    assert summary.realtime_factor == 6.0 and summary.wall_time_s == 2.0
    assert summary.trigger_time_s is None and summary.trigger_range_m is None


def test_the_trigger_is_rounded_and_an_unseen_obstacle_has_no_range():
    seen = _facts(
        modes_visited=LIMIT_BRAKING,
        trigger_time_s=12.3456789,
        trigger_range_m=41.00000049,
        mu_believed_at_trigger=0.7,
    )
    summary = summarise(seen, INFO)
    assert (summary.trigger_time_s, summary.trigger_range_m) == (12.345679, 41.0)
    assert summary.mu_believed_at_trigger == 0.7
    assert summarise(replace(seen, trigger_range_m=math.nan), INFO).trigger_range_m is None


def test_the_verdict_imports_nothing_of_sumo():
    code = (
        "import sys, eoam_sumo.sim.verdict, eoam_sumo.sim.outcome; "
        "bad = [m for m in sys.modules if m.startswith(('eoam_sumo.sim.session', 'libsumo', "
        "'traci', 'sumolib', 'eoam_sumo.sensing.radar', 'eoam_sumo.sim.cosim'))]; "
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
