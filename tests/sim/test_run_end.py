"""The run's end rule: never settled while the ego moves towards a road user close ahead in
its lane (ground truth, ``margins.road_user_close_ahead``)."""

from __future__ import annotations

import pytest

from eoam_sumo.sim.margins import CLOSE_AHEAD_MARGIN_M, road_user_close_ahead
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body

LANE_M = 3.5
ROAD = RoadFrame([(-1000.0, 0.0), (5000.0, 0.0)])  # the ego's lane centre line, eastbound
FRONT_M = 2.0  # CG to front bumper
G = 9.81


def close(v_mps: float, body: Body, mu: float = 1.0, ego_d_m: float = 0.0) -> bool:
    """The ego's CG at x = 0 (front bumper at 2 m), at ``v_mps``, and one road user."""
    return road_user_close_ahead([0.0, ego_d_m, 0.0, v_mps], FRONT_M, ROAD, LANE_M, mu, [body])


def person(gap_m: float, d_m: float = -1.13, speed_mps: float = 0.0) -> Body:
    """A person whose rear is ``gap_m`` ahead of the ego's front bumper."""
    return Body("p", "pedestrian", FRONT_M + gap_m + 0.15, d_m, 0.0, speed_mps, 0.3, 0.55)


@pytest.mark.parametrize(("v_mps", "mu"), [(20.0, 1.0), (10.0, 0.3), (3.0, 0.1)])
def test_a_standing_person_counts_within_the_stopping_distance_plus_the_margin(v_mps, mu):
    need = v_mps**2 / (2 * mu * G) + CLOSE_AHEAD_MARGIN_M
    assert close(v_mps, person(need - 0.05), mu)
    assert not close(v_mps, person(need + 0.05), mu)


def test_a_stopped_ego_has_reached_its_end_whoever_is_ahead():
    assert not close(0.0, person(0.5))


def test_only_ahead_and_in_the_lane_the_ego_is_in():
    assert not close(10.0, person(-1.0))  # centre behind the front bumper
    assert not close(10.0, person(3.0, d_m=LANE_M))  # in the next lane
    # the ego in the next lane: the person in its original lane is not in its lane
    assert not close(10.0, person(3.0), ego_d_m=LANE_M)
    assert close(10.0, person(3.0, d_m=LANE_M), ego_d_m=LANE_M)


def test_a_road_user_driving_away_needs_only_the_difference_of_the_stopping_distances():
    """Both braking at the road's friction, the ego stops behind where a car doing u stops
    when the gap exceeds (v^2 - u^2) / (2 mu g)."""

    def car(gap_m, u):
        return Body("c", "passenger", FRONT_M + gap_m + 2.3, 0.0, 0.0, u, 4.6, 1.8)

    need = (20.0**2 - 15.0**2) / (2 * G) + CLOSE_AHEAD_MARGIN_M
    assert close(20.0, car(need - 0.05, 15.0)) and not close(20.0, car(need + 0.05, 15.0))
    assert not close(20.0, car(CLOSE_AHEAD_MARGIN_M + 0.05, 25.0))  # faster than the ego


@pytest.mark.sumo
def test_the_last_timeseries_row_carries_the_mode_and_sector_in_force(tmp_path):
    """The end state's row (no command is decided from it) keeps the last step's mode and DMM
    sector; it used to leave them empty."""
    import pandas as pd

    from eoam_sumo.sim.cosim import run_case
    from eoam_sumo.sim.scenario import ScenarioOverrides
    from eoam_sumo.sim.settings import RunSettings
    from tests.builders import BASELINE

    over = ScenarioOverrides(ego_speed_mps=120 / 3.6, mu=1.0)
    run_case(BASELINE, over, tmp_path, RunSettings(max_time_s=4.0))
    ts = pd.read_csv(tmp_path / "timeseries.csv", keep_default_na=False)
    last, before = ts.iloc[-1], ts.iloc[-2]
    assert last["mode"] != "" and last["sector"] != ""
    assert (last["mode"], last["sector"]) == (before["mode"], before["sector"])
    assert last["steer_cmd_rad"] == "" and last["fcw"] == ""  # no command of its own
