"""The online EOAM module: one decision + control step per SUMO step (paper sec. 3, 5-6, 8-9).

Every step the controller places the sensed obstacle in the DMM phase diagram (sectors A-G),
advances the mode machine 0-5 (point of no return, manoeuvre timer, return, hand-back), builds
the lateral and longitudinal references of the active mode and runs the steering (eq. 38) and
longitudinal controllers. It sees only ego measurements and radar-derived perception.

References per mode (road frame of the ego's original lane, d left positive):

* 0 NORMAL, 1 UPDATE BRAKE: keep the lane centre (d = 0); 0 holds the initial speed with the
  speed PID, 1 brakes at the no-lock limit (``limit_brake_fraction`` of it), to standstill
  and holding, unless a steering sector, oncoming traffic or the obstacle leaving the path
  (or pulling away) ends it.
* 2 / 4 STEER+BRAKE: the table lane change (trigger speed and friction) from the offset at the
  trigger to one lane width to the left; the table acceleration profile tracked by the
  acceleration PID until the end of the path, then the speed reached is held.
* 3 ONCOMING BRAKE: limit braking to standstill in the original lane: lane keeping to d = 0
  (the lane change is abandoned), the brake force shrunk by the friction ellipse while the
  ego still turns so that no wheel locks.
* 5 RETURN: a quintic (sec. 4.2) from the current offset back to d = 0 at the speed held
  when the return began, long enough for its peak lateral acceleration to be
  ``return_lateral_g`` mu g (``evasive_return_lateral_g`` when oncoming traffic ended the lane
  change, mode 4). The table's minimum-distance path is not reused: it is that short only
  with its braking profile, which a return does not need.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import NamedTuple

from eoam_sumo.control.longitudinal import LongitudinalController, LongitudinalGains
from eoam_sumo.control.paths import PathReference, QuinticShift
from eoam_sumo.control.steering import SteeringController, SteeringGains
from eoam_sumo.decision import modes
from eoam_sumo.decision.dmm import Action, BoundaryCurve, Sector
from eoam_sumo.decision.modes import Mode, next_mode
from eoam_sumo.decision.policy import NextLaneView, PolicySettings, SafePolicy
from eoam_sumo.params import G_MPS2, PONR_FRACTION, VehicleParams

_TWO_PI = 2.0 * math.pi


class EgoMeasurement(NamedTuple):
    """Ego state in the road frame of its original lane (s along, d left of its centre).

    The per-step messages (this, ``ObjectState``, ``Perception``, ``Command``) are named
    tuples: as immutable as frozen dataclasses and built in a quarter of the time."""

    time_s: float
    vx_mps: float
    vy_mps: float
    yaw_rate_radps: float
    ax_mps2: float
    ay_mps2: float
    s_m: float
    d_m: float
    e_yaw_rad: float
    road_curvature_1pm: float
    mu: float
    lane_width_m: float
    left_lane_available: bool = True  # map: a lane (either direction) left of the ego's lane


class ObjectState(NamedTuple):
    """A tracked object in the road frame of the ego's original lane (a sensor's object list)."""

    s_m: float  # station of its centre
    d_m: float  # lateral offset of its centre, left positive
    speed_mps: float  # along the road
    length_m: float
    width_m: float


class Perception(NamedTuple):
    """Radar-derived view: the in-path obstacle (None when nothing) and oncoming traffic."""

    aro_range_m: float | None = None
    aro_range_rate_mps: float | None = None
    oncoming_detected: bool = False
    aro_object: ObjectState | None = None  # the in-path obstacle as an object, when tracked
    next_lane_obstacle_range_m: float | None = None  # nearest standing object in the next lane
    next_lane: NextLaneView | None = None  # what is known of the next lane (safe policy)


class Command(NamedTuple):
    """Actuator commands for the next step plus what the controller decided, for logging."""

    steer_cmd_rad: float
    drive_force_cmd_n: float
    brake_force_cmd_n: float
    mode: int
    fcw: bool
    sector: str
    ax_target_mps2: float
    y_target_m: float
    dx_m: float
    lateral_error_m: float
    lookahead_error_m: float
    steer_ff_rad: float
    steer_fb_rad: float
    steer_yd_rad: float
    speed_target_mps: float


@dataclass(frozen=True)
class EoamSettings:
    """Tunable values of the EOAM logic (the paper's defaults where it gives them)."""

    ponr_fraction: float = PONR_FRACTION  # point of no return / lane-change height
    manoeuvre_time_s: float = 8.0  # steering manoeuvre timer before RETURN (sec. 3.1 step 5)
    arrive_tolerance_m: float = 0.3  # 2 -> 5 early: within this of the next lane's centre ...
    pass_margin_m: float = 1.0  # mode 4 -> 5: ego rear this far past the obstacle's front
    side_clearance_m: float = 0.5  # mode 4: lateral gap kept to the obstacle's side
    unknown_obstacle_length_m: float = 12.0  # assumed without an object track (a truck)
    track_gate_m: float = 5.0  # modes 2, 4: a sensed object further off the track is another
    settle_offset_m: float = 0.1  # mode 5 -> 0: |d| below this ...
    settle_heading_rad: float = 0.02  # ... and |e_yaw| below this ...
    settle_dwell_s: float = 0.5  # ... for this long after the return path ended
    release_opening_speed_mps: float = 0.5  # mode 1 -> 0: obstacle pulls away faster than this
    min_steer_speed_mps: float = 20.0 / 3.6  # below it a STEER sector brakes instead
    limit_brake_fraction: float = 0.95  # share of the no-lock brake force used as limit braking
    reference_step_m: float = 0.25  # dx spacing of the sampled manoeuvre reference
    return_when_stable: bool = True  # ... heading within settle_heading_rad and clear of the
    # obstacle: 2 -> 5 before the timer (False: the timer alone, as in the paper's runs)
    return_lateral_g: float = 0.3  # mode 5 after 2: return's peak lateral acceleration / (mu g)
    evasive_lateral_g: float = 0.8  # mode 4 and the return after it (oncoming traffic): the same
    return_min_length_m: float = 10.0  # mode 5: shortest return path
    next_lane_clear_m: float = 50.0  # a standing object in the next lane closer than the
    # in-path obstacle's range plus this (room to pass it and return) blocks the lane change
    # as oncoming traffic does (modes 3, 4); the paper checks the next lane for oncoming only
    preview_time_s: float = 0.3  # feedforward curvature taken this far ahead on the path
    steering: SteeringGains = field(default_factory=SteeringGains)
    longitudinal: LongitudinalGains = field(default_factory=LongitudinalGains)
    policy: PolicySettings = field(default_factory=PolicySettings)  # paper or safe

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"EOAM setting {f.name}={v!r} must be finite and >= 0")
        if not 0.0 < self.ponr_fraction < 1.0:
            raise ValueError(f"ponr_fraction={self.ponr_fraction} must be in (0, 1)")
        if not 0.0 < self.limit_brake_fraction <= 1.0:
            raise ValueError(f"limit_brake_fraction={self.limit_brake_fraction} must be in (0, 1]")
        for name in (
            "manoeuvre_time_s",
            "reference_step_m",
            "return_lateral_g",
            "evasive_lateral_g",
            "return_min_length_m",
            "settle_offset_m",
            "settle_heading_rad",
            "unknown_obstacle_length_m",
            "arrive_tolerance_m",
        ):
            if getattr(self, name) <= 0.0:
                raise ValueError(f"EOAM setting {name} must be > 0")


# Enum members bound once for ``step`` (the modes in decision.modes): on Python 3.11 each
# ``Mode.X`` read goes through the enum metaclass (~80 ns), and a step reads about fifteen.
_NORMAL, _UPDATE_BRAKE, _STEER_BRAKE = modes.NORMAL, modes.UPDATE_BRAKE, modes.STEER_BRAKE
_ONCOMING_BRAKE, _ONCOMING_STEER, _RETURN = modes.ONCOMING_BRAKE, modes.ONCOMING_STEER, modes.RETURN
_STEER, _BRAKE, _LIMIT_BRAKE = Action.STEER, Action.BRAKE, Action.LIMIT_BRAKE
_NO_ACTION = Action.NONE
_SECTOR_G = Sector.G
_WARNING_MODES = (_UPDATE_BRAKE, _STEER_BRAKE, _ONCOMING_BRAKE, _ONCOMING_STEER)  # FCW stays on
_STEERING = (_STEER_BRAKE, _ONCOMING_STEER)
_COMMITTING = (_NORMAL, _UPDATE_BRAKE)  # a STEER here begins a lane change (safe policy gate)
_WATCHING = (_STEER_BRAKE, _RETURN)  # the safe policy watches the next lane in these modes


class EoamController:
    """Decision (DMM, modes 0-5) and control (steering, longitudinal) of the ego."""

    _curve: BoundaryCurve  # the DMM boundaries at the sensed friction, set by _friction()

    def __init__(self, params: VehicleParams, tables, settings: EoamSettings = EoamSettings()):
        self.params = params
        self.tables = tables
        self.settings = settings
        self._steer = SteeringController(params, settings.steering)
        self._long = LongitudinalController(params, settings.longitudinal)
        self._mass = params.mass_kg
        self._brake_mu = math.nan
        self._brake_limit = 0.0
        self._initial_speed: float | None = None
        self.policy = (SafePolicy(params, tables, settings, settings.policy)
                       if settings.policy.name == "safe" else None)
        self._reset_state()

    # ----------------------------------------------------------------------------- lifecycle
    def _reset_state(self) -> None:
        """Back to NORMAL with no manoeuvre and an empty history (keeps the set speed)."""
        self.mode = Mode.NORMAL
        self.modes_visited: list[int] = [0]
        self.fcw_raised = False
        self.sector = ""
        self._path: PathReference | None = None
        self._s0 = 0.0
        self._t_steer = 0.0
        self._height = 0.0
        self._settle_since: float | None = None
        self._hold_speed: float | None = None
        self._urgent_return = False
        self._obstacle: tuple[float, float, float, float] | None = None  # t, front s, v, left
        self._long.reset()
        if self.policy is not None:
            self.policy.reset()

    def reset(self, initial_speed_mps: float) -> None:
        """Start a run: NORMAL, holding ``initial_speed_mps`` with the speed PID."""
        v = float(initial_speed_mps)
        if not (math.isfinite(v) and v >= 0.0):
            raise ValueError(f"initial_speed_mps={initial_speed_mps!r} must be finite and >= 0")
        self._initial_speed = v
        self._reset_state()

    # ----------------------------------------------------------------------------- helpers
    def _friction(self, mu: float) -> None:
        """Refresh what depends on the sensed friction: brake limit and DMM boundaries."""
        if mu == self._brake_mu:
            return
        if not mu > 0.0:
            raise ValueError(f"friction mu={mu!r} must be > 0")
        self._brake_mu = mu
        decel = float(self.tables.max_decel_mps2(mu))
        self._brake_limit = self.settings.limit_brake_fraction * self._mass * decel
        bounds = self.tables.boundaries
        self._curve = BoundaryCurve(bounds, mu, bounds.speed_grid_mps)

    def _start_return(self, meas: EgoMeasurement, *, urgent: bool) -> None:
        """Mode 5's path back to the lane centre; urgent (oncoming traffic) at the evasive
        lateral acceleration, else at the comfortable one."""
        self._urgent_return = urgent
        st = self.settings
        self._shift_to(0.0, meas, st.evasive_lateral_g if urgent else st.return_lateral_g)

    def _shift_to(self, target_m: float, meas: EgoMeasurement, lateral_g: float) -> None:
        """A quintic (``QuinticShift``) from the ego's offset and heading to ``target_m``, with
        its peak lateral acceleration ``lateral_g`` mu g."""
        traj = QuinticShift.for_lateral_accel(
            meas.d_m,
            math.tan(_wrap(meas.e_yaw_rad)),
            target_m,
            meas.vx_mps,
            lateral_g * meas.mu * G_MPS2,
            self.settings.return_min_length_m,
        )
        self._start_path(meas, traj, meas.d_m, None)

    def _passing_offset_m(self, meas: EgoMeasurement) -> float:
        """Mode 4's target: just far enough left to pass the obstacle with ``side_clearance_m``
        (less exposure to the oncoming vehicle than a whole lane), at most a lane width, and
        never back towards the obstacle from where the ego already is."""
        left_edge = self._obstacle[3] if self._obstacle is not None else 0.5 * meas.lane_width_m
        need = left_edge + 0.5 * self.params.width_m + self.settings.side_clearance_m
        return max(min(need, meas.lane_width_m), meas.d_m)

    def _start_path(
        self, meas: EgoMeasurement, traj, start: float, height: float | None
    ) -> None:
        v = meas.vx_mps
        self._path = PathReference(
            traj,
            start_offset_m=start,
            height_m=height,
            speed_mps=v,
            step_m=self.settings.reference_step_m,
        )
        self._s0 = meas.s_m
        self._settle_since = None
        self._long.reset()

    def _enter(self, mode: Mode, previous: Mode, meas: EgoMeasurement) -> None:
        """Entry actions of a new mode (mode 4 keeps the lane change of mode 2 going)."""
        if mode is Mode.UPDATE_STEER_BRAKE:
            self._hold_speed = None
            self._height = meas.lane_width_m
            self._t_steer = meas.time_s
            traj = self.tables.trajectory(meas.mu, meas.vx_mps)  # clamped to the speed grid
            self._start_path(meas, traj, meas.d_m, meas.lane_width_m)
        elif mode is Mode.RETURN:
            self._hold_speed = meas.vx_mps
            self._start_return(meas, urgent=previous is Mode.ONCOMING_STEER_BRAKE)
        elif mode is Mode.ONCOMING_STEER_BRAKE:
            self._shift_to(self._passing_offset_m(meas), meas, self.settings.evasive_lateral_g)
        else:
            self._path = None
            self._long.reset()
        if int(mode) not in self.modes_visited:
            self.modes_visited.append(int(mode))

    def _track_obstacle(
        self, meas: EgoMeasurement, range_m: float, closing_mps: float, obj: ObjectState | None
    ) -> None:
        """Remember the in-path obstacle's front station, speed and left edge (offset).

        From its object track when the sensor gives one; else from the range, an assumed
        length (``unknown_obstacle_length_m``) and a width filling its lane. During a lane
        change (modes 2, 4) only the obstacle being avoided is followed: one whose front is
        more than ``track_gate_m`` off the prediction is another object."""
        if obj is not None:
            front_s = obj.s_m + 0.5 * obj.length_m
            speed = max(obj.speed_mps, 0.0)
            left_edge = obj.d_m + 0.5 * obj.width_m
        else:
            front_s = (meas.s_m + self.params.cg_to_front_bumper_m + range_m
                       + self.settings.unknown_obstacle_length_m)
            speed = max(meas.vx_mps - closing_mps, 0.0)
            left_edge = 0.5 * meas.lane_width_m
        if self._obstacle is not None and self.mode in _STEERING:
            t0, front0, speed0, _ = self._obstacle
            if abs(front_s - front0 - speed0 * (meas.time_s - t0)) > self.settings.track_gate_m:
                return
        self._obstacle = (meas.time_s, front_s, speed, left_edge)

    def _clear_of_obstacle(self, meas: EgoMeasurement, path, dx_m: float) -> bool:
        """Mode 4's "desired position": the ego's rear is ``pass_margin_m`` past the obstacle's
        front, predicted at its last sensed speed (a braking obstacle is further back, so the
        prediction errs on the late side). Without a track, the end of the lane change."""
        if self._obstacle is None:
            return path is not None and dx_m >= path.length_m
        t0, front_s, speed, _ = self._obstacle
        front_s += speed * (meas.time_s - t0)
        ego_rear_s = meas.s_m - self.params.cg_to_rear_bumper_m
        return ego_rear_s - front_s >= self.settings.pass_margin_m

    # ----------------------------------------------------------------------------- the step
    def step(self, meas: EgoMeasurement, perception: Perception, dt_s: float) -> Command:
        """One decision + control step; commands hold until the next call."""
        if self._initial_speed is None:
            raise ValueError("EoamController.reset(initial_speed_mps) must be called first")
        if not math.isfinite(sum(meas)):  # a NaN or inf field (or finite fields overflowing)
            for name, value in zip(EgoMeasurement._fields, meas):
                if not math.isfinite(value):
                    raise ValueError(f"ego measurement {name}={value!r} is not finite")
        if not meas.lane_width_m > 0.0:
            raise ValueError(f"lane_width_m={meas.lane_width_m!r} must be > 0")
        mu = meas.mu
        self._friction(mu)
        st = self.settings
        t, v, d = meas.time_s, meas.vx_mps, meas.d_m

        # ---- DMM: sector of the in-path obstacle (none when nothing is sensed) -------------
        rng = perception.aro_range_m
        rate = perception.aro_range_rate_mps
        if rng is not None and math.isfinite(rng):
            closing = -rate if rate is not None and math.isfinite(rate) else 0.0
            sector = self._curve.sector(rng, closing)
            action = sector.action
            if action is _STEER and v < st.min_steer_speed_mps:
                action = _BRAKE  # too slow for a lane change: braking needs less room
            elif (action is _STEER and self.mode is _UPDATE_BRAKE
                  and rng > self._curve.at(closing).stop_m):
                action = _BRAKE  # braking already stops short of it: no lane change
            elif action is _STEER and not meas.left_lane_available:
                action = _LIMIT_BRAKE  # no lane to change into: brake in lane
            threat_gone = closing < -st.release_opening_speed_mps
            self._track_obstacle(meas, rng, closing, perception.aro_object)
        else:
            sector = None
            action = _NO_ACTION
            threat_gone = True
        oncoming = bool(perception.oncoming_detected)
        block_m = perception.next_lane_obstacle_range_m
        if block_m is not None and rng is not None and block_m <= rng + st.next_lane_clear_m:
            oncoming = True  # the lane change would end against a standing car: as deadly
        policy = self.policy
        if policy is not None and policy.blocks(
                meas, perception, action is _STEER and self.mode in _COMMITTING,
                self.mode in _WATCHING):
            oncoming = True  # the next lane is not known free (safe policy): as oncoming

        # ---- mode machine --------------------------------------------------------------
        mode = self.mode
        path = self._path
        dx = meas.s_m - self._s0 if path is not None else 0.0
        travel = d - path.start_offset_m if path is not None else 0.0
        height = self._height
        settled = False
        if mode is _RETURN and path is not None and dx >= path.length_m:
            if abs(d) <= st.settle_offset_m and abs(_wrap(meas.e_yaw_rad)) <= st.settle_heading_rad:
                if self._settle_since is None:
                    self._settle_since = t
                settled = t - self._settle_since >= st.settle_dwell_s - 1e-9
            else:
                self._settle_since = None
        clear = mode in _STEERING and self._clear_of_obstacle(meas, path, dx)  # 2 and 4 only
        stable = (
            clear
            and path is not None
            and st.return_when_stable
            and mode is _STEER_BRAKE
            and dx >= path.length_m
            and abs(d - path.start_offset_m - height) <= st.arrive_tolerance_m
            and abs(_wrap(meas.e_yaw_rad)) <= st.settle_heading_rad
        )
        past_ponr = travel >= st.ponr_fraction * height
        if (past_ponr and oncoming and mode is _STEER_BRAKE and policy is not None
                and policy.prefer_braking(meas, perception)):
            past_ponr = False  # severity tie-breaker: braking in lane ends softer
        new = next_mode(
            mode,
            action,
            oncoming=oncoming,
            past_ponr=past_ponr,
            timer_expired=t - self._t_steer >= st.manoeuvre_time_s - 1e-9,
            stable_in_next_lane=stable,
            clear_of_obstacle=clear,
            settled=settled,
            threat_gone=threat_gone,
        )
        if new is not mode:
            self._enter(new, mode, meas)
            self.mode = mode = new
        elif mode is _RETURN and oncoming and not self._urgent_return:
            self._start_return(meas, urgent=True)  # oncoming traffic seen during the return
        path = self._path
        dx = meas.s_m - self._s0 if path is not None else 0.0

        # ---- lateral reference (lane centre unless a path is active) and steering, eq. 38 ----
        y_ref = yaw_ref = kappa_ref = kappa_ff = ax_ref = v_plan = 0.0
        in_path = False
        if path is not None:
            y_ref, yaw_ref, kappa_ref, ax_ref, v_plan = path.at(dx)
            in_path = dx < path.length_m
            if in_path:
                kappa_ff = path.at(dx + v * st.preview_time_s).curvature_1pm
            else:
                yaw_ref = kappa_ref = 0.0
        e_lat = d - y_ref
        road_kappa = meas.road_curvature_1pm
        e_head = meas.e_yaw_rad - yaw_ref
        if road_kappa:
            # following a curved road the body points off it by the steady-state sideslip,
            # which the look-ahead would turn into a steady offset (Kapania and Gerdes 2015)
            e_head += self._steer.steady_sideslip(v, road_kappa)
        delta, ff, fb, yd, e_la = self._steer.command(
            v,
            meas.yaw_rate_radps,
            e_lat,
            _wrap(e_head),
            kappa_ref + road_kappa,
            kappa_ff + road_kappa,
            mu,
        )

        # ---- longitudinal: force limits from the friction ellipse with the lateral acceleration
        # in use (measured; outside the table's profile also the one this steering command asks
        # for, so that the brake yields before a turning axle locks), then the mode's loop -----
        tracking = in_path and mode is not _RETURN  # the table's ax already fits the ellipse
        ay_use = abs(meas.ay_mps2)
        if not tracking:
            ay_use = max(ay_use, abs(self._steer.lateral_accel(v, delta)))
        drive_lim, brake_lim = self._long.limits(v, mu, ay_use, self._brake_limit)
        if mode is _NORMAL:
            drive, brake, ax_target = self._long.track_speed(
                self._initial_speed, v, mu, drive_lim, brake_lim, dt_s
            )
            v_target = self._initial_speed
        elif mode is _UPDATE_BRAKE or mode is _ONCOMING_BRAKE:
            drive, brake = 0.0, brake_lim  # limit braking without locking
            ax_target = -brake_lim / self._mass
            v_target = 0.0
        elif tracking:
            drive, brake = self._long.track_accel(
                ax_ref, meas.ax_mps2, v, drive_lim, brake_lim, dt_s
            )
            ax_target, v_target = ax_ref, v_plan
        else:
            if self._hold_speed is None:
                self._hold_speed = v
                self._long.reset()
            drive, brake, ax_target = self._long.track_speed(
                self._hold_speed, v, mu, drive_lim, brake_lim, dt_s
            )
            v_target = self._hold_speed

        warns = sector is not None and sector is not _SECTOR_G
        fcw = warns or mode in _WARNING_MODES
        if fcw:
            self.fcw_raised = True
        self.sector = sector.value if sector is not None else ""
        return Command(
            delta,
            drive,
            brake,
            int(mode),
            fcw,
            self.sector,
            ax_target,
            y_ref,
            dx,
            e_lat,
            e_la,
            ff,
            fb,
            yd,
            v_target,
        )


def _wrap(angle_rad: float) -> float:
    """Angle wrapped to [-pi, pi)."""
    if -math.pi <= angle_rad < math.pi:
        return angle_rad
    return (angle_rad + math.pi) % _TWO_PI - math.pi
