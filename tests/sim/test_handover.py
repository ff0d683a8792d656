"""The time before the ego departs runs at the sumocfg's step: the state handed over to the
co-simulation's 10 ms SUMO equals a plain SUMO run at the sumocfg's step (real SUMO runs)."""

from __future__ import annotations

import pytest
import sumolib

from eoam_sumo.sim.scenario import check_scenario
from eoam_sumo.sim.session import SumoSession
from eoam_sumo.sim.session.handover import SAVE_STATE_OPTIONS, handover_plan, run_and_hand_over
from eoam_sumo.sim.session.launch import sumo_command
from eoam_sumo.traffic_scenario import write_traffic_scenario
from tests.builders import BASELINE

pytestmark = pytest.mark.sumo

DEPART_S = 30.0


def _snapshot(api) -> dict:
    """Every vehicle's position, speed, angle, lane and lane position."""
    veh = api.vehicle
    return {
        vid: (
            veh.getPosition(vid),
            veh.getSpeed(vid),
            veh.getAngle(vid),
            veh.getLaneID(vid),
            veh.getLanePosition(vid),
        )
        for vid in veh.getIDList()
    }


@pytest.fixture(scope="module")
def traffic_cfg(tmp_path_factory):
    return write_traffic_scenario(
        tmp_path_factory.mktemp("traffic"), ego_depart_s=DEPART_S, step_length_s=0.5
    )


def test_handed_over_state_is_the_sumocfg_steps_state(traffic_cfg, tmp_path):
    import libsumo

    files = check_scenario(traffic_cfg)
    assert handover_plan(files, "ego", 0.01, {}, ()) == (0.5, DEPART_S)
    binary = sumolib.checkBinary("sumo")
    coarse, _ = sumo_command(binary, traffic_cfg, files.options, 0.5, tmp_path / "e.log", (), False)
    fine, _ = sumo_command(binary, traffic_cfg, files.options, 0.01, tmp_path / "e.log", (), False)
    libsumo.start(coarse)  # plain SUMO at the sumocfg's step
    try:
        while libsumo.simulation.getTime() < DEPART_S - 0.25:
            libsumo.simulationStep()
        plain = _snapshot(libsumo)
    finally:
        libsumo.close()
    libsumo.start([*coarse, *SAVE_STATE_OPTIONS])
    try:
        run_and_hand_over(libsumo, fine, DEPART_S, tmp_path)
        assert libsumo.simulation.getTime() == DEPART_S
        assert libsumo.simulation.getDeltaT() == 0.01
        handed = _snapshot(libsumo)
        libsumo.simulationStep()  # the ego departs in the first 10 ms step, as planned
        assert "ego" in libsumo.simulation.getDepartedIDList()
    finally:
        libsumo.close()
    assert len(plain) > 50
    assert handed == plain  # exactly: the state file carries every digit


def test_session_departs_the_ego_after_the_handover(traffic_cfg):
    with SumoSession.start(traffic_cfg) as session:
        assert session.ego_depart_time_s == DEPART_S
        assert session.time_s == pytest.approx(DEPART_S + 0.01, abs=1e-9)
        assert "ego" in session.vehicle_ids() and "broken" in session.vehicle_ids()
        assert session.vehicle_speed("broken") == 0.0
        before = session.time_s
        session.step()
        assert session.time_s == pytest.approx(before + 0.01, abs=1e-9)


def test_no_handover_where_the_scenario_does_not_ask_for_a_longer_step(traffic_cfg, tmp_path):
    files = check_scenario(traffic_cfg)
    assert handover_plan(files, "ego", 0.5, {}, ()) is None  # already the step
    assert handover_plan(files, "ego", 0.01, {}, ("--step-length", "0.1")) is None
    assert handover_plan(files, "ego", 0.01, {"broken": (0.0, 5.0)}, ()) is None
    text = traffic_cfg.read_text()
    with_output = tmp_path / "o.sumocfg"
    with_output.write_text(
        text.replace('net-file value="', f'net-file value="{traffic_cfg.parent}/')
        .replace('route-files value="', f'route-files value="{traffic_cfg.parent}/')
        .replace(
            "</configuration>", '<output><fcd-output value="fcd.xml"/></output></configuration>'
        )
    )
    assert handover_plan(check_scenario(with_output), "ego", 0.01, {}, ()) is None
    baseline = check_scenario(BASELINE)  # its own step is 10 ms: Table 2 is unchanged
    assert handover_plan(baseline, "ego", 0.01, {}, ()) is None
