"""The co-simulation step loop: SUMO, radar, EOAM logic, plant and write-back, step by step.

Three rates: the EOAM's decision/control every ``step_s`` (10 ms); SUMO every
``sumo_step_s`` (by default the same 10 ms; up to 100 ms, the road users interpolated between
its steps by :mod:`eoam_sumo.sim.interpolation`, the ego's pose written back at each); the
plant at ``plant_dt_s`` (1 ms) inside each control step, all sub-steps in one compiled call
(the automotive radar scans at its own cycle). A step (:meth:`CoSimulation.step`) is a
sequence of named phases: ``sense`` (the ego in the road frame, the radar on the road users
near it), ``decide`` (EOAM decision and control), ``actuate`` (the plant), ``write_back``
(the ego's pose to SUMO with ``moveToXY``, SUMO one step on), ``check_contact`` (oriented
boxes at each plant sub-step), then the observers (time series, running extremes, anything
added) and ``finished``.
"""

from __future__ import annotations

import gc
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

from eoam_sumo.drivers.controller import make_controller
from eoam_sumo.eoam import (
    Command,
    EgoMeasurement,
    ObjectState,
    Perception,
)
from eoam_sumo.eoam_messages import NextLaneView
from eoam_sumo.errors import InputError
from eoam_sumo.params import VehicleParams
from eoam_sumo.plant import Plant, initial_state
from eoam_sumo.plant.model import AX_LOAD, AY_LOAD
from eoam_sumo.plant.stepping import brake_gains_n_per_bar
from eoam_sumo.sensing.automotive import make_radar
from eoam_sumo.sensing.friction import FrictionBelief
from eoam_sumo.sensing.next_lane import NextLaneSensing
from eoam_sumo.sensing.radar import RadarReport
from eoam_sumo.sim.facts import collect_facts, collect_info
from eoam_sumo.sim.interpolation import ego_ahead, interpolate_reports
from eoam_sumo.sim.margins import (
    EGO_STANDSTILL_MPS,
    Margins,
    follower_arriving,
    road_user_close_ahead,
)
from eoam_sumo.sim.observers import (
    AvoidedObstacle,
    Extremes,
    RolloverWatch,
    StepObserver,
    TimeSeries,
    no_lap,
)
from eoam_sumo.sim.outcome import role_of
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.sim.runlog import RunLog, write_run
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.session import SumoSession
from eoam_sumo.sim.session.session import SideLane
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.sim.severity import ContactRecord, substep_contact
from eoam_sumo.sim.summary import RunSummary
from eoam_sumo.sim.trafficlog import TrafficLog
from eoam_sumo.sim.vehicle import TYRES, rollover_limits, vehicle_tables
from eoam_sumo.sim.verdict import summarise
from eoam_sumo.world.bodies import Body, nav_angle_deg
from eoam_sumo.world.geometry import (
    GAP_ROUNDING_M,
    OrientedBox,
    box_distance,
    boxes_overlap,
    gap_lower_bound,
)

__all__ = ["CoSimulation", "policy_settings", "run_case"]


#: Box gaps are measured and contact checked for a road user whose box may lie within a watch
#: of the ego's box: the centres' distance minus both bounding radii (a lower bound of the box
#: gap) at most ``GAP_WATCH_M - ego radius - WATCH_RADIUS_M``. A road user smaller than
#: ``WATCH_RADIUS_M`` (a car, a van, a person) counts as that large: watched while the centres
#: are within ``GAP_WATCH_M``; a longer one (a trailer) as far as its box may come.
GAP_WATCH_M = 20.0  # centre distance watched for road users up to WATCH_RADIUS_M [m]
WATCH_RADIUS_M = 4.0  # a 7.5 m x 2.5 m box's bounding radius [m]
ROAD_END_MARGIN_M = 50.0  # a run ends when the ego is this close to the end of its road [m]
ROAD_END_LAST_M = 1.0  # ... or, a road user ahead, when its front is this close to it [m]
ROAD_END_SIDE_M = 1.0  # a road user ahead this far beside the ego's path at most counts [m]
#: A run ends when the ego's centre is this far beyond the road's edge with no road user near
#: (ours: its box some 2 m clear of the road; ``left_road`` judges from 0.5 m) [m].
OFF_ROAD_END_M = 3.0


class CoSimulation:
    """One run of a SUMO scenario with the ego driven by the plant under the EOAM logic.

    ``run()`` does it all. To drive it by hand: ``start()``, then ``step()`` until it returns
    True, then ``finish()``; between steps the run's state is readable (``t``, ``x`` the plant
    state, ``meas``, ``perception``, ``cmd``, ``bodies``, ``first_contact``). ``observers``
    (see :mod:`eoam_sumo.sim.observers`) watch every step.
    """

    #: Called as each phase of a step ends, with its name, and with "" as a step begins:
    #: ``no_lap``, unless an observer times the phases (PhaseTimer). Never a bound method of
    #: the simulation: that would make it a reference cycle, freed only by a full garbage
    #: collection (in a batch worker, after hundreds of runs' memory).
    lap: Callable[[str], None]
    # the run's state, set by ``start`` and the steps
    session: SumoSession
    meas: EgoMeasurement
    perception: Perception
    cmd: Command
    bodies: list[Body]
    bodies_before: list[Body]

    def __init__(
        self,
        cfg: Path,
        overrides: ScenarioOverrides | None = None,
        settings: RunSettings | None = None,
        params: VehicleParams | None = None,
        observers: Sequence[StepObserver] = (),
    ):
        self.cfg = Path(cfg)
        self.overrides = overrides = overrides or ScenarioOverrides()
        self.settings = settings = settings or RunSettings()
        self.params = params or settings.vehicle
        self.tables = vehicle_tables(settings.vehicle_id, self.params, settings.tables_dir)
        # refuse what the tables do not cover before starting SUMO (checked again at the start)
        self.tables.check_run(
            overrides.mu if overrides.mu is not None else self.tables.mu_grid[-1],
            overrides.ego_speed_mps
            if overrides.ego_speed_mps is not None
            else self.tables.speed_grid_mps[0],
        )
        self.plant = Plant(self.params, dt_s=settings.plant_dt_s, substeps=settings.substeps)
        self.radar = make_radar(settings.radar_model, settings.radar, settings.seed)
        self.belief = self._new_belief()
        if isinstance(self.belief.belief, float):
            self.tables.check_run(self.belief.belief, self.tables.speed_grid_mps[0])
        self.extra_observers = tuple(observers)
        self.lap = no_lap

    def _new_belief(self) -> FrictionBelief:
        st = self.settings
        return FrictionBelief(st.mu_belief, seed=st.seed, mu_min=self.tables.mu_grid[0])

    # ----------------------------------------------------------------------------- a whole run
    def run(self) -> tuple[dict, RunLog]:
        """The whole run: (summary as summary.json writes it, the time series).

        The objects built before the step loop (modules, tables, SUMO's set-up) are frozen out
        of Python's garbage collector over the loop, so that its collections scan only what the
        loop made (a full collection otherwise walks the whole heap)."""
        wall0 = time.perf_counter()
        session = self.open_session()
        try:
            self.start(session, wall0)
            gc.freeze()
            try:
                while not self.step():
                    pass
            finally:
                gc.unfreeze()
            summary = self.finish()
        finally:
            session.close()
        return summary.as_dict(), self.timeseries.log

    def open_session(self) -> SumoSession:
        """Start SUMO on the scenario (the caller closes the session)."""
        st = self.settings
        return SumoSession.start(
            self.cfg,
            self.overrides,
            ego_id=st.ego_id,
            step_length_s=st.sumo_step_length_s,
            gui=st.gui,
            use_traci=st.use_traci,
            gui_settings=st.gui_settings,
        )

    # ----------------------------------------------------------------------------- set-up
    def start(self, session: SumoSession, wall0: float | None = None) -> None:
        """Set the run up on an open session: the ego's plant state, road frame, controller
        and observers; refuses a road user overlapping the ego at its departure."""
        self.session = session
        self.wall0 = time.perf_counter() if wall0 is None else wall0
        self.step_s = self.settings.step_s
        p = self.params
        session.size_ego(p.length_m, p.width_m, p.mass_kg)
        ego = session.ego_body()
        self._place_ego(session, ego)
        self._set_up_sensing(session, ego)
        self._set_up_geometry()
        self._reset_run_state(session)
        self._check_departure()
        st = self.settings
        self.belief = self._new_belief()
        left = self.side_lanes[0]  # the radar's next lane is the lane to the left, as wide
        radar = st.radar if left is None else replace(st.radar, next_lane_width_m=left.width_m)
        self.radar = make_radar(st.radar_model, radar, st.seed)  # fresh state per run
        self.mu_true = self.mu_start
        self._start_observers()
        self._loop0 = time.perf_counter()

    def _place_ego(self, session: SumoSession, ego: Body) -> None:
        """The ego at its departure: the friction under it, the road frame of its lane, its
        plant state and a fresh controller; refuses what the tables do not cover."""
        self.mu_start = session.friction_at_ego()
        self.tables.check_run(self.mu_start, ego.speed_mps)
        self.ego_initial_speed_mps = ego.speed_mps
        self.road = road = RoadFrame(session.ego_lane_centreline())
        road.locate(ego.x_m, ego.y_m)
        self.lane_width_m = session.lane_width_m
        self.left_lane = session.left_lane_exists
        self.next_lane_opposing = self.left_lane and session.next_lane_traffic()[0]
        # the lanes beside the ego's its class may use (the EOAM may evade into either)
        self.side_lanes = (session.side_lane(1), session.side_lane(-1))
        if self.side_lanes[0] is None:  # the safe policy still senses the left side
            opposing, limit = session.next_lane_traffic()
            self._left_fallback = SideLane("", self.lane_width_m, limit, opposing)
        self.left_usable = self.side_lanes[0] is not None
        self.mu_sides = _side_frictions(session, self.side_lanes)
        self.right_width_m = self.side_lanes[1].width_m if self.side_lanes[1] else 0.0
        cg_x_m, cg_y_m = _centre_of_gravity(ego, self.params)
        kappa, road_yaw = _start_curve(road, cg_x_m, cg_y_m)
        self.x = initial_state(
            cg_x_m,
            cg_y_m,
            road_yaw if kappa else ego.yaw_rad,
            ego.speed_mps,
            params=self.params,
            curvature_per_m=kappa,
        ).tolist()
        self.x_prev = self.x
        self.ax = self.ay = 0.0
        self.ctrl = make_controller(
            self.settings.driver, self.params, self.tables, self.settings.eoam
        )
        self.ctrl.reset(ego.speed_mps)

    def _set_up_sensing(self, session: SumoSession, ego: Body) -> None:
        """The next lane's sensing (safe policy), the traffic log and how far around the ego
        SUMO reports road users: from the front bumper, where the radar is; further for V2X
        and the corner radars, and for the traffic log (its radius is from the centre of
        gravity)."""
        st, p = self.settings, self.params
        self.lane_sensing = self._next_lane_sensing(1)  # safe policy, or a right lane
        self.right_sensing = self._next_lane_sensing(-1)  # a usable right lane only
        self.traffic = TrafficLog(
            st.ego_id,
            ego.vclass,
            p.length_m,
            p.width_m,
            p.cg_to_front_bumper_m - 0.5 * p.length_m,
            session.ego_lane_centreline(),
            self.lane_width_m,
        )
        self._sense_radius_m = max(
            st.radar.range_m,
            self.lane_sensing.reach_m if self.lane_sensing else 0.0,
            self.right_sensing.reach_m if self.right_sensing else 0.0,
            self.traffic.radius_m + p.cg_to_front_bumper_m,
        )

    def _set_up_geometry(self) -> None:
        """The time limit in steps, where the road ends for the run, and the ego's box seen
        from its centre of gravity (front, box centre, the radii the contact check uses)."""
        st, p = self.settings, self.params
        self.max_steps = round(st.max_time_s / st.step_s)
        self._end_s_m = self.road.length_m - ROAD_END_MARGIN_M  # the run ends this close
        self._front = front = p.cg_to_front_bumper_m
        self._back = front - 0.5 * p.length_m  # CG to the ego box's centre, as in OrientedBox
        self._ego_box_radius = math.hypot(0.5 * p.length_m, 0.5 * p.width_m)
        self._ego_radius = 0.5 * math.hypot(p.length_m, p.width_m) + front - 0.5 * p.length_m

    def _reset_run_state(self, session: SumoSession) -> None:
        """Nothing hit, no gap measured, no end yet; SUMO's time and the road users near the
        ego at the departure."""
        self.first_contact: ContactRecord | None = None
        self.min_gap_aro_m = math.inf
        self._gaps: dict = {}  # vid -> (box, gap) measured at the last step's ego pose
        self._gaps_pose: tuple | None = None
        # vid -> True: first met in the ego's lane band ahead of the ego (the obstacle, which
        # keeps that identity once passed); False: first met behind it (a follower)
        self._met_ahead: dict[str, bool] = {}
        self._obstacles: set[str] = set()  # road users once in the obstacle's role (``_role``)
        self.end_cause: str | None = None
        self._end_request: str | None = None  # an observer's end of the run (``request_end``)
        self.n_steps = 0
        self._stop_at: float | None = None
        self.t = self.t_start = session.time_s
        self.bodies = session.nearby(self._sense_radius_m)  # with their boxes
        self._reset_rates()

    def _reset_rates(self) -> None:
        """A multi-rate run's state: control steps since SUMO's earlier report, that report
        (SUMO's time then, in ms) and its later one; the margin the contact check allows for
        a road user's move in a step beyond its speed's."""
        st = self.settings
        self._every = st.sumo_every
        self._since_sumo = 0
        self._report0 = self._report1 = self.bodies
        self._step_ms = round(st.step_s * 1000.0)
        self._sumo_step_ms = round(st.sumo_step_length_s * 1000.0)
        # SUMO inserts the ego one of its steps after its departure: the run's clock is the
        # 10 ms reference's, which starts one 10 ms step after it
        self._sumo_ms = round(self.t * 1000.0) - (self._sumo_step_ms - self._step_ms)
        if self._every > 1:
            self.t = self.t_start = self._sumo_ms / 1000.0
        self._reach_pad_m = 0.05 if self._every == 1 else 0.1

    def _check_departure(self) -> None:
        """Refuse a road user overlapping the ego's box at its departure."""
        p, x = self.params, self.x
        start_box = OrientedBox.from_axis_point(
            x[0], x[1], x[2], p.length_m, p.width_m, self._front
        )
        for b in self.bodies:
            if boxes_overlap(start_box, b.box):
                raise InputError(f"{self.cfg}: vehicle '{b.vid}' overlaps the ego at its departure")
        self._cy, self._sy = math.cos(x[2]), math.sin(x[2])

    def _start_observers(self) -> None:
        """The run's own observers (time series, extremes, traffic log, margins, the avoided
        obstacle), then those added, all started; the step's phases untimed until one of them
        times them."""
        p = self.params
        self.timeseries = TimeSeries(brake_gains_n_per_bar(p))
        self.extremes = Extremes()
        self.margins = Margins(p.length_m, p.width_m, self._front)
        self.avoided = AvoidedObstacle()
        self.rollover = RolloverWatch(*rollover_limits(p), AX_LOAD, AY_LOAD, TYRES)
        self.observers = (
            self.timeseries,
            self.extremes,
            self.traffic,
            self.margins,
            self.avoided,
            self.rollover,
            *self.extra_observers,
        )
        self.lap = no_lap
        for obs in self.observers:
            obs.start(self)
        self._after_step = tuple(obs.after_step for obs in self.observers)

    # ----------------------------------------------------------------------------- the step
    def step(self) -> bool:
        """One co-simulation step (as highway-env's ``AbstractEnv.step``: named phases in
        order, ``observers.PHASES``, each followed by ``lap`` with its name); True when the
        run is over."""
        lap = self.lap
        lap("")
        self.meas, self.perception = meas, perception = self.sense()
        lap("sense")
        self.cmd = cmd = self.decide(meas, perception)
        lap("decide")
        self.actuate(cmd)
        lap("actuate")
        self.write_back()
        lap("write_back")
        self.check_contact()
        lap("check_contact")
        self.n_steps += 1
        for after_step in self._after_step:
            after_step(self)
        return self.finished()

    def sense(self) -> tuple[EgoMeasurement, Perception]:
        """The ego in the road frame and the radar's view of the road users, at time ``t``."""
        x, road = self.x, self.road
        X, Y, yaw, vx, vy, r = x[:6]
        s, d, road_yaw = road.project(X, Y)
        self.mu_true = mu_true = self.session.friction_at_ego()
        mu, mu_right = self._believed_mu(mu_true)
        front = self._front
        front_xy = (X + front * self._cy, Y + front * self._sy)
        report = self.radar.scan(front_xy, yaw, vx, road, self.bodies, self.lane_width_m, self.t)
        left = right = None
        if self.lane_sensing is not None:
            left = self.lane_sensing.update(self.t, front_xy, yaw, road, report, self.bodies)
        if self.right_sensing is not None:
            right = self.right_sensing.update(self.t, front_xy, yaw, road, report, self.bodies)
        perception = _perception(report, left, right)
        meas = EgoMeasurement(
            self.t,
            vx,
            vy,
            r,
            self.ax,
            self.ay,
            s,
            d,
            yaw - road_yaw,  # e_yaw not wrapped:
            road.curvature_at(s),
            mu,
            self.lane_width_m,
            self.left_usable,  # yaw is continuous
            mu_right,
            mu_true if self.belief.belief == "known" else mu,
        )
        return meas, perception

    def _believed_mu(self, mu_true: float) -> tuple[float, float]:
        """The friction the EOAM believes for a lane change to the left (or to its only usable
        side) and to the right. Known friction: the lower of the ego's lane's and the lane
        that lane change takes (the net's, or --mu), so that a lane the EOAM does not evade
        into does not lower it; that belief is recorded at ``decide``. Braking in its lane,
        the EOAM believes the friction under the ego (``EgoMeasurement.mu_lane``)."""
        if self.belief.belief != "known":
            mu = self.belief.mu(mu_true, self.t, self.ax, self.ay)
            return mu, mu
        left_mu, right_mu = self.mu_sides
        mu = min(mu_true, left_mu)
        return mu, (mu if math.isnan(right_mu) else min(mu_true, right_mu))

    def decide(self, meas: EgoMeasurement, perception: Perception) -> Command:
        """The EOAM's decision and control for this step; known friction: the belief it
        used, on the side it chose (``_believed_mu``), recorded."""
        cmd = self.ctrl.step(meas, perception, self.settings.step_s)
        if self.belief.belief == "known":
            used = meas.mu_right if self.ctrl.state.side < 0 else meas.mu
            self.belief.mu(used, self.t, self.ax, self.ay)
        return cmd

    def actuate(self, cmd: Command) -> None:
        """The plant over the step, on the road's true friction: all sub-steps in one call."""
        self.x_prev = x = self.x
        self.x, y_out = self.plant.advance(
            x, (cmd.steer_cmd_rad, cmd.drive_force_cmd_n, cmd.brake_force_cmd_n), self.mu_true
        )
        self.ax, self.ay = y_out[0], y_out[1]

    def write_back(self) -> None:
        """The ego's pose to SUMO (front bumper, navigation angle), SUMO one step on, and the
        road users around the ego then; in a multi-rate run, between SUMO's steps, the road
        users interpolated instead."""
        X, Y, yaw, vx = self.x[:4]
        self._cy, self._sy = cy, sy = math.cos(yaw), math.sin(yaw)
        if self._every > 1:
            self._multi_rate_step()
            return
        front = self._front
        session = self.session
        session.move_ego(X + front * cy, Y + front * sy, nav_angle_deg(yaw), max(vx, 0.0))
        session.step()
        self.t = session.time_s
        self.bodies_before, self.bodies = self.bodies, session.nearby(self._sense_radius_m)

    def _multi_rate_step(self) -> None:
        """SUMO one step ahead of the control steps: at the first control step after SUMO's
        earlier report, the ego's pose carried on to SUMO's next step
        (:func:`~eoam_sumo.sim.interpolation.ego_ahead`) and SUMO one step on; the road users
        between its two reports (:func:`~eoam_sumo.sim.interpolation.interpolate_reports`)."""
        self._since_sumo = since = self._since_sumo + 1
        session = self.session
        if since == 1:
            ahead_s = (self._sumo_step_ms - self._step_ms) / 1000.0
            X, Y, yaw, speed = ego_ahead(self.x, self.ax, ahead_s)
            front = self._front
            session.move_ego(
                X + front * math.cos(yaw), Y + front * math.sin(yaw), nav_angle_deg(yaw), speed
            )
            session.step()
            self._report0, self._report1 = self._report1, session.nearby(self._sense_radius_m)
        since_ms = since * self._step_ms
        self.t = (self._sumo_ms + since_ms) / 1000.0
        self.bodies_before = self.bodies
        self.bodies = interpolate_reports(
            self._report0, self._report1, since_ms / 1000.0, self._sumo_step_ms / 1000.0
        )
        if since == self._every:
            self._since_sumo = 0
            self._sumo_ms += self._sumo_step_ms

    def check_contact(self) -> None:
        """Ground truth: oriented-box contact with every road user near the ego at every plant
        sub-step of the step, and the smallest gap to the in-lane obstacle (ARO)."""
        x_prev, x = self.x_prev, self.x
        Xn, Yn, yawn = x[0], x[1], x[2]
        back, cy, sy = self._back, self._cy, self._sy
        ego_cx, ego_cy = Xn + back * cy, Yn + back * sy
        ego_box = None  # built when a body comes close
        # farthest any point of the ego box moved during the step (translation + rotation)
        ego_move = math.hypot(Xn - x_prev[0], Yn - x_prev[1]) + self._ego_radius * abs(
            yawn - x_prev[2]
        )
        step_s = self.settings.step_s
        ego_box_radius, p = self._ego_box_radius, self.params
        gaps = self._gaps if (Xn, Yn, yawn) == self._gaps_pose else {}
        self._gaps, self._gaps_pose = {}, (Xn, Yn, yawn)
        min_gap_aro = self.min_gap_aro_m
        for b in self.bodies:
            vid, _, bx, by, _, speed_mps, _, _, parked, box = b  # see ``_BodyFields``
            _, _, _, _, _, _, _, _, _, radius_m = box
            centres_m = math.hypot(bx - ego_cx, by - ego_cy)
            # the box gap's bound beyond the watch (the same as centres - ego radius -
            # max(radius, WATCH_RADIUS_M) > GAP_WATCH_M - ego radius - WATCH_RADIUS_M)
            if centres_m - max(radius_m - WATCH_RADIUS_M, 0.0) > GAP_WATCH_M:
                continue
            reach_m = ego_move + speed_mps * step_s + self._reach_pad_m
            # the bounding circles' gap is a lower bound of the boxes' gap
            circles_m = centres_m - ego_box_radius - radius_m - GAP_ROUNDING_M
            if circles_m > reach_m and circles_m >= min_gap_aro:
                continue  # the box gap can be neither the ARO's least nor a contact
            # a parked car cannot be the ARO: its role is worked out only if it is hit; the
            # obstacle keeps its identity once it left the lane band (a person crossing on)
            role = None if parked else self._role(b)
            aro = role == "aro" or vid in self._obstacles
            if circles_m > reach_m and not aro:
                continue
            if ego_box is None:
                ego_box = OrientedBox.from_axis_point(
                    Xn, Yn, yawn, p.length_m, p.width_m, self._front
                )
            bound_m = gap_lower_bound(ego_box, box) - GAP_ROUNDING_M  # tighter, dearer
            if bound_m > reach_m and (not aro or bound_m >= min_gap_aro):
                continue
            known = gaps.get(vid)  # the same boxes as at the last step: the same gap
            gap = known[1] if known is not None and known[0] is box else box_distance(ego_box, box)
            self._gaps[vid] = (box, gap)
            if aro and gap < self.min_gap_aro_m and self._met_ahead_of(b, ego_cx, ego_cy):
                self.min_gap_aro_m = gap
            # contact during the step is possible only if the gap is within both moves
            if self.first_contact is None and gap <= reach_m:
                before = next((o for o in self.bodies_before if o.vid == b.vid), b)
                found = substep_contact(
                    x_prev, x, b, before, p.length_m, p.width_m, self._front, self.settings.substeps
                )
                if found is not None:
                    hit, ebox, obox = found
                    self.first_contact = ContactRecord(
                        hit, self._role_hit(b, role, ego_cx, ego_cy), self.t, b, ebox, obox
                    )

    def _role_hit(self, b, role: str | None, ego_x_m: float, ego_y_m: float) -> str:
        """The role of a road user hit (``role_of``; ``role`` when known): one in the ego's
        lane band first met behind the ego is a follower (``other``), never the obstacle."""
        role = role or self._role(b)
        if role == "aro" and not self._met_ahead_of(b, ego_x_m, ego_y_m):
            return "other"
        return role

    def _role(self, b) -> str:
        """``role_of`` a road user, remembering those once in the obstacle's role: one that
        then crosses the ego's lane keeps it, cross traffic never in it does not."""
        role = role_of(b, self.road, self.lane_width_m, was_obstacle=b.vid in self._obstacles)
        if role == "aro":
            self._obstacles.add(b.vid)
        return role

    def _met_ahead_of(self, b, ego_x_m: float, ego_y_m: float) -> bool:
        """Whether a road user in the ego's lane band was first met ahead of the ego (the
        obstacle, which keeps that identity once passed), not behind it (a follower)."""
        ahead = (b.x_m - ego_x_m) * self._cy + (b.y_m - ego_y_m) * self._sy > 0.0
        return self._met_ahead.setdefault(b.vid, ahead)

    def finished(self) -> bool:
        """Whether the run is over: a contact, a rollover (``sim/vehicle.py``: past it the
        plant, which has no roll, no longer describes the car), the ego far off the road
        (``_off_the_road``), ``settle_s`` after the EOAM
        handed back to NORMAL after a manoeuvre or stopped (a manoeuvre begun in that time
        runs to its end; not while the ego moves towards a road user close ahead in its lane:
        :func:`~eoam_sumo.sim.margins.road_user_close_ahead`), the end of the road, or the
        time limit. Sets ``end_cause``."""
        if self.first_contact is not None:
            self.end_cause = "contact"
            return True
        if self.rollover.time_s is not None:
            self.end_cause = "rollover"
            return True
        if self._off_the_road():
            self.end_cause = "left_road"
            return True
        if not self.eoam_done():
            self._stop_at = None  # (again) a manoeuvre under way: run on to its end
        elif self._stop_at is None:
            self._stop_at = self.t + self._run_on_s()
        if (
            self._stop_at is not None
            and self.t >= self._stop_at - 1e-9
            and not road_user_close_ahead(
                self.x, self._front, self.road, self.lane_width_m, self.mu_true, self.bodies
            )
            and not self._waiting_for_follower()
        ):
            self.end_cause = "settled"
        elif self.meas.s_m > self._end_s_m and not self._road_user_before_the_end():
            self.end_cause = "road_end"
        elif self.n_steps >= self.max_steps:
            self.end_cause = self._end_request or "time_limit"
        else:
            return False
        return True

    def _off_the_road(self) -> bool:
        """Whether the ego's centre is more than ``OFF_ROAD_END_M`` beyond the road's edge
        (its lane, the lane left of it if any, the usable one right of it: ``left_road``'s
        road) and no road user is within ``GAP_WATCH_M`` of it: nothing on the road is left
        to meet, and the run would wander to its time limit."""
        d, w = self.meas.d_m, self.lane_width_m
        left = 0.5 * w + (w if self.left_lane else 0.0)
        beyond = max(d - left, -0.5 * w - self.right_width_m - d)
        if beyond <= OFF_ROAD_END_M:
            return False
        X, Y = self.x[0], self.x[1]
        return all(math.hypot(b.x_m - X, b.y_m - Y) > GAP_WATCH_M for b in self.bodies)

    def _road_user_before_the_end(self) -> bool:
        """Whether the ego, in the road end's margin (``ROAD_END_MARGIN_M``), may still meet a
        road user ahead of it before its front bumper is at the very end of the road
        (``ROAD_END_LAST_M``): one whose box lies across the ego's path (their half widths
        and ``ROAD_END_SIDE_M`` apart at most), its back short of that end. The run goes on
        to meet it (it ended 50 m short and hid the contact)."""
        front_s = self.meas.s_m + self._front
        last_s = self.road.length_m - ROAD_END_LAST_M
        if front_s > last_s:
            return False
        d_ego, half_width = self.meas.d_m, 0.5 * self.params.width_m
        for b in self.bodies:
            s, d, _ = self.road.project(b.x_m, b.y_m)
            back_s = s - 0.5 * b.length_m
            side = abs(d - d_ego) - half_width - 0.5 * b.width_m
            if front_s < s and back_s <= last_s and side <= ROAD_END_SIDE_M:
                return True
        return False

    def request_end(self, cause: str) -> None:
        """End the run after this step, its ``end_cause`` ``cause`` (an OpenSCENARIO
        StopTrigger: ``storyboard``), unless a contact, a rollover or the settling ends it
        first."""
        self.max_steps = self.n_steps
        self._end_request = cause

    def _run_on_s(self) -> float:
        """How long the run goes on once the EOAM is done: ``after_stop_s`` after a stop
        when set, else ``settle_s``."""
        st = self.settings
        if st.after_stop_s is not None and self.x[3] < EGO_STANDSTILL_MPS:
            return st.after_stop_s
        return st.settle_s

    def _waiting_for_follower(self) -> bool:
        """By default (no ``after_stop_s``), a stopped ego waits for a road user behind it
        moving towards it (``margins.follower_arriving``): it stops behind the ego, or hits
        it."""
        if self.settings.after_stop_s is not None or self.x[3] >= EGO_STANDSTILL_MPS:
            return False
        return follower_arriving(
            self.x, self._front - self.params.length_m, self.road, self.lane_width_m, self.bodies
        )

    def eoam_done(self) -> bool:
        """The EOAM is over: handed back to NORMAL after a manoeuvre, or stopped."""
        ctrl = self.ctrl
        mode = ctrl.mode
        return (mode == 0 and len(ctrl.modes_visited) > 1) or (
            mode in (1, 3) and self.x[3] < EGO_STANDSTILL_MPS
        )

    # ----------------------------------------------------------------------------- the end
    def finish(self) -> RunSummary:
        """The end state to the observers, the outcome and the run's summary."""
        loop_wall_s = time.perf_counter() - self._loop0
        self.meas = self._end_state()
        for obs in self.observers:
            obs.end(self)
        self.loop_wall_s = loop_wall_s
        facts = collect_facts(self)
        return summarise(facts, collect_info(self, loop_wall_s))

    def _end_state(self) -> EgoMeasurement:
        """The ego at the end of the run (no road curvature: nothing steers from it)."""
        x = self.x
        X, Y, yaw, vx = x[:4]
        s, d, road_yaw = self.road.project(X, Y)
        self.mu_true = self.session.friction_at_ego()
        return EgoMeasurement(
            self.t,
            vx,
            x[4],
            x[5],
            self.ax,
            self.ay,
            s,
            d,
            yaw - road_yaw,
            0.0,
            self.mu_true,
            self.lane_width_m,
            self.left_usable,
        )

    def _next_lane_sensing(self, side: int) -> NextLaneSensing | None:
        """The sensing of the lane on ``side`` (+1 left, -1 right): the left one for every
        policy (each checks the road users in it at a commit), the right one too when the
        ego's class may use it (the EOAM then chooses its side); None: no usable lane there."""
        st = self.settings
        left, right = self.side_lanes
        if right is None and side < 0:
            return None
        lane = left if side > 0 else right
        if lane is None:
            if side < 0:
                return None
            lane = self._left_fallback
        return NextLaneSensing(
            opposing=lane.opposing,
            speed_limit_mps=lane.speed_limit_mps,
            lane_width_m=self.lane_width_m,
            radar_range_m=st.radar.range_m,
            radar_fov_deg=st.radar.fov_deg,
            ego_length_m=self.params.length_m,
            ego_width_m=self.params.width_m,
            v2x=st.v2x,
            corner=st.corner_radar,
            fastest_mps=st.eoam.policy.opposing_speed_mps,
            side=side,
            target_width_m=lane.width_m,
        )

    def policy_record(self) -> dict:
        """The policy, the V2X settings and what the sight-distance gate needed."""
        st = self.settings
        record = {
            "policy": st.eoam.policy.name,
            "v2x_range_m": st.v2x.range_m,
            "v2x_latency_s": st.v2x.latency_s,
            "v2x_loss": st.v2x.loss,
            "v2x_penetration": st.v2x.penetration,
        }
        if self.ctrl.policy is not None:
            return {**record, **self.ctrl.policy.summary()}
        return {
            **record,
            "sight_gate": "",
            "sight_needed_m": None,
            "sight_known_free_m": None,
            "sight_time_s": None,
            "sight_reason": self.ctrl.parts.gate.reason,
            "tie_break": "",
        }


def policy_settings(
    settings: RunSettings,
    policy: str,
    v2x_range_m: float = 0.0,
    v2x_latency_s: float = 0.1,
    v2x_loss: float = 0.0,
    v2x_penetration: float = 1.0,
) -> RunSettings:
    """``settings`` with the decision policy and the V2X link set."""
    eoam = replace(settings.eoam, policy=replace(settings.eoam.policy, name=policy))
    v2x = replace(
        settings.v2x,
        range_m=v2x_range_m,
        latency_s=v2x_latency_s,
        loss=v2x_loss,
        penetration=v2x_penetration,
    )
    return replace(settings, eoam=eoam, v2x=v2x)


def run_case(
    cfg: Path,
    overrides: ScenarioOverrides | None = None,
    out_dir: Path | None = None,
    settings: RunSettings | None = None,
    extra: dict | None = None,
    timeseries: str = "csv",
) -> dict:
    """Run one case; write the time series and the traffic log (``timeseries``: csv, parquet
    or none) and ``summary.json`` to ``out_dir`` if given."""
    sim = CoSimulation(cfg, overrides, settings)
    summary, log = sim.run()
    if extra:
        summary = {**extra, **summary}
    if out_dir is not None:
        write_run(
            Path(out_dir),
            summary,
            log,
            timeseries,
            sim.traffic,
            sim.session.ego_lane_centreline(),
        )
    return summary


def _centre_of_gravity(ego: Body, params: VehicleParams) -> tuple[float, float]:
    """Where the plant's centre of gravity starts: ``cg_to_front_bumper_m`` behind the front
    bumper SUMO departed (half the box ``ego`` ahead of its centre), as every write-back
    places the front bumper from it."""
    back_m = 0.5 * ego.length_m - params.cg_to_front_bumper_m
    return (
        ego.x_m + back_m * math.cos(ego.yaw_rad),
        ego.y_m + back_m * math.sin(ego.yaw_rad),
    )


#: A road straighter than this at the ego's start is straight (a radius above 100 km).
STRAIGHT_PER_M = 1.0e-5


def _start_curve(road: RoadFrame, x_m: float, y_m: float) -> tuple[float, float]:
    """The road's curvature where the ego starts (0 on a straight, ``STRAIGHT_PER_M``) and
    its heading there: on a curve the plant starts turning on it
    (``plant.stepping.initial_state``) along the road's smooth heading (SUMO's angle is its
    lane segment's: 0.025 rad off on a 400 m curve of 25 m chords, 0.8 m/s of drift at
    120 km/h)."""
    s_m, _, road_yaw = road.project(x_m, y_m)
    kappa = road.curvature_at(s_m)
    return (kappa, road_yaw) if abs(kappa) > STRAIGHT_PER_M else (0.0, road_yaw)


def _side_frictions(session: SumoSession, side_lanes: tuple) -> tuple[float, float]:
    """The friction of the lane a lane change takes, (left, right): the left lane's, or the
    right lane's when only that one is usable (inf: neither); the right lane's (nan: not
    usable, the EOAM does not evade right). Each the lowest along the route within the
    manoeuvre's reach (``SumoSession.side_friction``)."""
    left, right = (
        session.side_friction(side) if lane else math.nan
        for side, lane in zip((1, -1), side_lanes, strict=True)
    )
    if math.isnan(left):
        left = math.inf if math.isnan(right) else right
    return left, right


_NOTHING = Perception(None, None, False)  # immutable, so shared by all steps that see nothing


def _perception(
    report: RadarReport,
    next_lane: NextLaneView | None = None,
    right_lane: NextLaneView | None = None,
) -> Perception:
    """The EOAM's view of a radar report: the in-path obstacle as an object, the oncoming
    flag, the nearest oncoming road user as an object, the range of a coasted in-path
    object; with what is known of the lanes beside (``next_lane`` left, ``right_lane``)."""
    det, coasted = report.in_path, report.coasted
    oncoming = _nearest_oncoming(report) if report.oncoming_detected else None
    nothing_beside = next_lane is None and right_lane is None
    if det is None and oncoming is None and coasted is None and nothing_beside:
        return _NOTHING
    obstacle: ObjectState | None = None
    aro_range: float | None = None
    aro_rate: float | None = None
    next_range: float | None = None
    seen = oncoming is not None
    if det is not None:
        obstacle = ObjectState(det.s_m, det.d_m, det.road_speed_mps, det.length_m, det.width_m)
        aro_range, aro_rate, seen = det.range_m, det.range_rate_mps, report.oncoming_detected
        next_range = report.next_lane_range_m
    return Perception(
        aro_range,
        aro_rate,
        seen,
        obstacle,
        next_range,
        next_lane,
        None if coasted is None else coasted.range_m,
        0.0 if coasted is None else coasted.range_rate_mps,
        oncoming,
        right_lane,
    )


def _nearest_oncoming(report: RadarReport) -> ObjectState | None:
    """The nearest detection classed oncoming, as an object (detections are sorted by range)."""
    for det in report.detections:
        if det.category == "oncoming":
            return ObjectState(
                det.s_m, det.d_m, det.road_speed_mps, det.length_m, det.width_m, report.time_s
            )
    return None
