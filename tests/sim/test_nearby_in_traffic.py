"""In dense traffic the session's road users around the ego (one context subscription a step)
are exactly those SUMO's own getters put within reach, with SUMO's values (real SUMO run)."""

from __future__ import annotations

import math

import pytest

from eoam_sumo.sim.session import SumoSession
from eoam_sumo.traffic_scenario import write_traffic_scenario

pytestmark = pytest.mark.sumo


def _truth(session: SumoSession, radius_m: float) -> dict:
    """id -> Body of every vehicle whose front is within radius plus its diagonal of the
    ego's front, from one getter call per value."""
    import libsumo  # the session runs SUMO in-process: the test reads it directly

    veh, types = libsumo.vehicle, libsumo.vehicletype
    ex, ey = veh.getPosition(session.ego_id)
    truth = {}
    for vid in veh.getIDList():
        if vid == session.ego_id:
            continue
        fx, fy = veh.getPosition(vid)
        type_id = veh.getTypeID(vid)
        length = types.getLength(type_id)
        width = types.getWidth(type_id)
        if math.hypot(fx - ex, fy - ey) <= radius_m + math.hypot(length, width):
            truth[vid] = session.body(vid)
    return truth


def test_nearby_matches_sumos_getters_step_by_step(tmp_path):
    cfg = write_traffic_scenario(tmp_path, ego_depart_s=40.0)
    with SumoSession.start(cfg) as session:
        assert len(session.vehicle_ids()) > 80
        for k, radius_m in enumerate([60.0, 60.0, 150.0, 20.0, 150.0, 60.0] * 5):
            near = session.nearby(radius_m)
            truth = _truth(session, radius_m)
            assert [b.vid for b in near] == sorted(truth), (k, radius_m)
            for body in near:
                assert body == truth[body.vid]
            ego = session.ego_body()
            x, y = ego.x_m + 0.5 * ego.length_m + 0.2, ego.y_m
            session.move_ego(x, y, 90.0, 20.0)
            session.step()
        assert any(b.parked or b.speed_mps == 0.0 for b in session.nearby(300.0))
