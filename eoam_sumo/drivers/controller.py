"""A reference driver as the ego's controller, in the EOAM's place (``make_controller``): the
same ``step(meas, perception, dt) -> Command`` and the same run facts (mode, modes visited,
FCW), on the same plant and sensing.

The driver model decides the longitudinal acceleration (``careful``, ``fsm``, ``rss``); the
EOAM's own controllers carry it out: the lane-keeping steering of mode 0, the speed PID holding
the set speed while the model does not intervene (or, after it did, the speed it left the ego
at), and while it brakes the feedforward of the acceleration loop, the profile commanded the
brake's lag ahead, with feedback on the speed (``DriverController._follow``). It never
changes lanes. While it brakes the mode is 1 (a brake in the lane, as the EOAM's limit
braking: a stop ends the run), when it lets go mode 0 again (a hand-back)."""

from __future__ import annotations

from eoam_sumo.control.longitudinal import LongitudinalController, LongitudinalGains
from eoam_sumo.decision.modes import NORMAL, UPDATE_BRAKE
from eoam_sumo.drivers import DRIVERS
from eoam_sumo.drivers.careful import CarefulDriver
from eoam_sumo.drivers.common import LeadTracker
from eoam_sumo.drivers.fsm import FsmDriver
from eoam_sumo.drivers.rss import RssDriver
from eoam_sumo.eoam.controller import EoamController, command
from eoam_sumo.eoam.lateral import lateral_control
from eoam_sumo.eoam.longitudinal import force_limits, longitudinal_control
from eoam_sumo.eoam.perceive import check_measurement, friction_at
from eoam_sumo.eoam.state import LongitudinalOutput
from eoam_sumo.eoam_messages import Command, EgoMeasurement, Perception
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.params import VehicleParams

#: A driver's profile is carried out by feedforward (the acceleration loop's, gains 0: the
#: equivalent mass and the resistance) commanded the brake's lag ahead, plus this gain on the
#: speed error to the profile's speed [1/s] (an acceleration PID on the body acceleration,
#: wound up during the ramp's lag, held the deceleration 0.06 m/s^2 too hard for seconds:
#: 1 m of gap at 100 km/h).
DRIVER_ACCEL_GAINS = LongitudinalGains(accel_kp=0.0, accel_ki_per_s=0.0, accel_kd_s=0.0)
SPEED_GAIN_PER_S = 2.0

_MODELS = {"r157-cc": CarefulDriver, "fsm": FsmDriver, "rss": RssDriver}


class DriverController(EoamController):
    """A reference driver's longitudinal model on the EOAM's lane keeping and actuators."""

    def __init__(self, model, params: VehicleParams, tables, settings: EoamSettings | None = None):
        super().__init__(params, tables, settings)
        self.model = model
        self.lead = LeadTracker()
        self.intervened = False
        self.v_ref: float | None = None  # the profile's speed since the driver intervened
        self.accel_loop = LongitudinalController(params, DRIVER_ACCEL_GAINS)

    def reset(self, initial_speed_mps: float) -> None:
        super().reset(initial_speed_mps)
        self.model.reset()
        self.lead.reset()
        self.intervened = False
        self.v_ref = None

    def step(self, meas: EgoMeasurement, perception: Perception, dt_s: float) -> Command:
        parts, state = self.parts, self.state
        check_measurement(state, meas)
        if state.friction is None or meas.mu != state.friction.mu:
            state.friction = friction_at(parts, meas.mu)
        lead = self.lead.update(meas.vx_mps, perception, dt_s, meas.lane_width_m)
        accel = self.model.step(meas.time_s, meas.vx_mps, meas.ax_mps2, lead, dt_s)
        state.mode = NORMAL  # the lane centre for the steering
        lateral = lateral_control(parts, state, meas)
        if accel is None:
            self.v_ref = None
            if self.intervened and state.hold_speed_mps is None:
                state.hold_speed_mps = meas.vx_mps  # the speed the driver left the ego at
                parts.longitudinal.reset()
            if state.hold_speed_mps is not None:
                state.initial_speed_mps = state.hold_speed_mps
            longitudinal = longitudinal_control(parts, state, meas, lateral, dt_s)
        else:
            longitudinal = self._follow(meas, lateral, accel, dt_s)
        return command(state, None, lateral, longitudinal)

    def _follow(self, meas: EgoMeasurement, lateral, accel: float, dt_s: float):
        """Mode 1: the driver's acceleration profile carried out, commanded ``brake_lag_s``
        ahead (``Response.preview``) plus ``SPEED_GAIN_PER_S`` times the speed error to the
        profile's own speed, through the feedforward (equivalent mass, resistance)."""
        parts, state = self.parts, self.state
        if not self.intervened:
            self.accel_loop.reset()
        self.intervened = True
        state.hold_speed_mps = None
        state.mode = UPDATE_BRAKE
        if UPDATE_BRAKE not in state.modes_visited:
            state.modes_visited.append(int(UPDATE_BRAKE))
        v = meas.vx_mps
        if self.v_ref is None:
            self.v_ref = v
        ahead = self.model.response.preview(meas.time_s, dt_s, self.params.brake_lag_s)
        a_cmd = (accel if ahead is None else ahead) + SPEED_GAIN_PER_S * (self.v_ref - v)
        self.v_ref = max(self.v_ref + accel * dt_s, 0.0)
        drive_lim, brake_lim = force_limits(parts, state, meas, lateral.steer_rad, False)
        drive, brake = self.accel_loop.track_accel(
            a_cmd, meas.ax_mps2, v, drive_lim, brake_lim, dt_s
        )
        return LongitudinalOutput(drive, brake, accel, self.v_ref)


def make_controller(
    driver: str, params: VehicleParams, tables, settings: EoamSettings | None = None
) -> EoamController:
    """The ego's controller: the EOAM (``eoam``) or a reference driver (``DRIVERS``)."""
    if driver == "eoam":
        return EoamController(params, tables, settings)
    if driver not in _MODELS:
        raise ValueError(f"driver {driver!r} is not one of {', '.join(DRIVERS)}")
    return DriverController(_MODELS[driver](), params, tables, settings)
