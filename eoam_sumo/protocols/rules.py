"""Scoring rules of the protocols: colour bands, points, weights, pass/fail. Pure: no SUMO,
no pandas.

Sources (cited per rule below):

- ``RATING_2026``: Euro NCAP's published rating code, github.com/Euro-NCAP/euroncap_rating_2026
  (Apache-2.0), commit 94b1035: ``crash_avoidance/matrix_processing.py`` (colour bands, cell
  points), ``crash_avoidance/data_model.py`` (weights, extended cells, score parameters),
  ``crash_avoidance/test_info.py`` (``compute_predicted_score``,
  ``apply_extended_range_bands``, the measured value rounded half-up to 2 decimals in
  ``compute_stage_score``), ``crash_avoidance/compute_score.py``
  (``check_general_requirements_rules``, the FC gate) and ``numeric.py`` (half-up rounding);
  they cite Crash Avoidance - Frontal Collisions (FC) protocol v1.2 sec. 5.2 (colour bands),
  Figure 5-2 (speed-reduction bands) and sec. 4.2.4 (tolerance).
- ``R152``: UN Regulation No. 152 (AEBS for M1 and N1), 00 series: the original text,
  E/ECE/TRANS/505/Rev.3/Add.151 (in force 22 Jan 2020; authentic text
  ECE/TRANS/WP.29/2019/61), and its Supplement 1, Add.151/Amend.1 (in force 25 Sep 2020;
  ECE/TRANS/WP.29/2020/9): para. 5.2.1.3 (speed range 10-60 km/h) and para. 5.2.1.4 (speed
  reduction by braking demand), table "Maximum relative impact speed (km/h) for M1 vehicles"
  (page 7 of both). Para. 5.2.1.1's warning lead (0.8 s before the start of emergency
  braking) is NOT verified against the authentic text: ``R152_WARNING_SOURCE`` says where it
  comes from. The 01-03 series are not held here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal

RATING_2026 = "Euro-NCAP/euroncap_rating_2026@94b1035"

GREEN, YELLOW, ORANGE, BROWN, RED = "green", "yellow", "orange", "brown", "red"
#: colour of a point not scored, and why (the scorecard names the reason)
NOT_RUN = "not_run"
COLOURS = (GREEN, YELLOW, ORANGE, BROWN, RED)

#: Colour bands of the "mitigation or avoidance" tests (CCRs, CCRm, CCRb) by VUT speed
#: [km/h] (VUT speeds of 50 and above use the 50 row): (colour, highest relative impact
#: speed [km/h] of the band), bands (-inf, t0], (t0, t1], ... . RATING_2026
#: matrix_processing.py ``ComputedTestPoint._compute_color_logic``
#: (``mitigation_or_avoidance_thresholds``), FC v1.2 sec. 5.2.
MITIGATION_OR_AVOIDANCE_BANDS: dict[float, tuple[tuple[str, float], ...]] = {
    10.0: ((GREEN, 0.0), (RED, math.inf)),
    20.0: ((GREEN, 0.0), (RED, math.inf)),
    30.0: ((GREEN, 0.0), (BROWN, 10.0), (RED, math.inf)),
    40.0: ((GREEN, 0.0), (ORANGE, 10.0), (BROWN, 20.0), (RED, math.inf)),
    50.0: ((GREEN, 0.0), (YELLOW, 10.0), (ORANGE, 20.0), (BROWN, 30.0), (RED, math.inf)),
}
#: Bands of the "mitigation" tests (CCFhos, CCFhol) on the VUT's speed *reduction* [km/h]
#: (score parameter ``v_reduction``): RATING_2026 ``mitigation_scenarios_thresholds`` (FC
#: v1.2 Figure 5-2), ascending upper bounds, as published: <= 10 red, <= 20 orange, <= 30
#: green, above 30 red.
MITIGATION_BANDS: tuple[tuple[str, float], ...] = (
    (RED, 10.0),
    (ORANGE, 20.0),
    (GREEN, 30.0),
    (RED, math.inf),
)
#: Our reading (the protocol's Figure 5-2 itself is not held): the published last band
#: scores a full stop at 50/50 (a 50 km/h reduction) red like no reaction at all, so a
#: larger reduction would score less. We score a reduction above 30 km/h green, like 20-30,
#: so the points never fall as the reduction grows; a run with no contact is green too.
MITIGATION_ABOVE_TOP_BAND = GREEN
#: Points of one standard-range cell by colour: RATING_2026 matrix_processing.py
#: ``TestPoint.predicted_score``; an extended-range cell scores 1 unless red.
STANDARD_POINTS = {GREEN: 1.0, YELLOW: 0.75, ORANGE: 0.5, BROWN: 0.25, RED: 0.0}
#: Weight of each test's standard, extended range and robustness layer [points]:
#: RATING_2026 data_model.py ``TOTAL_SCORES``, the car-target Frontal Collision tests.
TOTAL_SCORES = {
    "CCRs": {"standard": 1.2, "extended": 0.15, "robustness": 0.15},
    "CCRm": {"standard": 2.4, "extended": 0.3, "robustness": 0.3},
    "CCRb": {"standard": 1.6, "extended": 0.2, "robustness": 0.2},
    "CCFhos": {"standard": 2.0, "extended": 0.25, "robustness": 0.25},
    "CCFhol": {"standard": 2.0, "extended": 0.25, "robustness": 0.25},
    "CCFtap": {"standard": 4.0, "extended": 0.5, "robustness": 0.5},
    "CCCscp": {"standard": 6.0, "extended": 0.75, "robustness": 0.75},
}
#: Low Speed Collisions, car target (RATING_2026 ``TOTAL_SCORES``, standard range only)
LSC_CAR_SCORES = {"CCCscp SfS": 3.0, "CCFtap SfS": 1.0}
#: The motorcycle-target tests of the same "Car & PTW" subelement (RATING_2026 ``TOTAL_SCORES``):
#: Frontal Collisions standard / extended / robustness, and Low Speed Collisions (standard)
PTW_SCORES = {
    "CMRs": {"standard": 1.2, "extended": 0.15, "robustness": 0.15},
    "CMRb": {"standard": 1.6, "extended": 0.2, "robustness": 0.2},
    "CMFtap": {"standard": 4.0, "extended": 0.5, "robustness": 0.5},
    "CMCscp": {"standard": 6.0, "extended": 0.75, "robustness": 0.75},
}
LSC_PTW_SCORES = {"CMCscp SfS": 3.0, "CMFtap SfS": 3.0}


def weight_total(test: str) -> float:
    """A test's whole weight: standard + extended + robustness layer."""
    return sum(TOTAL_SCORES[test].values())


#: The car-target Frontal Collision maximum: the sum over its seven tests (24 points)
CAR_FC_MAX = sum(weight_total(t) for t in TOTAL_SCORES)
#: FC v1.2 sec. 4.2.4: 2 km/h on the impact speed, applied only when a *predicted* colour is
#: verified (RATING_2026 ``NCAP_TEST_CRITERIA_TO_TOLERANCE``). We predict nothing and measure
#: every point, so the colour is the band the impact speed falls in, no tolerance.
IMPACT_SPEED_TOLERANCE_KMH = 2.0


def band_colour(bands: tuple[tuple[str, float], ...], value: float) -> str:
    """The band ``value`` falls in: (-inf, t0] the first, (t0, t1] the next, ...
    (RATING_2026 ``get_band_color``)."""
    lower = -math.inf
    for colour, upper in sorted(bands, key=lambda b: b[1]):
        if lower < value <= upper:
            return colour
        lower = upper
    return bands[-1][0]


def bands_for_speed(ego_speed_kmh: float) -> tuple[tuple[str, float], ...]:
    """The mitigation-or-avoidance bands of a VUT speed (50 and above: the 50 row);
    ValueError for a speed the published table has no row for."""
    key = 50.0 if ego_speed_kmh >= 50.0 else float(ego_speed_kmh)
    if key not in MITIGATION_OR_AVOIDANCE_BANDS:
        raise ValueError(f"no colour bands for a VUT speed of {ego_speed_kmh:g} km/h")
    return MITIGATION_OR_AVOIDANCE_BANDS[key]


def round_half_up(value: float, ndigits: int) -> float:
    """``value`` rounded half-up (ties away from zero) to ``ndigits`` decimals, as Excel's
    ROUND and RATING_2026 ``numeric.round_half_up``: the exact binary value is first settled
    at 9 decimals, so a tie computed 1 ulp low still rounds up."""
    guard = Decimal(1).scaleb(-max(9, ndigits + 4))
    settled = Decimal(float(value)).quantize(guard, rounding=ROUND_HALF_UP)
    return float(settled.quantize(Decimal(1).scaleb(-ndigits), rounding=ROUND_HALF_UP))


def mitigation_colour(reduction_kmh: float) -> str:
    """Colour of a head-on point from the VUT's speed reduction: the published bands up to
    30 km/h, ``MITIGATION_ABOVE_TOP_BAND`` above (our reading, never falling)."""
    if reduction_kmh > MITIGATION_BANDS[-2][1]:
        return MITIGATION_ABOVE_TOP_BAND
    return band_colour(MITIGATION_BANDS, reduction_kmh)


def ncap_colour(test: str, ego_speed_kmh: float, value_kmh: float) -> str:
    """Colour of a measured point from its score parameter (RATING_2026
    ``NCAP_TEST_CRITERIA_TO_SCORE_PARAMETER``), rounded half-up to 0.01 km/h first
    (``compute_stage_score``): CCR tests the longitudinal relative impact speed
    (``v_rel_impact``), head-on tests the speed reduction (``v_reduction``)."""
    value = round_half_up(value_kmh, 2)
    if test in ("CCFhos", "CCFhol"):
        return mitigation_colour(value)
    return band_colour(bands_for_speed(ego_speed_kmh), value)


def cell_points(colour: str, extended: bool) -> float:
    """Points of one cell: standard range by colour, extended range 1 unless red; a point
    not run scores 0."""
    if colour not in COLOURS:
        return 0.0
    if extended:
        return 0.0 if colour == RED else 1.0
    return STANDARD_POINTS[colour]


def extended_band(score: float, total: float) -> float:
    """An extended-range score snapped to its band (RATING_2026 ``apply_extended_range_bands``):
    below 50 % of ``total`` 0, below 75 % half, below 100 % three quarters, else all; compared
    at 6 decimals so a score 1 ulp off an edge lands on it."""
    settled = round_half_up(score, 6)
    if settled < round_half_up(0.5 * total, 6):
        return 0.0
    if settled < round_half_up(0.75 * total, 6):
        return 0.5 * total
    if settled < total:
        return 0.75 * total
    return total


@dataclass(frozen=True)
class TestScore:
    """A test's points: standard range, extended range (banded), robustness layer (not
    assessed here: 0 of its weight)."""

    test: str
    standard: float
    extended: float
    max_standard: float
    max_extended: float
    max_robustness: float

    @property
    def total(self) -> float:
        return self.standard + self.extended

    @property
    def max_total(self) -> float:
        return self.max_standard + self.max_extended + self.max_robustness


def test_score(test: str, cells: list[tuple[float, bool]]) -> TestScore:
    """``cells``: (cell points, extended) of every point of a test, the points not run (or
    not selected) included with 0. Each range scores its weight times the mean of its cells'
    points (RATING_2026 ``compute_predicted_score``), the extended range then banded
    (``extended_band``); the maxima are the test's whole weights (``TOTAL_SCORES``)."""
    weights = TOTAL_SCORES[test]
    parts = {}
    for name, extended in (("standard", False), ("extended", True)):
        own = [p for p, ext in cells if ext == extended]
        parts[name] = weights[name] * sum(own) / len(own) if own else 0.0
    return TestScore(
        test,
        parts["standard"],
        extended_band(parts["extended"], weights["extended"]),
        weights["standard"],
        weights["extended"],
        weights["robustness"],
    )


#: The FC gate (RATING_2026 compute_score.py ``check_general_requirements_rules``): every
#: Frontal Collision point is 0 unless every standard-range CCRs cell at a VUT speed of at
#: most this is green (its other conditions: the two general requirements and the CPNA
#: day/night 75 % cell at 10 km/h, pedestrian tests this tool does not run).
FC_GATE_CCRS_MAX_KMH = 20.0


def fc_gate(cells: list[tuple[str, float, bool, str, str]]) -> tuple[bool, list[str]]:
    """(passed, the point ids that fail it) from (test, VUT speed, extended, colour, id)
    of every point; a point not run is not green, so it fails the gate."""
    bad = [
        pid
        for test, speed, extended, colour, pid in cells
        if test == "CCRs" and speed <= FC_GATE_CCRS_MAX_KMH and not extended and colour != GREEN
    ]
    return not bad, bad


R152 = "UN R152 00 series (Add.151 and its Supplement 1, Amend.1), para. 5.2.1.4"
#: R152 para. 5.2.1.4, M1 table: relative speed [km/h] -> largest relative impact speed
#: [km/h] at (maximum mass, mass in running order) ("laden", "unladen" in the original text),
#: the same for a stationary and a moving target (Supplement 1: one "Stationary/Moving"
#: column pair; the original's moving columns hold these values up to 40 km/h, "-" above).
R152_M1_TABLE_KMH: dict[float, tuple[float, float]] = {
    10.0: (0.0, 0.0),
    15.0: (0.0, 0.0),
    20.0: (0.0, 0.0),
    25.0: (0.0, 0.0),
    30.0: (0.0, 0.0),
    35.0: (0.0, 0.0),
    40.0: (0.0, 0.0),
    42.0: (10.0, 0.0),
    45.0: (15.0, 15.0),
    50.0: (25.0, 25.0),
    55.0: (30.0, 30.0),
    60.0: (35.0, 35.0),
}
#: R152 para. 5.2.1.3: the AEBS shall be active at least from 10 to 60 km/h (subject speed)
R152_MAX_SUBJECT_SPEED_KMH = 60.0
#: the moving target's speed in R152's test procedure (subject at 30 and 60 km/h)
R152_MOVING_TARGET_KMH = 20.0
#: R152 rows: (target, relative speed [km/h]) -> the limit applied [km/h]. The plant's mass
#: is the sedan's (params.VehicleParams.mass_kg), taken as its mass in running order, so the
#: unladen column applies; it is never above the laden one. A moving target's rows stop at
#: a subject speed of 60 km/h (para. 5.2.1.3).
R152_LIMITS_KMH: dict[tuple[str, float], float | None] = {
    **{("stationary", v): lim[1] for v, lim in R152_M1_TABLE_KMH.items()},
    **{
        ("moving", v): lim[1]
        for v, lim in R152_M1_TABLE_KMH.items()
        if v + R152_MOVING_TARGET_KMH <= R152_MAX_SUBJECT_SPEED_KMH
    },
}
PASS, FAIL, UNDETERMINED = "pass", "fail", "undetermined"

#: The protocols' test surface: a dry road. R152's test conditions: a dry, solid-paved
#: surface of "nominal peak braking coefficient (PBC) of 0.9" (the PBC reference that
#: CLEPA/OICA's GRVA-09-17 proposes to amend; the clause's number is not verified here);
#: Euro NCAP's test protocols: a dry surface (their PBC clause is not held here). We run the
#: dry road at mu 1.0 (the default); a run below 0.9 is not a protocol condition: its
#: figures are ours, with no regulation verdict and no rating (docs/protocols.md).
DRY_ROAD_MU = 0.9
#: What a scorecard says of a run on another surface
OFF_PROTOCOL = (
    "friction {mu:g}: not a protocol condition; figures only (the protocols test on a dry "
    "road, a peak braking coefficient of 0.9; below it no regulation verdict and no rating)"
)


def on_protocol_surface(mu: float) -> bool:
    """The friction is the protocols' dry road (``DRY_ROAD_MU`` or above)."""
    return mu >= DRY_ROAD_MU


def r152_verdict(limit_kmh: float | None, impact_speed_kmh: float) -> tuple[str, str]:
    """(verdict, reason) of one R152 row from its relative impact speed and its limit."""
    if impact_speed_kmh <= 0.0:
        return PASS, "collision avoided (passes under any limit)"
    if limit_kmh is None:
        return UNDETERMINED, (f"impact at {impact_speed_kmh:.1f} km/h; no R152 limit for this row")
    if impact_speed_kmh <= limit_kmh:
        return PASS, f"impact {impact_speed_kmh:.1f} <= {limit_kmh:g} km/h allowed"
    return FAIL, f"impact {impact_speed_kmh:.1f} > {limit_kmh:g} km/h allowed"


#: R152 para. 5.2.1.1 as secondary sources give it: the collision warning at the latest this
#: long before the start of emergency braking [s] (unverified: ``R152_WARNING_SOURCE``)
R152_WARNING_LEAD_S = 0.8
#: Where the warning rule comes from (the scorecard prints it)
R152_WARNING_SOURCE = (
    "Warning rule (0.8 s before the start of emergency braking, para. 5.2.1.1) NOT verified "
    "against the regulation's authentic text (ECE/TRANS/WP.29/2019/61, or Supplement 1's "
    "ECE/TRANS/WP.29/2020/9), which we do not hold: it is taken from secondary sources that "
    "quote or summarise R152 (a paper quoting 'collision warning [..] shall be provided at "
    "the latest 0.8 seconds before the start of emergency braking' and a summary of para. "
    "5.2.1), neither naming the series or supplement; any condition or exception the clause "
    "may carry is not applied. The speed verdict does not depend on it."
)


#: A lead is the difference of two time stamps of the run's time series (multiples of the
#: plant's 0.01 s step, written as decimals): it is settled at 1 us, a ten-thousandth of the
#: step, before the comparison, so that 4.21 - 3.41 = 0.7999999999999998 s counts as 0.8 s.
LEAD_DIGITS = 6


def r152_warning(
    fcw_raised: bool, lead_s: float | None, braked: bool, collided: bool = False
) -> tuple[str, str]:
    """(verdict, reason) of R152's warning (para. 5.2.1.1) from the FCW: raised at least
    ``R152_WARNING_LEAD_S`` before the emergency braking began (``lead_s``; None: unknown);
    without emergency braking, required before a collision (``collided``)."""
    if not braked:
        if collided and not fcw_raised:
            return FAIL, "a collision with neither a warning nor emergency braking"
        return PASS, "no emergency braking, no warning required"
    if not fcw_raised:
        return FAIL, "no collision warning before the emergency braking"
    if lead_s is None:
        return UNDETERMINED, "warning raised; its lead over the braking not measured"
    if round_half_up(lead_s, LEAD_DIGITS) >= R152_WARNING_LEAD_S:
        return PASS, f"warning {lead_s:.2f} s before the braking (>= {R152_WARNING_LEAD_S:g} s)"
    return FAIL, f"warning {lead_s:.2f} s before the braking (< {R152_WARNING_LEAD_S:g} s)"


def left_lane(left_road: bool, max_offset_m: float, lane_width_m: float, width_m: float) -> bool:
    """The run left its lane (or the road): a part of the body beyond the lane's edge,
    |lateral offset| above (lane width - vehicle width) / 2. An AEB brakes in its lane; a
    point whose run leaves it is not an R152 pass (our rule: the regulation's para. 5.2.1.4
    is a speed reduction by braking demand)."""
    return left_road or max_offset_m > (lane_width_m - width_m) / 2.0
