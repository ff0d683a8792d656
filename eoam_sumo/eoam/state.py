"""What the EOAM step remembers between steps, and what its stages hand each other in one step.

``ControllerState`` is the one mutable record of a run (mode machine, manoeuvre, obstacle
track); the stages of ``EoamController.step`` read and update it. The named tuples are the
per-step results one stage passes to the next: ``Situation`` (perceive), ``Decision`` (DMM),
``LateralOutput`` (steering), ``LongitudinalOutput`` (drive and brake).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

from eoam_sumo.decision.dmm import Action, BoundaryCurve, Sector
from eoam_sumo.decision.modes import NORMAL, Mode
from eoam_sumo.decision.obstacle import ObstacleDecel, ObstacleTrack
from eoam_sumo.decision.oncoming import Choice
from eoam_sumo.eoam_messages import EgoMeasurement
from eoam_sumo.manoeuvre.lateral_state import lateral_state
from eoam_sumo.manoeuvre.path_reference import PathReference
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift


class Friction(NamedTuple):
    """What depends on the sensed friction, refreshed when it changes."""

    mu: float
    brake_limit_n: float  # limit braking: a share of the no-lock brake force
    brake_decel_mps2: float  # what limit braking delivers: brake_limit_n / m_eq (wheels spin)
    curve: BoundaryCurve  # the DMM boundaries at this friction


@dataclass
class ControllerState:
    """The EOAM's memory of one run (a new record at every ``reset``)."""

    obstacle_decel: ObstacleDecel  # low-pass estimate of the obstacle's own braking
    initial_speed_mps: float = math.nan  # the set speed of mode 0 (nan: not reset yet)
    friction: Friction | None = None
    lane_friction: Friction | None = None  # under the ego (``EgoMeasurement.mu_lane``)
    mode: Mode = NORMAL
    modes_visited: list[int] = field(default_factory=lambda: [0])  # in order of first visit
    fcw_raised: bool = False
    sector: str = ""  # the last step's DMM sector letter ("": nothing in the path)
    path: PathReference | None = None  # the active manoeuvre's reference (None: lane centre)
    s0_m: float = 0.0  # station where the path began
    t0_s: float = 0.0  # when the path began
    t_steer_s: float = 0.0  # when mode 2 began (manoeuvre timer)
    height_m: float = 0.0  # mode 2's lateral travel (a lane width)
    settle_since_s: float | None = None  # mode 5: since when the ego is settled
    hold_speed_mps: float | None = None  # the speed held after a manoeuvre's profile
    urgent_return: bool = False  # mode 5's return runs at the evasive lateral acceleration
    braking_return: bool = False  # mode 3 entered from 5: the return's path, braking on
    stop_path: QuinticShift | None = None  # the lateral stop judged for the point of no return
    arrest: float = 0.0  # mode 3: sign of the lateral motion being arrested (0: none)
    obstacle: ObstacleTrack | None = None  # the in-path obstacle as last sensed
    avoided: ObstacleTrack | None = None  # mode 5: the obstacle modes 2 and 4 steered around
    oncoming_choice: Choice | None = None  # the commit/abort decision, when made
    side: int = 1  # the side of the lane change: +1 left, -1 right (the step mirrored)
    target_offset_m: float = 0.0  # the target lane's centre from the ego's (0: a lane width)
    following: bool = False  # mode 0 after mode 3 let a moving obstacle go: keep a time gap

    def path_progress(self, meas: EgoMeasurement) -> tuple[float, float]:
        """(dx on the active path, how many times faster than the ego it advances): the
        distance travelled since it began, or its pace's for an escape laid out in time
        (``PathReference.progress``); (0, 1) without a path."""
        path = self.path
        if path is None:
            return 0.0, 1.0
        travelled = meas.s_m - self.s0_m
        if path.pace_mps is None:
            return travelled, 1.0
        return path.progress(meas.time_s - self.t0_s, travelled, lateral_state(meas)[2])

    def friction_now(self) -> Friction:
        """The friction record of this step (the perceive stage refreshes it first)."""
        friction = self.friction
        if friction is None:
            raise RuntimeError("the perceive stage sets the friction before it is read")
        return friction


class Situation(NamedTuple):
    """The perceive stage's view of this step."""

    range_m: float | None  # the in-path obstacle's range (None: nothing finite sensed)
    closing_mps: float  # its closing speed (0 without one)
    obstacle_decel_mps2: float  # its own braking, filtered (0 without one)
    threat_gone: bool  # nothing in the path, or it pulls away (and no coasted object holds)
    coasted_near: bool  # an object lost from view is within the stopping distance
    oncoming: bool  # oncoming traffic seen, or a standing car where the lane change would end


class Decision(NamedTuple):
    """The DMM stage's result: the sector, the action it asks for, and whether the next lane
    is closed (the mode machine's "oncoming": traffic, a standing car or the safe policy)."""

    sector: Sector | None
    action: Action
    oncoming: bool


class LateralOutput(NamedTuple):
    """The lateral stage's reference and steering command (eq. 38)."""

    steer_rad: float
    y_ref_m: float
    dx_m: float
    lateral_error_m: float
    lookahead_error_m: float
    steer_ff_rad: float
    steer_fb_rad: float
    steer_yd_rad: float
    in_path: bool  # the active path is being followed (not past its end)
    ax_ref_mps2: float  # the path's longitudinal acceleration and planned speed there
    v_plan_mps: float


class LongitudinalOutput(NamedTuple):
    """The longitudinal stage's forces and its target."""

    drive_n: float
    brake_n: float
    ax_target_mps2: float
    speed_target_mps: float
