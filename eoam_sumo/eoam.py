"""The online EOAM module: one decision + control step per SUMO step (paper sec. 3, 5-6, 8-9).

Every step the controller places the sensed obstacle in the DMM phase diagram (sectors A-G),
advances the mode machine 0-5 (point of no return, manoeuvre timer, return, hand-back), builds
the lateral and longitudinal references of the active mode and runs the steering (eq. 38) and
longitudinal controllers. It sees only ego measurements and radar-derived perception.

References per mode (road frame of the ego's original lane, d left positive):

* 0 NORMAL, 1 UPDATE BRAKE: keep the lane centre; 0 holds the initial speed (speed PID), 1
  brakes at the no-lock limit to standstill unless a steering sector, oncoming traffic or the
  obstacle leaving the path (or pulling away) ends it.
* 2 STEER+BRAKE: the table lane change (trigger speed and friction) to one lane width left,
  steered with the plan's own road-wheel angle; the table acceleration profile, then held.
* 3 ONCOMING BRAKE: a lateral motion away from the lane centre arrested at the front tyre's
  slip envelope, then back to the lane centre (a time-optimal ``MinTimeShift`` within
  ``arrest_return_g`` mu g, ``evasive_lateral_g`` without an arrest; or a quintic), braking
  with what the friction ellipse leaves meanwhile, then at the limit to standstill.
* 4 ONCOMING STEER+BRAKE: the same kind of shift to just past the obstacle's side.
* 5 RETURN: back to d = 0: a quintic within ``return_lateral_g`` mu g, an escape after mode 4.

When an oncoming road user is seen during a lane change, passing on and aborting are both
predicted and the less severe taken (``compare_outcomes``; ``decision.oncoming``); otherwise the
point of no return (sec. 8.1) is judged where the lateral motion would stop
(``ponr_at_lateral_stop``). The DMM places a braking obstacle where it will stop
(``obstacle_decel_in_dmm``). Each can be set back to the paper's rule.
"""

from __future__ import annotations

import math

from eoam_sumo.control.escape import MinTimeShift, course_state, lateral_state, wrap_angle
from eoam_sumo.control.longitudinal import LongitudinalController
from eoam_sumo.control.paths import PathReference, QuinticShift
from eoam_sumo.control.steering import SteeringController
from eoam_sumo.decision.dmm import (
    BRAKE,
    LIMIT_BRAKE,
    NONE,
    SECTOR_ORDER,
    STEER,
    BoundaryCurve,
    Sector,
)
from eoam_sumo.decision.modes import (
    NORMAL,
    ONCOMING_BRAKE,
    ONCOMING_STEER_BRAKE,
    RETURN,
    UPDATE_BRAKE,
    UPDATE_STEER_BRAKE,
    Mode,
    next_mode,
)
from eoam_sumo.decision.obstacle import ObstacleDecel, ObstacleTrack, stopping_range_m
from eoam_sumo.decision.oncoming import Budget, Choice, commit_choice, return_clears
from eoam_sumo.decision.policy import SafePolicy
from eoam_sumo.eoam_messages import Command, EgoMeasurement, ObjectState, Perception
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.params import G_MPS2, VehicleParams

_new = tuple.__new__  # builds the per-step Command without its Python-level constructor
__all__ = [
    "Command",
    "EgoMeasurement",
    "EoamController",
    "EoamSettings",
    "ObjectState",
    "Perception",
]

_WARNING_MODES = (UPDATE_BRAKE, UPDATE_STEER_BRAKE, ONCOMING_BRAKE, ONCOMING_STEER_BRAKE)  # FCW
_STEERING = (UPDATE_STEER_BRAKE, ONCOMING_STEER_BRAKE)
_COMMITTING = (NORMAL, UPDATE_BRAKE)  # a STEER here begins a lane change (safe policy gate)
_WATCHING = (UPDATE_STEER_BRAKE, RETURN)  # the safe policy watches the next lane
_HOLDING = (NORMAL, UPDATE_BRAKE)  # a coasted object keeps these braking (track persistence)


class EoamController:
    """Decision (DMM, modes 0-5) and control (steering, longitudinal) of the ego."""

    _curve: BoundaryCurve  # the DMM boundaries at the sensed friction, set by _friction()

    def __init__(self, params: VehicleParams, tables, settings: EoamSettings | None = None):
        self.params = params
        self.tables = tables
        self.settings = settings = settings or EoamSettings()
        self._steer = SteeringController(params, settings.steering)
        self._steer_plan = SteeringController(params, settings.planned_steering)
        self._long = LongitudinalController(params, settings.longitudinal)
        self._mass = params.mass_kg
        self._front_offset_m = params.cg_to_front_bumper_m
        self._decel = ObstacleDecel(settings.obstacle_decel_time_constant_s)
        self._brake_mu = math.nan
        self._brake_limit = 0.0
        self._initial_speed: float | None = None
        self.policy = (
            SafePolicy(params, tables, settings, settings.policy)
            if settings.policy.name == "safe"
            else None
        )
        self._reset_state()

    # ----------------------------------------------------------------------------- lifecycle
    def _reset_state(self) -> None:
        """Back to NORMAL with no manoeuvre and an empty history (keeps the set speed)."""
        self.mode = NORMAL
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
        self._stop_path: QuinticShift | None = None  # lateral stop judged for the PONR
        self._arrest = 0.0  # mode 3: sign of the lateral motion being arrested (0: none)
        self._obstacle: ObstacleTrack | None = None  # the in-path obstacle
        self.oncoming_choice: Choice | None = None  # the commit/abort decision, when made
        self._decel.reset()
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
        """Refresh what depends on the sensed friction (``step`` calls it when the friction
        changes): brake limit and DMM boundaries."""
        if not mu > 0.0:
            raise ValueError(f"friction mu={mu!r} must be > 0")
        self._brake_mu = mu
        decel = float(self.tables.max_decel_mps2(mu))
        self._brake_limit = self.settings.limit_brake_fraction * self._mass * decel
        bounds = self.tables.boundaries
        self._curve = BoundaryCurve(bounds, mu, bounds.speed_grid_mps)

    def _budget(self, mu: float) -> Budget:
        return Budget.of(self.params, self.settings, mu, self._brake_limit / self._mass)

    def _start_return(self, meas: EgoMeasurement, *, urgent: bool) -> None:
        """Mode 5's path back to the lane centre; urgent (oncoming traffic) at the evasive
        lateral acceleration, else at the comfortable one."""
        self._urgent_return = urgent
        if urgent:
            self._escape_to(0.0, meas)
        else:
            self._shift_to(0.0, meas, self.settings.return_lateral_g)

    def _escape_to(
        self, target_m: float, meas: EgoMeasurement, lateral_g: float | None = None
    ) -> None:
        """An evasive shift to ``target_m`` within ``lateral_g`` (default
        ``evasive_lateral_g``) mu g: time-optimal (``MinTimeShift``) with
        ``min_time_escapes``, else the shortest quintic."""
        st = self.settings
        lateral_g = st.evasive_lateral_g if lateral_g is None else lateral_g
        if not st.min_time_escapes:
            return self._shift_to(target_m, meas, lateral_g)
        v_lat, a_lat, speed = lateral_state(meas)
        accel = lateral_g * meas.mu * G_MPS2
        traj = MinTimeShift(meas.d_m, v_lat, a_lat, target_m, speed, accel, st.escape_ramp_s)
        self._start_path(meas, traj, meas.d_m, None)

    def _shift_to(self, target_m: float, meas: EgoMeasurement, lateral_g: float) -> None:
        """The shortest quintic (``QuinticShift``) from the ego's lateral state (offset, course,
        path curvature) to ``target_m`` within ``lateral_g`` mu g that does not pass it."""
        slope, kappa, speed = course_state(meas)
        traj = QuinticShift.for_lateral_accel(
            meas.d_m,
            slope,
            target_m,
            speed,
            lateral_g * meas.mu * G_MPS2,
            self.settings.return_min_length_m,
            kappa,
        )
        self._start_path(meas, traj, meas.d_m, None)

    def _lateral_stop(self, meas: EgoMeasurement) -> QuinticShift:
        """The quintic that arrests the ego's lateral motion soonest within
        ``evasive_lateral_g`` mu g; it ends where the lateral motion stops."""
        slope, kappa, speed = course_state(meas)
        return QuinticShift.stopping(
            meas.d_m,
            slope,
            speed,
            self.settings.evasive_lateral_g * meas.mu * G_MPS2,
            self.settings.return_min_length_m,
            kappa,
            self.settings.lateral_reaction_s,
        )

    def _passing_offset_m(self, meas: EgoMeasurement) -> float:
        """Mode 4's target: just far enough left to pass the obstacle with ``side_clearance_m``
        (less exposure to the oncoming vehicle than a whole lane), at most a lane width, and
        never back towards the obstacle from where the ego already is."""
        obstacle = self._obstacle
        left_edge = obstacle.left_edge_m if obstacle is not None else 0.5 * meas.lane_width_m
        need = left_edge + 0.5 * self.params.width_m + self.settings.side_clearance_m
        return max(min(need, meas.lane_width_m), meas.d_m)

    def _start_path(self, meas: EgoMeasurement, traj, start: float, height: float | None) -> None:
        self._path = PathReference(
            traj,
            start_offset_m=start,
            height_m=height,
            speed_mps=meas.vx_mps,
            step_m=self.settings.reference_step_m,
        )
        self._s0 = meas.s_m
        self._settle_since = None
        self._long.reset()

    def _enter(self, mode: Mode, previous: Mode, meas: EgoMeasurement) -> None:
        """Entry actions of a new mode (mode 4 keeps the lane change of mode 2 going)."""
        self._arrest = 0.0
        if mode is UPDATE_STEER_BRAKE:
            self._hold_speed = None
            self._height = meas.lane_width_m
            self._t_steer = meas.time_s
            traj = self.tables.trajectory(meas.mu, meas.vx_mps)  # clamped to the speed grid
            self._start_path(meas, traj, meas.d_m, meas.lane_width_m)
        elif mode is RETURN:
            self._hold_speed = meas.vx_mps
            self._start_return(meas, urgent=previous is ONCOMING_STEER_BRAKE)
        elif mode is ONCOMING_STEER_BRAKE:
            self._escape_to(self._passing_offset_m(meas), meas)
        elif mode is ONCOMING_BRAKE and self.settings.min_time_escapes:
            # a lateral motion away from the lane centre arrested at the front tyre's limit
            # (``arrest_first``), then a time-optimal shift back; the brake gets what the
            # friction ellipse leaves
            self._stop_path = None
            v_lat = lateral_state(meas)[0]
            if (
                self.settings.arrest_first
                and v_lat * meas.d_m > 0.0
                and abs(v_lat) >= self.settings.arrest_min_speed_mps
            ):
                self._arrest = math.copysign(1.0, v_lat)
                self._path = None
            else:
                self._escape_to(0.0, meas)
        elif mode is ONCOMING_BRAKE:
            # arrest the lateral motion first (the brake gets what the friction ellipse
            # leaves), then hold that offset while braking to standstill
            if self._stop_path is None:
                self._stop_path = self._lateral_stop(meas)
            self._start_path(meas, self._stop_path, meas.d_m, None)
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
        st = self.settings
        decel = self._decel.decel_mps2 if st.obstacle_decel_in_dmm else 0.0
        if decel < 0.0:
            decel = 0.0
        track = ObstacleTrack.sensed(
            meas,
            self._front_offset_m,
            range_m,
            closing_mps,
            obj,
            st.unknown_obstacle_length_m,
            decel,
        )
        last = self._obstacle
        if (
            last is None
            or self.mode not in _STEERING
            or abs(track.front_s_m - last.at(meas.time_s)[0]) <= st.track_gate_m
        ):
            self._obstacle = track

    def _clear_of_obstacle(self, meas: EgoMeasurement, path, dx_m: float) -> bool:
        """Mode 4's "desired position": the ego's rear is ``pass_margin_m`` past the obstacle's
        front, predicted from its last sensed speed and measured deceleration (to its stop).
        Without a track, the end of the lane change."""
        if self._obstacle is None:
            return path is not None and dx_m >= path.length_m
        if self.mode is ONCOMING_STEER_BRAKE and self.settings.compare_outcomes:
            return return_clears(meas, self._obstacle, self._budget(meas.mu))
        front_s = self._obstacle.at(meas.time_s)[0]
        ego_rear_s = meas.s_m - self.params.cg_to_rear_bumper_m
        return ego_rear_s - front_s >= self.settings.pass_margin_m

    def _commits(
        self, meas: EgoMeasurement, perception: Perception, travel: float, height: float
    ) -> bool:
        """Oncoming traffic seen in mode 2: pass on (True) or abort (mode 3). With
        ``compare_outcomes`` and tracks of it and of the obstacle, the option of lower
        predicted delta-v (``decision.oncoming``); else the point of no return."""
        onc = perception.oncoming_object
        if not (self.settings.compare_outcomes and onc is not None and self._obstacle is not None):
            return self._past_ponr(meas, travel, height)
        self._stop_path = None
        self.oncoming_choice = commit_choice(meas, onc, self._obstacle, self._budget(meas.mu))
        return self.oncoming_choice.pass_on

    def _past_ponr(self, meas: EgoMeasurement, travel: float, height: float) -> bool:
        """Past the point of no return (sec. 8.1): the lateral travel since the trigger
        reaches ``ponr_fraction`` of the lane change's, judged where the lateral motion will
        stop if it is arrested now (``ponr_at_lateral_stop``) or, as in the paper, at the
        offset reached (mode 2 only: the other modes do not ask)."""
        st = self.settings
        self._stop_path = None
        if st.ponr_at_lateral_stop:
            self._stop_path = self._lateral_stop(meas)
            travel += self._stop_path.y1_m - meas.d_m
        return travel >= st.ponr_fraction * height

    def _dmm(self, t: float, v: float, rng: float, closing: float) -> tuple[Sector, float]:
        """The DMM sector of the in-path obstacle and the range to where it will stand.

        The paper's sector of (range, closing speed), or, with ``obstacle_decel_in_dmm``,
        the more urgent of it and the sector of the obstacle standing where its measured
        braking stops it, approached at the ego's speed (``decision.obstacle``)."""
        sector = self._curve.sector(rng, closing)
        decel = self._decel.update(t, v - closing)
        if not self.settings.obstacle_decel_in_dmm:
            return sector, math.inf
        stop_range = stopping_range_m(rng, v - closing, decel)
        if stop_range < math.inf and (stop_range != rng or v != closing):  # else the same point
            standing = self._curve.sector(stop_range, v)
            if SECTOR_ORDER.index(standing) < SECTOR_ORDER.index(sector):  # more urgent
                sector = standing
        return sector, stop_range

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
        if mu != self._brake_mu:
            self._friction(mu)
        st = self.settings
        t, v, d = meas.time_s, meas.vx_mps, meas.d_m

        # ---- DMM: sector of the in-path obstacle (none when nothing is sensed) -------------
        rng = perception.aro_range_m
        rate = perception.aro_range_rate_mps
        if rng is not None and math.isfinite(rng):
            closing = -rate if rate is not None and math.isfinite(rate) else 0.0
            sector, stop_range = self._dmm(t, v, rng, closing)
            action = sector.action
            if action is STEER:
                if v < st.min_steer_speed_mps:
                    action = BRAKE  # too slow for a lane change: braking needs less room
                elif (
                    self.mode is UPDATE_BRAKE
                    and rng > self._curve.at(closing).stop_m
                    and stop_range > self._curve.at(v).stop_m
                ):
                    action = BRAKE  # braking already stops short of it: no lane change
                elif not meas.left_lane_available:
                    action = LIMIT_BRAKE  # no lane to change into: brake in lane
            threat_gone = closing < -st.release_opening_speed_mps
            self._track_obstacle(meas, rng, closing, perception.aro_object)
        else:
            sector = None
            action = NONE
            threat_gone = True
            self._decel.reset()
        coasted_m = perception.coasted_range_m
        if coasted_m is not None and self.mode in _HOLDING:
            # an object lost from view, predicted in the path: no hand-back while it does not
            # pull away; braking while it is within the stopping distance (at the ego's speed
            # or the closing speed, the larger) plus a margin
            closing_c = -perception.coasted_range_rate_mps
            vc = max(v, closing_c)
            near = coasted_m <= 0.5 * vc * vc * self._mass / self._brake_limit + (
                st.coasted_margin_m
            )
            if near or closing_c > -st.release_opening_speed_mps:
                threat_gone = False
            if near and action is NONE:
                action = BRAKE
        oncoming = bool(perception.oncoming_detected)
        block_m = perception.next_lane_obstacle_range_m
        if block_m is not None and rng is not None and block_m <= rng + st.next_lane_clear_m:
            oncoming = True  # the lane change would end against a standing car: as deadly
        policy = self.policy
        if policy is not None and policy.blocks(
            meas, perception, action is STEER and self.mode in _COMMITTING, self.mode in _WATCHING
        ):
            oncoming = True  # the next lane is not known free (safe policy): as oncoming

        # ---- mode machine --------------------------------------------------------------
        mode = self.mode
        path = self._path
        dx = meas.s_m - self._s0 if path is not None else 0.0
        travel = d - path.start_offset_m if path is not None else 0.0
        height = self._height
        settled = False
        if mode is RETURN and path is not None and dx >= path.length_m:
            heading_ok = abs(wrap_angle(meas.e_yaw_rad)) <= st.settle_heading_rad
            if abs(d) <= st.settle_offset_m and heading_ok:
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
            and mode is UPDATE_STEER_BRAKE
            and dx >= path.length_m
            and abs(d - path.start_offset_m - height) <= st.arrive_tolerance_m
            and abs(wrap_angle(meas.e_yaw_rad)) <= st.settle_heading_rad
        )
        past_ponr = (
            oncoming
            and mode is UPDATE_STEER_BRAKE
            and self._commits(meas, perception, travel, height)
        )
        if (
            past_ponr
            and oncoming
            and mode is UPDATE_STEER_BRAKE
            and policy is not None
            and policy.prefer_braking(meas, perception)
        ):
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
        elif mode is RETURN and oncoming and not self._urgent_return:
            self._start_return(meas, urgent=True)  # oncoming traffic seen during the return
        elif self._arrest and lateral_state(meas)[0] * self._arrest <= 0.0:
            self._arrest = 0.0  # lateral motion arrested: back to the lane centre
            self._escape_to(0.0, meas, st.arrest_return_g)
        elif (
            mode is ONCOMING_BRAKE
            and path is not None
            and dx >= path.length_m
            and self._stop_path is not None
        ):
            # lateral motion arrested: back to the lane centre while braking on
            self._stop_path = None
            self._shift_to(0.0, meas, st.evasive_lateral_g)
        path = self._path
        dx = meas.s_m - self._s0 if path is not None else 0.0

        # ---- lateral reference (lane centre unless a path is active) and steering, eq. 38 ----
        y_ref = yaw_ref = kappa_ref = kappa_ff = ax_ref = v_plan = steer_ff = 0.0
        beta_ref: float | None = None
        in_path, steer = False, self._steer
        road_kappa = meas.road_curvature_1pm
        if path is not None:
            y_ref, yaw_ref, kappa_ref, ax_ref, v_plan, _, beta_plan = path.at(dx)
            in_path = dx < path.length_m
            if not in_path:
                yaw_ref = kappa_ref = 0.0
            elif path.planned_steering:
                # the plan's steering (planned with the plant's tyre), ahead by the lag
                ahead = max(0.0, st.planned_preview_time_s - st.planned_preview_slope_s2pm * v)
                steer_ff = path.at(dx + v * ahead).steer_rad
                beta_ref = beta_plan + steer.steady_sideslip(v, road_kappa)
                steer = self._steer_plan
            else:
                kappa_ff = path.at(dx + v * st.preview_time_s).curvature_1pm
        if self._arrest:  # the most lateral force against the motion the envelope allows
            y_ref, e_lat, fb, yd, e_la = d, 0.0, 0.0, 0.0, 0.0
            delta = ff = steer.envelope_edge(v, meas.yaw_rate_radps, meas.vy_mps, mu, -self._arrest)
        else:
            e_lat = d - y_ref
            delta, ff, fb, yd, e_la = steer.command(
                v,
                meas.yaw_rate_radps,
                meas.vy_mps,
                e_lat,
                wrap_angle(meas.e_yaw_rad - yaw_ref),
                kappa_ref + road_kappa,
                kappa_ff + road_kappa,
                mu,
                steer_ff,
                beta_ref,
            )

        # ---- longitudinal: force limits from the friction ellipse with the lateral acceleration
        # in use (measured; outside the table's profile also the one this steering command asks
        # for, so that the brake yields before a turning axle locks), then the mode's loop -----
        tracking = in_path and mode in _STEERING  # the table's ax already fits the ellipse
        ay_use = abs(meas.ay_mps2)
        if not tracking:
            ay_steer = abs(self._steer.lateral_accel(v, delta))
            if ay_steer > ay_use:
                ay_use = ay_steer
        drive_lim, brake_lim = self._long.limits(v, mu, ay_use, self._brake_limit)
        if mode is NORMAL:
            drive, brake, ax_target = self._long.track_speed(
                self._initial_speed, v, mu, drive_lim, brake_lim, dt_s
            )
            v_target = self._initial_speed
        elif mode is UPDATE_BRAKE or mode is ONCOMING_BRAKE:
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

        warns = sector is not None and sector.warns
        fcw = warns or mode in _WARNING_MODES
        if fcw:
            self.fcw_raised = True
        self.sector = sector.letter if sector is not None else ""
        return _new(
            Command,
            (
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
            ),
        )
