"""The closed loop follows the planned lane change: real co-simulations of Table 2 cells.

The cells of the paper's Table 2 (baseline scenario, 100 m radar, no oncoming car) whose lane
changes were tracked worst: 55 km/h on dry road (the shortest, most braked plan: 3.5 m in
about 20 m, course 0.4 rad) and 165 km/h on dry and on snowy road (braking from mode 1 into
the lane change). During the lane change (mode 2) the ego's lateral offset stays within
0.25 m of the planned one, and the lane change ends without contact. With plans made for the
paper's tyre at the whole friction ellipse the errors were 0.92, 0.43 and 0.33 m; with the
path's course rate as the yaw-rate reference instead of the plan's body yaw rate, 165 km/h on
mu 1.0 ran 0.27 m off (the plan's sideslip turns at up to 0.3 rad/s there).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from eoam_sumo.batch.runner import run_batch
from eoam_sumo.plant import OUTPUT_NAMES
from eoam_sumo.sim.cosim import CoSimulation
from eoam_sumo.sim.scenario.overrides import ScenarioOverrides

pytestmark = pytest.mark.sumo

REPO = Path(__file__).resolve().parents[2]
LIMIT_M = 0.25
FRONT_LOCKED, REAR_LOCKED = OUTPUT_NAMES.index("front_locked"), OUTPUT_NAMES.index("rear_locked")


def test_lane_change_follows_its_plan(tmp_path):
    matrix = tmp_path / "tracking.toml"
    matrix.write_text(
        f'[scenario]\nsumocfg = "{REPO / "scenarios" / "baseline.sumocfg"}"\n'
        "max_time_s = 30.0\n"
        '[sweep]\nego_speed_kmh = [55, 165]\nmu = [1.0, 0.3]\noncoming_start_m = ["none"]\n'
    )
    results = run_batch(matrix, tmp_path / "out", jobs=2, progress=False)
    assert (results["status"] == "ok").all()
    cells = results.set_index(["ego_speed_kmh", "mu"])
    for cell in ((55, 1.0), (165, 1.0), (165, 0.3)):
        row = cells.loc[cell]
        assert "2" in str(row["modes_visited"]).split("-"), (cell, row["modes_visited"])
        assert row["outcome"] == "green", (cell, row["reason"])
        ts = pd.read_csv(
            tmp_path / "out" / row["case_dir"] / "timeseries.csv",
            usecols=["mode", "lateral_error_m"],
        )
        worst = ts.loc[ts["mode"] == 2, "lateral_error_m"].abs().max()
        assert worst <= LIMIT_M, f"{cell}: lane change {worst:.3f} m off its plan"


def test_on_ice_the_lane_change_keeps_its_front_wheels_rolling():
    """90 km/h on mu 0.1 without ABS, the paper's Table 2 cell. Limit braking at
    0.95 of eq. 33 used to lock the front axle (rolling resistance and the tyre's load
    sensitivity on top of the split's share), so the lane change began on locked front
    wheels and ran 2.18 m off its plan into the obstacle. Now no wheel locks from the trigger
    on, and the lane change tracks its plan."""
    overrides = ScenarioOverrides(ego_speed_mps=90.0 / 3.6, mu=0.1)
    sim = CoSimulation(REPO / "scenarios" / "baseline.sumocfg", overrides)
    locked: list[float] = []
    advance = sim.plant.advance

    def watched(x, u, mu):
        x_next, y = advance(x, u, mu)
        if sim.cmd.mode and (y[FRONT_LOCKED] or y[REAR_LOCKED]) and x_next[3] > 3.0:
            locked.append(sim.t)
        return x_next, y

    sim.plant.advance = watched
    summary, log = sim.run()
    assert summary["outcome"] == "green", summary["reason"]
    assert 2 in summary["modes_visited"]
    assert not locked, f"a wheel locked at {locked[0]:.2f} s"
    mode, error = log.column("mode"), log.column("lateral_error_m")
    worst = float(np.abs(error[mode == 2]).max())
    assert worst <= LIMIT_M, f"lane change {worst:.3f} m off its plan"
