"""The protocols' scoring as a reviewer checks it, on hand-made rows (no SUMO): a --points
subset scored against the whole protocol, a run off the dry road labelled off-protocol, the
warning lead at exactly 0.8 s, the totals rounded as the rating code rounds them, the points
short of full marks, the vehicle column, a failed R152 run, the unscored 2023 edition, the
head-on cells green only by our reading, and the R157 study's verdict and options."""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd
import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.protocols import rules, runner, scorecard, scoring
from eoam_sumo.protocols.impact import Measured, warning_lead_s
from eoam_sumo.protocols.points import PROTOCOLS, protocol_points
from eoam_sumo.r157 import command as r157_command

WIDTH_M = 1.85
NCAP23, NCAP26, R152 = PROTOCOLS


def _label(name: str, mu: float = 1.0) -> scorecard.RunLabel:
    return scorecard.RunLabel(name, "aeb", "paper", "sedan", mu, 5.0, WIDTH_M)


def _row_of(point, impact_kmh: float, ego_at_impact_kmh: float | None = None) -> dict:
    """A run of ``point`` that hit at ``impact_kmh`` (0: none), as results.csv holds it."""
    measured = Measured(impact_kmh > 0, impact_kmh, ego_at_impact_kmh, 1.0, True)
    row = scoring.point_row(point, measured, "", scoring.RunFacts(fcw_raised=True))
    return {**row, "point_id": point.point_id, "status": "ok", "modes_visited": "0-1"}


def _markdown(rows: list[dict], run: scorecard.RunLabel) -> str:
    return scorecard.scorecard_markdown(pd.DataFrame(rows), run)


def _totals_line(markdown: str, test: str) -> str:
    return next(line for line in markdown.splitlines() if line.startswith(f"| {test} |"))


# 1. a --points subset is scored against the whole protocol


def test_a_points_subset_is_scored_against_the_whole_protocol():
    ccrs80 = [p for p in protocol_points(NCAP26, WIDTH_M) if p.point_id.startswith("CCRs_v80")]
    md = _markdown([_row_of(p, 0.0) for p in ccrs80], _label(NCAP26))
    assert "Partial run: 7 of the protocol's 274 points selected (--points)" in md
    # 5 of the 40 standard cells green, 2 of the 16 extended (12.5 %: banded to 0)
    assert "| CCRs | 7 / 56 | 0.150 of 1.200 | 0.000 of 0.150 |" in md
    assert "**FC gate FAILED**" in md and "CCRs_v10" in md
    assert "Overall, system aeb, policy paper: 0.000 of 11.500" in md


def test_a_subset_without_extended_cells_keeps_the_extended_maximum():
    score = rules.test_score("CCRb", [(1.0, True)])
    assert (score.max_standard, score.max_extended) == (1.6, 0.2)
    assert rules.test_score("CCRs", [(1.0, False)]).max_extended == 0.15


def test_the_summary_line_names_a_partial_run():
    line = runner.ProtocolSummary(7, 7, 0, 0, 274).line(Path("out"))
    assert line.startswith("partial run: 7 of the protocol's 274 points selected (--points)")
    assert "partial" not in runner.ProtocolSummary(274, 274, 0, 0, 274).line(Path("o"))


# 2. a run off the dry road is labelled off-protocol


@pytest.mark.parametrize("name", [NCAP26, R152, NCAP23])
def test_a_run_off_the_dry_road_is_labelled_off_protocol(name):
    assert scoring.edition(name, 1.0) == scoring.EDITION[name]
    text = scoring.edition(name, 0.1)
    assert "not a protocol condition; figures only" in text and "dry road;" not in text
    assert "friction 0.1" in text


def test_r152_rows_off_the_dry_road_are_no_regulation_verdicts():
    point = protocol_points(R152, WIDTH_M)[-1]  # stationary 60 km/h
    rows = [_row_of(point, 50.0)]
    off = _markdown(rows, _label(R152, 0.1))
    assert "off-protocol: not R152 verdicts" in off and "M1, dry road" not in off
    assert "off-protocol" not in _markdown(rows, _label(R152, 1.0))
    line = runner.ProtocolSummary(19, 19, 0, 0, 19, rules.OFF_PROTOCOL.format(mu=0.3)).line(
        Path("o")
    )
    assert line.startswith("friction 0.3: not a protocol condition; figures only")


# 4. a warning exactly 0.8 s ahead passes


def test_a_warning_lead_of_exactly_0_8_s_passes():
    lead = warning_lead_s([3.41, 4.21], [True, True], [0, 1])
    assert lead != 0.8  # 0.7999999999999998: the difference of the time stamps
    assert rules.r152_warning(True, lead, True)[0] == rules.PASS
    for hundredths in range(100, 2000):
        t = hundredths / 100
        lead = warning_lead_s([t, round(t + 0.8, 2)], [True, True], [0, 1])
        assert rules.r152_warning(True, lead, True)[0] == rules.PASS, t
    late = warning_lead_s([3.42, 4.21], [True, True], [0, 1])
    assert rules.r152_warning(True, late, True)[0] == rules.FAIL


# 5. totals rounded half-up to 3 decimals, as the rating code does


def test_totals_are_rounded_half_up_as_the_rating_code_does():
    rows = []
    for p in protocol_points(NCAP26, WIDTH_M):
        if p.test == "CCRs" and not p.extended:
            brown = p.ego_speed_kmh == 30 and p.overlap == 50
            rows.append(_row_of(p, 5.0 if brown or p.ego_speed_kmh < 30 else 40.0))
    # one brown cell (0.25) of 40: 1.2 x 0.25 / 40 = 0.0075, f"{:.3f}" gives 0.007
    assert "| 0.008 of 1.200 |" in _totals_line(_markdown(rows, _label(NCAP26)), "CCRs")


# 6. the points short of full marks are those below their maximum


def test_an_extended_cell_with_full_points_is_not_short_of_full_marks():
    points = protocol_points(NCAP26, WIDTH_M)
    extended = next(p for p in points if p.test == "CCRm" and p.extended and p.ego_speed_kmh >= 50)
    standard = next(
        p for p in points if p.test == "CCRm" and not p.extended and p.ego_speed_kmh >= 50
    )
    rows = [_row_of(extended, 15.0), _row_of(standard, 15.0)]  # orange both
    assert rows[0]["points"] == 1.0 and rows[1]["points"] == 0.5
    md = _markdown(rows, _label(NCAP26))
    assert "## Points short of full marks (1)" in md
    assert f"| {standard.point_id} |" in md and f"| {extended.point_id} |" not in md


# 7. and 8. the vehicle column; a failed R152 run is a fail, not "not run"


def test_every_row_of_results_csv_names_its_vehicle(tmp_path):
    points = protocol_points(R152, WIDTH_M)[:2]
    label = scorecard.RunLabel(R152, "aeb", "paper", "suv, ABS on", 1.0, 100.0, WIDTH_M, "suv")
    frame = runner.results_frame(points, pd.DataFrame({"case_id": []}), label, tmp_path)
    assert list(frame["vehicle"]) == ["suv", "suv"]


def test_a_failed_r152_run_fails_its_row(tmp_path):
    point = protocol_points(R152, WIDTH_M)[0]
    run = {"status": "failed", "error": "SUMO died", "case_dir": "cases/x"}
    row = runner._row(point, run, _label(R152), tmp_path)
    assert (row["verdict"], row["status"]) == (rules.FAIL, "failed")
    counts = scoring.verdict_counts([row])[0]
    assert counts.get("fail") == 1 and "not_run" not in counts


# 10. the unscored 2023 edition claims no full marks


def test_the_unscored_2023_scorecard_lists_the_contacts():
    head_on = [p for p in protocol_points(NCAP23, WIDTH_M) if p.head_on]
    rows = [_row_of(p, 60.0, 20.0) for p in head_on]
    md = _markdown(rows, _label(NCAP23))
    assert "No point short of full marks" not in md
    assert f"## Runs with a contact or that failed (unscored; {len(head_on)})" in md


# 11. the head-on cells green only by our reading


def test_the_edition_does_not_claim_the_rating_codes_head_on_bands():
    assert "red in the rating code" in scoring.EDITION[NCAP26]
    point = next(p for p in protocol_points(NCAP26, WIDTH_M) if p.test == "CCFhos")
    row = _row_of(point, 60.0, point.ego_speed_kmh - 40.0)  # a reduction of 40 km/h
    assert row["colour"] == rules.GREEN  # our reading; the rating code: red
    md = _markdown([row], _label(NCAP26))
    assert "Head-on cells green only by our reading" in md and "the rating code: red): 1." in md


# 3. and 9. the R157 study: a verdict only with both drivers; a speed given twice refused


@pytest.mark.parametrize("drivers", [["r157-cc"], ["fsm", "rss"], ["eoam"]])
def test_the_r157_verdict_needs_the_eoam_and_the_careful_driver(drivers):
    lines = r157_command.verdict_lines("deceleration", [60.0], drivers, [])
    assert len(lines) == 1 and "not compared" in lines[0] and "0 points" not in lines[0]
    both = r157_command.verdict_lines("deceleration", [60.0, 100.0], ["eoam", "r157-cc"], [])
    assert (
        both[0] == "deceleration 60 km/h: the EOAM hits where the careful driver avoids at 0 points"
    )


@pytest.mark.parametrize(
    ("speeds", "drivers"), [("60,60", "eoam,r157-cc"), ("60,100,60.0", "eoam"), ("60", "eoam,eoam")]
)
def test_a_speed_or_driver_given_twice_is_refused(speeds, drivers):
    with pytest.raises(InputError, match="given twice"):
        r157_command._parse(argparse.Namespace(speeds_kmh=speeds, drivers=drivers))


def test_a_collision_without_warning_or_braking_fails_the_warning():
    """Para. 5.2.1.1 asks a warning before a collision: a run that neither warned nor braked
    and hit passed the warning ("no emergency braking, no warning required")."""
    assert rules.r152_warning(False, None, False, collided=True)[0] == rules.FAIL
    assert rules.r152_warning(True, None, False, collided=True)[0] == rules.PASS
    assert rules.r152_warning(False, None, False, collided=False)[0] == rules.PASS
    (point,) = [p for p in protocol_points(R152, WIDTH_M) if "stationary_v30_" in p.point_id]
    measured = Measured(True, 30.0, 30.0, None, False)
    row = scoring.point_row(point, measured, "", scoring.RunFacts(fcw_raised=False))
    assert (row["verdict"], row["warning"]) == (rules.FAIL, rules.FAIL)


def test_points_are_selected_by_the_tests_own_name_and_r152_partial_runs_say_verdicts():
    """The ids write "R152-stationary" as "R152mstationary": --points 'R152-stationary_v10'
    matched nothing; a partial R152 run said 'not the protocol's score' (2026's rule)."""
    from eoam_sumo.protocols.command import named

    r152 = protocol_points(R152, WIDTH_M)
    chosen = [p for p in r152 if named(p).startswith("R152-stationary_v10_")]
    assert len(chosen) == 1 and chosen[0].point_id.startswith("R152mstationary_v10_")
    line = runner.ProtocolSummary(1, 1, 0, 0, 19, scored=False).line(Path("out"))
    assert "the verdicts are of the points run" in line and "protocol's score" not in line


def test_every_row_says_whether_its_run_was_on_the_protocols_road():
    """Rows of a run off the dry road carried verdicts and colours with nothing in results.csv
    saying they are figures only."""
    (point,) = [p for p in protocol_points(R152, WIDTH_M) if "stationary_v30_" in p.point_id]
    for mu, on in ((1.0, True), (0.2, False)):
        row = runner._row(point, None, _label(R152, mu), Path("out"))
        assert row["on_protocol"] is on
        assert list(runner.results_frame([point], pd.DataFrame(), _label(R152, mu), Path("o")))[
            :6
        ] == ["point_id", "protocol", "system", "policy", "vehicle", "on_protocol"]
