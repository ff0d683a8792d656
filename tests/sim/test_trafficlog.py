"""TrafficLog: radius, ego pose, roles and the written file (hand-made road users on a
straight east-bound lane centred on y = -1.75, 3.5 m wide)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.errors import InputError
from eoam_sumo.sim.trafficlog import TRAFFIC_COLUMNS, TrafficLog, read_traffic
from eoam_sumo.world.bodies import Body

User = Body  # a road user as the session gives it

LANE = [(0.0, -1.75), (1000.0, -1.75)]
EGO_LEN, EGO_WID, TO_CENTRE = 4.92, 1.85, 0.5


def _log(radius_m: float = 250.0) -> TrafficLog:
    return TrafficLog("ego", "passenger", EGO_LEN, EGO_WID, TO_CENTRE, LANE, 3.5, radius_m)


def _ego(x: float, y: float = -1.75, yaw: float = 0.0, vx: float = 30.0) -> list[float]:
    return [x, y, yaw, vx, 0.0, 0.0]


def test_radius_keeps_users_within_it_of_the_ego_cg():
    log = _log(radius_m=100.0)
    near = User("a", "passenger", 199.9, -1.75, 0.0, 10.0, 4.0, 1.8, False)
    far = User("b", "passenger", 200.1, -1.75, 0.0, 10.0, 4.0, 1.8, False)
    diagonal = User("c", "passenger", 100.0 + 60.0, -1.75 + 80.0, 0.0, 0.0, 4.0, 1.8, False)
    log.add(1.0, _ego(100.0), [near, far, diagonal])
    cols = log.columns()
    assert cols["id"] == ["ego", "a", "c"]  # c: exactly 100 m (60-80-100 triangle)


def test_ego_row_is_its_box_centre_heading_wrapped_and_vx():
    log = _log()
    yaw = 2.0 * math.pi + 0.3  # the plant's yaw is continuous
    log.add(2.5, _ego(10.0, 5.0, yaw, -1.5), [])
    c = log.columns()
    assert c["x_m"][0] == pytest.approx(10.0 + TO_CENTRE * math.cos(0.3))
    assert c["y_m"][0] == pytest.approx(5.0 + TO_CENTRE * math.sin(0.3))
    assert c["heading_rad"][0] == pytest.approx(0.3)
    assert c["speed_mps"][0] == -1.5
    assert (c["length_m"][0], c["width_m"][0], c["vclass"][0]) == (EGO_LEN, EGO_WID, "passenger")


def test_roles_relative_to_the_ego_lane():
    users = [
        User("ahead_car", "passenger", 150.0, -1.6, 0.0, 5.0, 5.0, 2.0, False),
        User("behind_car", "passenger", 50.0, -1.75, 0.0, 30.0, 5.0, 2.0, False),
        User("walker", "pedestrian", 130.0, -2.5, math.pi / 2, 1.2, 0.2, 0.5, False),
        User("pavement", "pedestrian", 130.0, -6.0, 0.0, 1.2, 0.2, 0.5, False),
        User("oncoming", "passenger", 180.0, 1.75, math.pi, 20.0, 4.7, 1.8, False),
        User("parked", "passenger", 140.0, -5.9, 0.0, 0.0, 4.3, 1.8, True),
        User("slow_west", "bicycle", 160.0, 1.75, math.pi, 1.0, 1.6, 0.65, False),
        User("east_left", "passenger", 160.0, 1.75, 0.0, 25.0, 4.7, 1.8, False),
        User("west_right", "passenger", 160.0, -8.0, math.pi, 25.0, 4.7, 1.8, False),
    ]
    log = _log()
    log.add(1.0, _ego(100.0), users)
    c = log.columns()
    roles = dict(zip(c["id"], c["role"]))
    assert roles == {
        "ego": "ego",
        "ahead_car": "aro",
        "behind_car": "other",
        "walker": "aro",
        "pavement": "other",
        "oncoming": "oncoming",
        "parked": "parked",
        "slow_west": "other",
        "east_left": "other",
        "west_right": "other",
    }


def test_the_obstacle_keeps_its_role_once_passed_and_a_follower_never_takes_it():
    """The ARO, first met ahead in the ego's lane, stays 'aro' once the ego (in the next lane)
    has passed it, as ``min_gap_aro_m`` counts it; a car first met behind the ego in its lane
    is a follower ('other') throughout, and so is the ARO once out of the ego's lane."""
    log = _log()
    for k, x in enumerate((150.0, 199.0, 201.0, 250.0)):
        aro = User("aro", "passenger", 200.0, -1.75 if k < 3 else 1.75, 0.0, 0.0, 5.0, 2.0, False)
        follower = User("follower", "passenger", x - 10.0, -1.75, 0.0, 30.0, 5.0, 2.0, False)
        log.add(k * 0.01, _ego(x, 1.75), [aro, follower])
    c = log.columns()
    assert [r for i, r in zip(c["id"], c["role"]) if i == "aro"] == ["aro", "aro", "aro", "other"]
    assert {r for i, r in zip(c["id"], c["role"]) if i == "follower"} == {"other"}


def test_cross_traffic_is_other_and_an_obstacle_that_turns_across_stays_the_obstacle():
    """A car crossing the ego's lane ahead at a junction (heading north at 15 m/s) is
    'other' while in the band; the ARO, in the lane along the road first, stays 'aro' when
    it then turns across."""
    log = _log()
    for k in range(3):
        cross = User(
            "cross", "passenger", 150.0, -5.0 + 3.0 * k, math.pi / 2, 15.0, 4.7, 1.8, False
        )
        yaw = 0.0 if k == 0 else math.pi / 2
        aro = User("aro", "passenger", 170.0, -1.75 + k, yaw, 10.0, 4.7, 1.8, False)
        log.add(k * 0.1, _ego(100.0 + k), [cross, aro])
    c = log.columns()
    assert {r for i, r in zip(c["id"], c["role"]) if i == "cross"} == {"other"}
    assert [r for i, r in zip(c["id"], c["role"]) if i == "aro"] == ["aro", "aro", "aro"]


def test_written_file_has_the_columns_and_reads_back(tmp_path):
    log = _log()
    users = [User("p", "pedestrian", 120.0, -1.0, 1.0, 1.3, 0.2, 0.5, False)]
    for k in range(3):
        log.add(1.0 + 0.01 * k, _ego(100.0 + 0.3 * k), users)
    path = tmp_path / "traffic.csv"
    log.write(path)
    assert path.read_text().splitlines()[0] == ",".join(TRAFFIC_COLUMNS)
    frame = read_traffic(path)
    assert len(frame) == 6
    assert list(frame["id"]) == ["ego", "p"] * 3
    assert frame["time_s"].tolist() == [1.0, 1.0, 1.01, 1.01, 1.02, 1.02]
    assert frame.loc[1, "vclass"] == "pedestrian"


def test_an_id_with_a_comma_is_quoted_and_reads_back(tmp_path):
    log = _log()
    log.add(
        1.0, _ego(100.0), [User('car,"7"', "passenger", 150.0, 1.75, 0.0, 5.0, 4.0, 1.8, False)]
    )
    path = tmp_path / "traffic.csv"
    log.write(path)
    assert list(read_traffic(path)["id"]) == ["ego", 'car,"7"']


def test_parquet_holds_the_same_table(tmp_path):
    import pandas as pd

    log = _log()
    log.add(1.0, _ego(100.0), [User("p", "pedestrian", 120.0, -1.0, 1.0, 1.3, 0.2, 0.5, False)])
    log.write(tmp_path / "traffic.csv")
    log.write(tmp_path / "traffic.parquet")
    pd.testing.assert_frame_equal(
        read_traffic(tmp_path / "traffic.csv"), pd.read_parquet(tmp_path / "traffic.parquet")
    )


def test_read_traffic_names_a_damaged_file(tmp_path):
    path = tmp_path / "traffic.csv"
    path.write_text("time_s,id,role\n1.0,ego,ego\n")
    with pytest.raises(InputError, match=r"traffic\.csv.*no column vclass"):
        read_traffic(path)
    path.write_text(",".join(TRAFFIC_COLUMNS) + "\n1.0,ego,passenger,ego,far,0,0,0,4,2\n")
    with pytest.raises(InputError, match=r"traffic\.csv: cannot be read as a run's traffic"):
        read_traffic(path)


def test_bad_radius_is_refused():
    with pytest.raises(ValueError, match="radius_m"):
        _log(radius_m=0.0)


CURVE = [(200.0 * math.sin(a / 20), 200.0 * (1 - math.cos(a / 20)) - 1.75) for a in range(40)]
coord = st.floats(-250.0, 250.0, allow_nan=False)


def _user(*fields):
    """A road user from its first nine fields (``builds(Body)`` would ask for its box too)."""
    return User(*fields)


users = st.lists(
    st.builds(
        _user,
        st.sampled_from(["a", "b", "c", "z"]),
        st.just("passenger"),
        coord,
        coord,
        st.floats(-4.0, 4.0),
        st.floats(0.0, 40.0),
        st.just(4.5),
        st.just(1.8),
        st.booleans(),
    ),
    max_size=4,
    unique_by=lambda u: u.vid,
)


@settings(max_examples=200, deadline=None)
@given(steps=st.lists(st.tuples(coord, coord, users), min_size=1, max_size=6), curved=st.booleans())
def test_had_oncoming_without_the_layout_is_the_layout_s_answer(steps, curved):
    """The summary's shortcut (no rows laid out) answers as the roles column does, on a
    straight and a curved lane (where a road-frame walk depends on where it starts)."""
    log = TrafficLog(
        "ego", "passenger", EGO_LEN, EGO_WID, TO_CENTRE, CURVE if curved else LANE, 3.5, 150.0
    )
    for k, (x, y, near) in enumerate(steps):
        log.add(0.01 * k, _ego(x, y), near)
    fast = log.had_role("oncoming")
    assert fast == ("oncoming" in log.columns()["role"])
    assert log.had_role("oncoming") == fast  # the laid-out answer, asked again
