"""The co-simulation step loop: SUMO, radar, EOAM logic, plant and write-back, step by step.

Two rates: SUMO and the EOAM decision/control run every ``step_s`` (10 ms by default); the
plant integrates at ``plant_dt_s`` (1 ms) inside each SUMO step, all sub-steps in one compiled
call. Per SUMO step: sense (radar on the vehicles SUMO reports near the ego), decide and
control, advance the plant, write the ego pose back with ``moveToXY``, step SUMO, check contact
with every other vehicle on oriented boxes at each plant sub-step, log.
"""

from __future__ import annotations

import contextlib
import gc
import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from eoam_sumo.eoam import EgoMeasurement, EoamController, EoamSettings, ObjectState, Perception
from eoam_sumo.errors import InputError
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import VehicleParams, ego_e_class_sedan
from eoam_sumo.plant import Plant, initial_state
from eoam_sumo.sensing.automotive import make_radar
from eoam_sumo.sensing.friction import FrictionBelief
from eoam_sumo.sensing.next_lane import CornerRadarSettings, NextLaneSensing
from eoam_sumo.sensing.v2x import V2XSettings
from eoam_sumo.sim.bodies import nav_angle_deg
from eoam_sumo.sim.geometry import OrientedBox, box_distance, boxes_overlap, contact
from eoam_sumo.sim.outcome import classify_outcome, left_road, role_of
from eoam_sumo.sim.radar import RadarReport, RadarSettings
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.sim.runlog import RunLog
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.session import SumoSession
from eoam_sumo.sim.session.gui import GuiSettings


@dataclass(frozen=True)
class RunSettings:
    """Rates, limits and sub-settings of one co-simulation run."""

    step_s: float = 0.01  # SUMO and decision/control step [s]; whole milliseconds in SUMO
    plant_dt_s: float = 0.001  # plant integration step [s]
    max_time_s: float = 40.0  # simulated time limit [s]
    settle_s: float = 2.0  # run on this long after the hand-back or a stop [s]
    ego_id: str = "ego"
    gui: bool = False
    use_traci: bool = False
    gui_settings: GuiSettings = field(default_factory=GuiSettings)  # with gui: pacing, view
    tables_dir: Path | None = None
    radar: RadarSettings = field(default_factory=RadarSettings)
    eoam: EoamSettings = field(default_factory=EoamSettings)
    mu_belief: str | float = "known"  # sensing.friction: known, estimate or a number
    seed: int = 0  # seeds every random model of the run (friction estimator, radar)
    v2x: V2XSettings = field(default_factory=V2XSettings)  # used by the safe policy
    corner_radar: CornerRadarSettings = field(default_factory=CornerRadarSettings)
    radar_model: str = "ideal"  # sensing.automotive: ideal or automotive

    def __post_init__(self) -> None:
        ms = self.step_s * 1000.0
        if self.step_s <= 0 or abs(ms - round(ms)) > 1e-9:
            raise ValueError(f"step_s={self.step_s} must be a positive whole number of ms")
        n = self.step_s / self.plant_dt_s
        if self.plant_dt_s <= 0 or abs(n - round(n)) > 1e-9:
            raise ValueError(f"plant_dt_s={self.plant_dt_s} must divide step_s={self.step_s}")
        if self.max_time_s <= 0:
            raise ValueError(f"max_time_s={self.max_time_s} must be > 0")
        if self.v2x.enabled and self.eoam.policy.name != "safe":
            raise ValueError("V2X informs the safe policy only: set policy 'safe' or V2X "
                             "range 0")

    @property
    def substeps(self) -> int:
        return round(self.step_s / self.plant_dt_s)


GAP_WATCH_M = 20.0  # centre distance under which box gaps are measured and contact checked [m]
ROAD_END_MARGIN_M = 50.0  # a run ends when the ego is this close to the end of its road [m]
ROUNDING_M = 1e-6  # margin for rounding when a lower bound of a gap rules the gap out [m]


@contextlib.contextmanager
def _collector_paused():
    """Pause Python's cyclic garbage collector (restored after): the step loop makes no
    reference cycles, reference counting frees all it allocates, and the collector's passes
    over the young tuples cost ~2 us per step on average."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


class CoSimulation:
    """One run of a SUMO scenario with the ego driven by the plant under the EOAM logic."""

    def __init__(
        self,
        cfg: Path,
        overrides: ScenarioOverrides | None = None,
        settings: RunSettings | None = None,
        params: VehicleParams | None = None,
    ):
        self.cfg = Path(cfg)
        self.overrides = overrides = overrides or ScenarioOverrides()
        self.settings = settings = settings or RunSettings()
        self.params = params or ego_e_class_sedan()
        tables_dir = settings.tables_dir or default_tables_dir()
        self.tables = LookupTables.load(tables_dir, params=self.params)
        # refuse what the tables do not cover before starting SUMO (checked again at the start)
        self.tables.check_run(
            overrides.mu if overrides.mu is not None else self.tables.mu_grid[-1],
            overrides.ego_speed_mps if overrides.ego_speed_mps is not None
            else self.tables.speed_grid_mps[0],
        )
        self.plant = Plant(self.params, dt_s=settings.plant_dt_s, substeps=settings.substeps)
        self.radar = make_radar(settings.radar_model, settings.radar, settings.seed)
        self.belief = self._new_belief()
        if isinstance(self.belief.belief, float):
            self.tables.check_run(self.belief.belief, self.tables.speed_grid_mps[0])

    def _new_belief(self) -> FrictionBelief:
        st = self.settings
        return FrictionBelief(st.mu_belief, seed=st.seed, mu_min=self.tables.mu_grid[0])

    def run(self) -> tuple[dict, RunLog]:
        st = self.settings
        wall0 = time.perf_counter()
        session = SumoSession.start(
            self.cfg, self.overrides, ego_id=st.ego_id, step_length_s=st.step_s,
            gui=st.gui, use_traci=st.use_traci, gui_settings=st.gui_settings,
        )
        try:
            with _collector_paused():
                summary, log = self._loop(session, wall0)
            summary["sumo_overrides"] = dict(session.sumo_overrides)
            return summary, log
        finally:
            session.close()

    def _loop(self, session: SumoSession, wall0: float) -> tuple[dict, RunLog]:
        st, p = self.settings, self.params
        clock = time.perf_counter
        ego = session.ego_body()
        mu0 = session.friction_at_ego()
        self.tables.check_run(mu0, ego.speed_mps)
        road = RoadFrame(session.ego_lane_centreline())
        road.locate(ego.x_m, ego.y_m)
        lane_width = session.lane_width_m
        x = initial_state(ego.x_m, ego.y_m, ego.yaw_rad, ego.speed_mps).tolist()  # plain floats
        ctrl = EoamController(p, self.tables, st.eoam)
        ctrl.reset(ego.speed_mps)
        left_lane = session.left_lane_exists
        lane_sensing = self._next_lane_sensing(session, lane_width)  # safe policy only
        # from the front bumper, where the radar is; further for V2X and the corner radars
        sense_radius = max(st.radar.range_m, lane_sensing.reach_m if lane_sensing else 0.0)
        steps = round(st.max_time_s / st.step_s)
        end_s_m = road.length_m - ROAD_END_MARGIN_M  # the run ends this close to the road end
        log = RunLog(steps + 1)
        front = p.cg_to_front_bumper_m
        back = front - 0.5 * p.length_m  # CG to the ego box's centre, as in OrientedBox
        ego_box_radius = math.hypot(0.5 * p.length_m, 0.5 * p.width_m)
        ego_radius = 0.5 * math.hypot(p.length_m, p.width_m) + front - 0.5 * p.length_m
        ax = ay = 0.0
        first_contact = None
        min_gap_aro = math.inf
        # loss of control and road departure (outcome rule 1), plain floats: the extremes of the
        # ego's lateral offset d (signed), of its heading error (wrapped) and of its vx
        min_d = max_d = 0.0
        max_e_yaw = 0.0
        min_vx = x[3]
        pi, tau = math.pi, math.tau
        stop_at = None
        t = t_start = session.time_s
        bodies = session.nearby(sense_radius)  # with their boxes: the radar's targets
        start_box = OrientedBox.from_axis_point(x[0], x[1], x[2], p.length_m, p.width_m, front)
        for b in bodies:
            if boxes_overlap(start_box, b.box):
                raise InputError(f"{self.cfg}: vehicle '{b.vid}' overlaps the ego at its "
                                 "departure")
        cy, sy = math.cos(x[2]), math.sin(x[2])
        self.belief = belief = self._new_belief()
        self.radar = make_radar(st.radar_model, st.radar, st.seed)  # fresh state per run
        radar, plant, step_s = self.radar, self.plant, st.step_s
        t_sense = t_control = t_plant = t_sumo = t_contact = 0.0
        loop0 = clock()
        n_steps = 0
        for n_steps in range(1, steps + 1):  # noqa: B007 - the count is read after the loop
            # --- sense: the world at time t ---------------------------------------------------
            c0 = clock()
            X, Y, yaw, vx, vy, r = x[:6]
            s, d, road_yaw = road.project(X, Y)
            mu_true = session.friction_at_ego()
            mu = belief.mu(mu_true, t, ax, ay)
            report = radar.scan(
                (X + front * cy, Y + front * sy), yaw, vx, road, bodies, lane_width, t
            )
            perception = _perception(report)
            if lane_sensing is not None:
                perception = perception._replace(next_lane=lane_sensing.update(
                    t, (X + front * cy, Y + front * sy), yaw, road, report, bodies))
            e_yaw = yaw - road_yaw  # not wrapped: the plant's yaw is continuous
            meas = EgoMeasurement(
                t, vx, vy, r, ax, ay, s, d, e_yaw, road.curvature_at(s), mu, lane_width,
                left_lane,
            )
            # --- decide and control -------------------------------------------------------------
            c1 = clock()
            cmd = ctrl.step(meas, perception, step_s)
            c2 = clock()
            log.add(t, x, ax, ay, s, d, e_yaw, mu_true, cmd, perception)
            # --- plant: all sub-steps of this SUMO step in one call -----------------------------
            c3 = clock()
            x_prev = x
            x, y_out = plant.advance(
                x, (cmd.steer_cmd_rad, cmd.drive_force_cmd_n, cmd.brake_force_cmd_n), mu_true
            )
            ax, ay = y_out[0], y_out[1]
            # --- write back and step SUMO -------------------------------------------------------
            c4 = clock()
            Xn, Yn, yawn, vxn = x[:4]
            cy, sy = math.cos(yawn), math.sin(yawn)
            ego_speed = 0.0 if vxn < 0.0 else vxn
            session.move_ego(Xn + front * cy, Yn + front * sy, nav_angle_deg(yawn), ego_speed)
            session.step()
            t = session.time_s
            bodies_next = session.nearby(sense_radius)
            # --- ground truth: oriented-box contact at every plant sub-step ---------------------
            c5 = clock()
            ego_cx, ego_cy = Xn + back * cy, Yn + back * sy
            ego_box = None  # built when a body comes close
            # farthest any point of the ego box moved during the step (translation + rotation)
            ego_move = math.hypot(Xn - x_prev[0], Yn - x_prev[1]) + ego_radius * abs(
                yawn - x_prev[2])
            for b in bodies_next:
                centres_m = math.hypot(b.x_m - ego_cx, b.y_m - ego_cy)
                if centres_m > GAP_WATCH_M:
                    continue
                reach_m = ego_move + b.speed_mps * step_s + 0.05
                # a parked car cannot be the ARO: its role is worked out only if it is hit
                role = None if b.parked else role_of(b, road, lane_width)
                # the bounding circles' gap is a lower bound of the boxes' gap
                circles_m = centres_m - ego_box_radius - b.box.radius_m - ROUNDING_M
                if circles_m > reach_m and (role != "aro" or circles_m >= min_gap_aro):
                    continue  # the box gap can be neither the ARO's least nor a contact
                if ego_box is None:
                    ego_box = OrientedBox.from_axis_point(Xn, Yn, yawn, p.length_m, p.width_m,
                                                          front)
                gap = box_distance(ego_box, b.box)
                if role == "aro":
                    min_gap_aro = min(min_gap_aro, gap)
                # contact during the step is possible only if the gap is within both moves
                if first_contact is None and gap <= reach_m:
                    before = next((o for o in bodies if o.vid == b.vid), b)
                    hit = self._substep_contact(x_prev, x, b, before)
                    if hit is not None:
                        first_contact = (hit, role or role_of(b, road, lane_width), t)
            bodies = bodies_next
            if d > max_d:
                max_d = d
            elif d < min_d:
                min_d = d
            if vx < min_vx:
                min_vx = vx
            if e_yaw > max_e_yaw or e_yaw < -max_e_yaw:  # wrapped only when it may be a new max
                e_yaw = (e_yaw + pi) % tau - pi
                if e_yaw < 0.0:
                    e_yaw = -e_yaw
                if e_yaw > max_e_yaw:
                    max_e_yaw = e_yaw
            c6 = clock()
            t_sense += c1 - c0
            t_control += c2 - c1
            t_plant += c4 - c3
            t_sumo += c5 - c4
            t_contact += c6 - c5
            # --- end of run ---------------------------------------------------------------------
            if first_contact is not None:
                break
            if not self._finished(ctrl, x):
                stop_at = None  # (again) a manoeuvre under way: run on to its end
            elif stop_at is None:
                stop_at = t + st.settle_s
            if stop_at is not None and t >= stop_at - 1e-9:
                break
            if s > end_s_m:
                break
        self.profile = {
            "sense": t_sense, "control": t_control, "plant": t_plant, "sumo": t_sumo,
            "contact": t_contact, "loop_wall_s": clock() - loop0, "steps": n_steps,
        }
        max_lat_offset = max_d if max_d >= -min_d else -min_d  # of the steps' starts, as logged
        X, Y, yaw, vx = x[:4]
        s, d, road_yaw = road.project(X, Y)
        log.add(t, x, ax, ay, s, d, yaw - road_yaw, session.friction_at_ego(), None, None)
        # the end state counts for loss of control and road departure too
        min_d, max_d, min_vx = min(min_d, d), max(max_d, d), min(min_vx, vx)
        max_e_yaw = max(max_e_yaw, abs((yaw - road_yaw + pi) % tau - pi))
        left_width = lane_width if left_lane else 0.0
        contact_info, role, contact_time_s = first_contact or (None, "none", None)
        outcome = classify_outcome(
            modes_visited=ctrl.modes_visited,
            max_lateral_offset_m=max_lat_offset,
            lane_width_m=lane_width,
            contact=contact_info,
            role=role,
            final_offset_m=d,
            final_speed_mps=vx,
            max_abs_heading_error_rad=max_e_yaw,
            min_speed_mps=min_vx,
            min_offset_m=min_d,
            max_offset_m=max_d,
            left_width_m=left_width,
        )
        wall = time.perf_counter() - wall0
        sim_time = t - t_start
        summary = {
            "outcome": outcome.colour,
            "collision_with": outcome.collision_with,
            "impact_speed_mps": round(outcome.impact_speed_mps, 6),
            "contact_kind": contact_info.kind if contact_info else "none",
            "contact_time_s": contact_time_s,
            "reason": outcome.reason,
            "modes_visited": list(ctrl.modes_visited),
            "fcw_raised": bool(ctrl.fcw_raised),
            "mu": mu0,
            "mu_belief": self.belief.label,
            "radar_model": st.radar_model,
            "seed": st.seed,
            **_trigger(log, self.belief),
            "min_gap_aro_m": None if math.isinf(min_gap_aro) else round(min_gap_aro, 6),
            "max_abs_lat_accel_mps2": round(log.max_abs("ay_mps2"), 6),
            "max_lateral_offset_m": round(max_lat_offset, 6),
            "final_lateral_offset_m": round(d, 6),
            "final_speed_mps": round(vx, 6) + 0.0,  # signed; + 0.0 turns -0.0 into 0.0
            "min_speed_mps": round(min_vx, 6) + 0.0,  # lowest forward speed vx, signed
            "max_abs_heading_error_rad": round(max_e_yaw, 6),  # |heading - road heading|
            "left_road": left_road(min_d, max_d, lane_width, left_width),  # CG off the road
            "ego_initial_speed_mps": round(ego.speed_mps, 6),
            "sim_time_s": round(sim_time, 6),
            "wall_time_s": wall,
            "realtime_factor": sim_time / self.profile["loop_wall_s"],
            **self._policy_record(ctrl),
        }
        return summary, log

    def _next_lane_sensing(self, session: SumoSession, lane_width: float):
        """The next lane's sensing for the safe policy (None for the paper's)."""
        st = self.settings
        if st.eoam.policy.name != "safe":
            return None
        opposing, limit = session.next_lane_traffic()
        return NextLaneSensing(
            opposing=opposing, speed_limit_mps=limit, lane_width_m=lane_width,
            radar_range_m=st.radar.range_m, radar_fov_deg=st.radar.fov_deg,
            ego_length_m=self.params.length_m, ego_width_m=self.params.width_m, v2x=st.v2x,
            corner=st.corner_radar, fastest_mps=st.eoam.policy.opposing_speed_mps)

    def _policy_record(self, ctrl: EoamController) -> dict:
        """The policy, the V2X settings and what the sight-distance gate needed."""
        st = self.settings
        record = {"policy": st.eoam.policy.name, "v2x_range_m": st.v2x.range_m,
                  "v2x_latency_s": st.v2x.latency_s, "v2x_loss": st.v2x.loss,
                  "v2x_penetration": st.v2x.penetration}
        if ctrl.policy is not None:
            return {**record, **ctrl.policy.summary()}
        return {**record, "sight_gate": "", "sight_needed_m": None, "sight_known_free_m": None,
                "sight_time_s": None, "tie_break": ""}

    def _finished(self, ctrl: EoamController, x) -> bool:
        """The EOAM is over: handed back to NORMAL after a manoeuvre, or stopped."""
        modes = ctrl.modes_visited
        if len(modes) > 1 and ctrl.mode == 0:
            return True
        return ctrl.mode in (1, 3) and x[3] < 0.05

    def _substep_contact(self, x_prev, x_next, body, b0):
        """First contact at any plant sub-step between ego and body (``b0`` its pose at the
        start of the step), both poses interpolated linearly over the step."""
        p = self.params
        n = self.settings.substeps
        for k in range(1, n + 1):
            w = k / n
            ex = x_prev[0] + w * (x_next[0] - x_prev[0])
            ey = x_prev[1] + w * (x_next[1] - x_prev[1])
            eyaw = x_prev[2] + w * (x_next[2] - x_prev[2])
            bx = b0.x_m + w * (body.x_m - b0.x_m)
            by = b0.y_m + w * (body.y_m - b0.y_m)
            byaw = body.yaw_rad
            ebox = OrientedBox.from_axis_point(
                ex, ey, eyaw, p.length_m, p.width_m, p.cg_to_front_bumper_m
            )
            obox = OrientedBox(bx, by, byaw, body.length_m, body.width_m)
            vx = x_prev[3] + w * (x_next[3] - x_prev[3])
            vy = x_prev[4] + w * (x_next[4] - x_prev[4])
            ce, se = math.cos(eyaw), math.sin(eyaw)
            ve = (vx * ce - vy * se, vx * se + vy * ce)
            vb = (body.speed_mps * math.cos(byaw), body.speed_mps * math.sin(byaw))
            hit = contact(ebox, obox, ve, vb)
            if hit is not None:
                return hit
        return None


def policy_settings(settings: RunSettings, policy: str, v2x_range_m: float = 0.0,
                    v2x_latency_s: float = 0.1, v2x_loss: float = 0.0,
                    v2x_penetration: float = 1.0) -> RunSettings:
    """``settings`` with the decision policy and the V2X link set."""
    eoam = replace(settings.eoam, policy=replace(settings.eoam.policy, name=policy))
    v2x = replace(settings.v2x, range_m=v2x_range_m, latency_s=v2x_latency_s, loss=v2x_loss,
                  penetration=v2x_penetration)
    return replace(settings, eoam=eoam, v2x=v2x)


def run_case(
    cfg: Path,
    overrides: ScenarioOverrides | None = None,
    out_dir: Path | None = None,
    settings: RunSettings | None = None,
    extra: dict | None = None,
    timeseries: str = "csv",
) -> dict:
    """Run one case; write the time series (``timeseries``: csv, parquet or none) and
    ``summary.json`` to ``out_dir`` if given."""
    summary, log = CoSimulation(cfg, overrides, settings).run()
    if extra:
        summary = {**extra, **summary}
    if out_dir is not None:
        from eoam_sumo.sim.runlog import write_run

        write_run(Path(out_dir), summary, log, timeseries)
    return summary


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
    return {"trigger_time_s": round(t, 6),
            "trigger_range_m": round(rng, 6) if math.isfinite(rng) else None,
            "mu_believed_at_trigger": belief.at(t)}


_NOTHING = Perception(None, None, False)  # immutable, so shared by all steps that see nothing
_ONCOMING_ONLY = Perception(None, None, True)


def _perception(report: RadarReport) -> Perception:
    """The EOAM's view of a radar report: the in-path obstacle as an object, the oncoming
    flag."""
    det = report.in_path
    if det is None:
        return _ONCOMING_ONLY if report.oncoming_detected else _NOTHING
    obstacle = ObjectState(det.s_m, det.d_m, det.road_speed_mps, det.length_m, det.width_m)
    return Perception(det.range_m, det.range_rate_mps, report.oncoming_detected, obstacle,
                      report.next_lane_range_m)
