"""A multi-rate run (SUMO at 100 ms, the EOAM at 10 ms) against the 10 ms reference: the same
outcome, contact partner and impact, found between SUMO's steps; the time series still one row
per 10 ms control step."""

from __future__ import annotations

import numpy as np
import pytest

from eoam_sumo.sim.cosim import CoSimulation
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.settings import RunSettings
from tests.builders import BASELINE

pytestmark = pytest.mark.sumo


def _run(sumo_step_s: float) -> tuple[dict, np.ndarray]:
    # Table 2's onc-300_v165_mu0.1: the lane change on ice meets the oncoming car head-on
    over = ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=0.1, oncoming_start_m=300.0)
    summary, log = CoSimulation(BASELINE, over, RunSettings(sumo_step_s=sumo_step_s)).run()
    return summary, log.column("time_s")


def test_a_run_at_100_ms_sumo_steps_ends_as_the_10_ms_reference():
    ref, t_ref = _run(0.01)
    got, t = _run(0.1)
    assert ref["outcome"] == "red" and ref["collision_with"] == "oncoming"
    for key in ("outcome", "collision_with", "collision_with_id", "modes_visited"):
        assert got[key] == ref[key], key
    assert got["impact_speed_mps"] == pytest.approx(ref["impact_speed_mps"], abs=0.05)
    # the contact is timed at the control rate: within a control step of the reference's,
    # though SUMO reported the oncoming car only every 100 ms
    assert got["sim_time_s"] == pytest.approx(ref["sim_time_s"], abs=0.011)
    # the same clock (the reference's departure) and one row per 10 ms step
    assert t[0] == t_ref[0]
    assert np.allclose(np.diff(t), 0.01)
    assert got["sumo_overrides"]["step-length"] == "0.100"
    assert got["sumo_overrides"]["step-method.ballistic"] == "true"
    # one physics at every step: SUMO's ballistic update at the 10 ms reference too
    assert ref["sumo_overrides"]["step-method.ballistic"] == "true"
