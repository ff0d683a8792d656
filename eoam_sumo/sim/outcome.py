"""Outcome colour of a run (paper sec. 11) from ground truth (docs/outcomes.md).

Inputs are the first contact found on the oriented boxes (``geometry.contact`` with the ego as
box ``a``), the ground-truth role of the body hit (``role_of``, from its position and motion,
never its id), the EOAM mode history and the ego's lateral offsets in the road frame of its
original lane (left positive).

Definitions:

* lane change made: the largest |lateral offset| of the ego during the run reached the point
  of no return, ``point_of_no_return_fraction`` (0.3, paper sec. 8.1) of the lane width; past
  it the EOAM logic is committed to the lane change, before it an oncoming vehicle still turns
  the manoeuvre into straight-line limit braking (yellow, not orange or red);
* back in lane: |final lateral offset| <= ``in_lane_tolerance_m``;
* stopped: final speed <= ``stopped_speed_mps``;
* lost control: at some time of the run the ego's heading was more than
  ``lost_control_heading_rad`` (1.0 rad) off the road direction, its forward speed vx was
  below ``reversing_speed_mps`` (-0.5 m/s: going backwards), or it rolled over (a wheel
  lifted or the static stability limit was passed, ``sim/vehicle.py``; the run ends there);
* left the road: the ego's centre of gravity went more than ``road_edge_margin_m`` (0.5 m)
  beyond a road edge; in the road frame of its original lane the road spans
  d in [-lane_width/2, lane_width/2 + left_width], left_width the width to the left of that
  lane (one lane width when a lane to the left exists, own direction or opposite, else 0).
  Lanes right of the original lane and a second lane to the left are not counted (the SUMO
  session reports neither): an ego that starts in a middle lane and moves a whole lane to the
  right is reported as having left the road.

* direct hit: the ego's front face hit the other body with at least ``DIRECT_HIT_MIN_OVERLAP``
  (50 %) of the narrower of the two widths in line (``geometry.face_overlap``); less is an
  offset hit (the frontal offset crash tests use 40 % and 25 % of the car's width);
* cut off: the run ended at its time limit or at the end of the road, not by the rules of
  the step loop (a contact, or the EOAM done and settled).

Rules, in order:

1. front against front (``head_on`` or ``oblique``) with an oncoming road user: ``red``, with
   or without a lane change (a frontal hit on oncoming traffic is the most severe outcome);
2. no lane change and a direct hit of the ego's front on a body that is not oncoming
   (front-to-rear or frontal, not a side contact): ``yellow`` (direct hit at reduced speed,
   paper sec. 8.1);
3. every other contact: ``orange`` (lateral or offset contact: side contact with the oncoming
   vehicle, any contact after a lane change with the ARO or a parked car, any side contact,
   an offset front hit, the ego hit from behind); an offset front-to-rear hit is orange, not
   yellow: the paper's yellow is a direct hit after straight-line braking, and an offset hit
   loads one side of the car as a lateral glance does;
4. no contact, and the ego lost control or left the road: ``orange`` (a spin or a road
   departure ends in lateral or roadside contact, the paper's orange; the run stops before
   it), ``collision_with`` ``none``, the reason saying what happened;
5. no contact and no mode other than 0 (NORMAL): ``none``;
6. no contact, the run cut off with the ego not back in its lane or a manoeuvre still
   running: ``unfinished`` (never green: nothing says how it would have ended);
7. no contact otherwise: ``green``; the reason says whether the lane change was completed
   (the ego back in its lane ahead of the obstacle it avoided), abandoned (back in its lane
   behind that obstacle: green, since nothing was hit and the ego is back where braking would
   have left it, but not "completed"), or the ego stopped or braked behind the obstacle.

Runs with contact are classified by rules 1-3 whatever the ego's motion before the contact.
``collision_with`` is the role of the body hit: ``aro``, ``oncoming``, ``parked`` or ``other``
(moving with the traffic outside the ego lane band, e.g. a car overtaking in the next
lane). Roles come from ground-truth position and motion, never from the radar's classes: a
road user heading against the road's direction (more than 90 deg off it) and not parked is
oncoming whatever its speed, a van creeping at 1.5 m/s as a car at 30 m/s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from mypy_extensions import mypyc_attr

from eoam_sumo.colours import OUTCOMES
from eoam_sumo.params import PONR_FRACTION
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import HEAD_ON_MIN_OVERLAP, Contact
from eoam_sumo.world.lanes import (
    LANE_MARGIN_M,
    STATIONARY_SPEED_MPS,
    RoadProjection,
    crosses_lane,
    lane_band_m,
)

COLOURS = OUTCOMES

# Loss of control: |heading error| (heading relative to the road) above this [rad]. A lane
# change turns the ego from the road by about atan(1.875 h / (T v)) (quintic of height h = the
# lane width over T seconds at speed v), and by more at low speed, where the ego also brakes
# to about half its entry speed during the steer. Measured: 0.03-0.18 rad at 90-165 km/h and
# 0.33 rad at 55 km/h in the Table 2 batch; 0.53 rad at the tables' 20 km/h floor on 3.5 m
# lanes, 0.60 rad on 4 m and 0.70 rad on 5 m lanes (a halted car ahead, mu 0.3-1.0). 1.0 rad
# (57 deg) keeps 0.3 rad above every lane change and a spin passes it early (a spin on an
# ice patch reaches 2.2 rad).
LOST_CONTROL_HEADING_RAD = 1.0
# Going backwards: forward speed vx below this [m/s]. The plant's vx is not clamped at 0; a
# stop by braking ends at vx = 0 to 6 decimals (Table 2, low-speed runs), so -0.5 m/s is no
# rounding or creep but the car sliding backwards, as after a spin.
REVERSING_SPEED_MPS = -0.5
# Road departure: the centre of gravity this far beyond a road edge [m], i.e. about 1.4 m of
# a 1.85 m wide car off the road. A lane change ends with the CG half a lane inside the left
# edge (overshoot 0.3 m at most measured) and a return overshoots the own lane centre by
# 0.33 m at most (Table 2), half a lane inside the right edge.
ROAD_EDGE_MARGIN_M = 0.5
# Stopped when the run ended: final forward speed at or below this [m/s]. It only words the
# reason of a green run ("stopped behind the obstacle" or "still moving"); the step loop's
# own standstill, which ends the EOAM's stop, is ``margins.EGO_STANDSTILL_MPS`` (0.05 m/s,
# strictly below), a different threshold: a run cut off at 0.07 m/s is reported stopped.
STOPPED_AT_END_MPS = 0.1

#: A front hit covering less than this share of the narrower width in line is an offset hit.
DIRECT_HIT_MIN_OVERLAP = HEAD_ON_MIN_OVERLAP

ROLES = ("aro", "oncoming", "parked", "other")
_COLLISION_WITH = {"aro": "aro", "oncoming": "oncoming", "parked": "parked", "other": "other"}
_ROLE_NAMES = {
    "aro": "the ARO",
    "oncoming": "the oncoming vehicle",
    "parked": "a parked car",
    "other": "another road user",
}


def role_of(
    body: Body,
    road_frame: RoadProjection,
    lane_width_m: float,
    *,
    in_lane_at_start: bool = False,
    was_obstacle: bool = False,
    stationary_speed_mps: float = STATIONARY_SPEED_MPS,
    lane_margin_m: float = LANE_MARGIN_M,
) -> str:
    """Ground-truth role of a body relative to the ego's original lane (``road_frame``).

    ``oncoming``: heading against the road direction there (more than 90 deg off it) and not
    parked, whatever its speed; ``aro``: otherwise, when its centre is inside the ego lane
    band (half-width lane_width/2 + lane_margin_m) or it was the vehicle ahead in the ego lane
    at the start (``in_lane_at_start``), unless it crosses the lane (``crosses_lane``: cross
    traffic at a junction) without having been the obstacle in it before (``was_obstacle``):
    then ``other``; ``parked``: slower than ``stationary_speed_mps`` outside the band;
    ``other``: the rest.
    """
    if not lane_width_m > 0.0:
        raise ValueError(f"lane_width_m={lane_width_m} must be > 0")
    _, d, road_yaw = road_frame.project(body.x_m, body.y_m)
    if not body.parked and math.cos(body.yaw_rad - road_yaw) < 0.0:
        return "oncoming"
    if in_lane_at_start or abs(d) < lane_band_m(lane_width_m, lane_margin_m):
        obstacle = in_lane_at_start or was_obstacle
        if not obstacle and crosses_lane(body.speed_mps, body.yaw_rad, road_yaw):
            return "other"
        return "aro"
    if abs(body.speed_mps) < stationary_speed_mps:
        return "parked"
    return "other"


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class OutcomeSettings:
    """Thresholds that turn the end state of a run into the facts the colours need."""

    point_of_no_return_fraction: float = PONR_FRACTION  # of the lane width (paper sec. 8.1)
    # ego centre within 0.5 m of the lane centre: a 1.85 m wide car keeps >= 0.3 m to the
    # markers of a 3.5 m lane
    in_lane_tolerance_m: float = 0.5
    stopped_speed_mps: float = STOPPED_AT_END_MPS  # "stopped" at the end of the run
    lost_control_heading_rad: float = LOST_CONTROL_HEADING_RAD  # |heading error| above: lost
    reversing_speed_mps: float = REVERSING_SPEED_MPS  # vx below: going backwards, lost control
    road_edge_margin_m: float = ROAD_EDGE_MARGIN_M  # CG beyond a road edge by more: left road

    def __post_init__(self) -> None:
        if not 0.0 < self.point_of_no_return_fraction <= 1.0:
            raise ValueError(
                f"point_of_no_return_fraction={self.point_of_no_return_fraction} must be in (0, 1]"
            )
        for name in ("in_lane_tolerance_m", "stopped_speed_mps", "lost_control_heading_rad"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"OutcomeSettings.{name}={v!r} must be finite and > 0")
        if not (math.isfinite(self.reversing_speed_mps) and self.reversing_speed_mps < 0.0):
            raise ValueError(
                f"OutcomeSettings.reversing_speed_mps={self.reversing_speed_mps!r} must be "
                "finite and < 0"
            )
        if not (math.isfinite(self.road_edge_margin_m) and self.road_edge_margin_m >= 0.0):
            raise ValueError(
                f"OutcomeSettings.road_edge_margin_m={self.road_edge_margin_m!r} must be "
                "finite and >= 0"
            )


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class Outcome:
    """Colour of a run, what was hit, how fast, and a one-line reason."""

    colour: str
    collision_with: str
    impact_speed_mps: float
    reason: str


#: Why mode 3 found the next lane closed, unless the decision policy names the cause.
NEXT_LANE_CLOSED = "oncoming traffic or a standing car"
#: What the EOAM did, where the reason names it (``driver_wording`` words it for a reference
#: driver, which only brakes in its lane: mode 1 while it brakes).
DMM_BRAKING = "limit braking chosen by the DMM"
NO_INTERVENTION = "no EOAM intervention"


def _manoeuvre_phrase(modes: set[int], lane_change: bool) -> str:
    """What the EOAM did, by the modes it visited: a run that entered mode 2 or 4 began a
    lane change, whatever it braked before or after."""
    steered = bool(modes & {2, 4, 5})
    if lane_change:
        return "lane change"
    if 3 in modes and 5 in modes:  # mode 5 hands over to 3 for a second obstacle
        return "lane change and return, then limit braking for another obstacle in the lane"
    if 3 in modes:
        chosen = "lane change aborted for limit braking" if steered else "limit braking chosen"
        return f"{chosen} (next lane not free before the point of no return: {NEXT_LANE_CLOSED})"
    if steered:
        return "lane change started but the point of no return not reached"
    if 1 in modes:
        return DMM_BRAKING
    return NO_INTERVENTION


def driver_wording(reason: str, driver: str) -> str:
    """``reason`` with what the EOAM did worded for the ego's controller ``driver`` (the EOAM:
    unchanged)."""
    if driver == "eoam":
        return reason
    reason = reason.replace(DMM_BRAKING, f"braking by the {driver} reference driver")
    return reason.replace(NO_INTERVENTION, f"no intervention by the {driver} reference driver")


def road_departure(
    min_offset_m: float,
    max_offset_m: float,
    lane_width_m: float,
    left_width_m: float = 0.0,
    right_width_m: float = 0.0,
) -> tuple[str, float]:
    """The side and distance [m] by which the ego's centre went farthest beyond a road edge.

    ``min_offset_m``/``max_offset_m``: the smallest and largest signed lateral offset d of the
    ego's centre in the road frame of its original lane (left positive); the road spans
    d in [-lane_width_m / 2 - right_width_m, lane_width_m / 2 + left_width_m]. The distance is
    <= 0 while the centre stayed on the road (then it is minus the least clearance to an edge).
    """
    right = -0.5 * lane_width_m - right_width_m - min_offset_m
    left = max_offset_m - 0.5 * lane_width_m - left_width_m
    return ("left", left) if left > right else ("right", right)


def left_road(
    min_offset_m: float,
    max_offset_m: float,
    lane_width_m: float,
    left_width_m: float = 0.0,
    settings: OutcomeSettings = OutcomeSettings(),
    right_width_m: float = 0.0,
) -> bool:
    """Whether the ego's centre went more than ``settings.road_edge_margin_m`` off the road."""
    _, beyond_m = road_departure(
        min_offset_m, max_offset_m, lane_width_m, left_width_m, right_width_m
    )
    return beyond_m > settings.road_edge_margin_m


def classify_outcome(
    modes_visited: Sequence[int],
    max_lateral_offset_m: float,
    lane_width_m: float,
    contact: Contact | None = None,
    role: str = "none",
    final_offset_m: float = 0.0,
    final_speed_mps: float = 0.0,
    settings: OutcomeSettings = OutcomeSettings(),
    *,
    max_abs_heading_error_rad: float = 0.0,
    min_speed_mps: float = 0.0,
    min_offset_m: float = 0.0,
    max_offset_m: float = 0.0,
    left_width_m: float = 0.0,
    right_width_m: float = 0.0,
    direct_overlap: float = 1.0,
    cut_off: str | None = None,
    manoeuvre_running: bool = False,
    passed_obstacle: bool | None = None,
    rollover: str | None = None,
) -> Outcome:
    """Colour of a run by the rules of the module docstring.

    ``modes_visited``: EOAM modes 0-5 in order of first visit; ``max_lateral_offset_m``: the
    largest |d| of the ego during the run; ``contact``: the first contact with the ego as box
    ``a`` (None if nothing was hit) and ``role`` the role of the other body (``role_of``);
    ``final_offset_m`` and ``final_speed_mps``: the ego's d and speed when the run ended.

    Loss of control and road departure (keyword-only; the defaults detect neither):
    ``max_abs_heading_error_rad`` the largest |heading - road heading| (wrapped to [-pi, pi))
    and ``min_speed_mps`` the lowest forward speed vx (signed) during the run;
    ``min_offset_m``/``max_offset_m`` the signed extremes of d and ``left_width_m`` the road
    width to the left of the original lane, ``right_width_m`` to its right (a usable lane
    there; ``road_departure``).

    Contact and end of the run (keyword-only): ``direct_overlap`` the share of the narrower
    width in line covered at the contact (direct or offset hit); ``cut_off`` what cut the run
    off (``"time limit"``, ``"end of the road"``; None when it ended by the loop's rules),
    ``manoeuvre_running`` whether a manoeuvre was still under way then; ``passed_obstacle``
    whether the ego ended ahead of the obstacle its lane change avoided (None: unknown);
    ``rollover`` what rolled the ego over and when (``sim/vehicle.py``; None: it did not).
    """
    modes = set(modes_visited)
    _check_inputs(
        modes_visited,
        lane_width_m,
        left_width_m,
        (
            ("max_lateral_offset_m", max_lateral_offset_m),
            ("final_offset_m", final_offset_m),
            ("final_speed_mps", final_speed_mps),
            ("max_abs_heading_error_rad", max_abs_heading_error_rad),
            ("min_speed_mps", min_speed_mps),
            ("min_offset_m", min_offset_m),
            ("max_offset_m", max_offset_m),
            ("left_width_m", left_width_m),
        ),
    )
    lane_change = _was_lane_change(modes, max_lateral_offset_m, lane_width_m, settings)
    if contact is not None:
        return _contact_outcome(modes, lane_change, contact, role, direct_overlap)
    lost = _loss_of_control(
        max_abs_heading_error_rad,
        min_speed_mps,
        road_departure(min_offset_m, max_offset_m, lane_width_m, left_width_m, right_width_m),
        settings,
        rollover,
    )
    if lost:
        return _lost_control(modes, lane_change, lost)
    return _no_contact(
        modes,
        lane_change,
        final_offset_m,
        final_speed_mps,
        settings,
        cut_off,
        manoeuvre_running,
        passed_obstacle,
    )


def _was_lane_change(
    modes: set[int], max_lateral_offset_m: float, lane_width_m: float, settings: OutcomeSettings
) -> bool:
    """Past the point of no return and never in mode 3: mode 3 is entered only before it, so
    limit braking was chosen, whatever lateral drift the aborted steer leaves (sec. 8.1)."""
    return 3 not in modes and (
        abs(max_lateral_offset_m) >= settings.point_of_no_return_fraction * lane_width_m
    )


def _lost_control(modes: set[int], lane_change: bool, lost: list[str]) -> Outcome:
    """Rule 4: orange without contact, saying how control was lost or the road left."""
    # an offset past the point of no return is a lane change only if the EOAM steered
    done = _manoeuvre_phrase(modes, lane_change and bool(modes & {2, 4, 5}))
    return Outcome("orange", "none", 0.0, f"{done}, no contact; {'; '.join(lost)}")


def _check_inputs(
    modes_visited: Sequence[int],
    lane_width_m: float,
    left_width_m: float,
    finite: tuple[tuple[str, float], ...],
) -> None:
    """Refuse mode numbers outside 0-5, a non-finite motion input (``finite``: name, value),
    a lane width not above 0 and a negative width to the left."""
    if not set(modes_visited) <= {0, 1, 2, 3, 4, 5}:
        raise ValueError(f"modes_visited={list(modes_visited)} must hold mode numbers 0-5")
    for name, v in finite:
        if not math.isfinite(v):
            raise ValueError(f"{name}={v!r} must be finite")
    if not lane_width_m > 0.0:
        raise ValueError(f"lane_width_m={lane_width_m} must be > 0")
    if left_width_m < 0.0:
        raise ValueError(f"left_width_m={left_width_m} must be >= 0")


def _contact_outcome(
    modes: set[int], lane_change: bool, contact: Contact, role: str, direct_overlap: float
) -> Outcome:
    """Rules 1-3 of the module docstring: red, yellow or orange by the contact's kind, the
    faces in contact, the role of the body hit and how squarely the ego's front hit it."""
    if role not in ROLES:
        raise ValueError(f"role={role!r} of the body hit must be one of {ROLES}")
    what = _ROLE_NAMES[role]
    v = contact.impact_speed_mps
    done = _manoeuvre_phrase(modes, lane_change)
    frontal = contact.kind in ("head_on", "oblique")
    front_hit = contact.face_a == "front" and contact.kind != "side" and role != "oncoming"
    if role == "oncoming" and frontal:
        how = "head-on" if contact.kind == "head_on" else "offset/oblique head-on"
        colour, reason = "red", f"{done}, {how} with the oncoming vehicle at {v:.1f} m/s"
    elif front_hit and not lane_change and direct_overlap >= DIRECT_HIT_MIN_OVERLAP:
        colour, reason = "yellow", f"{done}, front hit {what} at {v:.1f} m/s"
    elif front_hit:
        offset = "offset " if direct_overlap < DIRECT_HIT_MIN_OVERLAP else ""
        colour, reason = (
            "orange",
            (
                f"{done}, {offset}front hit {what} ({100 * direct_overlap:.0f} % of the "
                f"narrower width in line) at {v:.1f} m/s"
            ),
        )
    else:
        how = contact.kind.replace("_", "-")
        part = f"ego {contact.face_a} against its {contact.face_b}"
        colour, reason = "orange", f"{done}, {how} contact with {what} ({part}) at {v:.1f} m/s"
    return Outcome(colour, _COLLISION_WITH[role], v, reason)


def _loss_of_control(
    max_abs_heading_error_rad: float,
    min_speed_mps: float,
    departure: tuple[str, float],
    settings: OutcomeSettings,
    rollover: str | None = None,
) -> list[str]:
    """What went wrong, one phrase per trigger (empty when the ego stayed in control), a
    rollover first (the run ended there)."""
    what = [] if rollover is None else [f"rollover: {rollover}"]
    heading = abs(max_abs_heading_error_rad)
    if heading > settings.lost_control_heading_rad:
        what.append(
            f"lost control: heading {heading:.2f} rad ({math.degrees(heading):.0f} deg) off "
            "the road"
        )
    if min_speed_mps < settings.reversing_speed_mps:
        what.append(f"went backwards (vx down to {min_speed_mps:.1f} m/s)")
    side, beyond_m = departure
    if beyond_m > settings.road_edge_margin_m:
        what.append(f"left the road: centre {beyond_m:.1f} m beyond its {side} edge")
    return what


def _no_contact(
    modes: set[int],
    lane_change: bool,
    final_offset_m: float,
    final_speed_mps: float,
    settings: OutcomeSettings,
    cut_off: str | None = None,
    manoeuvre_running: bool = False,
    passed_obstacle: bool | None = None,
) -> Outcome:
    if not modes - {0}:
        return Outcome("none", "none", 0.0, "no manoeuvre needed, no contact")
    in_lane = abs(final_offset_m) <= settings.in_lane_tolerance_m
    stopped = final_speed_mps <= settings.stopped_speed_mps
    if cut_off is not None and (manoeuvre_running or not in_lane):
        where = (
            "a manoeuvre still running"
            if in_lane
            else f"the ego {final_offset_m:+.1f} m from its lane centre"
            + (" and a manoeuvre still running" if manoeuvre_running else "")
        )
        return Outcome(
            "unfinished",
            "none",
            0.0,
            f"no contact, but the run was cut off at its {cut_off} with {where}",
        )
    if lane_change and passed_obstacle is False:
        reason = (
            "lane change not completed: returned to its lane behind the obstacle it was "
            "avoiding, no contact"
        )
    elif lane_change:
        reason = (
            "lane change completed, returned to lane, no contact"
            if in_lane
            else "lane change completed, no contact, not back in lane when the run ended"
        )
    elif stopped:
        reason = (
            "stopped past the obstacle it was avoiding (the obstacle ended behind it), no contact"
            if passed_obstacle
            else "stopped behind the obstacle, no contact"
        )
    else:
        reason = "braked without contact, still moving when the run ended"
    return Outcome("green", "none", 0.0, reason)
