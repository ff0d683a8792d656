"""The scorecard of a protocol run (scorecard.md): edition, system and policy, totals per test
with the FC gate and the maxima, the tests not built with their points at stake, points not
run, and every point short of full marks with its cause."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd

from eoam_sumo.protocols import rules, scoring
from eoam_sumo.protocols.points import PROTOCOLS, protocol_points


@dataclass(frozen=True)
class RunLabel:
    """What a protocol run was: its name, system, policy, vehicle, friction, the design
    range's lowest speed [km/h] and the VUT's width [m]."""

    name: str
    system: str
    policy: str
    vehicle: str
    mu: float
    low_kmh: float
    width_m: float
    vehicle_id: str = "sedan"

    @property
    def title(self) -> str:
        ours = " (our extension, not the protocol's score)" if self.system == "eoam" else ""
        off = "" if rules.on_protocol_surface(self.mu) else f", off-protocol (mu {self.mu:g})"
        return f"{self.name}, system {self.system}{ours}, policy {self.policy}{off}"

    def matrix(self) -> list:
        """Every test point of the protocol (for this VUT's width)."""
        return protocol_points(self.name, self.width_m)


#: What the head-on sources say and what we did (the scorecard prints it)
CCFHOS_TEXT = (
    "CCFhos and CCFhol bands: the rating code scores the VUT's speed reduction (v_reduction) "
    "with mitigation_scenarios_thresholds: <= 10 km/h red, <= 20 orange, <= 30 green, above "
    "30 red (FC v1.2 Figure 5-2, not held here). Read literally a full stop at 50/50 would "
    "score red like no reaction; we score a reduction above 30 km/h green, and a run without "
    "contact green, so the points never fall as the reduction grows.\n\n"
    "CCFhol: the rating code gives it CCFhos's matrix (8 rows x 4 impact locations, the same "
    "extended cells); its row speeds are not held, so we run CCFhos's rows. The target pulls "
    "out from behind an obstruction vehicle and changes lanes along Vector's 2023 path "
    "(3.5 m over 43 m at 50 km/h, 60 m at 70 km/h, the 70 km/h path stretched above) to end "
    "at its impact location at a TTC of 1.5 s (docs/protocols.md)."
)


def scorecard_markdown(frame: pd.DataFrame, run: RunLabel) -> str:
    """The whole scorecard of one system and one policy."""
    rows = frame.to_dict("records")
    lines = [
        f"# Scorecard: {run.title}",
        "",
        f"Edition: {scoring.edition(run.name, run.mu)}.",
        "",
        *partial_lines(rows, run),
        f"System {scoring.SYSTEM_TEXT[run.system]}.",
        "",
        f"Vehicle {run.vehicle}, friction {run.mu:g}, decision policy {run.policy}. Colours, "
        "points, B/S (braked / steered) per point in results.csv; docs/protocols.md.",
        "",
        manoeuvre_line(rows) + ".",
        "",
    ]
    if run.name == PROTOCOLS[1]:
        scored = scoring.with_unselected(rows, run.matrix())
        lines += fc_lines(scored, run) + not_built_lines() + [CCFHOS_TEXT, ""]
        lines += our_reading_lines(scored)
    elif run.name == PROTOCOLS[2]:
        lines += r152_lines(rows, run)
    else:
        lines += unscored_lines(rows)
    lines += not_run_lines(rows, run)
    lines += contact_lines(rows) if run.name == PROTOCOLS[0] else short_lines(rows)
    return "\n".join(lines) + "\n"


def partial_lines(rows: list[dict], run: RunLabel) -> list[str]:
    """A ``--points`` subset: how many of the protocol's points ran, and how it is scored."""
    total = len(run.matrix())
    if len(rows) >= total:
        return []
    effect = {
        PROTOCOLS[1]: "the totals below count the points not selected as not run (0 points, "
        "in the maximum) and the FC gate fails without its cells: not the protocol's score",
        PROTOCOLS[2]: "the verdicts below are those of the rows run, not the regulation's",
    }.get(run.name, "the runs below are those selected")
    return [
        f"**Partial run: {len(rows)} of the protocol's {total} points selected (--points)**; "
        f"{effect}.",
        "",
    ]


def _pts(value: float) -> str:
    """A score as the rating code reports it: rounded half-up to 3 decimals (RATING_2026
    compute_score.py ``get_updated_dfs``: scenario, category and test scores)."""
    return f"{rules.round_half_up(value, 3):.3f}"


def manoeuvre_line(rows: list[dict]) -> str:
    """What the runs did: braked in lane (B), steered (S), never intervened (-)."""
    marks = [r["manoeuvre"] for r in rows if r["status"] == "ok"]
    return (
        f"Manoeuvres of the {len(marks)} runs: B (braked in lane) {marks.count('B')}, "
        f"S (steered) {marks.count('S')}, - (never intervened) {marks.count('-')}"
    )


def fc_lines(rows: list[dict], run: RunLabel) -> list[str]:
    """The 2026 totals per test, the FC gate and the overall line of this system and policy."""
    t = scoring.fc_totals(rows)
    lines = [
        f"## Totals: system {run.system}, policy {run.policy}",
        "",
        "| test | points run / rows | standard | extended (banded) | robustness | points | of |",
        "|---|---|---|---|---|---|---|",
    ]
    lines += [
        f"| {x['test']} | {x['run']} / {x['rows']} | {_pts(x['standard'])} of "
        f"{_pts(x['max_standard'])} | {_pts(x['extended'])} of {_pts(x['max_extended'])} | "
        f"not assessed, 0 of {_pts(x['max_robustness'])} | {_pts(x['points'])} | "
        f"{_pts(x['max_points'])} |"
        for x in t["tests"]
    ]
    gate = "passed" if t["gate_passed"] else "FAILED"
    lines += [
        "",
        f"**FC gate {gate}** (rating code `check_general_requirements_rules`: every Frontal "
        "Collision point is 0 unless every standard-range CCRs cell at 10 and 20 km/h is "
        "green; its general-requirement and pedestrian (CPNA) conditions are not assessed "
        "here)." + ("" if t["gate_passed"] else f" Failing: {', '.join(t['gate_failing'])}."),
        "",
        f"**Overall, system {run.system}, policy {run.policy}: {_pts(t['points'])} of "
        f"{_pts(t['max_run'])}** for the tests run ({_pts(t['points_before_gate'])} before "
        f"the gate); the protocol's car-target Frontal Collision maximum is "
        f"{_pts(t['max_protocol'])} (the tests not built below hold the rest).",
        "",
    ]
    return lines


def not_built_lines() -> list[str]:
    """Every car test of the 2026 protocol not built here, its weight and why."""
    lines = [
        "## Tests not built (points at stake)",
        "",
        "| test | standard / extended / robustness | at stake | why |",
        "|---|---|---|---|",
    ]
    for test, why in scoring.NOT_BUILT.items():
        w = rules.TOTAL_SCORES[test]
        lines.append(
            f"| {test} (FC) | {w['standard']:g} / {w['extended']:g} / {w['robustness']:g} | "
            f"{rules.weight_total(test):g} | {why} |"
        )
    for test, why in scoring.NOT_BUILT_LSC.items():
        lines.append(
            f"| {test} (Low Speed Collisions) | {rules.LSC_CAR_SCORES[test]:g} / - / - | "
            f"{rules.LSC_CAR_SCORES[test]:g} | {why} |"
        )
    lines += [_ptw_line(test, why) for test, why in scoring.NOT_BUILT_PTW.items()]
    return [
        *lines,
        "",
        "The car-target tests count in the protocol's maximum above; the motorcycle-target "
        "tests of the same Car & PTW subelement do not.",
        "",
    ]


def _ptw_line(test: str, why: str) -> str:
    """A motorcycle-target test's row: FC weights, or the LSC one (SfS)."""
    if test in rules.LSC_PTW_SCORES:
        w = rules.LSC_PTW_SCORES[test]
        return f"| {test} (Low Speed Collisions, motorcycle) | {w:g} / - / - | {w:g} | {why} |"
    parts = rules.PTW_SCORES[test]
    return (
        f"| {test} (FC, motorcycle) | {parts['standard']:g} / {parts['extended']:g} / "
        f"{parts['robustness']:g} | {sum(parts.values()):g} | {why} |"
    )


def r152_lines(rows: list[dict], run: RunLabel) -> list[str]:
    """R152 verdicts per target: pass / fail, and the warning's; off the dry road (para.
    5.2.1.4's test conditions) the rows against the table, no regulation verdict."""
    head = "Verdicts"
    if not rules.on_protocol_surface(run.mu):
        head = f"Rows against the table at mu {run.mu:g} (off-protocol: not R152 verdicts)"
    lines = [
        f"## {head} (pass: speed within the table, lane kept, warning >= 0.8 s before the braking)",
        "",
        "| test | rows | pass | fail | undetermined | not run | warning pass | warning fail |",
        "|---|---|---|---|---|---|---|---|",
    ]
    lines += [
        f"| {c['test']} | {c['rows']} | {c.get('pass', 0)} | {c.get('fail', 0)} | "
        f"{c.get('undetermined', 0)} | {c.get('not_run', 0)} | {c['warning_pass']} | "
        f"{c['warning_fail']} |"
        for c in scoring.verdict_counts(rows)
    ]
    return [*lines, "", rules.R152_WARNING_SOURCE, ""]


def unscored_lines(rows: list[dict]) -> list[str]:
    """2023: per test the rows run and those avoided (no points: the bands are not held)."""
    lines = ["## Runs (unscored)", "", "| test | rows | run | no contact |", "|---|---|---|---|"]
    for test in dict.fromkeys(r["test"] for r in rows):
        own = [r for r in rows if r["test"] == test]
        ran = [r for r in own if r["colour"] != rules.NOT_RUN]
        avoided = sum(r["impact_speed_kmh"] == 0.0 for r in ran)
        lines.append(f"| {test} | {len(own)} | {len(ran)} | {avoided} |")
    return [
        *lines,
        "",
        "Not built for 2023: CCFtap (its 2023 weight is not held; "
        "docs/protocols.md, tests not built).",
        "",
    ]


def not_run_lines(rows: list[dict], run: RunLabel) -> list[str]:
    """The points below the design range, and what that does to the score."""
    out = [r for r in rows if r["status"] == "not_run"]
    if not out:
        return []
    effect = {
        PROTOCOLS[1]: "They score 0 and count in the maximum; a standard CCRs cell at 10 km/h "
        "not run is not green, so the FC gate fails",
        PROTOCOLS[2]: "Their verdict is not_run (neither pass nor fail)",
    }.get(run.name, "They are listed, unscored like the rest of the edition")
    ids = ", ".join(r["point_id"] for r in out)
    return [
        f"## Not run: below the design range ({len(out)} points)",
        "",
        f"The design range starts at {run.low_kmh:g} km/h: a run below it is "
        f"refused. {effect}: {ids}.",
        "",
    ]


def _short(row: dict) -> bool:
    """The point is short of full marks: its run failed, its points are below its maximum
    (an extended cell scores 1 unless red, whatever its colour), or (R152) it does not pass."""
    if row["status"] == "failed" or row["verdict"] in (rules.FAIL, rules.UNDETERMINED):
        return True
    points, most = row["points"], row["max_points"]
    scored = row["status"] == "ok" and row["colour"] in rules.COLOURS
    return scored and not math.isnan(points) and points < most


def short_lines(rows: list[dict]) -> list[str]:
    """Every point short of full marks (R152: every row that does not pass), with its cause."""
    bad = [r for r in rows if _short(r)]
    if not bad:
        return ["No point short of full marks among those run.", ""]
    r152 = str(bad[0]["test"]).startswith("R152")
    lines = [
        f"## {'Rows that do not pass' if r152 else 'Points short of full marks'} ({len(bad)})",
        "",
        "| point | impact km/h | reduction km/h | B/S | colour / verdict | cause |",
        "|---|---|---|---|---|---|",
    ]
    lines += [
        f"| {r['point_id']} | {_num(r['impact_speed_kmh'])} | "
        f"{_num(r['speed_reduction_kmh'])} | {r['manoeuvre']} | {r['colour'] or r['verdict']} "
        f"| {scoring.failure_cause(r)} |"
        for r in bad
    ]
    return [*lines, ""]


def contact_lines(rows: list[dict]) -> list[str]:
    """2023 (unscored): every run with a contact, or that failed; no claim of full marks."""
    hit = [
        r
        for r in rows
        if r["status"] == "failed"
        or (r["status"] == "ok" and _num(r["impact_speed_kmh"]) != "0.00")
    ]
    if not hit:
        return ["No contact among the runs (unscored: no points are given).", ""]
    lines = [
        f"## Runs with a contact or that failed (unscored; {len(hit)})",
        "",
        "| point | impact km/h | reduction km/h | B/S | cause |",
        "|---|---|---|---|---|",
    ]
    lines += [
        f"| {r['point_id']} | {_num(r['impact_speed_kmh'])} | {_num(r['speed_reduction_kmh'])} "
        f"| {r['manoeuvre']} | {scoring.failure_cause(r)} |"
        for r in hit
    ]
    return [*lines, ""]


def our_reading_lines(rows: list[dict]) -> list[str]:
    """The head-on cells green only by our reading above 30 km/h of speed reduction, and the
    total the rating code's bands (red there) would give."""
    ours = [r for r in rows if _above_top_band(r)]
    if not ours:
        return []
    as_rated = [
        {**r, "colour": rules.RED, "points": rules.cell_points(rules.RED, r["range"] == "extended")}
        if _above_top_band(r)
        else r
        for r in rows
    ]
    t = scoring.fc_totals(as_rated)
    return [
        f"Head-on cells green only by our reading (a speed reduction above 30 km/h; the rating "
        f"code: red): {len(ours)}. With the rating code's bands there the overall is "
        f"{_pts(t['points'])} ({_pts(t['points_before_gate'])} before the gate).",
        "",
    ]


def _above_top_band(row: dict) -> bool:
    """A head-on cell with a contact and a speed reduction above the top published band."""
    value = row.get("speed_reduction_kmh")
    if row["test"] not in ("CCFhos", "CCFhol") or value is None or _num(value) == "-":
        return False
    return float(value) > rules.MITIGATION_BANDS[-2][1]


def _num(value) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    return f"{float(value):.2f}"


def picture_headline(run: RunLabel, totals: dict, rows: list[dict]) -> str:
    """The picture's title: the run, and (2026) the overall points and the gate."""
    head = f"{run.title}; {run.vehicle}, mu {run.mu:g}\n{manoeuvre_line(rows)}"
    total = len(run.matrix())
    if len(rows) < total:
        head += f"\npartial run: {len(rows)} of {total} points (--points)"
    if not rules.on_protocol_surface(run.mu):
        head += "\nnot a protocol condition (not the dry road): figures only"
    if run.name == PROTOCOLS[0]:
        return head + "\nunscored: the 2023 bands are not held"
    if run.name != PROTOCOLS[1]:
        return (
            head + "\nR152 rows: pass needs the speed limit, the lane kept and the warning in time"
        )
    gate = "passed" if totals["gate_passed"] else "FAILED: every FC point 0"
    return (
        f"{head}\noverall {_pts(totals['points'])} of {_pts(totals['max_run'])} for the tests "
        f"run ({_pts(totals['points_before_gate'])} before the gate); FC gate {gate}; "
        f"protocol maximum {totals['max_protocol']:.0f}"
    )


def plot(frame: pd.DataFrame, path, run: RunLabel) -> None:
    """scorecard.png of the run (plotting.protocol_plots)."""
    from eoam_sumo.plotting.protocol_plots import plot_scorecard

    scored = run.name == PROTOCOLS[1]
    rows = frame.to_dict("records")
    totals = scoring.fc_totals(scoring.with_unselected(rows, run.matrix())) if scored else {}
    kind = {PROTOCOLS[0]: "unscored", PROTOCOLS[1]: "bands", PROTOCOLS[2]: "verdicts"}[run.name]
    headline = picture_headline(run, totals, rows)
    plot_scorecard(frame, path, headline, kind, totals, not_built_note(run))


def not_built_note(run: RunLabel) -> str:
    """The picture's list of the tests not built and their points at stake."""
    if run.name == PROTOCOLS[0]:
        return "Not built for 2023: CCFtap (a junction test; 2023 weights not held)."
    if run.name != PROTOCOLS[1]:
        return ""
    fc = [f"{t} {rules.weight_total(t):g}" for t in scoring.NOT_BUILT]
    lsc = [f"{t} {rules.LSC_CAR_SCORES[t]:g}" for t in scoring.NOT_BUILT_LSC]
    ptw = [f"{t} {sum(w.values()):g}" for t, w in rules.PTW_SCORES.items()]
    ptw += [f"{t} {w:g}" for t, w in rules.LSC_PTW_SCORES.items()]
    return (
        "Tests not built (points at stake):\n"
        f"Frontal Collisions: {', '.join(fc)}\n"
        f"Low Speed Collisions: {', '.join(lsc)}\n"
        f"Motorcycle target (not in the car maximum): {', '.join(ptw)}\n"
        "(junction tests: out of a highway EOAM's scope; the motorcycle target is not "
        "modelled; docs/protocols.md)\n"
        "Robustness layer: not assessed, 0 of its weight in every test"
    )
