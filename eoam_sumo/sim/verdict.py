"""What a run came to: the outcome colour and the typed summary, from the co-simulation's
state at its end (ground truth: the first contact, the running extremes, the margins, the
obstacle a lane change avoided)."""

from __future__ import annotations

import math
import time
from typing import Any, Protocol

import numpy as np

from eoam_sumo.sensing.friction import FrictionBelief
from eoam_sumo.sim.observers import RunView, StepObserver
from eoam_sumo.sim.outcome import classify_outcome, left_road
from eoam_sumo.sim.radar import LANE_MARGIN_M
from eoam_sumo.sim.runlog import RunLog
from eoam_sumo.sim.severity import ContactRecord, contact_severity
from eoam_sumo.sim.summary import RunSummary, finite_or_none, rounded

#: How a run ended -> what cut it off, for the ``unfinished`` rule (None: the loop's rules).
CUT_OFF = {"time_limit": "time limit", "road_end": "end of the road"}
_LANE_CHANGE_MODES = (2, 4)


class EndedRun(RunView, Protocol):
    """What the verdict reads of a co-simulation that has ended (``CoSimulation``)."""

    @property
    def first_contact(self) -> ContactRecord | None: ...
    @property
    def end_cause(self) -> str | None: ...
    @property
    def t_start(self) -> float: ...
    @property
    def wall0(self) -> float: ...
    @property
    def mu_start(self) -> float: ...
    @property
    def ego_initial_speed_mps(self) -> float: ...
    @property
    def min_gap_aro_m(self) -> float: ...
    @property
    def belief(self) -> FrictionBelief: ...

    # the co-simulation's parts: settings, parameters, session, road, controller, observers
    settings: Any
    params: Any
    ctrl: Any
    timeseries: Any
    traffic: Any
    extremes: Any
    margins: Any
    avoided: Any

    def eoam_done(self) -> bool: ...
    def policy_record(self) -> dict: ...


class AvoidedObstacle(StepObserver):
    """The SUMO id of the obstacle a lane change avoided: when the EOAM first began one (mode 2
    or 4), the nearest road user ahead of the ego with its centre in the ego's lane band (from
    ground truth, for the verdict only; the EOAM never sees it)."""

    vid: str | None

    def start(self, sim: RunView) -> None:
        self.vid = None
        self._done = False

    def after_step(self, sim: RunView) -> None:
        if self._done or sim.cmd.mode not in _LANE_CHANGE_MODES:
            return
        self._done = True
        band_m = 0.5 * sim.lane_width_m + LANE_MARGIN_M
        s_ego, nearest = sim.meas.s_m, math.inf
        for b in sim.bodies_before:  # the road users at the start of that step
            s, d, _ = sim.road.project(b.x_m, b.y_m)
            if abs(d) < band_m and s_ego < s < s_ego + nearest:
                self.vid, nearest = b.vid, s - s_ego


def passed_obstacle(sim: EndedRun, vid: str | None) -> bool | None:
    """Whether the ego's centre ended ahead of the obstacle ``vid`` along its road (None when
    no lane change began or the obstacle has left the simulation)."""
    if vid is None:
        return None
    body = next((b for b in sim.bodies if b.vid == vid), None)
    if body is None:
        try:
            body = sim.session.body(vid)
        except Exception:  # noqa: BLE001 - gone from SUMO (libsumo and TraCI raise differently)
            return None
    s_obstacle = sim.road.project(body.x_m, body.y_m)[0]
    return sim.meas.s_m > s_obstacle


def summarise(sim: EndedRun, loop_wall_s: float) -> RunSummary:
    """The outcome and summary of a run that has ended (``sim.meas`` its end state)."""
    ext, margins, meas = sim.extremes, sim.margins, sim.meas
    lane_width = sim.lane_width_m
    left_width = lane_width if sim.left_lane else 0.0
    record = sim.first_contact
    severity = None
    if record is not None:
        severity = contact_severity(
            record, sim.params.mass_kg, sim.session.mass_kg(record.body.vid)
        )
    passed = passed_obstacle(sim, sim.avoided.vid)
    outcome = classify_outcome(
        modes_visited=sim.ctrl.modes_visited,
        max_lateral_offset_m=ext.max_abs_offset_m,
        lane_width_m=lane_width,
        contact=record.contact if record else None,
        role=record.role if record else "none",
        final_offset_m=meas.d_m,
        final_speed_mps=meas.vx_mps,
        max_abs_heading_error_rad=ext.max_abs_heading_error_rad,
        min_speed_mps=ext.min_vx_mps,
        min_offset_m=ext.min_d_m,
        max_offset_m=ext.max_d_m,
        left_width_m=left_width,
        direct_overlap=severity.direct_overlap if severity else 1.0,
        cut_off=CUT_OFF.get(sim.end_cause or ""),
        manoeuvre_running=not sim.eoam_done(),
        passed_obstacle=passed,
    )
    sim_time = sim.t - sim.t_start
    log = sim.timeseries.log
    return RunSummary(
        outcome=outcome.colour,
        collision_with=outcome.collision_with,
        impact_speed_mps=rounded(outcome.impact_speed_mps),
        contact_kind=record.contact.kind if record else "none",
        contact_time_s=record.time_s if record else None,
        contact_x_m=rounded(record.contact.point[0]) if record else None,
        contact_y_m=rounded(record.contact.point[1]) if record else None,
        collision_with_id=record.body.vid if record else None,
        collision_with_class=record.body.vclass if record else None,
        contact_overlap=rounded(severity.overlap) if severity else None,
        impact_angle_rad=rounded(severity.impact_angle_rad) if severity else None,
        delta_v_ego_mps=rounded(severity.delta_v_ego_mps) if severity else None,
        collision_with_mass_kg=rounded(severity.other_mass_kg) if severity else None,
        reason=outcome.reason,
        modes_visited=tuple(sim.ctrl.modes_visited),
        fcw_raised=bool(sim.ctrl.fcw_raised),
        mu=sim.mu_start,
        mu_belief=sim.belief.label,
        **_trigger(log, sim.belief),
        **sim.policy_record(),
        radar_model=sim.settings.radar_model,
        seed=sim.settings.seed,
        min_gap_aro_m=finite_or_none(sim.min_gap_aro_m),
        min_gap_oncoming_m=finite_or_none(margins.min_gap_oncoming_m),
        min_ttc_oncoming_s=finite_or_none(margins.min_ttc_oncoming_s),
        time_in_opposite_lane_s=rounded(margins.time_in_opposite_lane_s),
        near_miss=record is None and margins.near_miss(),
        passed_obstacle=passed,
        end_cause=sim.end_cause or "",
        max_abs_lat_accel_mps2=rounded(log.max_abs("ay_mps2")),
        max_lateral_offset_m=rounded(ext.max_abs_offset_m),
        final_lateral_offset_m=rounded(meas.d_m),
        final_speed_mps=rounded(meas.vx_mps),
        min_speed_mps=rounded(ext.min_vx_mps),
        max_abs_heading_error_rad=rounded(ext.max_abs_heading_error_rad),
        left_road=left_road(ext.min_d_m, ext.max_d_m, lane_width, left_width),
        ego_initial_speed_mps=rounded(sim.ego_initial_speed_mps),
        lane_width_m=rounded(sim.lane_width_m),
        oncoming_traffic=sim.traffic.had_role("oncoming"),
        net_file=str(sim.session.net_file.resolve()),
        radar_range_m=sim.settings.radar.range_m,
        radar_fov_deg=sim.settings.radar.fov_deg,
        sim_time_s=rounded(sim_time),
        wall_time_s=time.perf_counter() - sim.wall0,
        realtime_factor=sim_time / loop_wall_s,
        sumo_overrides=dict(sim.session.sumo_overrides),
    )


def _trigger(log: RunLog, belief: FrictionBelief) -> dict:
    """When the EOAM first left NORMAL (mode 0): SUMO time, the obstacle's range then and the
    friction it believed (all None when it never did)."""
    modes = log.column("mode")
    acting = np.flatnonzero(np.isfinite(modes) & (modes != 0))
    if acting.size == 0:
        return {"trigger_time_s": None, "trigger_range_m": None, "mu_believed_at_trigger": None}
    k = int(acting[0])
    t = float(log.column("time_s")[k])
    rng = float(log.column("aro_range_m")[k])
    return {
        "trigger_time_s": round(t, 6),
        "trigger_range_m": round(rng, 6) if math.isfinite(rng) else None,
        "mu_believed_at_trigger": belief.at(t),
    }
