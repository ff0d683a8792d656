"""A protocol's rows from its test points and their run summaries: colour, points, R152
verdict, and the totals per test. Pure: plain dicts, no SUMO, no pandas."""

from __future__ import annotations

import math

from eoam_sumo.protocols import rules
from eoam_sumo.protocols.points import PROTOCOLS, TestPoint

#: Why a point is not run: its VUT speed is below the lookup tables' speeds.
OUTSIDE_DESIGN = (
    "outside the design range: VUT speed {v:g} km/h is below the lookup tables' lowest "
    "entry speed {low:g} km/h (offline/design.py speeds_kmh); the run is refused"
)
#: colour of a point whose VUT speed the bands have no row for (not in the totals)
NO_BAND = "no_band"
EDITION = {
    PROTOCOLS[0]: "AEB C2C 2023 (4.3.1) grid; scored with the 2026 FC v1.2 sec. 5.2 bands "
    "(the 2023 assessment protocol's bands are not held)",
    PROTOCOLS[1]: "Crash Avoidance FC 2026 (v1.2), rating code " + rules.RATING_2026,
    PROTOCOLS[2]: rules.R152 + " (M1, dry road; the mass-in-running-order column)",
}


def point_row(point: TestPoint, impact_speed_kmh: float | None, note: str = "") -> dict:
    """One results row of a point: its parameters, impact speed, colour and points (R152:
    verdict). ``impact_speed_kmh`` None: the point did not run, ``note`` says why."""
    row = {
        "protocol": point.protocol,
        "test": point.test,
        "ego_speed_kmh": point.ego_speed_kmh,
        "target_speed_kmh": point.target_speed_kmh,
        "overlap": point.overlap,
        "gap_m": point.gap_m,
        "target_decel_mps2": point.target_decel_mps2,
        "target_offset_m": point.offset_m,
        "range": "extended" if point.extended else "standard",
        "policy_side": point.policy,
        "impact_speed_kmh": impact_speed_kmh,
    }
    if impact_speed_kmh is None:
        return {
            **row,
            "colour": rules.NOT_RUN,
            "points": 0.0,
            "max_points": 1.0,
            "verdict": "",
            "note": note,
        }
    if point.protocol == PROTOCOLS[2]:
        verdict, reason = _r152(point, impact_speed_kmh)
        return {
            **row,
            "colour": "",
            "points": math.nan,
            "max_points": math.nan,
            "verdict": verdict,
            "note": reason,
        }
    try:
        colour = _colour(point, impact_speed_kmh)
    except ValueError as exc:  # a 2023 speed (25, 35, 45 km/h) the 2026 bands have no row for
        return {
            **row,
            "colour": NO_BAND,
            "points": math.nan,
            "max_points": math.nan,
            "verdict": "",
            "note": f"not scored: {exc} (the 2026 table's rows are 10, 20, 30, 40, 50+ km/h)",
        }
    points = rules.cell_points(colour, point.extended)
    return {
        **row,
        "colour": colour,
        "points": points,
        "max_points": 1.0,
        "verdict": "",
        "note": note,
    }


def _r152(point: TestPoint, impact_speed_kmh: float) -> tuple[str, str]:
    """(verdict, reason) of an R152 row against its limit (``rules.R152_LIMITS_KMH``); the
    reason names the table's maximum-mass limit too."""
    target = point.test.removeprefix("R152-")
    rel = point.ego_speed_kmh - point.target_speed_kmh
    verdict, reason = rules.r152_verdict(rules.R152_LIMITS_KMH.get((target, rel)), impact_speed_kmh)
    table = rules.R152_M1_TABLE_KMH.get(rel)
    if table is not None:
        reason += f" (relative speed {rel:g} km/h; maximum mass: {table[0]:g} km/h allowed)"
    return verdict, reason


def _colour(point: TestPoint, impact_speed_kmh: float) -> str:
    """The point's colour; a head-on point avoided altogether is green (our reading: the
    published mitigation bands are on the speed reduction of a collision)."""
    if point.head_on and impact_speed_kmh <= 0.0:
        return rules.GREEN
    if point.head_on:
        ego_at_impact = max(impact_speed_kmh - point.target_speed_kmh, 0.0)
        return rules.ncap_colour(point.test, point.ego_speed_kmh, ego_at_impact)
    return rules.ncap_colour(point.test, point.ego_speed_kmh, impact_speed_kmh)


#: Why a head-on point the EOAM never reacted to fails (a finding for eoam/** and sensing/**,
#: not fixed here): the radar classes a road user driving towards the ego as ``oncoming``,
#: never as the in-path obstacle (sensing/radar.py ``classify``), and the EOAM intervenes on
#: an in-path obstacle only; the oncoming flag alone starts no manoeuvre.
NO_TRIGGER_ONCOMING = (
    "the EOAM never reacted: the radar classes a car driving towards the ego as oncoming, "
    "never as the in-path obstacle, and the EOAM intervenes on an in-path obstacle only"
)
NO_TRIGGER = "the EOAM never reacted (no trigger: the obstacle was never in its path)"


def failure_cause(row: dict) -> str:
    """Why a point falls short of full marks, in one line: the scoring's note, then the
    cause (a run that failed, an EOAM that never reacted), then the run's own account."""
    if row.get("status") == "failed":
        return "the run failed: " + str(row.get("error") or "")
    parts = [str(row["note"])] if row.get("note") else []
    if row.get("status") == "ok" and str(row.get("modes_visited")) == "0":
        parts.append(NO_TRIGGER_ONCOMING if str(row["test"]).startswith("CCFho") else NO_TRIGGER)
    reason = row.get("reason")
    if isinstance(reason, str) and reason:
        parts.append("run: " + reason)
    return "; ".join(parts)


def totals(rows: list[dict]) -> list[dict]:
    """Points per test (per policy side) and overall: the ranges' weights times their cells'
    mean points (``rules.test_score``); R152 rows are counted by verdict instead."""
    groups: dict[tuple[str, str], list[dict]] = {}
    for row in rows:
        groups.setdefault((row["test"], row["policy_side"]), []).append(row)
    out = []
    for (test, side), own in groups.items():
        if test in rules.TOTAL_SCORES:
            cells = [(r["points"], r["range"] == "extended") for r in own if r["colour"] != NO_BAND]
            score = rules.test_score(test, cells)
            out.append(
                {
                    "test": test,
                    "policy_side": side,
                    "points": score.total,
                    "max_points": score.max_total,
                    "rows": len(own),
                }
            )
        else:
            verdicts = [r["verdict"] or rules.NOT_RUN for r in own]
            out.append(
                {
                    "test": test,
                    "policy_side": side,
                    "points": math.nan,
                    "max_points": math.nan,
                    "rows": len(own),
                    **{v: verdicts.count(v) for v in sorted(set(verdicts))},
                }
            )
    return out
