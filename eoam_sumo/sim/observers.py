"""Observers of the co-simulation step: what watches a run without steering it.

An observer has three hooks, each given the running co-simulation (:class:`RunView`, what an
observer may read of :class:`~eoam_sumo.sim.cosim.CoSimulation`): ``start`` once the run is
set up (the ego placed, nothing stepped), ``after_step`` at the end of every step and ``end``
with the ego's end state in ``meas``. Add one with ``CoSimulation(..., observers=[...])``;
:class:`StepObserver` is a base with empty hooks.

Here: the time series (:class:`TimeSeries`), the running extremes of the ego
(:class:`Extremes`), its rollover (:class:`RolloverWatch`), the obstacle a lane change
avoided (:class:`AvoidedObstacle`) and the benchmark's timer of the step's phases
(:class:`PhaseTimer`); the margins are in ``sim/margins.py``, the traffic log in
``sim/trafficlog.py``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Any, Protocol

from mypy_extensions import mypyc_attr

from eoam_sumo.eoam import Command, EgoMeasurement, Perception
from eoam_sumo.sim.runlog import RunLog
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.lanes import lane_band_m

_LANE_CHANGE_MODES = (2, 4)  # the EOAM's modes that begin a lane change
#: The phases of a step, in order (``CoSimulation.step``).
PHASES = ("sense", "decide", "actuate", "write_back", "check_contact")


def no_lap(phase: str) -> None:
    """The step's ``lap`` when nothing times the phases: does nothing."""


class RunView(Protocol):
    """What observers read of a running co-simulation."""

    # called as each phase of a step ends, with its name, and with "" as the step begins
    # (``no_lap`` unless a PhaseTimer times the phases)
    lap: Callable[[str], None]

    @property
    def max_steps(self) -> int: ...  # the time limit in steps
    @property
    def t(self) -> float: ...  # SUMO time now (the end of the last step)
    @property
    def n_steps(self) -> int: ...  # steps made
    @property
    def meas(self) -> EgoMeasurement: ...  # the ego at the last step's start (the end state)
    @property
    def mu_true(self) -> float: ...  # the road's friction then (``meas.mu``: the believed)
    @property
    def perception(self) -> Perception: ...  # the radar's view at the last step's start
    @property
    def cmd(self) -> Command: ...  # the command decided from them
    @property
    def x_prev(self) -> list[float]: ...  # plant state at the last step's start
    @property
    def x(self) -> list[float]: ...  # plant state now
    @property
    def bodies(self) -> Sequence[Body]: ...  # the road users near the ego now
    @property
    def bodies_before(self) -> Sequence[Body]: ...  # the road users at the last step's start
    @property
    def session(self) -> Any: ...  # the SUMO session (queries only)
    @property
    def road(self) -> Any: ...  # the road frame of the ego's original lane
    @property
    def step_s(self) -> float: ...  # the step
    @property
    def lane_width_m(self) -> float: ...  # the ego's lane's width
    @property
    def left_lane(self) -> bool: ...  # a lane (either direction) lies left of the ego's
    @property
    def right_width_m(self) -> float: ...  # the lane right of the ego's it may use (0: none)
    @property
    def ay(self) -> float: ...  # the ego's lateral acceleration now (the plant's output)


@mypyc_attr(allow_interpreted_subclasses=True)  # observers are written in Python
class StepObserver:
    """An observer that does nothing: subclass it and override the hooks needed."""

    def start(self, sim: RunView) -> None:
        pass

    def after_step(self, sim: RunView) -> None:
        pass

    def end(self, sim: RunView) -> None:
        pass


class TimeSeries(StepObserver):
    """The run's time series (timeseries.csv): the state at each step's start with the command
    decided from it, then the end state with the mode and sector in force."""

    log: RunLog  # set when the run starts

    def __init__(self, brake_gains: tuple[float, ...]) -> None:
        self._brake_gains = brake_gains  # road brake force per bar, per wheel [N/bar]

    def start(self, sim: RunView) -> None:
        self.log = RunLog(sim.max_steps + 1, self._brake_gains)
        self._add = self.log.add

    def after_step(self, sim: RunView) -> None:
        self._add(sim.meas, sim.x_prev, sim.cmd, sim.perception, sim.mu_true)

    def end(self, sim: RunView) -> None:
        # the mode and sector in force at the end: the last command's (none without a step)
        self.log.add_end(sim.meas, sim.x, sim.cmd if sim.n_steps else None, sim.mu_true)


class Extremes(StepObserver):
    """Running extremes of the ego for the loss-of-control and road-departure rules: its
    lateral offset d (signed), |heading error| (wrapped to [-pi, pi)) and lowest forward speed.
    ``max_abs_offset_m`` covers the steps' starts only, as logged; the others include the end
    state."""

    def start(self, sim: RunView) -> None:
        self.min_d_m = self.max_d_m = 0.0
        self.max_abs_heading_error_rad = 0.0
        self.min_vx_mps = sim.x[3]
        self.max_abs_offset_m = 0.0

    def after_step(self, sim: RunView) -> None:
        meas = sim.meas
        d = meas.d_m
        self.max_d_m = max(self.max_d_m, d)
        self.min_d_m = min(self.min_d_m, d)
        self.min_vx_mps = min(self.min_vx_mps, meas.vx_mps)
        e_yaw = meas.e_yaw_rad
        m = self.max_abs_heading_error_rad
        if e_yaw > m or e_yaw < -m:  # wrapped only when it may be a new max
            self.max_abs_heading_error_rad = max(m, abs((e_yaw + math.pi) % math.tau - math.pi))

    def end(self, sim: RunView) -> None:
        max_d, min_d = self.max_d_m, self.min_d_m
        self.max_abs_offset_m = max(max_d, -min_d)
        meas = sim.meas
        self.min_d_m, self.max_d_m = min(min_d, meas.d_m), max(max_d, meas.d_m)
        self.min_vx_mps = min(self.min_vx_mps, meas.vx_mps)
        self.max_abs_heading_error_rad = max(
            self.max_abs_heading_error_rad, abs((meas.e_yaw_rad + math.pi) % math.tau - math.pi)
        )


class RolloverWatch(StepObserver):
    """Rollover, a loss of control (``sim/vehicle.py``): ``time_s`` the SUMO time at the end
    of the first step in which both inner tyres (front and rear of the side the lateral load
    transfer unloads) had lost their normal load under the plant's load transfer, or ``|ay|``
    passed the static stability limit (None: never), and ``cause`` which. A single inner wheel
    lifting is no rollover: ``lift_time_s`` (None: never), ``lift_tyre`` and ``lift_ay_mps2``
    report the first. ``min_load_n`` is the smallest normal load of any tyre at a step's end.

    The loads are ``static_n[i] + per_ax[i] ax + per_ay[i] ay`` (``vehicle.RolloverLimits``)
    with ``ax``, ``ay`` the plant's load accelerations, states ``ax_index`` and ``ay_index``;
    tyres in the order FL, FR, RL, RR."""

    def __init__(
        self,
        static_n: tuple[float, float, float, float],
        per_ax: tuple[float, float, float, float],
        per_ay: tuple[float, float, float, float],
        ssf_ay_mps2: float,
        ax_index: int,
        ay_index: int,
        tyres: tuple[str, str, str, str],
    ) -> None:
        self._static, self._per_ax, self._per_ay = static_n, per_ax, per_ay
        self._ssf_ay_mps2 = ssf_ay_mps2
        self._ax_index, self._ay_index = ax_index, ay_index
        self._tyres = tyres
        self.time_s: float | None = None
        self.cause = ""
        self.min_load_n = math.inf
        self.lift_time_s: float | None = None
        self.lift_tyre = ""
        self.lift_ay_mps2 = 0.0

    def start(self, sim: RunView) -> None:
        self.time_s, self.cause, self.min_load_n = None, "", math.inf
        self.lift_time_s, self.lift_tyre, self.lift_ay_mps2 = None, "", 0.0

    def after_step(self, sim: RunView) -> None:
        if self.time_s is not None:
            return
        x = sim.x
        ax, ay = x[self._ax_index], x[self._ay_index]
        static, per_ax, per_ay = self._static, self._per_ax, self._per_ay
        low = math.inf
        lifted = [False, False, False, False]
        any_lifted = False
        for i in range(4):
            load = static[i] + per_ax[i] * ax + per_ay[i] * ay
            low = min(low, load)
            if load <= 0.0 and per_ay[i] * ay < 0.0:  # inner: the roll unloads it
                lifted[i] = any_lifted = True
        self.min_load_n = min(self.min_load_n, max(low, 0.0))
        if any_lifted:  # else nothing lifted: the usual step, no more to do
            if self.lift_time_s is None:
                self.lift_time_s, self.lift_ay_mps2 = sim.t, ay
                self.lift_tyre = self._tyres[lifted.index(True)]
            for front, rear in ((0, 2), (1, 3)):
                if lifted[front] and lifted[rear]:
                    self.time_s = sim.t
                    side = self._tyres[front].split()[-1]
                    self.cause = f"both inner {side} wheels lifted"
                    return
        if abs(sim.ay) > self._ssf_ay_mps2:
            self.time_s = sim.t
            self.cause = (
                f"lateral acceleration {abs(sim.ay):.1f} m/s2 beyond the static stability "
                f"limit {self._ssf_ay_mps2:.1f} m/s2"
            )


class PhaseTimer(StepObserver):
    """Wall time spent in each phase of the step (``PHASES``), for the benchmark.

    It sets the simulation's ``lap`` to its own when the run starts and puts the one it found
    back at its end; ``totals`` maps each phase to its seconds, ``steps`` counts the steps.
    """

    def __init__(self) -> None:
        self.totals: dict[str, float] = {}
        self.steps = 0
        self._last_s = 0.0
        self._untimed: Callable[[str], None] = no_lap

    def start(self, sim: RunView) -> None:
        self.totals = dict.fromkeys(PHASES, 0.0)
        self.steps = 0
        self._untimed = sim.lap
        sim.lap = self.lap

    def lap(self, phase: str) -> None:
        """The phase ``phase`` has ended ("": the step begins): its time since the last lap."""
        now = time.perf_counter()
        if phase:
            self.totals[phase] += now - self._last_s
        self._last_s = now

    def after_step(self, sim: RunView) -> None:
        self.steps += 1

    def end(self, sim: RunView) -> None:
        sim.lap = self._untimed


class AvoidedObstacle(StepObserver):
    """The obstacle a lane change avoided, for the verdict only (ground truth; the EOAM never
    sees it): ``vid`` the SUMO id of the nearest road user ahead of the ego with its centre
    in the ego's lane band when the EOAM first began a lane change (mode 2 or 4), ``passed``
    at the end whether the ego's centre ended ahead of it along the road (None when no lane
    change began or the obstacle has left the simulation)."""

    vid: str | None
    passed: bool | None

    def start(self, sim: RunView) -> None:
        self.vid = None
        self.passed = None
        self._done = False

    def after_step(self, sim: RunView) -> None:
        if self._done or sim.cmd.mode not in _LANE_CHANGE_MODES:
            return
        self._done = True
        band_m = lane_band_m(sim.lane_width_m)
        s_ego, nearest = sim.meas.s_m, math.inf
        for b in sim.bodies_before:  # the road users at the start of that step
            s, d, _ = sim.road.project(b.x_m, b.y_m)
            if abs(d) < band_m and s_ego < s < s_ego + nearest:
                self.vid, nearest = b.vid, s - s_ego

    def end(self, sim: RunView) -> None:
        self.passed = None if self.vid is None else _ended_ahead_of(sim, self.vid)


def _ended_ahead_of(sim: RunView, vid: str) -> bool | None:
    """Whether the ego's centre ended ahead of the road user ``vid`` along the road (None
    when it has left the simulation)."""
    body = next((b for b in sim.bodies if b.vid == vid), None)
    if body is None:
        try:
            body = sim.session.body(vid)
        except Exception:  # noqa: BLE001 - gone from SUMO (libsumo and TraCI raise differently)
            return None
    s_obstacle = sim.road.project(body.x_m, body.y_m)[0]
    return sim.meas.s_m > s_obstacle
