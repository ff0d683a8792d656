"""The storyboard engine on a real file without a co-simulation: Vector's CCRb stepped by a
stand-in for the run (the ego driven at its speed along its lane), the target's speeds
against the file's timeline (netconvert only; no SUMO run)."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from eoam_sumo.openscenario.engine import Storyboard
from eoam_sumo.openscenario.runner import load
from eoam_sumo.openscenario.sumofiles import DEPART_S

pytestmark = pytest.mark.sumo  # netconvert

CCRB = (
    Path(__file__).parents[1]
    / "data/openscenario/ncap/OpenSCENARIO/NCAP/CA-FC_2026/Variations/SingleExecution"
    / "CCRb_50kph.xosc"
)


class _Puppets:
    def __init__(self, lanes, ego) -> None:
        self.lanes, self.ego, self.placed = lanes, ego, {}

    def take(self, vid: str) -> None:
        self.placed[vid] = None

    def place(self, vid, x_m, y_m, angle_nav_deg, speed_mps) -> None:
        self.placed[vid] = (x_m, y_m, speed_mps)

    def ego_lane(self) -> tuple[str, float]:
        return self.lanes.locate(self.ego.road, self.ego.lane, self.ego.s_m)


def test_ccrb_target_brakes_3_s_after_its_placement_to_standstill(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """CCRb 50 km/h: the target 13.9 m ahead (bumper to bumper), braking at 4 m/s^2 from
    Target_braking_delay = 3 s after its placement maneuver completes, to a standstill."""
    monkeypatch.setenv("EOAM_SUMO_CACHE_DIR", str(tmp_path / "cache"))
    loaded = load(CCRB, {})
    board = Storyboard(loaded.scenario.root, loaded.plan, loaded.lanes, loaded.scenario.parameters)
    ego = SimpleNamespace(road="0", lane=-1, s_m=loaded.plan.places["Ego"].s_m)
    v = 50 / 3.6
    sim = SimpleNamespace(
        step_s=0.01, t=DEPART_S, x=[0.0, 0.0, 0.0, v], first_contact=None, n_steps=0,
        max_steps=10_000, ctrl=SimpleNamespace(mode=0), eoam_done=lambda: False,
        session=SimpleNamespace(puppets=lambda: puppets, lane_friction=lambda lane: 1.0),
    )  # fmt: skip
    puppets = _Puppets(loaded.lanes, ego)
    speeds = {}
    board.start(sim)
    for k in range(1, 1000):
        sim.t, sim.n_steps = round(DEPART_S + 0.01 * k, 10), k
        ego.s_m += v * 0.01  # the ego's front bumper goes on at 50 km/h
        board.after_step(sim)
        speeds[round(0.01 * k, 2)] = puppets.placed["Target"][2]
        if k == 100:  # 1 s in: still 1 s (13.9 m) bumper to bumper ahead (the target's
            actors = board.world.actors  # state is already the coming step's: + v dt)
            gap = actors["Target"].rear_s_m() - actors["Ego"].front_s_m()
            assert gap == pytest.approx(v * (1.0 + 0.01), abs=1e-6)
    assert speeds[2.9] == pytest.approx(v)
    assert speeds[3.5] == pytest.approx(v - 4.0 * 0.5, abs=0.05)
    assert speeds[round(3.0 + v / 4.0 + 0.05, 2)] == 0.0  # a stop, not 2 km/h
    target = board.world.actors["Target"]
    braking = [e for e in board.world.elements.values() if e.name == "Target_DelayedBrakingEvent"]
    assert target.speed_mps == 0.0 and [e.state for e in braking] == ["complete"]
