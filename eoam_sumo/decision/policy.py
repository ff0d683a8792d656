"""Decision policies: the paper's EOAM, or ``safe``: a sight-distance gate on the lane change,
every road user in the next lane, and severity as the tie-breaker.

``paper`` is the framework as published (sec. 3, 8.1): the lane change is committed on the DMM's
STEER sector and only an oncoming vehicle *seen* by the radar makes it brake in lane.

``safe`` commits to a lane change into a lane of opposing traffic only when the length of that
lane *known* to be free (covered by the sensors and empty; :class:`NextLaneView`) covers the
passing sight distance of the manoeuvre, as road design sizes passing zones (AASHTO, *A Policy
on Geometric Design of Highways and Streets*, 7th ed. 2018, sec. 3.4 "passing sight distance";
Glennon, "New and improved model of passing sight distance on two-lane highways", TRR 1195,
1988: the critical position where completing and aborting the pass need the same sight
distance)::

    needed = (v_ego + v_opposing_max) (t_pass + t_escape + margin_s) + margin_m

* t_pass: the table lane change (its length and acceleration profile, paper eqs. 14-29), then
  beside the obstacle until the ego's rear is ``pass_margin_m`` past its front (the obstacle
  assumed to hold its speed: a braking one is passed sooner), then the return at the EOAM's
  comfortable lateral acceleration;
* t_escape = sqrt(2 w / (mu g)): leaving the opposite lane at the friction limit, w = half a
  lane plus half the ego's width (from the lane centre until its whole body is out);
* v_opposing_max: the lane's speed limit (net file) unless a setting overrides it.

If the gate fails the lane change is not begun: the EOAM brakes in lane (mode 3). Any road user
in the next lane (vehicle, bicycle or person, whatever its speed or direction) closer than the
distance still needed blocks the lane change as an oncoming vehicle does in the paper (mode 3
before the point of no return, 4 after it), and so does one behind that would catch the ego up
(a car overtaking in the opposite lane, a faster one in a lane of the own direction). A lane of
the ego's own direction needs no sight distance against opposing traffic; there a road user
ahead that the ego would catch up during the manoeuvre blocks, and the lane must be seen as
far as the ego drives in it until it is past the obstacle. When every option
past the point of no return ends in contact, the one with the lower predicted delta-v of the
ego (equal masses, plastic impact) is taken.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from mypy_extensions import mypyc_attr

from eoam_sumo.eoam_messages import NextLaneView
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift
from eoam_sumo.params import G_MPS2

POLICIES = ("paper", "safe")


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class PolicySettings:
    """The decision policy and the safe policy's sight-distance terms."""

    name: str = "paper"  # "paper" or "safe"
    opposing_speed_mps: float | None = None  # v_opposing_max; None: the lane's speed limit
    margin_s: float = 0.5  # sensing, tracking and decision latency added to the times [s]
    margin_m: float = 10.0  # added to the sight distance [m]
    rear_gap_m: float = 10.0  # same-direction lane: a road user this close behind blocks [m]

    def __post_init__(self) -> None:
        if self.name not in POLICIES:
            raise ValueError(f"policy {self.name!r} is not one of {', '.join(POLICIES)}")
        for key in ("margin_s", "margin_m", "rear_gap_m"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"policy setting {key}={v!r} must be finite and >= 0")
        v = self.opposing_speed_mps
        if v is not None and not (math.isfinite(v) and v >= 0.0):
            raise ValueError(f"opposing_speed_mps={v!r} must be finite and >= 0")


class SightNeed(NamedTuple):
    """The passing sight distance of one lane change and its terms."""

    needed_m: float
    closing_speed_mps: float  # v_ego + v_opposing_max
    t_lane_change_s: float
    t_beside_s: float  # inf: the ego never gets past (the obstacle is as fast)
    t_return_s: float
    t_escape_s: float
    margin_s: float
    margin_m: float

    @property
    def t_total_s(self) -> float:
        return self.t_lane_change_s + self.t_beside_s + self.t_return_s


def escape_time_s(lateral_m: float, mu: float) -> float:
    """Shortest time to move ``lateral_m`` sideways from rest at the friction limit:
    sqrt(2 w / (mu g))."""
    return math.sqrt(2.0 * max(lateral_m, 0.0) / (mu * G_MPS2))


def lane_change_time_s(trajectory, speed_mps: float, step_m: float = 1.0) -> tuple[float, float]:
    """(duration, end speed) of a table lane change entered at ``speed_mps``: the table's
    acceleration profile ax(dx) integrated along its length (v dv = ax dx)."""
    v, t, x = speed_mps, 0.0, 0.0
    length = trajectory.length_m
    while x < length - 1e-9:
        dx = min(step_m, length - x)
        ax = trajectory.at(x + 0.5 * dx).ax_mps2
        v_next = math.sqrt(max(v * v + 2.0 * ax * dx, 0.01))
        t += 2.0 * dx / (v + v_next)
        v, x = v_next, x + dx
    return t, v


def sight_needed(
    *,
    speed_mps: float,
    mu: float,
    opposing_speed_mps: float,
    trajectory,
    gap_m: float,
    obstacle_speed_mps: float,
    obstacle_length_m: float,
    ego_length_m: float,
    ego_width_m: float,
    lane_width_m: float,
    pass_margin_m: float,
    return_lateral_g: float,
    return_min_length_m: float,
    margin_s: float,
    margin_m: float,
) -> SightNeed:
    """Passing sight distance of a lane change begun now (module doc): ``gap_m`` from the ego's
    front bumper to the obstacle's rear, the obstacle at ``obstacle_speed_mps``."""
    t_lc, v_end = lane_change_time_s(trajectory, speed_mps)
    # ego rear past the obstacle's front: relative travel gap + both lengths + the margin
    to_pass_m = gap_m + obstacle_length_m + ego_length_m + pass_margin_m
    left_m = to_pass_m - (trajectory.length_m - obstacle_speed_mps * t_lc)
    if left_m <= 0.0:
        t_beside = 0.0
    elif v_end > obstacle_speed_mps + 1e-6:
        t_beside = left_m / (v_end - obstacle_speed_mps)
    else:
        t_beside = math.inf
    back = QuinticShift.for_lateral_accel(
        lane_width_m, 0.0, 0.0, v_end, return_lateral_g * mu * G_MPS2, return_min_length_m
    )
    t_return = back.length_m / max(v_end, 0.1)
    t_escape = escape_time_s(0.5 * (lane_width_m + ego_width_m), mu)
    closing = speed_mps + opposing_speed_mps
    needed = closing * (t_lc + t_beside + t_return + t_escape + margin_s) + margin_m
    return SightNeed(needed, closing, t_lc, t_beside, t_return, t_escape, margin_s, margin_m)


def head_on_delta_v_mps(closing_speed_mps: float) -> float:
    """Predicted delta-v of the ego in a plastic impact with a road user of equal mass
    (momentum exchange: half the closing speed)."""
    return 0.5 * max(closing_speed_mps, 0.0)


def braking_impact_speed_mps(closing_mps: float, gap_m: float, decel_mps2: float) -> float:
    """Relative speed left when braking at ``decel_mps2`` from ``closing_mps`` over
    ``gap_m`` (the obstacle holding its speed): sqrt(max(v^2 - 2 a d, 0))."""
    return math.sqrt(max(closing_mps * closing_mps - 2.0 * decel_mps2 * max(gap_m, 0.0), 0.0))


class SafePolicy:
    """The ``safe`` policy's checks, asked by the EOAM step (module doc).

    ``blocks`` says whether the next lane is closed to the lane change this step (the EOAM
    then treats it as the paper treats oncoming traffic); ``prefer_braking`` is the severity
    tie-breaker past the point of no return. What the gate needed and knew at the first
    commit is kept for the run's summary (:meth:`summary`).
    """

    def __init__(self, params, tables, eoam_settings, settings: PolicySettings):
        self.params = params
        self.tables = tables
        self.eoam = eoam_settings
        self.settings = settings
        self.reset()

    def reset(self) -> None:
        self.need: SightNeed | None = None
        self.known_free_m: float | None = None
        self.gate: str = ""  # "" not asked, "passed", "refused" (at the first commit)
        self.tie_break: str = ""  # "" not needed, "continue" or "brake"
        self._commit_s = 0.0

    # ----------------------------------------------------------------------------- helpers
    def _opposing_speed(self, view: NextLaneView | None) -> float:
        v = self.settings.opposing_speed_mps
        if v is not None:
            return v
        return view.speed_limit_mps if view is not None else 0.0

    def _obstacle(self, meas, perception) -> tuple[float, float, float]:
        """(gap, speed, length) of the in-path obstacle as sensed (length assumed without a
        track, as the EOAM assumes it)."""
        gap = perception.aro_range_m
        rate = perception.aro_range_rate_mps
        closing = -rate if rate is not None and math.isfinite(rate) else 0.0
        obj = perception.aro_object
        length = obj.length_m if obj is not None else self.eoam.unknown_obstacle_length_m
        return (gap if gap is not None else 0.0), max(meas.vx_mps - closing, 0.0), length

    def sight_need(self, meas, perception, view: NextLaneView | None) -> SightNeed:
        gap, speed, length = self._obstacle(meas, perception)
        st, p = self.settings, self.params
        return sight_needed(
            speed_mps=meas.vx_mps,
            mu=meas.mu,
            opposing_speed_mps=self._opposing_speed(view),
            trajectory=self.tables.trajectory(meas.mu, meas.vx_mps),
            gap_m=gap,
            obstacle_speed_mps=speed,
            obstacle_length_m=length,
            ego_length_m=p.length_m,
            ego_width_m=p.width_m,
            lane_width_m=meas.lane_width_m,
            pass_margin_m=self.eoam.pass_margin_m,
            return_lateral_g=self.eoam.return_lateral_g,
            return_min_length_m=self.eoam.return_min_length_m,
            margin_s=st.margin_s,
            margin_m=st.margin_m,
        )

    def _lane_free(
        self, view: NextLaneView, speed_mps: float, t_left_s: float, need_m: float, committing: bool
    ) -> bool:
        """The next lane is free for ``t_left_s`` more seconds of manoeuvre; at a commit it
        must be seen ``need_m`` ahead (free of road users too, if it carries opposing
        traffic). In either kind of lane a road user behind must not catch the ego up (one
        overtaking in the opposite lane, or a faster car of the own direction)."""
        st = self.settings
        t = t_left_s + st.margin_s
        if view.nearest_behind_m is not None:
            behind_speed = view.nearest_behind_speed_mps or 0.0
            if view.nearest_behind_m <= max(behind_speed - speed_mps, 0.0) * t + st.rear_gap_m:
                return False
        if view.opposing:
            if committing:
                return view.known_free_ahead_m >= need_m
            return view.nearest_ahead_m is None or view.nearest_ahead_m > need_m
        if view.nearest_ahead_m is not None:  # the ego must not catch it up
            ahead_speed = view.nearest_ahead_speed_mps or 0.0
            if view.nearest_ahead_m <= max(speed_mps - ahead_speed, 0.0) * t + st.margin_m:
                return False
        # the lane must be seen as far as the ego goes in it before it is past the obstacle
        return not committing or view.coverage_ahead_m >= need_m

    # ----------------------------------------------------------------------------- checks
    def blocks(self, meas, perception, committing: bool, manoeuvring: bool) -> bool:
        """True when the next lane is closed: at a commit (``committing``: a lane change is
        about to begin) the sight-distance gate and every road user; during the lane change
        and the return (``manoeuvring``) any road user within the distance still needed."""
        view = perception.next_lane
        if committing:
            need = self.sight_need(meas, perception, view)
            if view is not None and not view.opposing:  # seen as far as it drives in it
                need = need._replace(
                    needed_m=meas.vx_mps * (need.t_lane_change_s + need.t_beside_s) + need.margin_m
                )
            free = (
                view is not None
                and math.isfinite(need.needed_m)
                and self._lane_free(view, meas.vx_mps, need.t_total_s, need.needed_m, True)
            )
            if not self.gate:
                self.gate = "passed" if free else "refused"
                self.known_free_m = view.known_free_ahead_m if view is not None else 0.0
                self.need = need
            self._commit_s = meas.time_s
            if free:
                self.need = need
            return not free
        if not manoeuvring or self.need is None or view is None:
            return False
        need = self.need
        t_left = max(need.t_total_s - (meas.time_s - self._commit_s), 0.0)
        left_m = need.closing_speed_mps * (t_left + need.t_escape_s + need.margin_s)
        return not self._lane_free(view, meas.vx_mps, t_left, left_m + need.margin_m, False)

    def prefer_braking(self, meas, perception) -> bool:
        """Past the point of no return with the next lane closed: True when braking in lane
        is predicted to end with a lower delta-v of the ego than passing on (mode 4), both
        ending in contact; False when passing on is predicted to end without contact."""
        view = perception.next_lane
        if view is None or view.nearest_ahead_m is None:
            return False
        v, mu, lane = meas.vx_mps, meas.mu, meas.lane_width_m
        closing = v - (view.nearest_ahead_speed_mps or 0.0)
        if closing <= 0.0:
            return False
        t_meet = view.nearest_ahead_m / closing
        gap, speed, length = self._obstacle(meas, perception)
        out_m = meas.d_m + 0.5 * self.params.width_m - 0.5 * lane  # body left of the marker
        to_pass = gap + length + self.params.length_m + self.eoam.pass_margin_m
        t_pass = to_pass / (v - speed) if v > speed + 1e-6 else math.inf
        t_out = t_pass + escape_time_s(out_m, mu)
        if t_meet >= t_out:
            self.tie_break = self.tie_break or "continue"
            return False
        dv_on = head_on_delta_v_mps(closing)
        decel = self.eoam.limit_brake_fraction * float(self.tables.max_decel_mps2(mu))
        if escape_time_s(out_m, mu) >= t_meet:
            dv_brake = head_on_delta_v_mps(closing - decel * t_meet)
        else:
            dv_brake = 0.5 * braking_impact_speed_mps(v - speed, gap, decel)
        brake = dv_brake < dv_on
        self.tie_break = "brake" if brake else "continue"
        return brake

    def summary(self) -> dict:
        """The gate's record for summary.json (empty values when it was never asked)."""
        need = self.need
        if need is not None and not math.isfinite(need.needed_m):
            need = None
        return {
            "sight_gate": self.gate,
            "sight_needed_m": round(need.needed_m, 3) if need is not None else None,
            "sight_known_free_m": (
                None if self.known_free_m is None else round(self.known_free_m, 3)
            ),
            "sight_time_s": (
                round(need.t_total_s + need.t_escape_s, 3) if need is not None else None
            ),
            "tie_break": self.tie_break,
        }
