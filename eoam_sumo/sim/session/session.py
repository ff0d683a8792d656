"""A running SUMO scenario with the ego under external control: :class:`SumoSession`.

:meth:`SumoSession.start` loads a ``.sumocfg`` after checking its files, applies the
:class:`~eoam_sumo.sim.scenario.ScenarioOverrides` (surface friction, an added oncoming car,
the ARO's emergency stop), advances SUMO to the ego's departure and makes the step that
inserts the ego at the requested speed (moveToXY before the insertion step). The session then
answers the co-simulation's queries: the ego's reference line, the road users around the ego
(vehicles of every class and persons, as :class:`~eoam_sumo.world.bodies.Body`), the friction
under the ego; :meth:`move_ego` writes the ego's pose back and :meth:`step` advances SUMO.

Time: :attr:`SumoSession.time_s` is SUMO's time at the end of the last step (``getTime``
after ``simulationStep``), the time the co-simulation logs (timeseries.csv ``time_s``). SUMO
labels its own outputs (fcd-output, collision-output, ...) with the time at the start of the
step, so the state logged at t is in SUMO's outputs at t - step length: fcd-output's row at t
holds the ego of timeseries.csv's row at t + 0.01 s (checked with libsumo 1.28; joined on
equal times they differ by one step, 0.33 m at 120 km/h).

Options: SUMO runs with the options of ``launch.sumo_command`` over the sumocfg's;
:attr:`SumoSession.sumo_overrides` names those that change what the sumocfg or SUMO's default
gives. A collision-output that the sumocfg asks for gets the co-simulation's own contacts
(:meth:`SumoSession.record_collision`, written at :meth:`SumoSession.close`).
"""

from __future__ import annotations

import math
import os
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Any, NamedTuple, Self

import numpy as np

from eoam_sumo.errors import InputError
from eoam_sumo.sim.scenario import (
    ROLE_KEY,
    ScenarioFiles,
    ScenarioOverrides,
    check_scenario,
    scripted_stops,
)
from eoam_sumo.sim.scenario.files import float_attr
from eoam_sumo.sim.scenario.values import number
from eoam_sumo.sim.session.calls import StepCalls
from eoam_sumo.sim.session.collisions import CollisionRecord, write_collision_output
from eoam_sumo.sim.session.gui import GuiSettings, GuiView
from eoam_sumo.sim.session.handover import SAVE_STATE_OPTIONS, handover_plan, run_and_hand_over
from eoam_sumo.sim.session.insertion import (
    EgoStart,
    add_oncoming,
    let_fast_vehicles_depart,
    place_ego,
)
from eoam_sumo.sim.session.launch import (
    ERROR_LOG_STDERR,
    shut_down,
    start_error,
    stderr_into,
    sumo_command,
    traci_connect,
)
from eoam_sumo.sim.session.puppets import Puppets
from eoam_sumo.sim.session.scripts import REFERENCE_STEP_S, StopScripts
from eoam_sumo.sim.session.tracking import RoadUsers
from eoam_sumo.world.bodies import PEDESTRIAN, Body

#: How far along the route a lane beside the ego's must be open to its class for the EOAM to
#: evade into it [m]: a lane change and a pass at 50 m/s take about 8 s (400 m).
PERMISSION_REACH_M = 500.0
_open_libsumo: list[SumoSession] = []  # libsumo runs one simulation per process
_NO_OVERRIDES = ScenarioOverrides()
_GUI_DEFAULTS = GuiSettings()
_ERROR_LOG = "sumo-errors.log"  # SUMO's --error-log in the session's working directory


def _delay_ms(text: str | None) -> float | None:
    """The sumocfg's sumo-gui ``delay`` [ms] when it is a number >= 0, else None."""
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        return None
    return value if math.isfinite(value) and value >= 0.0 else None


def _checked_step(overrides: ScenarioOverrides, step_length_s: float) -> float:
    """The SUMO step [s]: > 0 and a whole number of milliseconds (InputError otherwise);
    TypeError for overrides that are not a ScenarioOverrides."""
    if not isinstance(overrides, ScenarioOverrides):
        raise TypeError(f"overrides must be a ScenarioOverrides, not {type(overrides).__name__}")
    step = number("step_length_s", step_length_s, minimum=0.0, inclusive=False)
    if abs(step * 1000.0 - round(step * 1000.0)) > 1e-9:
        raise InputError(f"step_length_s={step_length_s!r} must be a whole number of milliseconds")
    return step


def _check_can_start(gui: bool, via_traci: bool) -> None:
    """InputError for sumo-gui without a display; RuntimeError for a second libsumo session."""
    if (
        gui
        and sys.platform.startswith("linux")
        and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    ):
        raise InputError(
            "--gui needs a display, and DISPLAY is not set (sumo-gui would "
            "fail to connect after 30 s)"
        )
    if not via_traci and _open_libsumo:
        raise RuntimeError("a libsumo session is already open in this process; close it first")


class SideLane(NamedTuple):
    """A lane beside the ego's start lane that its vehicle class may use."""

    lane_id: str
    width_m: float
    speed_limit_mps: float
    opposing: bool  # it carries opposing traffic


class _Started(NamedTuple):
    """A started SUMO: the API module (libsumo or traci), its constants, its error classes,
    the SUMO process (TraCI only, else None) and whether it runs through TraCI."""

    api: Any
    constants: Any
    errors: tuple
    process: Any
    via_traci: bool


def _connect(cmd: list, cfg: Path, error_log: Path, workdir: Path, via_traci: bool) -> _Started:
    """Start SUMO with ``cmd`` through TraCI or in-process libsumo; a start that fails is an
    InputError quoting SUMO's error log."""
    if via_traci:
        import traci

        errors = (traci.exceptions.TraCIException, traci.exceptions.FatalTraCIError)
        try:
            api, process = traci_connect(cmd)
        except (*errors, OSError) as exc:
            raise InputError(start_error(cfg, error_log, exc)) from exc
        return _Started(api, traci.constants, errors, process, True)
    import libsumo

    errors = (libsumo.TraCIException, libsumo.FatalTraCIError)
    try:
        with stderr_into(workdir / ERROR_LOG_STDERR):
            libsumo.start(cmd)
    except errors as exc:
        raise InputError(start_error(cfg, error_log, exc)) from exc
    return _Started(libsumo, libsumo.constants, errors, None, False)


def _started(
    cmd: list, files: ScenarioFiles, ego_id: str, error_log: Path, workdir: Path, via_traci: bool
) -> _Started:
    """SUMO started (``_connect``), the vehicles it loaded let depart above their lane's limit
    (``insertion.let_fast_vehicles_depart``: before the first step, at a handover's longer
    step too)."""
    started = _connect(cmd, files.cfg, error_log, workdir, via_traci)
    let_fast_vehicles_depart(started.api, started.errors, files, ego_id)
    return started


def _hand_over(
    started: _Started, cmd: list, handover_s: float, cfg: Path, error_log: Path, workdir: Path
) -> None:
    """Run SUMO at the sumocfg's step to ``handover_s``, then restart it with ``cmd`` from
    the saved state (``handover.run_and_hand_over``); SUMO is shut if that fails."""
    try:
        with stderr_into(workdir / ERROR_LOG_STDERR):
            run_and_hand_over(started.api, cmd, handover_s, workdir)
    except started.errors as exc:
        shut_down(started.api, started.process)
        raise InputError(start_error(cfg, error_log, exc)) from exc


class SumoSession:
    """One running SUMO scenario with the ego under external control. Use :meth:`start`.

    ``sumo_overrides``: option -> value of the SUMO options the session set over what the
    sumocfg (or SUMO's default) gives."""

    _ego: EgoStart  # the ego's start, placed by start() before any query

    def __init__(
        self,
        api,
        constants,
        errors: tuple,
        files: ScenarioFiles,
        overrides: ScenarioOverrides,
        ego_id: str,
        step_length_s: float,
        workdir: Path,
        process=None,
        sumo_overrides: dict | None = None,
        gui: GuiSettings | None = None,
    ) -> None:
        self._api, self._tc, self._errors, self._files = api, constants, errors, files
        self._overrides, self.ego_id, self._dt = overrides, ego_id, step_length_s
        self._workdir, self._process = workdir, process
        self.sumo_overrides = dict(sumo_overrides or {})
        self.gui = (
            None
            if gui is None
            else GuiView(
                api,
                gui,
                step_length_s,
                _delay_ms(files.options.get("delay")),
                "gui-settings-file" in files.options,
            )
        )
        self._collisions: list[CollisionRecord] = []
        output = files.options.get("collision-output")
        self.collision_output = files.cfg.parent / output if output else None
        self._veh, self._lane, self._sim = api.vehicle, api.lane, api.simulation
        self._calls = calls = StepCalls(api)
        self._closed = False
        self._time_s = self._sim.getTime()
        self._mu_cache: dict[str, float] = {}
        self._scripts = StopScripts(
            api, calls, constants, scripted_stops(files, overrides, ego_id), step_length_s
        )
        self._puppets: Puppets | None = None  # road users an outside storyboard moves
        self._users = RoadUsers(api, calls, constants, ego_id, self._scripts.running)
        self._radius_m: float | None = None
        self._ego_mu = 1.0
        self._over_limit: dict[str, float] = {}  # vid -> speed of a departure above the limit
        self.ego_depart_time_s = self._time_s
        self.oncoming_id: str | None = None
        self.roles = {
            vid: s.params[ROLE_KEY] for vid, s in files.vehicles.items() if ROLE_KEY in s.params
        }

    # ----------------------------------------------------------------------------- start
    @classmethod
    def start(
        cls,
        cfg: Path,
        overrides: ScenarioOverrides = _NO_OVERRIDES,
        *,
        ego_id: str = "ego",
        step_length_s: float = 0.01,
        gui: bool = False,
        use_traci: bool = False,
        extra_args: tuple[str, ...] = (),
        gui_settings: GuiSettings = _GUI_DEFAULTS,
    ) -> SumoSession:
        """Check the files, start SUMO, advance it to the ego's departure and make the step
        inserting the ego at the requested speed; then every query answers. ``gui``:
        ``sumo-gui`` through TraCI (shown as ``gui_settings`` says), ``use_traci``: ``sumo``
        through TraCI; else libsumo (in-process, one a process)."""
        step = _checked_step(overrides, step_length_s)
        extra = tuple(str(a) for a in extra_args)
        files = check_scenario(Path(cfg), ego_id)
        scripted = scripted_stops(files, overrides, ego_id)
        import sumo
        import sumolib

        os.environ.setdefault("SUMO_HOME", sumo.SUMO_HOME)
        via_traci = gui or use_traci
        _check_can_start(gui, via_traci)
        workdir = Path(tempfile.mkdtemp(prefix="eoam-sumo-"))
        error_log = workdir / _ERROR_LOG
        binary = sumolib.checkBinary("sumo-gui" if gui else "sumo")
        cmd, sumo_overrides = sumo_command(
            binary,
            files.cfg,
            files.options,
            step,
            error_log,
            extra,
            gui,
            keep_gui_open=gui_settings.keep_open,
        )
        plan = handover_plan(files, ego_id, step, scripted, extra)
        first_cmd = cmd
        if plan is not None:  # sumo-gui too: a run watched in it is the run without it
            coarse = sumo_command(binary, files.cfg, files.options, plan[0], error_log, extra, gui)
            first_cmd = [*coarse[0], *SAVE_STATE_OPTIONS]
        try:
            started = _started(first_cmd, files, ego_id, error_log, workdir, via_traci)
            if plan is not None:
                _hand_over(started, cmd, plan[1], files.cfg, error_log, workdir)
        except BaseException:
            shutil.rmtree(workdir, ignore_errors=True)
            raise
        return cls._opened(
            started,
            files,
            overrides,
            ego_id,
            step,
            workdir,
            sumo_overrides,
            gui_settings if gui else None,
        )

    @classmethod
    def _opened(
        cls,
        started: _Started,
        files: ScenarioFiles,
        overrides: ScenarioOverrides,
        ego_id: str,
        step: float,
        workdir: Path,
        sumo_overrides: dict,
        gui_settings: GuiSettings | None,
    ) -> SumoSession:
        """The session on a started SUMO, set up to the ego's insertion; on failure SUMO is
        shut and ``workdir`` removed, a TraCI error becoming an InputError that quotes SUMO's
        error log."""
        session = None
        try:
            session = cls(
                started.api,
                started.constants,
                started.errors,
                files,
                overrides,
                ego_id,
                step,
                workdir,
                started.process,
                sumo_overrides,
                gui_settings,
            )
            if not started.via_traci:
                _open_libsumo.append(session)
            session._set_up()
        except BaseException as exc:
            if session is not None:
                session._release()
            else:
                shut_down(started.api, started.process)
            error_log = workdir / _ERROR_LOG
            detail = (
                start_error(files.cfg, error_log, exc) if isinstance(exc, started.errors) else None
            )
            shutil.rmtree(workdir, ignore_errors=True)
            if detail is None:
                raise
            raise InputError(detail) from exc
        return session

    def _check_departures_on_steps(self, ego_depart_s: float) -> None:
        """At a SUMO step longer than the 10 ms reference, the ego's and every scripted
        vehicle's departure must fall on one of SUMO's steps from the begin: SUMO inserts a
        vehicle one of its steps after the step its departure falls in, which the run's clock
        and the scripted holds take as one step after the departure (at 0.07 s from a
        departure at 1 s the ego's first row came before its departure and the obstacle ran
        1.5 m behind the reference). InputError naming the vehicle and its departure."""
        step_ms = round(self._dt * 1000.0)
        if step_ms <= round(REFERENCE_STEP_S * 1000.0):
            return
        departs = {self.ego_id: ego_depart_s}
        for vid in self._scripts.ids:
            spec = self._files.vehicles[vid]
            departs[vid] = float_attr(spec, "depart", spec.attrs.get("depart", "0"))
        for vid, depart in departs.items():
            offset_ms = (depart - self._time_s) * 1000.0
            if abs(offset_ms - step_ms * round(offset_ms / step_ms)) > 1e-6:
                raise InputError(
                    f"{self._files.vehicles[vid].source}: vehicle '{vid}' departs at {depart:g} "
                    f"s, not on a SUMO step of {self._dt:g} s from the begin "
                    f"({self._time_s:g} s): give a SUMO step that divides it (0.01 s always "
                    "does)"
                )

    def _set_up(self) -> None:
        spec = self._files.vehicles[self.ego_id]
        depart = float_attr(spec, "depart", spec.attrs.get("depart", "0"))
        if depart < self._time_s - 1e-9:
            raise InputError(
                f"{spec.source}: vehicle '{self.ego_id}' departs at {depart:g} s, "
                f"before the simulation begins ({self._time_s:g} s)"
            )
        self._check_departures_on_steps(depart)
        if self._overrides.mu is not None:
            settable = True
            for lane_id in self._lane.getIDList():
                self._mu_cache[lane_id] = self._overrides.mu
                if settable:
                    try:
                        self._lane.setFriction(lane_id, self._overrides.mu)
                    except Exception:  # noqa: BLE001 - TraCI's class may come from SUMO_HOME/tools
                        # TraCI of SUMO 1.28 cannot set friction: the override lives here only
                        settable = False
        let_fast_vehicles_depart(self._api, self._errors, self._files, self.ego_id)
        while self._time_s < depart - 0.5 * self._dt:
            self._sumo_step()
        self.ego_depart_time_s = self._time_s
        ego = self._ego = place_ego(
            self._api, self._errors, self._files, self._overrides, self.ego_id, self._over_limit
        )
        if self.gui is not None:
            self.gui.depart(self._time_s, ego.front_xy)
            self.gui.request_screenshots(self._time_s + self._dt)
        self.lane_width_m = ego.lane_width_m
        self.left_lane_exists = ego.left_lane_exists
        self._ego_mu = self._friction(ego.lane_id)
        if self._overrides.oncoming_start_m is not None:
            self.oncoming_id = add_oncoming(
                self._api, self._errors, self._files, self._overrides, ego, self._over_limit
            )
            self.roles[self.oncoming_id] = "oncoming"
        self._veh.subscribe(self.ego_id, self._users.ego_vars)
        self._sumo_step()
        if self.ego_id not in self._veh.getIDList():
            raise InputError(f"{spec.source}: SUMO did not insert vehicle '{self.ego_id}'")
        placed = self._veh.getLaneID(self.ego_id)
        if placed != ego.lane_id:
            raise InputError(
                f"{spec.source}: SUMO placed vehicle '{self.ego_id}' on lane {placed}, not on "
                f"its departure lane {ego.lane_id}"
            )
        for vid, speed in self._over_limit.items():  # departed at rest (see insert)
            self._veh.setPreviousSpeed(vid, speed)
        if self.gui is not None:
            self.gui.follow(self.ego_id)

    # ----------------------------------------------------------------------------- stepping
    def _sumo_step(self) -> None:
        scripts, users = self._scripts, self._users
        if scripts.running:
            scripts.apply(
                self._time_s + self._dt, self._dt, users.step_results(), self._friction, users.watch
            )
        if self._puppets is not None:
            self._puppets.apply()
        calls = self._calls
        calls.step(0.0)
        users.new_step()
        self._time_s = calls.time()
        if users.tracking or scripts.pending:
            departed = calls.departed_ids()
            if users.tracking:
                users.track(departed)
            if scripts.pending:
                for vid in departed:
                    if vid in scripts.pending:
                        scripts.start(vid, users.watch)

    def step(self) -> None:
        """Advance SUMO by one step."""
        self._check_open()
        if self.gui is not None:
            self.gui.before_step(self._time_s + self._dt)
        try:
            self._sumo_step()
        except self._errors as exc:
            raise RuntimeError(f"SUMO failed at t={self._time_s:.3f} s: {exc}") from exc

    @property
    def time_s(self) -> float:
        """SUMO's simulation time."""
        return self._time_s

    @property
    def step_length_s(self) -> float:
        return self._dt

    @property
    def scripted_ids(self) -> frozenset[str]:
        """The vehicles whose emergency stop is scripted (their braking is not traffic's)."""
        return self._scripts.ids

    @property
    def net_file(self) -> Path:
        """The scenario's network file."""
        return self._files.net_file

    # ----------------------------------------------------------------------------- queries
    def ego_lane_centreline(self) -> np.ndarray:
        """(N, 2) centre line of the ego's start lane followed along its route (lane index kept)."""
        return self._ego.centreline.copy()

    def _friction(self, lane_id: str) -> float:
        mu = self._mu_cache.get(lane_id)
        if mu is None:
            mu = self._mu_cache[lane_id] = float(self._lane.getFriction(lane_id))
        return mu

    def friction_at_ego(self) -> float:
        """Friction of the lane under the ego now (the last known one while it is off all lanes)."""
        lane_id = self._ego_results()[self._tc.VAR_LANE_ID]
        if lane_id:
            self._ego_mu = self._friction(lane_id)
        return self._ego_mu

    def lane_friction(self, lane_id: str) -> float:
        """Friction of ``lane_id`` (the net's, or the ``mu`` override)."""
        return self._friction(lane_id)

    def next_lane_traffic(self) -> tuple[bool, float]:
        """(opposing, speed limit [m/s]) of the lane left of the ego's along its route: opposing
        when the ego's start edge has no lane of its own direction to the left but an opposite
        lane; the speed limit is the highest of those lanes along the route (0: none)."""
        ego, opposing, limit = self._ego, False, 0.0
        for edge in ego.route_edges:
            if ego.lane_index < self._api.edge.getLaneNumber(edge) - 1:
                lane: str | None = f"{edge}_{ego.lane_index + 1}"
            else:
                lane = self._files.opposite_lanes.get(f"{edge}_{ego.lane_index}")
                if lane is None:
                    continue
                opposing = opposing or edge == ego.route_edges[0]
            limit = max(limit, float(self._lane.getMaxSpeed(lane)))
        return opposing, limit

    def side_lane(self, side: int) -> SideLane | None:
        """The lane beside the ego's start lane on ``side`` (+1 left, -1 right) on its start
        edge, if the ego's vehicle class may use it (SUMO lane permissions): its width, its
        speed limit (the highest along the route) and whether it carries opposing traffic
        (left only: ``next_lane_traffic``). None: no such lane, or a forbidden one."""
        ego = self._ego
        index = ego.lane_index + side
        if index < 0:
            return None
        start = ego.route_edges[0]
        if index < self._api.edge.getLaneNumber(start):
            lane_id = f"{start}_{index}"
        elif side > 0:
            lane_id = self._files.opposite_lanes.get(ego.lane_id, "")
        else:
            lane_id = ""
        if not lane_id or not self._permits(lane_id) or not self._permitted_ahead(side):
            return None
        if side > 0:
            opposing, limit = self.next_lane_traffic()
        else:
            opposing, limit = False, self._side_limit(side)
        return SideLane(lane_id, float(self._lane.getWidth(lane_id)), limit, opposing)

    def _permits(self, lane_id: str) -> bool:
        """The ego's vehicle class may drive on ``lane_id`` (allowed list empty: all)."""
        vclass = self._api.vehicletype.getVehicleClass(self._ego.type_id)
        allowed = self._lane.getAllowed(lane_id)
        if allowed:
            return vclass in allowed
        return vclass not in self._lane.getDisallowed(lane_id)

    def _beside(self, side: int) -> list[tuple[str, str | None]]:
        """(edge, lane) for each edge of the ego's route: the lane on ``side`` (+1 left, -1
        right) of the lane the ego follows there (SUMO's indices shift where a lane is added
        or dropped), on the left the opposite direction's ``<neigh>`` lane beyond the
        edge's last; None where there is none."""
        beside: list[tuple[str, str | None]] = []
        for edge, lane in zip(self._ego.route_edges, self._ego.route_lanes, strict=False):
            k = int(lane.rsplit("_", 1)[1]) + side
            if 0 <= k < self._api.edge.getLaneNumber(edge):
                beside.append((edge, f"{edge}_{k}"))
            elif side > 0:
                beside.append((edge, self._files.opposite_lanes.get(lane) or None))
            else:
                beside.append((edge, None))
        return beside

    def _beside_within_reach(self, side: int) -> list[str | None]:
        """The lane on ``side`` of the ego's (``_beside``) on each edge of its route that
        begins within ``PERMISSION_REACH_M`` of its start edge's start: where the manoeuvre
        may take the ego."""
        lanes, begun_m = [], 0.0
        for edge, lane in self._beside(side):
            if begun_m > PERMISSION_REACH_M:
                break
            lanes.append(lane)
            begun_m += float(self._lane.getLength(f"{edge}_0"))
        return lanes

    def _permitted_ahead(self, side: int) -> bool:
        """A lane on ``side`` of the ego's lies beside it, and its class may use it, on every
        edge within the manoeuvre's reach (``_beside_within_reach``), not only at its start (a
        lane that ends on the way, an acceleration lane, a bus lane after a lane added, close
        the side)."""
        return all(
            lane is not None and self._permits(lane) for lane in self._beside_within_reach(side)
        )

    def side_friction(self, side: int) -> float:
        """The lowest friction of the lane on ``side`` of the ego's within the manoeuvre's
        reach (``_beside_within_reach``; nan: no lane there): a lane that turns icy on a later
        edge is the lane change's friction too."""
        lanes = [lane for lane in self._beside_within_reach(side) if lane]
        return min((self._friction(lane) for lane in lanes), default=math.nan)

    def _side_limit(self, side: int) -> float:
        """The highest speed limit of the lane on ``side`` of the ego's along its route (0:
        none)."""
        limits = (float(self._lane.getMaxSpeed(lane)) for _, lane in self._beside(side) if lane)
        return max(limits, default=0.0)

    def lane_ids(self) -> list[str]:
        return list(self._lane.getIDList())

    def move_ego(
        self, x_front_m: float, y_front_m: float, angle_nav_deg: float, speed_mps: float
    ) -> None:
        """Place the ego's front bumper for the next step (keepRoute=2: any lane, even opposite)."""
        self._check_open()
        calls = self._calls
        calls.move_to_xy(self.ego_id, "", -1, x_front_m, y_front_m, angle_nav_deg, 2)
        calls.set_speed(self.ego_id, speed_mps)

    def puppets(self) -> Puppets:
        """The road users an outside storyboard moves (OpenSCENARIO), and the ego's lane."""
        self._check_open()
        if self._puppets is None:
            self._puppets = Puppets(self._api, self._calls, self.ego_id, [], self._users.placed)
        return self._puppets

    def size_ego(self, length_m: float, width_m: float, mass_kg: float) -> None:
        """Tell SUMO the ego's length, width and mass (its vehicle's, where they differ from
        what SUMO has: SUMO then gives the ego a type of its own), so that SUMO's drivers,
        its outputs and sumo-gui see the car the co-simulation drives."""
        self._check_open()
        veh, ego = self._veh, self.ego_id
        for get, put, value in (
            (veh.getLength, veh.setLength, length_m),
            (veh.getWidth, veh.setWidth, width_m),
            (veh.getMass, veh.setMass, mass_kg),
        ):
            if float(get(ego)) != value:
                put(ego, value)

    def nearby(self, radius_m: float) -> list[Body]:
        """Every other road user (vehicles of every class, persons on foot) some part of which
        may be within ``radius_m`` of the ego's SUMO position (its front bumper), sorted by id
        (``RoadUsers.near``). From the first call on the session follows all road users
        (``session.tracking``)."""
        self._check_open()
        if radius_m != self._radius_m:
            number("radius_m", radius_m, minimum=0.0, inclusive=False)
            self._radius_m = radius_m
        ex, ey = self._ego_position()
        near = self._users.near(ex, ey, radius_m)
        near.sort()  # Body tuples start with their (unique) id
        return near

    def road_users(self) -> list[Body]:
        """Every road user but the ego, wherever it is, sorted by id."""
        self._check_open()
        self._ego_position()
        bodies = self._users.everyone()
        bodies.sort()
        return bodies

    def _ego_position(self) -> tuple[float, float]:
        """The ego's SUMO position (front bumper) from the subscription (following starts)."""
        users = self._users
        if not users.tracking:
            users.start()
        ego = users.step_results().get(self.ego_id)
        if not ego:
            raise RuntimeError(f"the ego '{self.ego_id}' is no longer in the simulation")
        return ego[self._tc.VAR_POSITION]

    def _ego_results(self) -> dict:
        self._check_open()
        res = self._users.step_results().get(self.ego_id)
        if not res:
            raise RuntimeError(f"the ego '{self.ego_id}' is no longer in the simulation")
        return res

    def ego_body(self) -> Body:
        """The ego as SUMO sees it: its type now, a type of its own once ``size_ego`` gave it
        the plant's size (not its route's)."""
        self._ego_results()  # fails when the ego has left
        veh, ego = self._veh, self.ego_id
        return self._users.vehicle_body(
            ego, veh.getPosition(ego), veh.getAngle(ego), veh.getSpeed(ego), veh.getTypeID(ego), 0
        )

    def body(self, vid: str) -> Body:
        """Any road user by id, a vehicle or a person (getters; for checks, not for the step
        loop)."""
        self._check_open()
        if vid not in self._veh.getIDList() and vid in self._api.person.getIDList():
            person = self._api.person
            return self._users.person_body(
                vid,
                person.getPosition(vid),
                person.getAngle(vid),
                person.getSpeed(vid),
                person.getTypeID(vid),
            )
        return self._users.vehicle_now(vid)

    def mass_kg(self, vid: str) -> float:
        """A road user's mass as SUMO has it (``getMass``: its vType's ``mass``, or SUMO's
        default for its vClass), a vehicle or a person."""
        self._check_open()
        if vid not in self._veh.getIDList() and vid in self._api.person.getIDList():
            return float(self._api.person.getMass(vid))
        return float(self._veh.getMass(vid))

    def vehicle_ids(self) -> list[str]:
        return list(self._veh.getIDList())

    def vehicle_speed(self, vid: str) -> float:
        return float(self._veh.getSpeed(vid))

    def vehicle_lane(self, vid: str) -> str:
        return self._veh.getLaneID(vid)

    def record_collision(self, time_s: float, collider: Body, victim: Body) -> None:
        """Note a contact the co-simulation found in the step that ended at ``time_s``
        (``collider`` hit ``victim``, as they were then) for the scenario's collision-output;
        does nothing when the sumocfg asks for none. Call it before the next step: the
        collider's lane and position are read from SUMO now."""
        if self.collision_output is None:
            return
        self._check_open()
        types = []
        for body in (collider, victim):
            domain = self._api.person if body.vclass == PEDESTRIAN else self._veh
            types.append(domain.getTypeID(body.vid))
        lane = self._veh.getLaneID(collider.vid) if collider.vclass != PEDESTRIAN else ""
        pos = self._veh.getLanePosition(collider.vid) if lane else 0.0
        self._collisions.append(
            CollisionRecord(time_s - self._dt, lane, pos, collider, victim, *types)
        )

    # ----------------------------------------------------------------------------- life cycle
    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError("the SUMO session is closed")

    def _release(self) -> None:
        """End SUMO, keeping the session's working directory."""
        if self._closed:
            return
        self._closed = True
        if self in _open_libsumo:
            _open_libsumo.remove(self)
        keep_open = self.gui is not None and self.gui.settings.keep_open
        shut_down(self._api, self._process, wait=not keep_open)

    def close(self) -> None:
        """End SUMO (idempotent; a sumo-gui window meant to stay open is left to the user),
        then add the recorded collisions to the scenario's collision-output."""
        if self.gui is not None:
            self.gui.finish(self._time_s)  # warns of the screenshots the run did not reach
        self._release()
        shutil.rmtree(self._workdir, ignore_errors=True)
        if self._collisions and self.collision_output is not None:
            write_collision_output(self.collision_output, self._collisions)
            self._collisions = []

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
