"""What a run came to: the outcome colour and the typed summary, as pure functions of the run's
facts (``sim/facts.py``: ground truth of the first contact, the running extremes, the
margins, the obstacle a lane change avoided) and, for the summary, its set-up and wall times.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from eoam_sumo.sim.facts import RunFacts, RunInfo
from eoam_sumo.sim.outcome import (
    NEXT_LANE_CLOSED,
    Outcome,
    classify_outcome,
    driver_wording,
    left_road,
)
from eoam_sumo.sim.severity import Severity, contact_severity
from eoam_sumo.sim.summary import RunSummary, finite_or_none, rounded

#: How a run ended -> what cut it off, for the ``unfinished`` rule (None: the loop's rules).
CUT_OFF = {"time_limit": "time limit", "road_end": "end of the road"}


def severity_of(facts: RunFacts) -> Severity | None:
    """The severity of the first contact (None without one)."""
    record = facts.contact
    if record is None:
        return None
    return contact_severity(record, facts.ego_mass_kg, facts.contact_sumo_mass_kg)


def left_width_m(facts: RunFacts) -> float:
    """The road's width left of the ego's original lane: one lane width when a lane lies
    there (either direction), else 0 (``outcome.road_departure``)."""
    return facts.lane_width_m if facts.left_lane else 0.0


def outcome_of(facts: RunFacts) -> Outcome:
    """The outcome colour of a run by the rules of ``sim/outcome.py``."""
    record, severity = facts.contact, severity_of(facts)
    return classify_outcome(
        modes_visited=facts.modes_visited,
        max_lateral_offset_m=facts.max_abs_offset_m,
        lane_width_m=facts.lane_width_m,
        contact=record.contact if record else None,
        role=record.role if record else "none",
        final_offset_m=facts.final_offset_m,
        final_speed_mps=facts.final_speed_mps,
        max_abs_heading_error_rad=facts.max_abs_heading_error_rad,
        min_speed_mps=facts.min_speed_mps,
        min_offset_m=facts.min_offset_m,
        max_offset_m=facts.max_offset_m,
        left_width_m=left_width_m(facts),
        right_width_m=facts.right_width_m,
        direct_overlap=severity.direct_overlap if severity else 1.0,
        cut_off=CUT_OFF.get(facts.end_cause),
        manoeuvre_running=facts.manoeuvre_running,
        passed_obstacle=facts.passed_obstacle,
        rollover=rollover_of(facts),
    )


def rollover_of(facts: RunFacts) -> str | None:
    """What rolled the ego over and when, for the reason (None: it did not)."""
    if facts.rollover_time_s is None:
        return None
    return f"{facts.rollover_cause} at t={facts.rollover_time_s:.2f} s"


def summarise(facts: RunFacts, info: RunInfo) -> RunSummary:
    """The outcome and summary of a run (summary.json's fields: ``sim/summary.py``)."""
    return RunSummary(
        **_contact_fields(facts, named_cause(outcome_of(facts), info), severity_of(facts)),
        **_eoam_fields(facts, info),
        **_margin_fields(facts),
        **_motion_fields(facts),
        **_run_fields(facts, info),
    )


def named_cause(outcome: Outcome, info: RunInfo) -> Outcome:
    """The outcome with the decision policy's cause of a closed next lane, when it gave one,
    and what the ego's controller did in its own words (``outcome.driver_wording``)."""
    outcome = replace(outcome, reason=driver_wording(outcome.reason, info.driver))
    why = info.policy_record.get("sight_reason")
    if not why or NEXT_LANE_CLOSED not in outcome.reason:
        return outcome
    return replace(outcome, reason=outcome.reason.replace(NEXT_LANE_CLOSED, why))


def _contact_fields(facts: RunFacts, outcome: Outcome, severity: Severity | None) -> dict[str, Any]:
    """The outcome, what was hit, where, when and how hard."""
    record = facts.contact
    return {
        "outcome": outcome.colour,
        "collision_with": outcome.collision_with,
        "impact_speed_mps": rounded(outcome.impact_speed_mps),
        "contact_kind": record.contact.kind if record else "none",
        "contact_time_s": record.time_s if record else None,
        "contact_x_m": rounded(record.contact.point[0]) if record else None,
        "contact_y_m": rounded(record.contact.point[1]) if record else None,
        "collision_with_id": record.body.vid if record else None,
        "collision_with_class": record.body.vclass if record else None,
        "contact_overlap": rounded(severity.overlap) if severity else None,
        "impact_angle_rad": rounded(severity.impact_angle_rad) if severity else None,
        "delta_v_ego_mps": rounded(severity.delta_v_ego_mps) if severity else None,
        "collision_with_mass_kg": rounded(severity.other_mass_kg) if severity else None,
        "reason": outcome.reason,
    }


def _eoam_fields(facts: RunFacts, info: RunInfo) -> dict[str, Any]:
    """The EOAM's modes and warning, the friction, when it first acted, its policy."""
    t, rng = facts.trigger_time_s, facts.trigger_range_m
    return {
        "modes_visited": facts.modes_visited,
        "fcw_raised": facts.fcw_raised,
        "mu": facts.mu_start,
        "mu_belief": info.mu_belief,
        "trigger_time_s": None if t is None else round(t, 6),
        "trigger_range_m": round(rng, 6) if t is not None and math.isfinite(rng) else None,
        "mu_believed_at_trigger": facts.mu_believed_at_trigger,
        "driver": info.driver,
        **{k: v for k, v in info.policy_record.items() if k != "sight_reason"},
        "radar_model": info.radar_model,
        "seed": info.seed,
        "vehicle": info.vehicle,
        "abs_fitted": info.abs_fitted,
        "esc_fitted": info.esc_fitted,
    }


def _margin_fields(facts: RunFacts) -> dict[str, Any]:
    """How close the ego came (infinite margins are empty) and whether it passed the obstacle
    its lane change avoided."""
    return {
        "min_gap_aro_m": finite_or_none(facts.min_gap_aro_m),
        "min_gap_oncoming_m": finite_or_none(facts.min_gap_oncoming_m),
        "min_ttc_oncoming_s": finite_or_none(facts.min_ttc_oncoming_s),
        "time_in_opposite_lane_s": rounded(facts.time_in_opposite_lane_s),
        "near_miss": facts.contact is None and facts.near_miss_margins,
        "passed_obstacle": facts.passed_obstacle,
        "end_cause": facts.end_cause,
        "rollover_time_s": facts.rollover_time_s,
        "wheel_lift_time_s": facts.wheel_lift_time_s,
        "wheel_lift_tyre": facts.wheel_lift_tyre,
        "wheel_lift_ay_mps2": (
            None if facts.wheel_lift_time_s is None else rounded(facts.wheel_lift_ay_mps2)
        ),
        "min_tyre_load_n": finite_or_none(facts.min_tyre_load_n, 1),
    }


def _motion_fields(facts: RunFacts) -> dict[str, Any]:
    """The ego's extremes and end state, and whether it left the road."""
    return {
        "max_abs_lat_accel_mps2": rounded(facts.max_abs_lat_accel_mps2),
        "max_lateral_offset_m": rounded(facts.max_abs_offset_m),
        "final_lateral_offset_m": rounded(facts.final_offset_m),
        "final_speed_mps": rounded(facts.final_speed_mps),
        "min_speed_mps": rounded(facts.min_speed_mps),
        "max_abs_heading_error_rad": rounded(facts.max_abs_heading_error_rad),
        "left_road": left_road(
            facts.min_offset_m,
            facts.max_offset_m,
            facts.lane_width_m,
            left_width_m(facts),
            right_width_m=facts.right_width_m,
        ),
        "ego_initial_speed_mps": rounded(facts.ego_initial_speed_mps),
        "lane_width_m": rounded(facts.lane_width_m),
        "oncoming_traffic": facts.oncoming_traffic,
    }


def _run_fields(facts: RunFacts, info: RunInfo) -> dict[str, Any]:
    """The scenario, the radar's coverage, the simulated and wall times, SUMO's options, the
    time in the next lane."""
    return {
        "net_file": info.net_file,
        "radar_range_m": info.radar_range_m,
        "radar_fov_deg": info.radar_fov_deg,
        "sim_time_s": rounded(facts.sim_time_s),
        "wall_time_s": info.wall_time_s,
        "realtime_factor": facts.sim_time_s / info.loop_wall_s,
        "sumo_overrides": info.sumo_overrides,
        "time_in_next_lane_s": rounded(facts.time_in_next_lane_s),
        **_traffic_margin_fields(facts),
    }


def _traffic_margin_fields(facts: RunFacts) -> dict[str, Any]:
    """The margins along the lanes and to the traffic behind (``sim/margins.py``)."""
    return {
        "min_ttc_s": finite_or_none(facts.min_ttc_s),
        "min_ttc_rear_s": finite_or_none(facts.min_ttc_rear_s),
        "min_gap_rear_m": finite_or_none(facts.min_gap_rear_m),
        "max_drac_rear_mps2": rounded(facts.max_drac_rear_mps2),
        "max_follower_decel_mps2": rounded(facts.max_follower_decel_mps2),
        "follower_decel_id": facts.follower_decel_id,
    }
