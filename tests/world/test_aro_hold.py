"""The car ahead holds its departure speed through ``aro_hold_s`` whatever its vType says,
in real SUMO runs: a driver imperfection (Krauss dawdling, ``sigma``), a speed factor drawn
from a distribution (``speedDev``, ``speedFactor``) or a slower car ahead of it must not move
it off that speed nor out of its lane (``sim/session/scripts.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from eoam_sumo import netbuild
from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.session import SumoSession

pytestmark = pytest.mark.sumo

SPEED_MPS = 130 / 3.6
HOLD_S = 4.0
DEPART_S = 1.0
NODES = '<nodes><node id="a" x="0" y="0"/><node id="b" x="3000" y="0"/></nodes>'
EDGES = '<edges><edge id="mw" from="a" to="b" numLanes="3" speed="36.12" width="3.5"/></edges>'
IMPERFECT = 'sigma="0.5" speedDev="0.1"'
#: a car 45 m ahead of the ARO's front at 30 m/s, never faster: Krauss's safe speed behind it
#: is below the ARO's (about 32 m/s), and the ARO gains only 24 m on it in the hold
SLOWER_LEADER = (
    '<vType id="lead" length="4.70" width="1.82" maxSpeed="30" sigma="0" speedDev="0"/>'
    '<vehicle id="lead" type="lead" route="r" depart="1.00" departLane="1" departPos="450" '
    'departSpeed="30" insertionChecks="none"/>'
)


def motorway(folder: Path, aro_type: str, others: str = "", seed: int = 42) -> Path:
    """A 3-lane motorway at 130 km/h; the ARO in the middle lane at 130 km/h, 400 m from the
    start, holding for ``HOLD_S`` then stopping at 8 m/s^2; the ego far behind at 10 m/s."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "m.nod.xml").write_text(NODES)
    (folder / "m.edg.xml").write_text(EDGES)
    netbuild.build_network(folder / "m.nod.xml")
    (folder / "r.rou.xml").write_text(
        '<routes><route id="r" edges="mw"/>'
        '<vType id="ego" length="4.92" width="1.85" maxSpeed="60" sigma="0" speedDev="0"/>'
        '<vType id="aro" length="5.09" width="1.99" maxSpeed="50" accel="2.5" decel="9" '
        f'emergencyDecel="12" {aro_type}/>'
        '<vehicle id="ego" type="ego" route="r" depart="1.00" departLane="1" departPos="20" '
        'departSpeed="10" insertionChecks="none"><param key="eoam.role" value="ego"/></vehicle>'
        '<vehicle id="aro" type="aro" route="r" depart="1.00" departLane="1" departPos="400" '
        f'departSpeed="{SPEED_MPS:.6f}" insertionChecks="none">'
        f'<param key="eoam.role" value="aro"/><param key="eoam.aro_hold_s" value="{HOLD_S}"/>'
        f'<param key="eoam.aro_decel_mps2" value="8.0"/></vehicle>{others}</routes>'
    )
    cfg = folder / "m.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="m.net.xml"/><route-files value="r.rou.xml"/>'
        '</input><time><step-length value="0.01"/></time><processing>'
        '<collision.action value="none"/><time-to-teleport value="-1"/></processing>'
        f'<random_number><seed value="{seed}"/></random_number></configuration>'
    )
    return cfg


def aro_through_the_hold(cfg: Path) -> list[tuple[float, float, str]]:
    """(time, speed, lane) of the ARO at every step until 1 s after its hold ends."""
    session = SumoSession.start(cfg, ScenarioOverrides())
    try:
        log = []
        while session.time_s < DEPART_S + HOLD_S + 1.0:
            body = session.body("aro")
            log.append((session.time_s, body.speed_mps, session.vehicle_lane("aro")))
            session.step()
        return log
    finally:
        session.close()


@pytest.mark.parametrize(
    ("aro_type", "others", "seed"),
    [
        (IMPERFECT, "", 42),
        (IMPERFECT, "", 7),
        (f'{IMPERFECT} speedFactor="0.9"', "", 42),
        ('sigma="0.5" speedFactor="normc(1,0.2,0.5,1.5)"', "", 3),
        (IMPERFECT, SLOWER_LEADER, 42),
    ],
    ids=["imperfect", "imperfect-seed7", "speed-factor-0.9", "speed-factor-drawn", "slower-leader"],
)
def test_the_aro_holds_its_speed_and_lane_then_stops(tmp_path, aro_type, others, seed):
    log = aro_through_the_hold(motorway(tmp_path, aro_type, others, seed))
    hold = [(v, lane) for t, v, lane in log if t <= DEPART_S + HOLD_S + 1e-9]
    assert len(hold) > 0.9 * HOLD_S / 0.01
    speeds = [v for v, _ in hold]
    assert max(speeds) - min(speeds) <= 0.01
    assert speeds[0] == pytest.approx(SPEED_MPS, abs=0.01)
    assert {lane for _, lane in hold} == {"mw_1"}
    # then the scripted stop in its lane: 8 m/s^2 down from the hold, or harder where SUMO's
    # safe speed brakes it for a slower car ahead (it no longer changes lanes to keep 8 m/s^2:
    # a car in an emergency stop changing lanes moved into the ego's evasion lane)
    after = [(t, v, lane) for t, v, lane in log if t > DEPART_S + HOLD_S + 0.5]
    t_end, v_end, _ = after[-1]
    profile = SPEED_MPS - 8.0 * (t_end - DEPART_S - HOLD_S)
    if others:
        assert v_end <= profile + 0.1
    else:
        assert v_end == pytest.approx(profile, abs=0.1)
    assert {lane for _, _, lane in after} == {"mw_1"}


def test_the_stopped_aro_stays_in_its_lane(tmp_path):
    """Once standing, the ARO keeps its lane (its lane changes are off again): given back its
    own lane-change mode, SUMO's keep-right moved the standing car a whole lane to the right."""
    cfg = motorway(tmp_path, 'sigma="0" speedDev="0"')
    session = SumoSession.start(cfg, ScenarioOverrides())
    try:
        standing = []
        while session.time_s < DEPART_S + HOLD_S + SPEED_MPS / 8.0 + 6.0:
            body = session.body("aro")
            if body.speed_mps == 0.0:
                standing.append((session.vehicle_lane("aro"), round(body.y_m, 6)))
            session.step()
    finally:
        session.close()
    assert len(standing) > 500
    assert set(standing) == {standing[0]} and standing[0][0] == "mw_1"
