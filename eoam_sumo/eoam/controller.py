"""``EoamController``: the EOAM step as a sequence of stages over one ``ControllerState``.

perceive -> DMM -> mode transitions -> lateral control -> longitudinal control -> ``Command``;
each stage is a function of the fixed ``Parts``, the state and the step's inputs, and hands
the next a small named tuple (``state``).
"""

from __future__ import annotations

import math

from eoam_sumo.decision.dmm import Sector
from eoam_sumo.decision.modes import (
    ONCOMING_BRAKE,
    ONCOMING_STEER_BRAKE,
    UPDATE_BRAKE,
    UPDATE_STEER_BRAKE,
    Mode,
)
from eoam_sumo.decision.obstacle import ObstacleDecel
from eoam_sumo.decision.oncoming import Choice
from eoam_sumo.decision.policy import SafePolicy
from eoam_sumo.eoam.decide import decide
from eoam_sumo.eoam.lateral import lateral_control
from eoam_sumo.eoam.longitudinal import longitudinal_control
from eoam_sumo.eoam.parts import Parts, build_parts
from eoam_sumo.eoam.perceive import perceive
from eoam_sumo.eoam.sides import (
    RIGHT,
    choose_side,
    mirrored_command,
    mirrored_measurement,
    mirrored_perception,
)
from eoam_sumo.eoam.state import ControllerState, LateralOutput, LongitudinalOutput
from eoam_sumo.eoam.transitions import advance_mode
from eoam_sumo.eoam_messages import Command, EgoMeasurement, Perception
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.params import VehicleParams

_WARNING_MODES = (UPDATE_BRAKE, UPDATE_STEER_BRAKE, ONCOMING_BRAKE, ONCOMING_STEER_BRAKE)  # FCW


class EoamController:
    """Decision (DMM, modes 0-5) and control (steering, longitudinal) of the ego."""

    def __init__(self, params: VehicleParams, tables, settings: EoamSettings | None = None):
        self.params = params
        self.tables = tables
        self.settings = settings = settings or EoamSettings()
        self.parts: Parts = build_parts(params, tables, settings)
        self.state = self._fresh_state(math.nan)

    def _fresh_state(self, initial_speed_mps: float) -> ControllerState:
        """NORMAL with no manoeuvre and an empty history; the controllers' memory cleared."""
        self.parts.longitudinal.reset()
        self.parts.gate.reset()
        decel = ObstacleDecel(self.settings.obstacle_decel_time_constant_s)
        return ControllerState(decel, initial_speed_mps)

    def reset(self, initial_speed_mps: float) -> None:
        """Start a run: NORMAL, holding ``initial_speed_mps`` with the speed PID."""
        v = float(initial_speed_mps)
        if not (math.isfinite(v) and v >= 0.0):
            raise ValueError(f"initial_speed_mps={initial_speed_mps!r} must be finite and >= 0")
        self.state = self._fresh_state(v)

    def step(self, meas: EgoMeasurement, perception: Perception, dt_s: float) -> Command:
        """One decision + control step; commands hold until the next call (evading right,
        in the mirrored road frame: ``sides``)."""
        parts, state = self.parts, self.state
        if choose_side(parts, state, meas, perception) == RIGHT:
            meas, perception = mirrored_measurement(meas), mirrored_perception(perception)
            return mirrored_command(self._step(meas, perception, dt_s))
        return self._step(meas, perception, dt_s)

    def _step(self, meas: EgoMeasurement, perception: Perception, dt_s: float) -> Command:
        parts, state = self.parts, self.state
        situation = perceive(parts, state, meas, perception)
        decision = decide(parts, state, meas, perception, situation)
        advance_mode(parts, state, meas, perception, decision, situation.threat_gone)
        lateral = lateral_control(parts, state, meas)
        longitudinal = longitudinal_control(parts, state, meas, lateral, dt_s)
        return command(state, decision.sector, lateral, longitudinal)

    # ------------------------------------------------------- what the simulation reads
    @property
    def mode(self) -> Mode:
        """The mode of operation after the last step."""
        return self.state.mode

    @property
    def modes_visited(self) -> list[int]:
        """Modes 0-5 in order of first visit."""
        return self.state.modes_visited

    @property
    def fcw_raised(self) -> bool:
        """The forward-collision warning was raised at some step."""
        return self.state.fcw_raised

    @property
    def sector(self) -> str:
        """The last step's DMM sector letter ("": nothing in the path)."""
        return self.state.sector

    @property
    def oncoming_choice(self) -> Choice | None:
        """The commit/abort decision on oncoming traffic, when made."""
        return self.state.oncoming_choice

    @property
    def policy(self) -> SafePolicy | None:
        """The safe policy's checks (None: the paper's policy)."""
        return self.parts.gate.policy


def command(
    state: ControllerState,
    sector: Sector | None,
    lateral: LateralOutput,
    longitudinal: LongitudinalOutput,
) -> Command:
    """The actuator commands and what was decided; raises the forward-collision warning in
    sectors A-F and the intervening modes."""
    mode = state.mode
    fcw = (sector is not None and sector.warns) or mode in _WARNING_MODES
    if fcw:
        state.fcw_raised = True
    state.sector = sector.letter if sector is not None else ""
    return Command(
        lateral.steer_rad,
        longitudinal.drive_n,
        longitudinal.brake_n,
        int(mode),
        fcw,
        state.sector,
        longitudinal.ax_target_mps2,
        lateral.y_ref_m,
        lateral.dx_m,
        lateral.lateral_error_m,
        lateral.lookahead_error_m,
        lateral.steer_ff_rad,
        lateral.steer_fb_rad,
        lateral.steer_yd_rad,
        longitudinal.speed_target_mps,
    )
