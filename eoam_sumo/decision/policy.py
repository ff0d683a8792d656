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

from eoam_sumo.eoam_messages import ONCOMING, WITH, NextLaneView, next_lane_motion
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift
from eoam_sumo.params import G_MPS2

POLICIES = ("paper", "safe")
#: A road user behind in the target lane: it may brake at 3 m/s^2 from 0.4 s after the lane
#: change begins, and keeps 1 s of its own travel as the gap. The project's
#: assumption, modelled on the "critical situation" of a lane change in UN Regulation No. 79
#: (ACSF of Category C, para. 5.6.4.7) as recalled; the values were not found in the text
#: of R79 or of UN R157 (ALKS), and are not cited as either's (docs/policy.md).
FOLLOWER_REACTION_S = 0.4
FOLLOWER_DECEL_MPS2 = 3.0
FOLLOWER_HEADWAY_S = 1.0
#: The longest lane change the policy plans (from its commit until the ego's body has left the
#: target lane) [s]: a pass that takes longer (the obstacle about as fast as the ego, closing
#: speed near 0) is not an avoidance manoeuvre and counts as never passed (the EOAM brakes
#: in lane and follows); it also bounds every prediction over the manoeuvre.
PLAN_HORIZON_S = 30.0


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class PolicySettings:
    """The decision policy and the safe policy's sight-distance terms."""

    name: str = "paper"  # "paper" or "safe"
    opposing_speed_mps: float | None = None  # v_opposing_max; None: the lane's speed limit
    margin_s: float = 0.5  # sensing, tracking and decision latency added to the times [s]
    margin_m: float = 10.0  # added to the sight distance [m]
    rear_gap_m: float = 10.0  # same-direction lane: a road user this close behind blocks [m]
    # the paper's policy checks the road users of the target lane at a commit (False: as
    # published, the paper being silent on them; the follower measures' test uses it)
    check_target_lane: bool = True

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

    needed_m: float  # unseen road ahead must be covered this far (module doc)
    closing_speed_mps: float  # v_ego + v_opposing_max
    t_lane_change_s: float
    t_beside_s: float  # inf: the ego never gets past (the obstacle is as fast)
    t_return_s: float  # the return until the ego's body has left the target lane
    t_escape_s: float  # leaving the target lane from its centre at the limit (not added)
    margin_s: float
    margin_m: float
    lane_change_m: float = 0.0  # length of the table lane change
    end_speed_mps: float = 0.0  # the ego's speed at its end, held until it is back

    @property
    def t_total_s(self) -> float:
        """Time from the commit until the ego's body has left the target lane."""
        return self.t_lane_change_s + self.t_beside_s + self.t_return_s

    def ego_travel_m(self, t_s: float) -> float:
        """Distance the ego drives in ``t_s`` on its planned speed profile: the table lane
        change (at its mean speed), then the speed at its end held."""
        t_lc = self.t_lane_change_s
        if t_s <= t_lc:
            return self.lane_change_m * t_s / t_lc if t_lc > 0.0 else 0.0
        return self.lane_change_m + self.end_speed_mps * (t_s - t_lc)


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


def road_user_travel_m(speed_mps: float, accel_mps2: float, t_s: float) -> float:
    """Distance along the road a road user covers in ``t_s`` at constant acceleration, a
    braking one (acceleration against its speed) until it stands."""
    if speed_mps * accel_mps2 < 0.0:
        t_stop = -speed_mps / accel_mps2
        if t_s >= t_stop:
            return 0.5 * speed_mps * t_stop
    return speed_mps * t_s + 0.5 * accel_mps2 * t_s * t_s


def beside_time_s(left_m: float, ego_mps: float, obstacle_mps: float, decel_mps2: float) -> float:
    """Time for the ego at constant ``ego_mps`` to gain ``left_m`` on an obstacle at
    ``obstacle_mps`` braking at ``decel_mps2`` to a stop (inf: never)."""
    if left_m <= 0.0:
        return 0.0
    rel = ego_mps - obstacle_mps
    if decel_mps2 <= 1e-9 or obstacle_mps <= 0.0:
        return left_m / rel if rel > 1e-6 else math.inf
    t_stop = obstacle_mps / decel_mps2
    # 0.5 a t^2 + rel t - left = 0 while it brakes
    t = (-rel + math.sqrt(rel * rel + 2.0 * decel_mps2 * left_m)) / decel_mps2
    if t <= t_stop:
        return t
    if ego_mps <= 1e-6:
        return math.inf
    return (left_m + 0.5 * obstacle_mps * t_stop) / ego_mps


def out_of_lane_time_s(back: QuinticShift, lane_width_m: float, ego_width_m: float, v: float):
    """Time along the return ``back`` (from the target lane's centre to 0, at speed ``v``)
    until the ego's body has left the target lane: |y| <= (w - ego width) / 2."""
    inside = 0.5 * (lane_width_m - ego_width_m)
    lo, hi = 0.0, back.length_m
    if abs(back.at(hi).y_m) > inside:
        return hi / max(v, 0.1)
    for _ in range(40):  # bisection on the monotone shift
        mid = 0.5 * (lo + hi)
        if abs(back.at(mid).y_m) > inside:
            lo = mid
        else:
            hi = mid
    return hi / max(v, 0.1)


def remaining_plan(need: SightNeed, elapsed_s: float) -> SightNeed:
    """The plan of ``need`` from ``elapsed_s`` after its commit on (the same speed profile,
    so that the checks during the manoeuvre agree with the gate's)."""
    t_lc = need.t_lane_change_s
    if elapsed_s < t_lc:
        left = t_lc - elapsed_s
        return need._replace(t_lane_change_s=left, lane_change_m=need.lane_change_m * left / t_lc)
    return need._replace(t_lane_change_s=0.0, lane_change_m=0.0)


def follower_keeps_distance(
    need: SightNeed,
    gap_m: float,
    speed_mps: float,
    t_s: float,
    min_gap_m: float,
    accel_mps2: float = 0.0,
) -> bool:
    """A road user ``gap_m`` behind the ego's rear in the target lane at ``speed_mps`` keeps
    its distance while the ego drives its planned profile for ``t_s``: it may brake at
    ``FOLLOWER_DECEL_MPS2`` from ``FOLLOWER_REACTION_S`` after the lane change begins, and
    the gap stays at least its own ``FOLLOWER_HEADWAY_S`` of travel (and ``min_gap_m``): the
    project's assumption (see ``FOLLOWER_REACTION_S``). Until it reacts it keeps its own
    ``accel_mps2`` (where known; 0: its speed). Bounded: the prediction stops once nothing
    changes any more (past the reaction and the lane change, the follower no faster than the
    ego: the gap cannot shrink) and at ``PLAN_HORIZON_S``."""
    t, step = 0.0, 0.05
    t_s = min(t_s, PLAN_HORIZON_S)
    settled_s = max(FOLLOWER_REACTION_S, need.t_lane_change_s)
    ego_x, x_b, v_b = 0.0, 0.0, speed_mps
    v0 = need.lane_change_m / need.t_lane_change_s if need.t_lane_change_s > 0.0 else 0.0
    while t < t_s:
        v_e = v0 if t < need.t_lane_change_s else need.end_speed_mps
        if t >= FOLLOWER_REACTION_S:
            v_b = max(v_b - FOLLOWER_DECEL_MPS2 * step, min(v_e, v_b))
        elif accel_mps2 != 0.0:
            v_b = max(v_b + accel_mps2 * step, 0.0)
        ego_x += v_e * step
        x_b += v_b * step
        t += step
        if gap_m + ego_x - x_b < max(min_gap_m, v_b * FOLLOWER_HEADWAY_S):
            return False
        if t >= settled_s and v_b <= v_e:
            return True  # the gap no longer shrinks, the headway needed no longer grows
    return True


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
    obstacle_decel_mps2: float = 0.0,
    offset_m: float | None = None,
) -> SightNeed:
    """Passing sight distance of a lane change begun now (module doc): ``gap_m`` from the ego's
    front bumper to the obstacle's rear, the obstacle at ``obstacle_speed_mps`` braking at
    ``obstacle_decel_mps2`` (its estimate), the ego on its planned speed profile;
    ``offset_m`` the target lane's centre from the ego's lane's (None: a lane width)."""
    travel_m = lane_width_m if offset_m is None else offset_m
    t_lc, v_end = lane_change_time_s(trajectory, speed_mps)
    # ego rear past the obstacle's front: relative travel gap + both lengths + the margin
    to_pass_m = gap_m + obstacle_length_m + ego_length_m + pass_margin_m
    decel = max(obstacle_decel_mps2, 0.0)
    obstacle_end = max(obstacle_speed_mps - decel * t_lc, 0.0)
    moved = road_user_travel_m(obstacle_speed_mps, -decel, t_lc)
    t_beside = beside_time_s(to_pass_m - (trajectory.length_m - moved), v_end, obstacle_end, decel)
    if t_lc + t_beside > PLAN_HORIZON_S:  # a closing speed near 0: never passed
        t_beside = math.inf
    back = QuinticShift.for_lateral_accel(
        travel_m, 0.0, 0.0, v_end, return_lateral_g * mu * G_MPS2, return_min_length_m
    )
    t_out = out_of_lane_time_s(back, lane_width_m, ego_width_m, v_end)
    # from the target lane's centre until the body is out of it (past the ego's lane marker)
    out_m = 0.5 * (lane_width_m + ego_width_m) + (travel_m - lane_width_m)
    t_escape = escape_time_s(out_m, mu)
    need = SightNeed(
        math.inf,
        speed_mps + opposing_speed_mps,
        t_lc,
        t_beside,
        t_out,
        t_escape,
        margin_s,
        margin_m,
        trajectory.length_m,
        v_end,
    )
    t = need.t_total_s + margin_s
    if math.isfinite(t):
        need = need._replace(needed_m=need.ego_travel_m(t) + opposing_speed_mps * t + margin_m)
    return need


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
        self.reason: str = ""  # why the next lane was closed (the first time it was)
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

    def sight_need(
        self, meas, perception, view: NextLaneView | None, obstacle_decel_mps2: float = 0.0
    ) -> SightNeed:
        gap, speed, length = self._obstacle(meas, perception)
        st, p = self.settings, self.params
        own_w = meas.lane_width_m
        target_w = view.lane_width_m if view is not None and view.lane_width_m else own_w
        lane_w, offset = (
            (target_w, None) if target_w == own_w else (own_w, 0.5 * (own_w + target_w))
        )
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
            lane_width_m=lane_w,
            pass_margin_m=self.eoam.pass_margin_m,
            return_lateral_g=self.eoam.return_lateral_g,
            return_min_length_m=self.eoam.return_min_length_m,
            margin_s=st.margin_s,
            margin_m=st.margin_m,
            obstacle_decel_mps2=obstacle_decel_mps2,
            offset_m=offset,
        )

    def _behind_reason(
        self, view: NextLaneView, need: SightNeed, t_s: float, unseen: bool = True
    ) -> str:
        """A road user behind in the target lane (at its own speed), or (``unseen``) one
        unseen beyond the rear coverage at the speed limit, that could not keep its distance
        to the ego (:func:`follower_keeps_distance`) within ``t_s``."""
        gap_m = self.settings.rear_gap_m
        if view.nearest_behind_m is not None:
            v_b = view.nearest_behind_speed_mps or 0.0
            a_b = view.nearest_behind_accel_mps2
            if not follower_keeps_distance(need, view.nearest_behind_m, v_b, t_s, gap_m, a_b):
                return "a road user behind in the target lane would catch the ego up"
        cover = view.coverage_behind_m if unseen else None
        v_lim = self._opposing_speed(view)
        if cover is not None and not follower_keeps_distance(need, cover, v_lim, t_s, gap_m):
            return "unseen road behind: a road user at the speed limit could catch the ego up"
        return ""

    def _ahead_reason(
        self, view: NextLaneView, need: SightNeed, t_s: float, moving_only: bool = False
    ) -> str:
        """A road user ahead in the target lane (at its own speed) that the ego would come
        within ``margin_m`` of during ``t_s``, or that would reach the ego (oncoming); one
        beside the ego always closes the lane. ``moving_only``: only those moving the ego's
        way (``next_lane_motion``); the oncoming and standing ones are the radar's classes,
        which the paper's own rules judge."""
        margin = self.settings.margin_m
        times = (0.0, min(need.t_lane_change_s, t_s), t_s)
        for gap, speed, accel in view.users_ahead_accel():
            if gap <= 0.0:
                return "a road user beside the ego in the target lane"
            motion = next_lane_motion(speed)
            if moving_only and motion != WITH:
                continue
            if any(
                gap + road_user_travel_m(speed, accel, t) - need.ego_travel_m(t) <= margin
                for t in times
            ):
                if motion == ONCOMING:
                    return "an oncoming road user in the target lane"
                return "a road user ahead in the target lane"
        return ""

    def _commit_reason(self, meas, view: NextLaneView | None, need: SightNeed) -> str:
        """Why the lane change may not begin now ("" : it may): module doc."""
        if not math.isfinite(need.t_total_s):
            return "the obstacle would never be passed"
        if view is None:
            return "nothing is known of the target lane"
        t = need.t_total_s + need.margin_s
        reason = self._behind_reason(view, need, t) or self._ahead_reason(view, need, t)
        if reason:
            return reason
        if view.coverage_ahead_m < need.needed_m:
            return "unseen road ahead in the target lane"
        return ""

    def _watch_reason(self, meas, view: NextLaneView) -> str:
        """During the lane change and the return: a road user that would meet the ego before
        its body has left the target lane (the time left on the plan, at least the escape
        from where it is now)."""
        need = self.need
        if need is None:
            return ""
        elapsed = meas.time_s - self._commit_s
        t_left = max(need.t_total_s - elapsed, 0.0)
        into_m = abs(meas.d_m) + 0.5 * (self.params.width_m - meas.lane_width_m)
        t = min(max(t_left, escape_time_s(into_m, meas.mu)) + need.margin_s, PLAN_HORIZON_S)
        now = remaining_plan(need, elapsed)
        return self._behind_reason(view, now, t) or self._ahead_reason(view, now, t)

    # ----------------------------------------------------------------------------- checks
    def lane_reason(
        self,
        meas,
        perception,
        view: NextLaneView | None,
        obstacle_decel_mps2: float = 0.0,
        traffic_only: bool = False,
    ) -> tuple[SightNeed, str]:
        """The plan of a lane change into ``view``'s lane begun now, and why it may not begin
        ("": it may; module doc). ``traffic_only``: the road users in the lane alone (the
        paper's policy choosing a side), not the unseen road."""
        need = self.sight_need(meas, perception, view, obstacle_decel_mps2)
        if view is not None and not view.opposing:  # seen as far as it drives in it
            drive_m = need.ego_travel_m(need.t_lane_change_s + need.t_beside_s)
            need = need._replace(needed_m=drive_m + need.margin_m)
        if traffic_only:
            if view is None or not math.isfinite(need.t_total_s):
                return need, ""
            t = need.t_total_s + need.margin_s
            reason = self._behind_reason(view, need, t, unseen=False)
            return need, reason or self._ahead_reason(view, need, t)
        return need, self._commit_reason(meas, view, need)

    def occupied_reason(
        self, meas, perception, view: NextLaneView | None, obstacle_decel_mps2: float = 0.0
    ) -> str:
        """The paper policy's added check at a commit ("": the lane may be entered): a road
        user of the target lane beside the ego, one behind that could not keep its distance
        (:func:`follower_keeps_distance`), or one ahead moving the ego's way that it would come
        within ``margin_m`` of, over the planned manoeuvre (at most ``PLAN_HORIZON_S``). The
        paper is silent on traffic in the target lane; its oncoming and standing road users
        stay with the paper's rules."""
        if view is None:
            return ""
        need = self.sight_need(meas, perception, view, obstacle_decel_mps2)
        t = min(need.t_total_s + need.margin_s, PLAN_HORIZON_S)
        return self._behind_reason(view, need, t, unseen=False) or self._ahead_reason(
            view, need, t, moving_only=True
        )

    def blocks(
        self,
        meas,
        perception,
        committing: bool,
        manoeuvring: bool,
        obstacle_decel_mps2: float = 0.0,
    ) -> bool:
        """True when the next lane is closed: at a commit (``committing``: a lane change is
        about to begin) the sight-distance gate and every road user; during the lane change
        and the return (``manoeuvring``) any road user that would meet the ego in it."""
        view = perception.next_lane
        if committing:
            need, reason = self.lane_reason(meas, perception, view, obstacle_decel_mps2)
            if not self.gate:
                self.gate = "refused" if reason else "passed"
                self.known_free_m = view.known_free_ahead_m if view is not None else 0.0
                self.need = need
                self.reason = reason
            self._commit_s = meas.time_s
            if not reason:
                self.need = need
            return bool(reason)
        if not manoeuvring or self.need is None or view is None:
            return False
        reason = self._watch_reason(meas, view)
        if reason and not self.reason:
            self.reason = reason
        return bool(reason)

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
        decel = float(self.tables.limit_brake_decel_mps2(mu))
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
            "sight_time_s": round(need.t_total_s, 3) if need is not None else None,
            "sight_reason": self.reason,
            "tie_break": self.tie_break,
        }
