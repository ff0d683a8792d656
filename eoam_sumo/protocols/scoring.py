"""A protocol's rows from its test points and their runs: colour, cell points, R152 verdict,
and the totals per test with the FC gate. Pure: plain dicts, no SUMO, no pandas."""

from __future__ import annotations

import math
from dataclasses import dataclass

from eoam_sumo.protocols import rules
from eoam_sumo.protocols.impact import Measured
from eoam_sumo.protocols.points import PROTOCOLS, TestPoint

#: Why a point is not run: its VUT speed is below the design range.
OUTSIDE_DESIGN = (
    "not run: below the design range (VUT speed {v:g} km/h, the design range starts at "
    "{low:g} km/h, offline/tables.py MIN_ENTRY_SPEED_KMH); it scores 0 and counts in the maximum"
)
#: colour of a point that ran but is not scored (the 2023 edition: its bands are not held)
UNSCORED = "unscored"
SYSTEMS = ("aeb", "eoam")
EDITION = {
    PROTOCOLS[0]: "AEB C2C 2023 (test protocol 4.3.1) grid, run unscored: the 2023 "
    "assessment protocol's bands and weights are not held (docs/protocols.md); its CCRs at "
    "55-80 km/h are FCW tests in Vector's set (CCRs_FCW_Variation_2023), recorded "
    "(fcw_raised) but not assessed",
    PROTOCOLS[1]: "Crash Avoidance FC 2026 (v1.2), scored as the rating code "
    + rules.RATING_2026
    + " computes it, but for CCFhos and CCFhol: a speed reduction above 30 km/h scores green "
    "here (our reading), red in the rating code (mitigation_scenarios_thresholds; below)",
    PROTOCOLS[2]: rules.R152 + " and 5.2.1.1 (M1, dry road; the mass-in-running-order column)",
}


def edition(name: str, mu: float) -> str:
    """The scorecard's edition line for a run at friction ``mu``: the protocol's own on its
    dry road (``rules.DRY_ROAD_MU`` or above), else its rules applied off-protocol (figures
    only: no rating, no regulation verdict)."""
    if rules.on_protocol_surface(mu):
        return EDITION[name]
    off = rules.OFF_PROTOCOL.format(mu=mu)
    if name == PROTOCOLS[1]:
        return (
            f"Crash Avoidance FC 2026 (v1.2): the bands and weights of the rating code "
            f"{rules.RATING_2026} (CCFhos and CCFhol above 30 km/h of speed reduction: our "
            f"reading, below) applied to runs at {off}"
        )
    if name == PROTOCOLS[2]:
        return f"{rules.R152}: its M1 table (mass in running order) applied to runs at {off}"
    return f"{EDITION[name]}; at {off}"


#: Note of a protocol point that ``--points`` left out (scored 0, as a point not run)
NOT_SELECTED = "not selected by --points: scores 0 and counts in the maximum, as not run"


def with_unselected(rows: list[dict], matrix: list[TestPoint]) -> list[dict]:
    """``rows`` and a not-run row for every point of the protocol's ``matrix`` they lack:
    the scoring of a ``--points`` subset against the whole protocol, by the rule for a point
    not run (0 points, in the maximum; a gate cell not run is not green: the gate fails)."""
    have = {r["point_id"] for r in rows}
    missing = [
        {**point_row(p, None, NOT_SELECTED), "point_id": p.point_id, "status": "not_selected"}
        for p in matrix
        if p.point_id not in have
    ]
    return [*rows, *missing]


SYSTEM_TEXT = {
    "aeb": "aeb: the EOAM with its lane change inhibited (it brakes in lane; the FCW is its "
    "warning): what the protocol scores",
    "eoam": "eoam: the EOAM with its evasive lane change (our extension, not an AEB; its "
    "points are reported beside the aeb ones, never as the protocol's)",
}


@dataclass(frozen=True)
class RunFacts:
    """What a run did beside its impact: steered (lane change or time in the next lane),
    left its lane or the road, raised the FCW."""

    steered: bool = False
    left_lane: bool = False
    fcw_raised: bool = False


def _base(point: TestPoint) -> dict:
    return {
        "protocol": point.protocol,
        "test": point.test,
        "ego_speed_kmh": point.ego_speed_kmh,
        "target_speed_kmh": point.target_speed_kmh,
        "overlap": point.overlap,
        "gap_m": point.gap_m,
        "target_decel_mps2": point.target_decel_mps2,
        "target_offset_m": point.offset_m,
        "range": "extended" if point.extended else "standard",
    }


def manoeuvre_mark(measured: Measured, facts: RunFacts) -> str:
    """B: the EOAM braked (in lane), S: it steered, -: it never intervened."""
    if facts.steered:
        return "S"
    return "B" if measured.braked else "-"


def point_row(
    point: TestPoint,
    measured: Measured | None,
    note: str = "",
    facts: RunFacts | None = None,
    failed: bool = False,
) -> dict:
    """One results row of a point: its parameters, the scored quantities, colour and cell
    points (R152: verdict). ``measured`` None: the point did not run, ``note`` says why;
    ``failed``: its run failed (R152: a row whose test did not complete is not a pass, so
    its verdict is fail; Euro NCAP: it scores 0 as a point not run)."""
    if measured is None:
        return _not_run_row(point, note, failed)
    row = _base(point)
    facts = facts or RunFacts()
    impact = rules.round_half_up(measured.impact_long_kmh, 2)
    reduction = None
    if measured.contact and measured.ego_speed_at_impact_kmh is not None:
        reduction = rules.round_half_up(point.ego_speed_kmh - measured.ego_speed_at_impact_kmh, 2)
    row |= {
        "impact_speed_kmh": impact,
        "speed_reduction_kmh": reduction,
        "manoeuvre": manoeuvre_mark(measured, facts),
        "warning_lead_s": None
        if measured.warning_lead_s is None
        else round(measured.warning_lead_s, 3),
    }
    if point.protocol == PROTOCOLS[2]:
        return {**row, **_r152(point, measured, facts), "colour": "", "points": math.nan}
    if point.protocol == PROTOCOLS[0]:
        fcw = (
            " (an FCW test in Vector's set)"
            if point.test == "CCRs" and point.ego_speed_kmh > 50
            else ""
        )
        return {
            **row,
            "colour": UNSCORED,
            "points": math.nan,
            "max_points": math.nan,
            "verdict": "",
            "warning": "",
            "note": note or f"unscored: the 2023 bands are not held{fcw}",
        }
    colour = _colour(point, measured)
    return {
        **row,
        "colour": colour,
        "points": rules.cell_points(colour, point.extended),
        "max_points": 1.0,
        "verdict": "",
        "warning": "",
        "note": note,
    }


def _not_run_row(point: TestPoint, note: str, failed: bool) -> dict:
    """The row of a point without a measurement: 0 points (in the maximum); R152 verdict
    not_run, or fail when its run failed."""
    r152 = point.protocol == PROTOCOLS[2]
    return {
        **_base(point),
        "impact_speed_kmh": None,
        "speed_reduction_kmh": None,
        "manoeuvre": "",
        "colour": rules.NOT_RUN,
        "points": 0.0,
        "max_points": 1.0,
        "verdict": (rules.FAIL if failed else rules.NOT_RUN) if r152 else "",
        "warning": "",
        "warning_lead_s": None,
        "note": note,
    }


def _colour(point: TestPoint, measured: Measured) -> str:
    """A head-on point: no contact green, else its speed reduction's band; a CCR point: the
    band of its longitudinal relative impact speed."""
    if point.head_on:
        if not measured.contact or measured.ego_speed_at_impact_kmh is None:
            return rules.GREEN
        reduction = point.ego_speed_kmh - measured.ego_speed_at_impact_kmh
        return rules.ncap_colour(point.test, point.ego_speed_kmh, reduction)
    return rules.ncap_colour(point.test, point.ego_speed_kmh, measured.impact_long_kmh)


def _r152(point: TestPoint, measured: Measured, facts: RunFacts) -> dict:
    """An R152 row's verdict: the speed (para. 5.2.1.4) on the longitudinal impact speed,
    the lane kept, the warning (para. 5.2.1.1); the row passes when all three do."""
    target = point.test.removeprefix("R152-")
    rel = point.ego_speed_kmh - point.target_speed_kmh
    impact = rules.round_half_up(measured.impact_long_kmh, 2) if measured.contact else 0.0
    speed, reason = rules.r152_verdict(rules.R152_LIMITS_KMH.get((target, rel)), impact)
    table = rules.R152_M1_TABLE_KMH.get(rel)
    if table is not None:
        reason += f" (relative speed {rel:g} km/h; maximum mass: {table[0]:g} km/h allowed)"
    warning, why = rules.r152_warning(
        facts.fcw_raised, measured.warning_lead_s, measured.braked, measured.contact
    )
    verdicts = [speed, warning]
    if facts.left_lane:
        verdicts.append(rules.FAIL)
        reason = "left its lane or the road (not a speed reduction by braking); " + reason
    verdict = next((v for v in (rules.FAIL, rules.UNDETERMINED) if v in verdicts), rules.PASS)
    return {
        "verdict": verdict,
        "warning": warning,
        "max_points": math.nan,
        "note": f"{reason}; warning: {why}",
    }


#: Why a point the EOAM never reacted to falls short (the run's own account follows).
NO_TRIGGER = "the EOAM never reacted (no mode other than 0 visited)"


def failure_cause(row: dict) -> str:
    """Why a point falls short of full marks, in one line: the scoring's note, then the
    cause (a run that failed, an EOAM that never reacted), then the run's own account."""
    if row.get("status") == "failed":
        return "the run failed: " + str(row.get("error") or "")
    parts = [str(row["note"])] if row.get("note") else []
    if row.get("status") == "ok" and str(row.get("modes_visited")) == "0":
        parts.append(NO_TRIGGER)
    reason = row.get("reason")
    if isinstance(reason, str) and reason:
        parts.append("run: " + reason)
    return "; ".join(parts)


#: The car-target FC tests not built here, and why (docs/protocols.md): test -> reason
NOT_BUILT = {
    "CCFtap": "a junction test (the VUT turns across an oncoming car): out of a highway "
    "EOAM's scope, no junction network here",
    "CCCscp": "a junction test (crossing straight paths): out of a highway EOAM's scope, no "
    "junction network here",
}
#: Low Speed Collisions car tests, starting from standstill (SfS): not built either
NOT_BUILT_LSC = {
    "CCCscp SfS": "junction, from standstill: out of scope (the EOAM works from 5 km/h)",
    "CCFtap SfS": "junction, from standstill: out of scope",
}
#: The motorcycle-target tests of the Car & PTW subelement (outside the car-target maximum)
NOT_BUILT_PTW = {
    "CMRs": "a motorcycle target (Euro NCAP's EMT) and its radar signature are not modelled",
    "CMRb": "as CMRs",
    "CMFtap": "a junction test with a motorcycle target: out of scope",
    "CMCscp": "a junction test with a motorcycle target: out of scope",
    "CMCscp SfS": "junction, from standstill, motorcycle target: out of scope",
    "CMFtap SfS": "junction, from standstill, motorcycle target: out of scope",
}


def per_test_totals(rows: list[dict]) -> list[dict]:
    """Per scored test: its ranges' points (extended banded), the maxima (the robustness
    layer not assessed: 0 of its weight, in the maximum), the rows and those run."""
    groups: dict[str, list[dict]] = {}
    for row in rows:
        groups.setdefault(row["test"], []).append(row)
    out = []
    for test, own in groups.items():
        if test not in rules.TOTAL_SCORES:
            continue
        score = rules.test_score(test, [(r["points"], r["range"] == "extended") for r in own])
        out.append(
            {
                "test": test,
                "rows": len(own),
                "run": sum(r["colour"] != rules.NOT_RUN for r in own),
                "standard": score.standard,
                "max_standard": score.max_standard,
                "extended": score.extended,
                "max_extended": score.max_extended,
                "max_robustness": score.max_robustness,
                "points": score.total,
                "max_points": score.max_total,
            }
        )
    return out


def fc_totals(rows: list[dict]) -> dict:
    """The protocol's totals for one system and policy: the tests, the FC gate, the points
    before and after it, the maximum of the tests run and of the car-target FC protocol."""
    tests = per_test_totals(rows)
    cells = [
        (r["test"], r["ego_speed_kmh"], r["range"] == "extended", r["colour"], r["point_id"])
        for r in rows
    ]
    passed, failing = rules.fc_gate(cells)
    before = sum(t["points"] for t in tests)
    return {
        "tests": tests,
        "gate_passed": passed,
        "gate_failing": failing,
        "points_before_gate": before,
        "points": before if passed else 0.0,
        "max_run": sum(t["max_points"] for t in tests),
        "max_protocol": rules.CAR_FC_MAX,
    }


def verdict_counts(rows: list[dict]) -> list[dict]:
    """R152: the verdicts per test (pass, fail, undetermined, not_run) and the warnings."""
    groups: dict[str, list[dict]] = {}
    for row in rows:
        groups.setdefault(row["test"], []).append(row)
    out = []
    for test, own in groups.items():
        verdicts = [r["verdict"] or rules.NOT_RUN for r in own]
        warnings = [r["warning"] for r in own if r["warning"]]
        out.append(
            {
                "test": test,
                "rows": len(own),
                **{v: verdicts.count(v) for v in sorted(set(verdicts))},
                "warning_pass": warnings.count(rules.PASS),
                "warning_fail": warnings.count(rules.FAIL),
            }
        )
    return out
