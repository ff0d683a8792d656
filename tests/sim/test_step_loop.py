"""The co-simulation driven step by step (real SUMO runs of the baseline scenario)."""

from __future__ import annotations

import gc
from pathlib import Path

import numpy as np
import pytest

from eoam_sumo.sim.cosim import CoSimulation
from eoam_sumo.sim.observers import PHASES, PhaseTimer, StepObserver, no_lap
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.sim.summary import TIMING_FIELDS

pytestmark = pytest.mark.sumo

BASELINE = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.sumocfg"
OVER = ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=1.0)  # a lane change (120 km/h stops)


class Recorder(StepObserver):
    """Keeps what an observer sees: hook calls, times, the ego's offsets."""

    def __init__(self):
        self.calls, self.times, self.offsets = [], [], []

    def start(self, sim):
        self.calls.append("start")

    def after_step(self, sim):
        self.calls.append("step")
        self.times.append(sim.meas.time_s)
        self.offsets.append(sim.meas.d_m)

    def end(self, sim):
        self.calls.append("end")


def _physics(summary: dict) -> dict:
    return {k: v for k, v in summary.items() if k not in TIMING_FIELDS}


def test_stepping_by_hand_gives_the_run_result_and_observers_see_every_step():
    settings = RunSettings(max_time_s=20.0)
    whole, whole_log = CoSimulation(BASELINE, OVER, settings).run()
    rec = Recorder()
    sim = CoSimulation(BASELINE, OVER, settings, observers=[rec])
    session = sim.open_session()
    try:
        sim.start(session)
        t0, step_s = sim.t, settings.step_s
        steered_at = None
        while not sim.step():
            assert sim.t == pytest.approx(t0 + sim.n_steps * step_s)
            assert sim.first_contact is None
            if steered_at is None and sim.cmd.mode == 2:
                steered_at = sim.n_steps
        summary = sim.finish()
    finally:
        session.close()
    assert _physics(summary.as_dict()) == _physics(whole)
    np.testing.assert_array_equal(sim.timeseries.log.array(), whole_log.array())
    assert rec.calls == ["start", *["step"] * sim.n_steps, "end"]
    assert rec.times == pytest.approx([t0 + k * step_s for k in range(sim.n_steps)])
    assert sim.end_cause == "settled" and summary.outcome == "green"
    # the lane change seen from outside: the offset grows to the next lane after the steer
    assert steered_at is not None
    assert max(rec.offsets[steered_at:]) > 0.8 * sim.lane_width_m > rec.offsets[steered_at]


def test_a_run_ends_at_its_time_limit_after_as_many_steps():
    sim = CoSimulation(BASELINE, OVER, RunSettings(max_time_s=1.5))
    summary, log = sim.run()
    assert sim.end_cause == "time_limit" and sim.n_steps == 150
    assert log.n == 151  # every step's start and the end state
    assert summary["sim_time_s"] == pytest.approx(1.5)


def test_the_phase_timer_times_every_phase_and_leaves_the_phases_as_they_were():
    timer = PhaseTimer()
    sim = CoSimulation(BASELINE, OVER, RunSettings(max_time_s=1.0), observers=[timer])
    sim.run()
    assert set(timer.totals) == set(PHASES) and timer.steps == 100
    assert all(t > 0.0 for t in timer.totals.values())
    assert sum(timer.totals.values()) < sim.loop_wall_s
    assert sim.lap is no_lap  # untimed again after the run


def test_a_finished_simulation_is_freed_without_the_garbage_collector():
    """Nothing of a run keeps its simulation alive once the caller drops it: no reference
    cycle through it, which only a full collection would free (a batch worker grew by 6 MB a
    run when its phases were bound methods)."""

    def alive() -> int:
        return sum(isinstance(o, CoSimulation) for o in gc.get_objects())

    gc.collect()
    before = alive()
    gc.disable()
    try:
        for observers in ([], [PhaseTimer()]):
            sim = CoSimulation(BASELINE, OVER, RunSettings(max_time_s=0.5), observers=observers)
            sim.run()
            del sim
            assert alive() == before
    finally:
        gc.enable()
