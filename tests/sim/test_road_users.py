"""Every road user SUMO has comes back from the session as a Body: persons (walking or
standing, on the ego's road or the opposite one), bicycles, trucks; in real SUMO runs."""

import math
import tempfile

import pytest

from eoam_sumo.sim.scenario import ScenarioOverrides
from eoam_sumo.sim.session import SumoSession
from eoam_sumo.world.bodies import PEDESTRIAN, Body
from tests.builders import on_highway  # E0 eastbound (y -3.5..0), -E0 westbound

pytestmark = pytest.mark.sumo

# sizes written here are the test's truth (none is a SUMO default)
SIZES = {"bike": (1.80, 0.70), "lorry": (12.00, 2.50), "walker": (0.30, 0.55)}
ROUTES = """<routes>
  <vType id="bike" vClass="bicycle" length="1.80" width="0.70" maxSpeed="6" sigma="0"/>
  <vType id="lorry" vClass="truck" length="12.00" width="2.50" maxSpeed="25" sigma="0"/>
  <vType id="walker" vClass="pedestrian" length="0.30" width="0.55" maxSpeed="1.4"/>
  <route id="east" edges="E0"/>
  <route id="west" edges="-E0"/>
  <vehicle id="ego" type="ego" route="east" depart="1" departLane="0" departPos="100"
           departSpeed="20"/>
  <vehicle id="cyclist" type="bike" route="east" depart="0" departPos="160" departSpeed="5"/>
  <vehicle id="truck" type="lorry" route="west" depart="0" departPos="500" departSpeed="20"/>
  <person id="pedestrian" type="walker" depart="0" departPos="190">
    <walk edges="E0" arrivalPos="3000"/>
  </person>
  <person id="waiting" type="walker" depart="0" departPos="400">
    <stop edge="-E0" duration="500" startPos="400" endPos="401"/>
  </person>
</routes>
"""


@pytest.fixture
def session(tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    s = SumoSession.start(on_highway(tmp_path, ROUTES), ScenarioOverrides())
    yield s
    s.close()


def _sumo_truth(s: SumoSession, uid: str):
    """(front x, front y, nav angle, speed) as SUMO's own getters report them."""
    api = s._api
    domain = api.person if uid in api.person.getIDList() else api.vehicle
    return (*domain.getPosition(uid), domain.getAngle(uid), domain.getSpeed(uid))


def _check(body: Body, s: SumoSession, vclass: str, size: tuple[float, float]) -> None:
    fx, fy, angle, speed = _sumo_truth(s, body.vid)
    assert body.vclass == vclass
    assert (body.length_m, body.width_m) == pytest.approx(size, abs=1e-9)
    assert body.speed_mps == pytest.approx(speed, abs=1e-9)
    assert not body.parked
    # SUMO's position is the front (for persons too): the centre lies half a length behind
    # it along the heading, and the heading is SUMO's angle turned to the math convention
    assert math.cos(body.yaw_rad) == pytest.approx(math.sin(math.radians(angle)), abs=1e-9)
    assert math.sin(body.yaw_rad) == pytest.approx(math.cos(math.radians(angle)), abs=1e-9)
    assert body.x_m + 0.5 * body.length_m * math.cos(body.yaw_rad) == pytest.approx(fx, abs=1e-9)
    assert body.y_m + 0.5 * body.length_m * math.sin(body.yaw_rad) == pytest.approx(fy, abs=1e-9)
    assert body.box.x_m == body.x_m and body.box.length_m == body.length_m


def test_a_walking_person_and_a_bicycle_on_the_ego_road_are_nearby(session):
    s = session
    for _ in range(100):  # 1 s: all have moved
        s.step()
    near = {b.vid: b for b in s.nearby(150.0)}
    assert set(near) == {"cyclist", "pedestrian"}  # the truck and the waiting person are far
    _check(near["cyclist"], s, "bicycle", SIZES["bike"])
    _check(near["pedestrian"], s, PEDESTRIAN, SIZES["walker"])
    walker = near["pedestrian"]
    assert walker.speed_mps > 0.5 and abs(walker.yaw_rad) < 1e-9  # walking east, on E0
    assert -3.5 < walker.y_m < 0.0  # in the ego's lane (no sidewalk: persons use the road)
    assert list(near) == sorted(near)


def test_every_road_user_with_its_class_wherever_it_is(session):
    s = session
    s.step()
    users = {b.vid: b for b in s.road_users()}
    assert set(users) == {"cyclist", "pedestrian", "truck", "waiting"}
    _check(users["truck"], s, "truck", SIZES["lorry"])
    _check(users["waiting"], s, PEDESTRIAN, SIZES["walker"])
    assert users["waiting"].speed_mps == 0.0 and users["waiting"].y_m > 0.0  # on -E0
    assert s.body("waiting") == users["waiting"] and s.body("truck") == users["truck"]
    assert s.ego_body().vclass == "passenger"


def test_a_person_who_arrives_is_dropped(tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    cfg = on_highway(
        tmp_path,
        '<routes><route id="east" edges="E0"/>'
        '<vehicle id="ego" type="ego" route="east" depart="0" departPos="100" '
        'departSpeed="0"/>'
        '<person id="p" depart="0" departPos="120"><walk edges="E0" arrivalPos="121.5"/>'
        "</person></routes>",
    )
    with SumoSession.start(cfg, ScenarioOverrides()) as s:
        assert [b.vid for b in s.nearby(50.0)] == ["p"]
        for _ in range(500):  # 1.5 m at up to 1.39 m/s: arrived within 5 s
            s.step()
        assert s.nearby(50.0) == [] and s.road_users() == []


def test_a_long_vehicle_that_departs_later_is_found_by_its_reach(tmp_path, monkeypatch):
    """The context range grows with the longest vehicle SUMO has: a 60 m road train departing
    after following began, its front 75 m ahead of the ego's (beyond a 20 m radius plus any
    car's diagonal, within its own), is nearby at its first step, as SUMO's getters say."""
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    cfg = on_highway(
        tmp_path,
        '<routes><vType id="train" vClass="truck" length="60" width="2.5"/>'
        '<route id="east" edges="E0"/>'
        '<vehicle id="ego" type="ego" route="east" depart="0" departPos="100" '
        'departSpeed="0"/>'
        '<vehicle id="long" type="train" route="east" depart="2" departLane="0" '
        'departPos="175" departSpeed="0"/></routes>',
    )
    with SumoSession.start(cfg, ScenarioOverrides()) as s:
        assert s.nearby(20.0) == []
        while "long" not in s.vehicle_ids():
            s.step()
            s.move_ego(100.0, -1.75, 90.0, 0.0)
        fx, fy, _angle, _speed = _sumo_truth(s, "long")
        ex, ey, _a, _v = _sumo_truth(s, "ego")
        assert 20.0 + 2 * math.hypot(2.5, 0.9) < math.hypot(fx - ex, fy - ey) < 20.0 + 60.0
        assert [b.vid for b in s.nearby(20.0)] == ["long"]
