"""What a run came to, as facts: the record the verdict (``sim/verdict.py``) is a pure function
of, and what the summary records of the run's set-up and wall times.

:class:`RunFacts` holds what happened: the road of the ego's original lane, the EOAM's modes
and warning, the ego's end state and running extremes, the first contact and what SUMO
reports of the body hit, the margins, whether a lane change passed the obstacle it avoided,
a rollover, and how the run ended. :class:`RunInfo` holds what the summary adds: the
settings that shaped the run, the scenario's files and the wall times. Both are filled once,
at the end of the run, from the co-simulation and its observers (:func:`collect_facts`,
:func:`collect_info`); a test builds them by hand.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from mypy_extensions import mypyc_attr

from eoam_sumo.sim.observers import RunView
from eoam_sumo.sim.runlog import RunLog
from eoam_sumo.sim.severity import ContactRecord


@mypyc_attr(native_class=False)  # a Python dataclass: built by hand in tests, replaced
@dataclass(frozen=True, kw_only=True)
class RunFacts:
    """What happened in a run (road frame of the ego's original lane, left positive).

    The defaults are a run in which nothing happened: no contact, no margin measured, the
    ego on its lane centre."""

    # the road: the original lane's width, and whether a lane (either direction) lies left
    lane_width_m: float
    left_lane: bool
    # the EOAM: modes 0-5 in order of first visit, the warning, a manoeuvre still under way
    # at the end; when it first left NORMAL (mode 0), the obstacle's range then (nan: none
    # seen) and the friction it believed then (all None/nan when it never did)
    modes_visited: tuple[int, ...]
    fcw_raised: bool = False
    manoeuvre_running: bool = False
    trigger_time_s: float | None = None
    trigger_range_m: float = math.nan
    mu_believed_at_trigger: float | None = None
    # the ego: mass, start, end state, running extremes (``observers.Extremes``) and the
    # largest |lateral acceleration| logged
    ego_mass_kg: float
    ego_initial_speed_mps: float = 0.0
    mu_start: float = 1.0
    final_offset_m: float = 0.0
    final_speed_mps: float = 0.0
    min_offset_m: float = 0.0
    max_offset_m: float = 0.0
    max_abs_offset_m: float = 0.0
    max_abs_heading_error_rad: float = 0.0
    min_speed_mps: float = 0.0
    max_abs_lat_accel_mps2: float = 0.0
    # the first contact (None: none) and the mass SUMO reports for the road user hit [kg]
    contact: ContactRecord | None = None
    contact_sumo_mass_kg: float = math.nan
    # the margins (``sim/margins.py``; infinite: never measured) and whether they make a
    # near miss of a run without contact; the time with the ego's centre left of its lane,
    # in the next lane whatever its direction, and in it when that lane is the opposite one
    min_gap_aro_m: float = math.inf
    min_gap_oncoming_m: float = math.inf
    min_ttc_oncoming_s: float = math.inf
    time_in_opposite_lane_s: float = 0.0
    time_in_next_lane_s: float = 0.0
    near_miss_margins: bool = False
    # along the lanes: the smallest time to collision with any moving road user and with
    # those behind; the ego's follower: smallest gap, largest DRAC and deceleration, who
    min_ttc_s: float = math.inf
    min_ttc_rear_s: float = math.inf
    min_gap_rear_m: float = math.inf
    max_drac_rear_mps2: float = 0.0
    max_follower_decel_mps2: float = 0.0
    follower_decel_id: str | None = None
    # around the ego: whether it ended ahead of the obstacle its lane change avoided (None:
    # no lane change, or the obstacle gone), whether oncoming traffic came within the log
    passed_obstacle: bool | None = None
    oncoming_traffic: bool = False
    # the end: contact, rollover, left_road, settled, road_end, time_limit or storyboard;
    # simulated time since the departure
    end_cause: str = "settled"
    sim_time_s: float = 0.0
    # the road's width right of the original lane: a lane there the ego may evade into
    right_width_m: float = 0.0
    # rollover (``sim/vehicle.py``): SUMO time of the step both inner wheels had lifted or
    # the static stability limit was passed (None: never), which, and the smallest tyre load
    # [N]; the first single wheel lift (None: never), its tyre and the load's ay [m/s2]
    rollover_time_s: float | None = None
    rollover_cause: str = ""
    min_tyre_load_n: float = math.inf
    wheel_lift_time_s: float | None = None
    wheel_lift_tyre: str = ""
    wheel_lift_ay_mps2: float = 0.0


@mypyc_attr(native_class=False)  # a Python dataclass: built by hand in tests
@dataclass(frozen=True, kw_only=True)
class RunInfo:
    """What the summary records beside the facts: the settings and files of the run and its
    wall times (the whole run's, and the step loop's)."""

    mu_belief: str | float
    driver: str  # the ego's controller (``RunSettings.driver``)
    policy_record: dict  # the policy, V2X and sight-distance fields of the summary
    radar_model: str
    seed: int
    vehicle: str
    abs_fitted: bool
    esc_fitted: bool
    radar_range_m: float
    radar_fov_deg: float
    net_file: str
    sumo_overrides: dict
    wall_time_s: float
    loop_wall_s: float


class EndedRun(RunView, Protocol):
    """What the facts are collected from: a co-simulation that has ended (``CoSimulation``)."""

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
    def next_lane_opposing(self) -> bool: ...  # the lane left of the ego's is the opposite one
    @property
    def right_width_m(self) -> float: ...  # a usable lane's width right of the ego's (0: none)

    # the co-simulation's parts: settings, parameters, controller, friction belief, observers
    settings: Any
    params: Any
    ctrl: Any
    belief: Any
    timeseries: Any
    traffic: Any
    extremes: Any
    margins: Any
    avoided: Any
    rollover: Any

    def eoam_done(self) -> bool: ...
    def policy_record(self) -> dict: ...


def collect_facts(sim: EndedRun) -> RunFacts:
    """The facts of a run that has ended (``sim.meas`` its end state, the observers ended)."""
    ext, margins, meas, record = sim.extremes, sim.margins, sim.meas, sim.first_contact
    log = sim.timeseries.log
    return RunFacts(
        lane_width_m=sim.lane_width_m,
        left_lane=sim.left_lane,
        modes_visited=tuple(sim.ctrl.modes_visited),
        fcw_raised=bool(sim.ctrl.fcw_raised),
        manoeuvre_running=not sim.eoam_done(),
        **_trigger(log, sim.belief),
        ego_mass_kg=sim.params.mass_kg,
        ego_initial_speed_mps=sim.ego_initial_speed_mps,
        mu_start=sim.mu_start,
        final_offset_m=meas.d_m,
        final_speed_mps=meas.vx_mps,
        min_offset_m=ext.min_d_m,
        max_offset_m=ext.max_d_m,
        max_abs_offset_m=ext.max_abs_offset_m,
        max_abs_heading_error_rad=ext.max_abs_heading_error_rad,
        min_speed_mps=ext.min_vx_mps,
        max_abs_lat_accel_mps2=log.max_abs("ay_mps2"),
        contact=record,
        contact_sumo_mass_kg=math.nan if record is None else sim.session.mass_kg(record.body.vid),
        min_gap_aro_m=sim.min_gap_aro_m,
        min_gap_oncoming_m=margins.min_gap_oncoming_m,
        min_ttc_oncoming_s=margins.min_ttc_oncoming_s,
        # the margins count the steps left of the lane, whatever the next lane's direction
        time_in_opposite_lane_s=margins.time_in_left_lane_s if sim.next_lane_opposing else 0.0,
        time_in_next_lane_s=margins.time_in_next_lane_s,
        near_miss_margins=margins.near_miss(),
        min_ttc_s=margins.min_ttc_s,
        min_ttc_rear_s=margins.min_ttc_rear_s,
        min_gap_rear_m=margins.min_gap_rear_m,
        max_drac_rear_mps2=margins.max_drac_rear_mps2,
        max_follower_decel_mps2=margins.max_follower_decel_mps2,
        follower_decel_id=margins.follower_decel_id,
        passed_obstacle=sim.avoided.passed,
        oncoming_traffic=sim.traffic.had_role("oncoming"),
        end_cause=sim.end_cause or "",
        sim_time_s=sim.t - sim.t_start,
        right_width_m=sim.right_width_m,
        rollover_time_s=sim.rollover.time_s,
        rollover_cause=sim.rollover.cause,
        min_tyre_load_n=sim.rollover.min_load_n,
        wheel_lift_time_s=sim.rollover.lift_time_s,
        wheel_lift_tyre=sim.rollover.lift_tyre,
        wheel_lift_ay_mps2=sim.rollover.lift_ay_mps2,
    )


def collect_info(sim: EndedRun, loop_wall_s: float) -> RunInfo:
    """The set-up and wall times of a run that has ended; ``loop_wall_s`` its step loop's."""
    st = sim.settings
    return RunInfo(
        mu_belief=sim.belief.label,
        driver=st.driver,
        policy_record=sim.policy_record(),
        radar_model=st.radar_model,
        seed=st.seed,
        vehicle=st.vehicle_id,
        abs_fitted=sim.params.abs_fitted,
        esc_fitted=sim.params.esc_fitted,
        radar_range_m=st.radar.range_m,
        radar_fov_deg=st.radar.fov_deg,
        net_file=str(sim.session.net_file.resolve()),
        sumo_overrides=dict(sim.session.sumo_overrides),
        wall_time_s=time.perf_counter() - sim.wall0,
        loop_wall_s=loop_wall_s,
    )


def _trigger(log: RunLog, belief: Any) -> dict[str, Any]:
    """When the EOAM first left NORMAL (mode 0): SUMO time, the obstacle's range then (nan:
    none seen) and the friction it believed (``FrictionBelief.at``); None, nan and None when
    it never did."""
    modes = log.column("mode")
    acting = np.flatnonzero(np.isfinite(modes) & (modes != 0))
    if acting.size == 0:
        return {}
    k = int(acting[0])
    t = float(log.column("time_s")[k])
    return {
        "trigger_time_s": t,
        "trigger_range_m": float(log.column("aro_range_m")[k]),
        "mu_believed_at_trigger": belief.at(t),
    }
