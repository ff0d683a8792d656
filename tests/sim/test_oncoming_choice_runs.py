"""Commit or abort when the oncoming car is seen late: real co-simulations on the baseline.

Table 2's cell 300 m / 165 km/h / mu 0.7: the 100 m radar sees the oncoming car 1.7 s before
the fronts meet, with the ego 0.9 m into its lane change and moving left at 2.8 m/s. Passing
the obstacle and leaving the oncoming car's path takes longer; arresting the lateral motion and
returning into the lane keeps the ego out of the car's path and stops it behind the obstacle.
With the point of no return (0.3 x the lane width, judged where the lateral motion would stop)
it passed on and met the oncoming car head-on.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.sim.cosim import CoSimulation, RunSettings
from eoam_sumo.sim.scenario import ScenarioOverrides

pytestmark = pytest.mark.sumo

BASELINE = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.sumocfg"
CELL = ScenarioOverrides(ego_speed_mps=165 / 3.6, mu=0.7, oncoming_start_m=300.0)


def _run(eoam: EoamSettings):
    sim = CoSimulation(BASELINE, CELL, RunSettings(eoam=eoam))
    summary, _ = sim.run()
    return summary, sim.ctrl.oncoming_choice


def test_aborting_the_lane_change_avoids_the_head_on():
    """The ego follows its lane-change plan closely: it is seen 0.88 m out, moving left at
    2.8 m/s. The prediction now calls both options head-on, the abort with the lower delta-v;
    the abort keeps the ego out of the oncoming car's path and stops it behind the obstacle."""
    summary, choice = _run(EoamSettings())
    assert choice is not None and not choice.pass_on
    assert choice.passing.head_on
    assert choice.abort.delta_v_mps < choice.passing.delta_v_mps
    assert summary["outcome"] != "red"
    assert summary["collision_with"] in ("none", "aro")  # never the oncoming car
    assert summary["impact_speed_mps"] < 45.8  # below the ego's entry speed
    assert summary["modes_visited"] == [0, 1, 2, 3]


def test_the_point_of_no_return_rule_stays_available():
    summary, choice = _run(EoamSettings(compare_outcomes=False, min_time_escapes=False))
    assert choice is None
    assert summary["outcome"] == "red"
    assert summary["modes_visited"] == [0, 1, 2, 4, 5]
