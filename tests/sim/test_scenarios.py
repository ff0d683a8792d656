"""The SUMO experiment world in real SUMO runs: network, scenarios, adapter, overrides."""

import gzip
import math
import shutil
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import sumolib

from eoam_sumo import netbuild
from eoam_sumo.errors import InputError
from eoam_sumo.params import (
    G_MPS2,
    aro_d_class_minivan,
    ego_e_class_sedan,
    oncoming_sedan,
    parked_car,
)
from eoam_sumo.sim.scenario import ScenarioOverrides, check_scenario
from eoam_sumo.sim.session import SumoSession
from eoam_sumo.world.bodies import nav_angle_deg, yaw_rad
from tests.builders import (
    BASELINE,
    HIGHWAY_NET,
    NETWORKS,
    PARKED_ONLY,
    SCENARIOS,
    VTYPES,
    network,
    on_highway,
    write_sumocfg,
)

NET = sumolib.net.readNet(str(HIGHWAY_NET), withInternal=True)
EGO_LANE = NET.getLane("E0_0")
RIGHT_MARKER_Y = EGO_LANE.getShape()[0][1] - EGO_LANE.getWidth() / 2.0  # from the network file


def _route_vehicle(path: Path, vid: str) -> tuple[dict, dict]:
    """(attributes, params) of a vehicle as written in a route file: the test's truth."""
    for elem in ET.parse(path).getroot().iter("vehicle"):
        if elem.get("id") == vid:
            return dict(elem.attrib), {p.get("key"): p.get("value") for p in elem.iter("param")}
    raise AssertionError(f"{vid} not in {path}")


EGO_ATTRS, _ = _route_vehicle(SCENARIOS / "baseline.rou.xml", "ego")
ARO_ATTRS, ARO_PARAMS = _route_vehicle(SCENARIOS / "baseline.rou.xml", "aro")


@pytest.fixture(autouse=True)
def sumo_scratch_in_tmp_path(tmp_path, monkeypatch):
    """The adapter's scratch directory (SUMO's error log) goes under tmp_path; none may remain."""
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    yield
    assert list(scratch.iterdir()) == []


@pytest.fixture
def open_session():
    """Start sessions through this; every one is closed at the end of the test."""
    sessions = []

    def start(cfg, overrides=None, **kwargs):
        overrides = ScenarioOverrides() if overrides is None else overrides
        session = SumoSession.start(cfg, overrides, **kwargs)
        sessions.append(session)
        return session

    yield start
    for session in sessions:
        session.close()


def _front(body):
    return (
        body.x_m + 0.5 * body.length_m * math.cos(body.yaw_rad),
        body.y_m + 0.5 * body.length_m * math.sin(body.yaw_rad),
    )


# --------------------------------------------------------------------------- network
@pytest.mark.sumo
def test_committed_network_is_what_netconvert_builds_from_the_sources(tmp_path):
    for name in ("highway.nod.xml", "highway.edg.xml"):
        shutil.copy(NETWORKS / name, tmp_path / name)
    (built,) = netbuild.build_all(tmp_path)

    def lanes(path):
        root = ET.parse(path).getroot()
        return {
            lane.get("id"): (dict(lane.attrib), [n.get("lane") for n in lane.iter("neigh")])
            for lane in root.iter("lane")
        }

    assert lanes(built) == lanes(HIGHWAY_NET)


def test_highway_geometry_and_surface():
    assert set(NET.getEdges(withInternal=False)) == {NET.getEdge("E0"), NET.getEdge("-E0")}
    onc_lane = NET.getLane("-E0_0")
    for lane in (EGO_LANE, onc_lane):
        assert lane.getWidth() == 3.5
        assert lane.getLength() == pytest.approx(4000.0)
        assert lane.getSpeed() * 3.6 >= 165.0
    root = ET.parse(HIGHWAY_NET).getroot()
    assert {ln.get("id"): ln.get("friction") for ln in root.iter("lane")} == {
        "E0_0": "1.00",
        "-E0_0": "1.00",
    }
    # oncoming lane directly to the left of the eastbound ego lane, sharing the centre line
    assert onc_lane.getShape()[0][1] - EGO_LANE.getShape()[0][1] == pytest.approx(3.5)
    assert EGO_LANE.getShape()[-1][0] > EGO_LANE.getShape()[0][0]


def test_netbuild_command_needs_a_directory(tmp_path, capsys):
    assert netbuild.main([]) == 2
    assert netbuild.main([str(tmp_path / "missing")]) == 2
    assert "missing" in capsys.readouterr().err


# --------------------------------------------------------------------------- ego and vTypes
@pytest.mark.sumo
@pytest.mark.parametrize("speed_kmh", [55.0, 165.0])
def test_ego_is_present_at_the_requested_speed_from_the_first_step(open_session, speed_kmh):
    speed = speed_kmh / 3.6
    s = open_session(BASELINE, ScenarioOverrides(ego_speed_mps=speed))
    assert s.time_s == pytest.approx(float(EGO_ATTRS["depart"]) + s.step_length_s)
    ego = s.ego_body()
    assert ego.speed_mps == pytest.approx(speed, abs=1e-9)
    front = _front(ego)
    assert front == pytest.approx(
        (float(EGO_ATTRS["departPos"]), EGO_LANE.getShape()[0][1]), abs=1e-6
    )
    assert ego.yaw_rad == pytest.approx(0.0, abs=1e-9)
    aro = s.body("aro")
    rear_aro = aro.x_m - 0.5 * aro.length_m
    assert rear_aro - front[0] == pytest.approx(120.0, abs=1e-6)  # the stated ego-ARO gap
    for _ in range(5):
        s.step()
        assert s.vehicle_speed("ego") == pytest.approx(speed, abs=1e-9)


@pytest.mark.sumo
def test_vehicle_types_have_the_preset_footprints(open_session):
    s = open_session(BASELINE, ScenarioOverrides(oncoming_start_m=300.0))
    ego, aro, onc = s.ego_body(), s.body("aro"), s.body(s.oncoming_id)
    parked = [b for b in s.nearby(1000.0) if b.parked]
    for body, preset in [
        (ego, ego_e_class_sedan()),
        (aro, aro_d_class_minivan()),
        (onc, oncoming_sedan()),
    ] + [(p, parked_car()) for p in parked]:
        assert (body.length_m, body.width_m) == (preset.length_m, preset.width_m)
    assert len(parked) == 8


# --------------------------------------------------------------------------- ARO stop
@pytest.mark.sumo
@pytest.mark.parametrize("mu,decel_override", [(1.0, None), (0.3, None), (1.0, 3.0)])
def test_aro_holds_then_stops_no_harder_than_the_surface_allows(open_session, mu, decel_override):
    s = open_session(
        BASELINE, ScenarioOverrides(ego_speed_mps=5.0, mu=mu, aro_decel_mps2=decel_override)
    )
    v0 = float(ARO_ATTRS["departSpeed"])
    assert v0 == pytest.approx(60.0 / 3.6, abs=1e-5)
    hold_end = float(ARO_ATTRS["depart"]) + float(ARO_PARAMS["eoam.aro_hold_s"])
    decel = (
        decel_override if decel_override is not None else float(ARO_PARAMS["eoam.aro_decel_mps2"])
    )
    allowed = min(decel, mu * G_MPS2)
    t_stop = hold_end + v0 / allowed
    log = []
    while s.time_s < t_stop + 1.0:
        aro = s.body("aro")
        log.append((s.time_s, aro.speed_mps, aro.x_m, aro.y_m, s.vehicle_lane("aro")))
        s.step()
    t, v, x, y, lanes = (np.array(c) if i < 4 else c for i, c in enumerate(zip(*log)))
    holding = t <= hold_end + 1e-9
    assert np.all(np.abs(v[holding] - v0) < 1e-9)
    expected = np.maximum(0.0, v0 - allowed * (t[~holding] - hold_end))
    assert np.max(np.abs(v[~holding] - expected)) < 1e-6
    decel_seen = -np.diff(v) / s.step_length_s
    assert decel_seen.max() <= allowed + 1e-6
    assert decel_seen.max() == pytest.approx(allowed, rel=1e-6)
    stopped = t >= t_stop + 0.02
    assert stopped.sum() > 50
    assert np.all(v[stopped] == 0.0)
    assert np.ptp(x[stopped]) == 0.0
    assert set(lanes) == {"E0_0"}
    assert np.all(y == pytest.approx(EGO_LANE.getShape()[0][1]))


# --------------------------------------------------------------------------- oncoming
@pytest.mark.sumo
def test_oncoming_car_starts_at_the_distance_and_keeps_20_mps(open_session):
    s = open_session(BASELINE, ScenarioOverrides(ego_speed_mps=10.0, oncoming_start_m=300.0))
    onc_lane = NET.getLane("-E0_0")
    ego, onc = s.ego_body(), s.body(s.oncoming_id)
    assert s.roles[s.oncoming_id] == "oncoming"
    assert s.vehicle_lane(s.oncoming_id) == onc_lane.getID()
    assert _front(onc)[0] - _front(ego)[0] == pytest.approx(300.0, abs=1e-6)
    assert onc.y_m == pytest.approx(onc_lane.getShape()[0][1])
    assert abs(onc.yaw_rad) == pytest.approx(math.pi)  # heading west, towards the ego
    x0, t0 = _front(onc)[0], s.time_s
    for _ in range(100):
        s.step()
        assert s.vehicle_speed(s.oncoming_id) == pytest.approx(20.0, abs=1e-9)
    # the ego moves into the oncoming lane 40 m ahead of it: SUMO must not make it brake
    gap_front = _front(s.body(s.oncoming_id))[0] - 40.0
    for k in range(150):
        s.move_ego(gap_front + 0.1 * k, onc_lane.getShape()[0][1], 90.0, 10.0)
        s.step()
        assert s.vehicle_speed(s.oncoming_id) == pytest.approx(20.0, abs=1e-9)
        assert "ego" in s.vehicle_ids()
    assert x0 - _front(s.body(s.oncoming_id))[0] == pytest.approx(20.0 * (s.time_s - t0), abs=1e-6)


@pytest.mark.sumo
def test_move_ego_into_the_opposite_lane_and_back(open_session):
    s = open_session(BASELINE, ScenarioOverrides(ego_speed_mps=20.0))
    length = s.ego_body().length_m
    for y_lane, lane_id in [(1.75, "-E0_0"), (-1.75, "E0_0")]:
        x_front = _front(s.ego_body())[0] + 0.2
        s.move_ego(x_front, y_lane, 90.0, 20.0)
        s.step()
        ego = s.ego_body()
        assert s.vehicle_lane("ego") == lane_id
        assert (ego.x_m, ego.y_m) == pytest.approx((x_front - length / 2.0, y_lane), abs=1e-9)
        assert ego.speed_mps == pytest.approx(20.0)
    # a yawed pose: the centre lies half a length behind the front along the heading
    yaw = math.radians(4.0)
    s.move_ego(x_front + 0.2, -1.2, nav_angle_deg(yaw), 20.0)
    s.step()
    ego = s.ego_body()
    assert ego.yaw_rad == pytest.approx(yaw, abs=1e-9)
    assert _front(ego) == pytest.approx((x_front + 0.2, -1.2), abs=1e-9)


# --------------------------------------------------------------------------- parked cars
@pytest.mark.sumo
def test_parked_cars_sit_beside_the_ego_lane_and_never_in_it(open_session):
    s = open_session(PARKED_ONLY)
    ego_front_x = _front(s.ego_body())[0]
    ahead = sorted(_front(b)[0] - ego_front_x for b in s.nearby(1000.0))
    assert len(ahead) == 8 and ahead[0] > 0.0 and ahead[-1] <= 850.0  # the first ~800 m
    assert min(np.diff(ahead)) > 50.0
    for _ in range(400):
        parked = s.nearby(1000.0)
        assert len(parked) == 8 and all(b.parked for b in parked)
        for b in parked:
            near_side_y = b.y_m + b.width_m / 2.0
            assert RIGHT_MARKER_Y - near_side_y == pytest.approx(1.5, abs=1e-9)
            assert b.yaw_rad == pytest.approx(0.0, abs=1e-9)
            assert s.vehicle_lane(b.vid) == ""
        s.step()
    assert s.ego_body().x_m > ego_front_x + ahead[0]  # the ego drove past the first one
    assert "aro" not in s.vehicle_ids()


@pytest.mark.sumo
def test_nearby_agrees_with_sumo_at_every_step(open_session):
    """nearby() follows the vehicles without a context subscription: at every step it equals
    SUMO's getters for every vehicle some part of which may be within the radius (front
    bumper within the radius plus the box's diagonal), through the ARO's stop, the oncoming
    car's insertion and a parked car that drives off (its parking ended by libsumo)."""
    import libsumo

    s = open_session(BASELINE, ScenarioOverrides(oncoming_start_m=300.0))
    radius = 250.0
    leaving = None

    def reach(vid):
        t = libsumo.vehicle.getTypeID(vid)
        return radius + math.hypot(
            libsumo.vehicletype.getLength(t), libsumo.vehicletype.getWidth(t)
        )

    for k in range(600):
        ego_front = libsumo.vehicle.getPosition(s.ego_id)
        want = sorted(
            vid
            for vid in s.vehicle_ids()
            if vid != s.ego_id
            and math.dist(libsumo.vehicle.getPosition(vid), ego_front) <= reach(vid)
        )
        got = s.nearby(radius)
        assert [b.vid for b in got] == want
        assert got == [s.body(vid) for vid in want]
        if k == 50:  # right before a step, as SUMO would end a parking within one
            leaving = next(b.vid for b in got if b.parked)
            libsumo.vehicle.resume(leaving)
        s.step()
    assert leaving is not None and not s.body(leaving).parked
    assert s.vehicle_speed(leaving) > 1.0


# --------------------------------------------------------------------------- friction
@pytest.mark.sumo
def test_friction_override_sets_every_lane(open_session):
    s = open_session(BASELINE, ScenarioOverrides(mu=0.3))
    assert s.lane_ids() and all(
        s.lane_friction(lane) == pytest.approx(0.3) for lane in s.lane_ids()
    )
    assert s.friction_at_ego() == pytest.approx(0.3)
    s.close()
    s = open_session(BASELINE)
    assert s.friction_at_ego() == pytest.approx(1.0)  # the network's own surface
    assert s.lane_width_m == 3.5 and s.left_lane_exists
    line = s.ego_lane_centreline()
    assert line.shape == (2, 2)
    assert line == pytest.approx(np.array(EGO_LANE.getShape()))


# --------------------------------------------------------------------------- TraCI path
@pytest.mark.sumo
def test_traci_path_with_plain_sumo(open_session):
    s = open_session(
        BASELINE,
        ScenarioOverrides(ego_speed_mps=55.0 / 3.6, oncoming_start_m=400.0),
        use_traci=True,
    )
    assert s.ego_body().speed_mps == pytest.approx(55.0 / 3.6)
    for _ in range(20):
        s.step()
    assert s.vehicle_speed("aro") == pytest.approx(float(ARO_ATTRS["departSpeed"]))
    ids = {b.vid for b in s.nearby(450.0)}
    assert {"aro", s.oncoming_id} <= ids
    s.close()
    s.close()  # idempotent


# --------------------------------------------------------------------------- a user's scenario
USER_NODES = """<nodes>
  <node id="a" x="0" y="0" type="priority"/><node id="b" x="500" y="0" type="priority"/>
  <node id="c" x="900" y="300" type="priority"/>
</nodes>"""
USER_EDGES = """<edges>
  <edge id="road1" from="a" to="b" numLanes="1" speed="40" width="3.2">
    <lane index="0" friction="0.6"><neigh lane="back1_0"/></lane></edge>
  <edge id="road2" from="b" to="c" numLanes="1" speed="40" width="3.2">
    <lane index="0" friction="0.6"><neigh lane="back2_0"/></lane></edge>
  <edge id="back2" from="c" to="b" numLanes="1" speed="40" width="3.2">
    <lane index="0" friction="0.6"><neigh lane="road2_0"/></lane></edge>
  <edge id="back1" from="b" to="a" numLanes="1" speed="40" width="3.2">
    <lane index="0" friction="0.6"><neigh lane="road1_0"/></lane></edge>
</edges>"""
USER_ROUTES = """<routes>
  <vType id="car" length="4.5" width="1.8" sigma="0"/>
  <vehicle id="blocker" type="car" depart="0" departPos="150" departSpeed="10">
    <route edges="road1 road2"/>
    <stop lane="road1_0" endPos="260" duration="1000"/>
  </vehicle>
  <vehicle id="ego" type="car" depart="0" departSpeed="12"><route edges="road1 road2"/></vehicle>
</routes>"""
USER_CFG = """<configuration><input><net-file value="user.net.xml"/>
  <route-files value="user.rou.xml.gz"/></input></configuration>"""


@pytest.fixture
def user_scenario(tmp_path):
    network(tmp_path, "user", USER_NODES, USER_EDGES)
    (tmp_path / "user.rou.xml.gz").write_bytes(gzip.compress(USER_ROUTES.encode()))
    (tmp_path / "user.sumocfg").write_text(USER_CFG)
    return tmp_path


@pytest.mark.sumo
def test_a_users_scenario_with_its_own_network_and_a_plain_stop(open_session, user_scenario):
    net = sumolib.net.readNet(str(user_scenario / "user.net.xml"))
    shape1 = np.array(net.getLane("road1_0").getShape())
    s = open_session(user_scenario / "user.sumocfg", ScenarioOverrides(oncoming_start_m=700.0))
    ego = s.ego_body()
    assert ego.speed_mps == pytest.approx(12.0)  # the file's departSpeed
    # departPos "base": the front bumper one vehicle length into the first lane
    start_dir = (shape1[1] - shape1[0]) / np.linalg.norm(shape1[1] - shape1[0])
    assert _front(ego) == pytest.approx(tuple(shape1[0] + 4.5 * start_dir), abs=1e-6)
    assert s.lane_width_m == pytest.approx(3.2)
    assert s.friction_at_ego() == pytest.approx(0.6)
    line = s.ego_lane_centreline()
    both = np.vstack([shape1, net.getLane("road2_0").getShape()])
    assert line[0] == pytest.approx(both[0]) and line[-1] == pytest.approx(both[-1])
    # the oncoming car starts on the opposite lane of the second edge, 700 m along the road
    assert s.vehicle_lane(s.oncoming_id) == "back2_0"
    seg = np.hypot(*np.diff(both, axis=0).T)
    along = np.concatenate(([0.0], np.cumsum(seg)))
    onc_front = _front(s.body(s.oncoming_id))
    k = int(np.argmin(np.hypot(both[:, 0] - onc_front[0], both[:, 1] - onc_front[1])))
    i = min(k, len(both) - 2)
    d = both[i + 1] - both[i]
    s_onc = along[i] + np.dot(np.array(onc_front) - both[i], d) / np.dot(d, d) * seg[i]
    assert s_onc - 4.5 == pytest.approx(700.0, abs=1.0)
    for _ in range(2500):
        s.step()
    assert s.vehicle_speed("blocker") == 0.0
    assert s.vehicle_lane("blocker") == "road1_0"


# --------------------------------------------------------------------------- bad input
def _cfg(tmp_path, routes: str) -> Path:
    return write_sumocfg(tmp_path / "bad.sumocfg", HIGHWAY_NET, routes)


def test_bad_scenarios_are_input_errors_naming_the_file(tmp_path):
    with pytest.raises(InputError, match=r"missing\.sumocfg"):
        SumoSession.start(tmp_path / "missing.sumocfg")
    broken = tmp_path / "broken.sumocfg"
    broken.write_text("<configuration><input>")
    with pytest.raises(InputError, match=r"broken\.sumocfg: malformed XML"):
        SumoSession.start(broken)
    with pytest.raises(InputError, match=r"nowhere\.rou\.xml"):
        SumoSession.start(_cfg(tmp_path, str(tmp_path / "nowhere.rou.xml")))
    with pytest.raises(InputError, match="no vehicle 'ego'"):
        SumoSession.start(_cfg(tmp_path, str(SCENARIOS / "parked.rou.xml")))
    with pytest.raises(InputError, match="no vehicle 'nobody'"):
        SumoSession.start(BASELINE, ego_id="nobody")
    with pytest.raises(InputError, match=r"eoam\.role"):
        SumoSession.start(PARKED_ONLY, ScenarioOverrides(aro_hold_s=1.0))
    with pytest.raises(InputError, match="step_length_s"):
        SumoSession.start(BASELINE, step_length_s=0.0105)


@pytest.mark.parametrize("end_s, refused", [(0.5, True), (3.0, False), (-1.0, False)])
def test_an_end_before_the_ego_departs_is_refused_like_a_begin_after_it(tmp_path, end_s, refused):
    """A sumocfg whose ``end`` comes before the ego's departure is refused before SUMO
    starts, in one line naming the file and both times (SUMO's -1: no end)."""
    routes = tmp_path / "r.rou.xml"
    routes.write_text('<routes><vehicle id="ego" depart="1"><route edges="E0"/></vehicle></routes>')
    cfg = write_sumocfg(tmp_path / "s.sumocfg", HIGHWAY_NET, routes)
    text = cfg.read_text().replace("</input>", f'</input><time><end value="{end_s:g}"/></time>')
    cfg.write_text(text)
    if not refused:
        assert check_scenario(cfg).options["end"] == f"{end_s:g}"
        return
    with pytest.raises(
        InputError, match=r"s\.sumocfg: the simulation ends at 0\.5 s .* 'ego' departs \(1 s"
    ):
        check_scenario(cfg)


@pytest.mark.sumo
@pytest.mark.parametrize("use_traci", [False, True])
def test_sumos_own_load_errors_become_input_errors(tmp_path, use_traci):
    bad_route = tmp_path / "bad.rou.xml"
    bad_route.write_text(
        '<routes><vehicle id="ego" depart="0"><route edges="nowhere"/></vehicle></routes>'
    )
    with pytest.raises(InputError, match=r"bad\.sumocfg: SUMO could not load .*'nowhere'"):
        SumoSession.start(_cfg(tmp_path, str(bad_route)), use_traci=use_traci)


@pytest.mark.parametrize(
    "kwargs,name",
    [
        ({"mu": 0.0}, "mu"),
        ({"mu": 1.3}, "mu"),
        ({"ego_speed_mps": -1.0}, "ego_speed_mps"),
        ({"oncoming_start_m": -3.0}, "oncoming_start_m"),
        ({"oncoming_speed_mps": math.nan}, "oncoming_speed_mps"),
        ({"aro_hold_s": -0.5}, "aro_hold_s"),
        ({"aro_decel_mps2": 0.0}, "aro_decel_mps2"),
        ({"mu": True}, "mu"),
    ],
)
def test_overrides_validate_themselves(kwargs, name):
    with pytest.raises(ValueError, match=name):
        ScenarioOverrides(**kwargs)


@pytest.mark.sumo
def test_one_libsumo_session_at_a_time_and_close_is_final(open_session):
    s = open_session(PARKED_ONLY)
    with pytest.raises(RuntimeError, match="already open"):
        SumoSession.start(PARKED_ONLY)
    s.close()
    s.close()
    with pytest.raises(RuntimeError, match="closed"):
        s.step()
    with SumoSession.start(PARKED_ONLY) as again:
        again.step()
        assert again.ego_body().speed_mps == pytest.approx(float(EGO_ATTRS["departSpeed"]))


def test_angle_conversions_round_trip():
    for yaw in np.linspace(-math.pi + 1e-9, math.pi, 13):
        assert yaw_rad(nav_angle_deg(yaw)) == pytest.approx(yaw, abs=1e-12)
    assert nav_angle_deg(0.0) == 90.0 and yaw_rad(0.0) == pytest.approx(math.pi / 2)


# --------------------------------------------------------------------------- scenario variety
@pytest.mark.sumo
def test_an_ego_alone_in_the_simulation_is_sensed_and_stepped(tmp_path, open_session):
    s = open_session(on_highway(tmp_path, (SCENARIOS / "ego_only.rou.xml").read_text()))
    assert s.nearby(150.0) == []  # no other vehicle: nothing near, no error
    for _ in range(10):
        s.step()
    assert s.nearby(150.0) == []


@pytest.mark.sumo
@pytest.mark.parametrize("ego_first", [True, False])
def test_the_ego_may_be_listed_after_a_vehicle_departing_with_it(tmp_path, open_session, ego_first):
    ego = (
        '<vehicle id="ego" type="ego" route="r" depart="1.00" departPos="100" '
        'departSpeed="30" insertionChecks="none"/>'
    )
    aro = (
        '<vehicle id="aro" type="aro" route="r" depart="1.00" departPos="225" '
        'departSpeed="16" insertionChecks="none"/>'
    )
    pair = ego + aro if ego_first else aro + ego
    s = open_session(on_highway(tmp_path, f'<routes><route id="r" edges="E0"/>{pair}</routes>'))
    assert s.time_s == pytest.approx(1.01)
    assert s.ego_body().speed_mps == pytest.approx(30.0)
    assert {b.vid for b in s.nearby(300.0)} == {"aro"}


@pytest.mark.sumo
def test_a_trip_ego_gets_the_route_sumo_finds(open_session, user_scenario):
    routes = USER_ROUTES.replace(
        '<vehicle id="ego" type="car" depart="0" departSpeed="12"><route edges="road1 road2"/>'
        "</vehicle>",
        '<trip id="ego" type="car" depart="0" departSpeed="12" from="road1" to="road2"/>',
    )
    assert routes != USER_ROUTES
    (user_scenario / "user.rou.xml.gz").write_bytes(gzip.compress(routes.encode()))
    net = sumolib.net.readNet(str(user_scenario / "user.net.xml"))
    s = open_session(user_scenario / "user.sumocfg")
    line = s.ego_lane_centreline()  # over both edges, as routed (the trip names only the ends)
    assert line[-1] == pytest.approx(net.getLane("road2_0").getShape()[-1])


@pytest.mark.sumo
def test_an_ego_faster_than_the_lane_limit_starts_at_its_speed(open_session):
    limit = EGO_LANE.getSpeed()
    s = open_session(
        BASELINE,
        ScenarioOverrides(
            ego_speed_mps=limit + 10.0, oncoming_start_m=500.0, oncoming_speed_mps=limit + 5.0
        ),
    )
    assert s.ego_body().speed_mps == pytest.approx(limit + 10.0)
    s.step()
    assert s.vehicle_speed(s.oncoming_id) == pytest.approx(limit + 5.0)


@pytest.mark.parametrize(
    "old,new",
    [
        ('friction="1.00"', 'friction="2.00"'),
        ('friction="1.00"', 'friction="abc"'),
        ('friction="1.00"', 'friction="0.00"'),
        ('width="3.50"', 'width="abc"'),
        ('index="0"', 'index="x"'),
        ('speed="50.00"', 'speed="-1"'),
    ],
)
def test_bad_lane_numbers_in_the_network_name_the_file(tmp_path, old, new):
    """SUMO segfaults on some of these (friction or width "abc"), or tracebacks followed."""
    net = tmp_path / "bad.net.xml"
    text = HIGHWAY_NET.read_text()
    assert old in text
    net.write_text(text.replace(old, new, 1))
    cfg = on_highway(tmp_path, (SCENARIOS / "ego_only.rou.xml").read_text(), net)
    key, value = new.split("=")
    with pytest.raises(InputError, match=rf"bad.net.xml: lane .* {key}='{value.strip(chr(34))}'"):
        SumoSession.start(cfg)


@pytest.mark.sumo
def test_an_ego_type_slower_than_the_requested_speed_still_starts_at_it(tmp_path, open_session):
    routes = (
        '<routes><vType id="slow" maxSpeed="25" speedDev="0" length="4.9" width="1.85"/>'
        '<route id="r" edges="E0"/><vehicle id="ego" type="slow" route="r" depart="1.00" '
        'departPos="100" departSpeed="20" insertionChecks="none"/></routes>'
    )
    s = open_session(on_highway(tmp_path, routes), ScenarioOverrides(ego_speed_mps=100 / 3.6))
    assert s.ego_body().speed_mps == pytest.approx(100 / 3.6)


@pytest.mark.sumo
def test_a_two_way_road_without_neigh_elements_has_its_opposite_lane(tmp_path, open_session):
    """netconvert's default two-way road (no <neigh>): the reverse edge's lane beside the ego's
    is its opposite lane, for the lane change and for the oncoming car."""
    net = network(
        tmp_path,
        "plain",
        '<nodes><node id="w" x="0" y="0"/><node id="e" x="3000" y="0"/></nodes>',
        '<edges><edge id="E0" from="w" to="e" numLanes="1" speed="50" width="3.5"/>'
        '<edge id="-E0" from="e" to="w" numLanes="1" speed="50" width="3.5"/></edges>',
    )
    assert "<neigh" not in net.read_text()
    cfg = on_highway(tmp_path, (SCENARIOS / "ego_only.rou.xml").read_text(), net)
    s = open_session(cfg, ScenarioOverrides(oncoming_start_m=400.0))
    assert s.left_lane_exists
    assert s.vehicle_lane(s.oncoming_id) == "-E0_0"
    ego, onc = s.ego_body(), s.body(s.oncoming_id)
    assert onc.x_m - ego.x_m == pytest.approx(400.0, abs=6.0)


@pytest.mark.sumo
def test_a_one_way_road_has_no_opposite_lane(tmp_path, open_session):
    net = network(  # a reverse edge elsewhere is not beside it
        tmp_path,
        "oneway",
        '<nodes><node id="w" x="0" y="0"/><node id="e" x="3000" y="0"/>'
        '<node id="far" x="3000" y="500"/></nodes>',
        '<edges><edge id="E0" from="w" to="e" numLanes="1" speed="50" width="3.5"/>'
        '<edge id="back" from="e" to="w" numLanes="1" speed="50" width="3.5" '
        'shape="3000,500 0,500"/></edges>',
    )
    cfg = on_highway(tmp_path, (SCENARIOS / "ego_only.rou.xml").read_text(), net)
    s = open_session(cfg)
    assert not s.left_lane_exists


def test_a_left_hand_traffic_network_is_refused_by_name(tmp_path):
    net = tmp_path / "lh.net.xml"
    text = HIGHWAY_NET.read_text()
    net.write_text(text.replace("<net ", '<net lefthand="true" ', 1))
    cfg = on_highway(tmp_path, (SCENARIOS / "ego_only.rou.xml").read_text(), net)
    with pytest.raises(InputError, match=r"lh.net.xml: a left-hand-traffic network"):
        SumoSession.start(cfg)


# --------------------------------------------------------------------------- fast departures
SLOW_ROAD_NODES = '<nodes><node id="w" x="0" y="0"/><node id="e" x="3000" y="0"/></nodes>'
SLOW_ROAD_EDGES = (
    '<edges><edge id="E0" from="w" to="e" numLanes="1" speed="25" width="3.5"/>'
    '<edge id="-E0" from="e" to="w" numLanes="1" speed="25" width="3.5"/></edges>'
)


def _fast_departures(folder: Path, step_length_s: float | None, lead_speed_mps: float) -> Path:
    """A 25 m/s road: the ego departing at 120 s; "early" (at 119 s), "lead" (with the ego) and
    "late" (at 121 s) departing at 30 m/s, "lead" at ``lead_speed_mps``; types without a
    speed deviation (SUMO refuses their departures above the limit by itself). The sumocfg
    gives ``begin`` and, if not None, its ``step-length``."""
    network(folder, "slow", SLOW_ROAD_NODES, SLOW_ROAD_EDGES)
    vehicle = (
        '<vehicle id="{}" type="aro" route="r" depart="{}" departPos="{}" departSpeed="{}" '
        'insertionChecks="none"/>'
    )
    (folder / "fast.rou.xml").write_text(
        '<routes><route id="r" edges="E0"/>'
        + vehicle.format("early", "119.00", 100, 30)
        + vehicle.format("ego", "120.00", 100, 20).replace('"aro"', '"ego"')
        + vehicle.format("lead", "120.00", 400, lead_speed_mps)
        + vehicle.format("late", "121.00", 10, 30)
        + "</routes>"
    )
    step = "" if step_length_s is None else f'<step-length value="{step_length_s}"/>'
    cfg = folder / "fast.sumocfg"
    cfg.write_text(
        f'<configuration><input><net-file value="slow.net.xml"/>'
        f'<route-files value="fast.rou.xml"/><additional-files value="{VTYPES}"/></input>'
        f'<time><begin value="0"/>{step}</time></configuration>'
    )
    return cfg


@pytest.mark.sumo
@pytest.mark.parametrize("step_length_s", [None, 0.1])
def test_vehicles_faster_than_the_lane_limit_depart_at_their_speed(
    tmp_path, open_session, step_length_s
):
    """docs/scenarios.md: other vehicles faster than the lane's limit depart at their speed
    (SUMO alone refuses them for a type without speedDev), before, with and after the ego,
    whether or not the time before the ego's departure runs at a longer step."""
    s = open_session(_fast_departures(tmp_path, step_length_s, 30.0))
    assert s.vehicle_speed("lead") == pytest.approx(30.0)
    assert s.vehicle_speed("early") == pytest.approx(30.0)
    while s.time_s < 121.5:
        s.step()
    for vid in ("early", "lead", "late"):
        assert s.vehicle_speed(vid) == pytest.approx(30.0), vid


@pytest.mark.sumo
@pytest.mark.parametrize("step_length_s", [None, 0.1])
def test_a_refusal_quotes_sumos_error_not_the_warnings_before_it(tmp_path, step_length_s):
    """Faster than its type's maxSpeed (50 m/s): SUMO's refusal, in SUMO's words, even when
    the handover at the longer step leaves a warning in SUMO's error log first. (Through
    TraCI: the message comes from the error log, and SUMO runs in a process of its own; a
    libsumo that failed during a step may not fail the same way in its next session.)"""
    cfg = _fast_departures(tmp_path, step_length_s, 70.0)
    with pytest.raises(InputError) as refused:
        SumoSession.start(cfg, use_traci=True)
    message = str(refused.value)
    assert "Departure speed for vehicle 'lead' is too high for the vehicle type 'aro'" in message
    assert "Warning" not in message and "State was written" not in message


# --------------------------------------------------------------------------- refusals that say why
def test_a_flow_cannot_be_the_ego(tmp_path):
    cfg = on_highway(
        tmp_path,
        '<routes><route id="r" edges="E0"/>'
        '<flow id="ego" type="ego" route="r" begin="0" end="10" number="2"/></routes>',
    )
    with pytest.raises(InputError, match=r"v\.rou\.xml: 'ego' is a <flow>: a flow cannot be"):
        SumoSession.start(cfg)


@pytest.mark.sumo
def test_a_route_that_skips_an_edge_is_not_connected(tmp_path):
    net = network(
        tmp_path,
        "chain",
        '<nodes><node id="n0" x="0" y="0"/><node id="n1" x="1000" y="0"/>'
        '<node id="n2" x="2000" y="0"/><node id="n3" x="3000" y="0"/></nodes>',
        '<edges><edge id="a" from="n0" to="n1" numLanes="2" speed="30"/>'
        '<edge id="b" from="n1" to="n2" numLanes="2" speed="30"/>'
        '<edge id="c" from="n2" to="n3" numLanes="2" speed="30"/></edges>',
    )
    routes = (
        '<routes><vehicle id="ego" type="ego" depart="0" departPos="20" departSpeed="25">'
        '<route edges="a c"/></vehicle></routes>'
    )
    with pytest.raises(
        InputError,
        match=r"v\.rou\.xml: the route of vehicle 'ego' is not connected: edge 'a' "
        r"does not lead onto edge 'c'",
    ):
        SumoSession.start(on_highway(tmp_path, routes, net))


@pytest.mark.sumo
def test_an_oncoming_car_on_a_one_way_road_is_refused_as_such(tmp_path):
    net = network(
        tmp_path,
        "oneway2",
        '<nodes><node id="w" x="0" y="0"/><node id="e" x="3000" y="0"/></nodes>',
        '<edges><edge id="E0" from="w" to="e" numLanes="2" speed="50" width="3.5"/></edges>',
    )
    cfg = on_highway(tmp_path, (SCENARIOS / "ego_only.rou.xml").read_text(), net)
    with pytest.raises(InputError, match=r"oneway2\.net\.xml: no oncoming car .* one-way.*'E0'"):
        SumoSession.start(cfg, ScenarioOverrides(oncoming_start_m=400.0))
