"""Observers of the co-simulation step: what watches a run without steering it.

An observer has three hooks, each given the running co-simulation (:class:`RunView`, what an
observer may read of :class:`~eoam_sumo.sim.cosim.CoSimulation`): ``start`` once the run is
set up (the ego placed, nothing stepped), ``after_step`` at the end of every step and ``end``
with the ego's end state in ``meas``. Add one with ``CoSimulation(..., observers=[...])``;
:class:`StepObserver` is a base with empty hooks.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Any, Protocol

from mypy_extensions import mypyc_attr

from eoam_sumo.eoam import Command, EgoMeasurement, Perception
from eoam_sumo.sim.runlog import RunLog


class RunView(Protocol):
    """What observers read of a running co-simulation."""

    @property
    def PHASES(self) -> tuple[str, ...]: ...

    phase_calls: tuple[Callable[..., Any], ...]  # what the step calls for each phase (with

    # the simulation first)
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
    def bodies(self) -> Sequence[Any]: ...  # the road users near the ego now (``Body``)
    @property
    def bodies_before(self) -> Sequence[Any]: ...  # the road users at the last step's start
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
    decided from it, then the end state."""

    log: RunLog  # set when the run starts

    def start(self, sim: RunView) -> None:
        self.log = RunLog(sim.max_steps + 1)
        self._add = self.log.add

    def after_step(self, sim: RunView) -> None:
        self._add(sim.meas, sim.x_prev, sim.cmd, sim.perception, sim.mu_true)

    def end(self, sim: RunView) -> None:
        self._add(sim.meas, sim.x, None, None, sim.mu_true)


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


class PhaseTimer(StepObserver):
    """Wall time spent in each phase of the step (``CoSimulation.PHASES``), for the benchmark.

    It wraps the simulation's phase calls (``phase_calls``) when the run starts and puts them
    back at its end; ``totals`` maps each phase to its seconds, ``steps`` counts the steps.
    Without a PhaseTimer the phases run unwrapped.
    """

    def __init__(self) -> None:
        self.totals: dict[str, float] = {}
        self.steps = 0
        self._unwrapped: tuple[Callable[..., Any], ...] = ()

    def start(self, sim: RunView) -> None:
        self.totals = dict.fromkeys(sim.PHASES, 0.0)
        self.steps = 0
        self._unwrapped = calls = sim.phase_calls
        sim.phase_calls = tuple(self._timed(name, call) for name, call in zip(sim.PHASES, calls))

    def _timed(self, name: str, phase):
        clock, totals = time.perf_counter, self.totals

        def timed(*args):
            t0 = clock()
            out = phase(*args)
            totals[name] += clock() - t0
            return out

        return timed

    def after_step(self, sim: RunView) -> None:
        self.steps += 1

    def end(self, sim: RunView) -> None:
        sim.phase_calls = self._unwrapped
