"""Safety margins of a run, as an observer of the step: how close the ego came to the road
users around it, how soon it would have hit opposite-direction traffic, how long it spent
left of its lane, and whether a run without contact was a near miss.

* ``min_gap_oncoming_m``: the smallest box-to-box gap to any opposite-direction road user
  (not parked, heading more than 90 deg from the road's direction at the ego): at every step
  while SUMO reports it within the sensing reach, and for every such road user in the
  simulation at the start and at the end of the run (one never within reach has neither met
  nor passed the ego, so the smaller of those two gaps is its smallest); infinite (empty in
  the summary) when there is none;
* ``min_ttc_oncoming_s``: the smallest time to collision with such a road user, both moving
  on along their lanes at their present rates (below); infinite when never on a collision
  course;
* ``min_ttc_s``: the smallest time to collision along the lanes with any moving road user
  (opposite direction, or the same direction within ``TTC_HORIZON_S``), the obstacle ahead
  in the ego's lane aside (its margin is ``min_gap_aro_m``); ``min_ttc_rear_s`` the same for
  those behind the ego;
* the ego's follower (the nearest road user behind it overlapping its width, within
  ``FOLLOWER_REACH_M``; a car the ego passed and cut in front of is one, whatever role it
  had before): the smallest gap along the road ``min_gap_rear_m``, while it closes in on the
  ego the largest DRAC ``max_drac_rear_mps2`` (deceleration rate to avoid the crash,
  (v_f - v_ego)^2 / (2 gap)), and the largest deceleration it made while closing in or
  within ``LEADER_HEADWAY_S`` of the ego, ``max_follower_decel_mps2`` (``follower_decel_id``
  who; a vehicle whose stop is scripted and that is not closing in brakes for its script,
  not for the ego);
* ``time_in_left_lane_s``: steps with the ego's centre left of its lane (in the next lane
  to the left, the opposite lane on a two-way road) times the step; ``time_in_next_lane_s``
  the same, right of its lane counted too where the ego's class may use a lane there (the
  lane it evaded into, either side);
* ``closest_gap_m`` and ``closest_id``: the smallest gap to any road user once within
  ``NEAR_MISS_GAP_M`` (gaps farther out are not measured);
* a run without contact is a **near miss** when it came within ``NEAR_MISS_GAP_M`` of any
  road user, its ``min_ttc_s`` fell below ``NEAR_MISS_TTC_S``, or a follower was forced to
  brake at ``EMERGENCY_DECEL_MPS2`` or harder.

Along the lanes: every road user and the ego move on in the road frame of the ego's original
lane (station ``s``, offset ``d``) at their present rates, ``s' = v cos(psi - psi_road) /
(1 - kappa d)`` and ``d' = v sin(psi - psi_road)``: on a curve each keeps to its lane, where a
straight line would cross the bend into the other. On a straight road it is the straight
line.

``road_user_close_ahead`` is the ground truth the step loop asks before it ends a run as
settled: a run does not end while the ego moves towards a road user close ahead in its lane.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from eoam_sumo.params import G_MPS2
from eoam_sumo.sim.observers import RunView, StepObserver
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import (
    GAP_ROUNDING_M,
    OrientedBox,
    box_distance,
    gap_lower_bound,
    time_to_contact,
)
from eoam_sumo.world.lanes import RoadProjection, lane_band_m

#: A run without contact that came this close to another road user is a near miss [m].
NEAR_MISS_GAP_M = 0.5
#: ... or that was on a collision course with opposite-direction traffic less than this far
#: from the contact [s]: the minimum time to collision under which traffic-conflict studies
#: count an encounter as serious (van der Horst, *A time-based analysis of road user
#: interaction*, 1990: 1.5 s).
NEAR_MISS_TTC_S = 1.5
#: A run does not end settled while a road user is in the ego's lane ahead within the ego's
#: stopping distance plus this [m] (``road_user_close_ahead``): the end is then a stop behind
#: it, passing it, or a contact.
CLOSE_AHEAD_MARGIN_M = 5.0
#: The ego is at a standstill below this forward speed [m/s]: the EOAM's stop is over
#: (``CoSimulation.eoam_done``) and no road user ahead holds the run open. Not the outcome's
#: "stopped at the end" (``outcome.STOPPED_AT_END_MPS``, 0.1 m/s), which only words a reason.
EGO_STANDSTILL_MPS = 0.05
#: Times to collision with same-direction road users are looked for this far ahead [s].
TTC_HORIZON_S = 10.0
#: The ego's follower is the nearest road user behind it, overlapping its width, within [m].
FOLLOWER_REACH_M = 150.0
#: A follower forced to brake this hard or harder makes a near miss [m/s^2]: "emergency
#: braking" on the scale of the deceleration needed to stay clear of a leader (Hupfer 1997,
#: as tabulated for the DST/a_long,req metrics by Westhofen et al., "Criticality metrics for
#: automated driving: a review", 2023: < 4 considerable, < 6 heavy reaction, >= 6 emergency).
EMERGENCY_DECEL_MPS2 = 6.0
#: A follower not closing in on the ego still brakes for it while within this time gap of
#: it (its own speed times this): the "two-second rule" of the UK Highway Code (rule 126),
#: the gap below which a driver adjusts to the car in front [s].
LEADER_HEADWAY_S = 2.0


class Margins(StepObserver):
    """The margins of the module docstring, for an ego of ``length_m`` x ``width_m`` whose
    CG is ``cg_to_front_m`` behind its front."""

    def __init__(self, length_m: float, width_m: float, cg_to_front_m: float):
        self.length_m, self.width_m, self.front_m = length_m, width_m, cg_to_front_m
        self._back_m = cg_to_front_m - 0.5 * length_m  # CG to the box centre
        self._radius_m = math.hypot(0.5 * length_m, 0.5 * width_m)

    def start(self, sim: RunView) -> None:
        self.min_gap_oncoming_m = self._opposite_gap(sim, sim.x)
        self.min_ttc_oncoming_s = math.inf
        self.closest_gap_m = math.inf
        self.closest_id: str | None = None
        self._left_steps = self._right_steps = 0
        self._step_s = sim.step_s
        self._half_lane_m = 0.5 * sim.lane_width_m
        self._band_m = lane_band_m(sim.lane_width_m)
        self._left_lane = sim.left_lane
        self._right_lane = sim.right_width_m > 0.0  # a lane on the right the ego may use
        # along the lanes: the road frame of the ego's original lane (its own walk)
        self._frame = RoadFrame(sim.session.ego_lane_centreline())
        self._frame.locate(sim.x[0], sim.x[1])
        self.min_ttc_s = math.inf
        self.min_ttc_rear_s = math.inf
        self.min_gap_rear_m = math.inf
        self.max_drac_rear_mps2 = 0.0
        self.max_follower_decel_mps2 = 0.0
        self.follower_decel_id: str | None = None
        self._scripted: frozenset[str] = getattr(sim.session, "scripted_ids", frozenset())

    @property
    def time_in_left_lane_s(self) -> float:
        """Time with the ego's centre left of its lane, in the lane there."""
        return self._left_steps * self._step_s

    @property
    def time_in_next_lane_s(self) -> float:
        """Time with the ego's centre out of its lane, in the lane beside on either side."""
        return (self._left_steps + self._right_steps) * self._step_s

    def end(self, sim: RunView) -> None:
        self.min_gap_oncoming_m = min(self.min_gap_oncoming_m, self._opposite_gap(sim, sim.x))

    def _opposite_gap(self, sim: RunView, x) -> float:
        """The smallest gap from the ego (plant state ``x``) to any opposite-direction road
        user in the simulation (infinite when there is none); those near the ego as the step
        has them (in a multi-rate run SUMO is up to a step ahead of the step's time)."""
        X, Y, yaw = x[0], x[1], x[2]
        road_yaw = sim.road.project(X, Y)[2]
        cr, sr = math.cos(road_yaw), math.sin(road_yaw)
        ego = OrientedBox.from_axis_point(X, Y, yaw, self.length_m, self.width_m, self.front_m)
        near = {b.vid: b for b in sim.bodies}
        users = [near.get(b.vid, b) for b in sim.session.road_users()]
        return min(
            (
                box_distance(ego, b.box)
                for b in users
                if not b.parked and b.box.cos_yaw * cr + b.box.sin_yaw * sr < 0.0
            ),
            default=math.inf,
        )

    def near_miss(self) -> bool:
        """Within ``NEAR_MISS_GAP_M`` of any road user, a time to collision along the lanes
        below ``NEAR_MISS_TTC_S`` with any moving one (the obstacle ahead in the ego's lane
        aside), or a follower forced to brake at ``EMERGENCY_DECEL_MPS2`` or harder."""
        return (
            self.closest_gap_m <= NEAR_MISS_GAP_M
            or self.min_ttc_s < NEAR_MISS_TTC_S
            or self.max_follower_decel_mps2 >= EMERGENCY_DECEL_MPS2
        )

    def after_step(self, sim: RunView) -> None:
        d_m = sim.meas.d_m
        if self._left_lane and d_m > self._half_lane_m:
            self._left_steps += 1
        elif self._right_lane and d_m < -self._half_lane_m:
            self._right_steps += 1
        self._gaps(sim)
        self._along_lanes(sim)

    def _gaps(self, sim: RunView) -> None:
        """The box gaps: to opposite-direction road users, and the closest within
        ``NEAR_MISS_GAP_M``."""
        X, Y, yaw = sim.x[0], sim.x[1], sim.x[2]
        c, s = math.cos(yaw), math.sin(yaw)
        ex, ey = X + self._back_m * c, Y + self._back_m * s
        road_yaw = sim.x_prev[2] - sim.meas.e_yaw_rad  # the road's heading at the ego
        cr, sr = math.cos(road_yaw), math.sin(road_yaw)
        ego_box = None
        for b in sim.bodies:
            vid, _, _, _, _, _, _, _, parked, box = b  # see ``_BodyFields``
            bx, by, _, _, _, bc, bs, _, _, b_radius = box
            bound = math.hypot(bx - ex, by - ey) - self._radius_m - b_radius - GAP_ROUNDING_M
            opposite = not parked and bc * cr + bs * sr < 0.0
            near = bound < NEAR_MISS_GAP_M
            if not (near or (opposite and bound < self.min_gap_oncoming_m)):
                continue
            if ego_box is None:
                ego_box = OrientedBox(ex, ey, yaw, self.length_m, self.width_m)
            gap = -1.0
            if opposite and bound < self.min_gap_oncoming_m:
                gap = box_distance(ego_box, box)
                self.min_gap_oncoming_m = min(self.min_gap_oncoming_m, gap)
            if near and bound < self.closest_gap_m:
                # the separating-axis bound rules out most of what the circles let through
                # (a car parked beside the ego)
                if gap < 0.0 and gap_lower_bound(ego_box, box) - GAP_ROUNDING_M < NEAR_MISS_GAP_M:
                    gap = box_distance(ego_box, box)
                if 0.0 <= gap < self.closest_gap_m:
                    self.closest_gap_m, self.closest_id = gap, vid

    def _along_lanes(self, sim: RunView) -> None:
        """Times to collision along the lanes, and the follower's measures.

        Every road user and the ego move on in the road frame (station along the ego's
        original lane, offset from it) at their present rates: ``s' = v cos(psi - psi_road)
        / (1 - kappa d)``, ``d' = v sin(psi - psi_road)``, so that on a curve each keeps to
        its lane instead of leaving it on a straight line. Their boxes in that frame, turned
        by the heading relative to the road, give the time to contact
        (``geometry.time_to_contact``)."""
        ego, ego_v = self._ego_in_frame(sim)
        ego_st, ego_d = ego.x_m, ego.y_m
        follower: tuple[float, Body, float, tuple[float, float]] | None = None
        project, band = self._frame.project, self._band_m
        for b in sim.bodies:
            _, _, x_m, y_m, yaw_rad, speed_mps, length_m, width_m, parked, b_box = b
            _, _, _, _, _, _, _, _, _, radius = b_box
            if parked:
                continue
            st, d, road_yaw = project(x_m, y_m)
            rel = yaw_rad - road_yaw
            if math.cos(rel) < 0.0:  # opposite direction
                v = self._rates(speed_mps, st, d, rel)
                if _apart(ego, st, d, radius, ego_v, v, self.min_ttc_oncoming_s):
                    continue  # never on a collision course within the smallest yet
                box = OrientedBox(st, d, rel, length_m, width_m)
                ttc = time_to_contact(ego, box, ego_v, v, self.min_ttc_oncoming_s)
                self.min_ttc_oncoming_s = min(self.min_ttc_oncoming_s, ttc)
                self.min_ttc_s = min(self.min_ttc_s, ttc)
                continue
            behind_m = ego_st - st
            if behind_m < 0.0 and abs(d) < band:
                continue  # the obstacle ahead in the ego's lane: its margin is the gap
            horizon = min(self.min_ttc_s, TTC_HORIZON_S)
            if behind_m > 0.0:
                horizon = max(horizon, min(self.min_ttc_rear_s, TTC_HORIZON_S))
            v = self._rates(speed_mps, st, d, rel)
            # the box in the frame only when its bounding circle may meet the ego's
            if _apart(ego, st, d, radius, ego_v, v, horizon):
                ttc = math.inf
            else:
                box = OrientedBox(st, d, rel, length_m, width_m)
                ttc = time_to_contact(ego, box, ego_v, v, horizon)
            self.min_ttc_s = min(self.min_ttc_s, ttc)
            if behind_m <= 0.0:
                continue
            self.min_ttc_rear_s = min(self.min_ttc_rear_s, ttc)
            overlap = abs(d - ego_d) < 0.5 * (self.width_m + width_m)
            if (
                overlap
                and behind_m < FOLLOWER_REACH_M
                and (follower is None or behind_m < follower[0])
            ):
                follower = (behind_m, b, st, v)
        if follower is not None:
            self._follower(sim, ego, ego_v, follower[1], follower[2], follower[3])

    def _ego_in_frame(self, sim: RunView) -> tuple[OrientedBox, tuple[float, float]]:
        """The ego's box in the road frame, and its rates (s', d')."""
        X, Y, yaw, vx, vy = sim.x[:5]
        c, s = math.cos(yaw), math.sin(yaw)
        ex, ey = X + self._back_m * c, Y + self._back_m * s
        st, d, road_yaw = self._frame.project(ex, ey)
        rel = yaw - road_yaw
        cr, sr = math.cos(rel), math.sin(rel)
        stretch = 1.0 - self._frame.curvature_at(st) * d
        v = ((vx * cr - vy * sr) / stretch, vx * sr + vy * cr)
        return OrientedBox(st, d, rel, self.length_m, self.width_m), v

    def _rates(self, speed_mps: float, st: float, d: float, rel: float) -> tuple[float, float]:
        """A road user's rates (s', d') in the road frame, at station ``st``, offset ``d``,
        heading ``rel`` to the road, at its speed."""
        stretch = 1.0 - self._frame.curvature_at(st) * d
        return (speed_mps * math.cos(rel) / stretch, speed_mps * math.sin(rel))

    def _follower(
        self,
        sim: RunView,
        ego: OrientedBox,
        ego_v: tuple[float, float],
        b: Body,
        station_m: float,
        v: tuple[float, float],
    ) -> None:
        """The nearest road user behind the ego overlapping its width (the ego is its
        leader): the gap between them along the road, while it closes in on the ego its DRAC
        ((v_f - v_ego)^2 / (2 gap)), and its deceleration over the step while closing in or
        within ``LEADER_HEADWAY_S`` of its own travel behind the ego (forced by the ego: a car
        the ego cut in front of brakes though it is slower; one falling back farther, or a
        scripted stop such as an obstacle the ego passed, is not)."""
        gap = ego.x_m - 0.5 * ego.length_m - (station_m + 0.5 * b.length_m)
        self.min_gap_rear_m = min(self.min_gap_rear_m, max(gap, 0.0))
        closing = v[0] - ego_v[0]
        if closing > 0.0 and gap > 0.0:
            self.max_drac_rear_mps2 = max(self.max_drac_rear_mps2, closing * closing / (2.0 * gap))
        if closing <= 0.0 and (b.vid in self._scripted or gap > LEADER_HEADWAY_S * v[0]):
            return
        before = next((o for o in sim.bodies_before if o.vid == b.vid), None)
        if before is not None:
            decel = (before.speed_mps - b.speed_mps) / self._step_s
            if decel > self.max_follower_decel_mps2:
                self.max_follower_decel_mps2, self.follower_decel_id = decel, b.vid


def _apart(
    a: OrientedBox,
    x_m: float,
    y_m: float,
    radius_m: float,
    va: tuple[float, float],
    vb: tuple[float, float],
    t_s: float,
) -> bool:
    """Whether a box and a road user centred at (``x_m``, ``y_m``) within ``radius_m``,
    moving at these rates, cannot touch within ``t_s`` (infinite: ever): along either axis
    of the frame their centres are farther apart than their bounding circles, by more than
    the rate between them closes in that time (not at all when it opens or holds)."""
    ax, ay, _, _, _, _, _, _, _, a_radius = a
    reach = a_radius + radius_m + GAP_ROUNDING_M
    return _axis_apart(x_m - ax, vb[0] - va[0], reach, t_s) or _axis_apart(
        y_m - ay, vb[1] - va[1], reach, t_s
    )


def _axis_apart(offset_m: float, rate_mps: float, reach_m: float, t_s: float) -> bool:
    """Centres ``offset_m`` apart on an axis, the offset changing at ``rate_mps``: farther
    than ``reach_m`` for the whole of ``t_s``."""
    gap = abs(offset_m) - reach_m
    if gap <= 0.0:
        return False
    closing = -rate_mps if offset_m > 0.0 else rate_mps
    return closing <= 0.0 or closing * t_s < gap


def road_user_close_ahead(
    x: Sequence[float],
    cg_to_front_m: float,
    road: RoadProjection,
    lane_width_m: float,
    mu: float,
    bodies: Sequence[Body],
) -> bool:
    """Whether the ego (plant state ``x``) is moving and a road user's centre is in the ego's
    lane (the one its centre is in; band as the radar's) ahead of its front bumper, with a gap
    along the road within what the ego needs to stop behind where that road user would stop
    (both braking at the road's friction: (v^2 - u^2) / (2 mu g), u its speed along the road)
    plus ``CLOSE_AHEAD_MARGIN_M``."""
    X, Y, _, vx = x[:4]
    if vx < EGO_STANDSTILL_MPS:
        return False  # stopped behind it: the run's real end
    s_ego, d_ego, _ = road.project(X, Y)
    front_s = s_ego + cg_to_front_m
    lane_d = lane_width_m * round(d_ego / lane_width_m)  # centre of the lane the ego is in
    band = lane_band_m(lane_width_m)
    two_decel = 2.0 * mu * G_MPS2
    for b in bodies:
        s, d, road_yaw = road.project(b.x_m, b.y_m)
        if s <= front_s or abs(d - lane_d) >= band:
            continue
        u = max(b.speed_mps * math.cos(b.yaw_rad - road_yaw), 0.0)
        need = max(vx * vx - u * u, 0.0) / two_decel + CLOSE_AHEAD_MARGIN_M
        if s - 0.5 * b.length_m - front_s <= need:
            return True
    return False


def follower_arriving(
    x: Sequence[float],
    cg_to_rear_m: float,
    road: RoadProjection,
    lane_width_m: float,
    bodies: Sequence[Body],
) -> bool:
    """Whether the nearest road user behind the ego in its lane (centre in the lane, behind
    the ego's rear bumper, ``cg_to_rear_m`` ahead of the CG: negative, within
    ``FOLLOWER_REACH_M``) still moves towards it: it has not yet stopped behind the ego, and
    may hit it. The run of a stopped ego waits for that one road user to stop or pass
    (``RunSettings.after_stop_s`` None), not for the queue forming behind it."""
    X, Y = x[0], x[1]
    s_ego, d_ego, _ = road.project(X, Y)
    rear_s = s_ego + cg_to_rear_m
    lane_d = lane_width_m * round(d_ego / lane_width_m)
    band = lane_band_m(lane_width_m)
    nearest_s, closing = -math.inf, False
    for b in bodies:
        if b.parked:
            continue
        s, d, road_yaw = road.project(b.x_m, b.y_m)
        if not rear_s - FOLLOWER_REACH_M < s < rear_s or abs(d - lane_d) >= band:
            continue
        if s > nearest_s:
            nearest_s = s
            closing = b.speed_mps * math.cos(b.yaw_rad - road_yaw) > EGO_STANDSTILL_MPS
    return closing
