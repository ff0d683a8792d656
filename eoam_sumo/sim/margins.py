"""Safety margins of a run, as an observer of the step: how close the ego came to the road
users around it, how soon it would have hit opposite-direction traffic, how long it spent
left of its lane, and whether a run without contact was a near miss.

* ``min_gap_oncoming_m``: the smallest box-to-box gap to any opposite-direction road user
  (not parked, heading more than 90 deg from the road's direction at the ego): at every step
  while SUMO reports it within the sensing reach, and for every such road user in the
  simulation at the start and at the end of the run (one never within reach has neither met
  nor passed the ego, so the smaller of those two gaps is its smallest); infinite (empty in
  the summary) when there is none;
* ``min_ttc_oncoming_s``: the smallest time to collision with such a road user, both keeping
  their velocities (``geometry.time_to_contact``); infinite when never on a collision course;
* ``time_in_opposite_lane_s``: steps with the ego's centre left of its lane (in the next lane
  to the left, the opposite lane on a two-way road) times the step;
* ``closest_gap_m`` and ``closest_id``: the smallest gap to any road user once within
  ``NEAR_MISS_GAP_M`` (gaps farther out are not measured);
* a run without contact is a **near miss** when it came within ``NEAR_MISS_GAP_M`` of any
  road user or its ``min_ttc_oncoming_s`` fell below ``NEAR_MISS_TTC_S``.

``road_user_close_ahead`` is the ground truth the step loop asks before it ends a run as
settled: a run does not end while the ego moves towards a road user close ahead in its lane.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from eoam_sumo.params import G_MPS2
from eoam_sumo.sim.observers import RunView, StepObserver
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
        self._opposite_steps = 0
        self._step_s = sim.step_s
        self._half_lane_m = 0.5 * sim.lane_width_m
        self._left_lane = sim.left_lane

    @property
    def time_in_opposite_lane_s(self) -> float:
        return self._opposite_steps * self._step_s

    def end(self, sim: RunView) -> None:
        self.min_gap_oncoming_m = min(self.min_gap_oncoming_m, self._opposite_gap(sim, sim.x))

    def _opposite_gap(self, sim: RunView, x) -> float:
        """The smallest gap from the ego (plant state ``x``) to any opposite-direction road
        user in the simulation (infinite when there is none)."""
        X, Y, yaw = x[0], x[1], x[2]
        road_yaw = sim.road.project(X, Y)[2]
        cr, sr = math.cos(road_yaw), math.sin(road_yaw)
        ego = OrientedBox.from_axis_point(X, Y, yaw, self.length_m, self.width_m, self.front_m)
        return min(
            (
                box_distance(ego, b.box)
                for b in sim.session.road_users()
                if not b.parked and b.box.cos_yaw * cr + b.box.sin_yaw * sr < 0.0
            ),
            default=math.inf,
        )

    def near_miss(self) -> bool:
        return self.closest_gap_m <= NEAR_MISS_GAP_M or self.min_ttc_oncoming_s < NEAR_MISS_TTC_S

    def after_step(self, sim: RunView) -> None:
        meas = sim.meas
        if self._left_lane and meas.d_m > self._half_lane_m:
            self._opposite_steps += 1
        X, Y, yaw, vx, vy = sim.x[:5]
        c, s = math.cos(yaw), math.sin(yaw)
        ex, ey = X + self._back_m * c, Y + self._back_m * s
        road_yaw = sim.x_prev[2] - meas.e_yaw_rad  # the road's heading at the ego
        cr, sr = math.cos(road_yaw), math.sin(road_yaw)
        ego_box = None
        for b in sim.bodies:
            box = b.box
            bound = (
                math.hypot(box.x_m - ex, box.y_m - ey)
                - self._radius_m
                - box.radius_m
                - GAP_ROUNDING_M
            )
            opposite = not b.parked and box.cos_yaw * cr + box.sin_yaw * sr < 0.0
            near = bound < NEAR_MISS_GAP_M
            if not (opposite or near):
                continue
            if ego_box is None:
                ego_box = OrientedBox(ex, ey, yaw, self.length_m, self.width_m)
                ve = (vx * c - vy * s, vx * s + vy * c)
            gap = -1.0
            if opposite:
                if bound < self.min_gap_oncoming_m:
                    gap = box_distance(ego_box, box)
                    self.min_gap_oncoming_m = min(self.min_gap_oncoming_m, gap)
                vb = (b.speed_mps * box.cos_yaw, b.speed_mps * box.sin_yaw)
                ttc = time_to_contact(ego_box, box, ve, vb, self.min_ttc_oncoming_s)
                self.min_ttc_oncoming_s = min(self.min_ttc_oncoming_s, ttc)
            if near and bound < self.closest_gap_m:
                # the separating-axis bound rules out most of what the circles let through
                # (a car parked beside the ego)
                if gap < 0.0 and gap_lower_bound(ego_box, box) - GAP_ROUNDING_M < NEAR_MISS_GAP_M:
                    gap = box_distance(ego_box, box)
                if 0.0 <= gap < self.closest_gap_m:
                    self.closest_gap_m, self.closest_id = gap, b.vid


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
