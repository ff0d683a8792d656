"""The traffic plot's pure parts on made-up data whose answers are known: road.csv written and
read back, the centre line recovered from an ego's samples on a circle, box gaps, hard
braking."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.plotting.roadtracks import (
    HARD_BRAKING_MPS2,
    EgoRoad,
    centreline_from_ego,
    closest_approach,
    hard_braking,
    project_traffic,
    telling_roles,
)
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.sim.runlog import ROAD_FILE, read_road, write_road

RADIUS_M = 100.0


def test_road_csv_round_trip_with_stations(tmp_path):
    xy = np.array([[0.0, 0.0], [30.0, 40.0], [30.0, 100.0]])
    write_road(tmp_path / ROAD_FILE, xy)
    frame = pd.read_csv(tmp_path / ROAD_FILE)
    assert list(frame.columns) == ["s_m", "x_m", "y_m"]
    np.testing.assert_allclose(frame["s_m"], [0.0, 50.0, 110.0])
    np.testing.assert_allclose(read_road(tmp_path / ROAD_FILE), xy)


@pytest.mark.parametrize("text", ["", "s_m,x_m\n0,1\n", "s_m,x_m,y_m\n0,0,0\n", "x_m,y_m\n0,a\n"])
def test_a_damaged_road_csv_is_an_input_error_naming_it(tmp_path, text):
    (tmp_path / ROAD_FILE).write_text(text)
    with pytest.raises(InputError, match=ROAD_FILE):
        read_road(tmp_path / ROAD_FILE)


def _circle_samples(d_m: float, heading_error_rad: float) -> pd.DataFrame:
    """An ego going counter-clockwise round a circle of ``RADIUS_M`` about the origin, its
    centre of gravity ``d_m`` left of the circle, yawed ``heading_error_rad`` off the road,
    its stations counted from s = 40 m."""
    phi = np.linspace(0.0, 1.8 * math.pi, 2000)  # 324 degrees
    r = RADIUS_M - d_m
    road_yaw = phi + math.pi / 2
    return pd.DataFrame(
        {
            "x_m": r * np.cos(phi),
            "y_m": r * np.sin(phi),
            "yaw_rad": road_yaw + heading_error_rad,
            "heading_error_rad": np.full_like(phi, heading_error_rad),
            "s_m": 40.0 + RADIUS_M * phi,
            "lateral_offset_m": np.full_like(phi, d_m),
        }
    )


def test_the_centre_line_comes_back_from_the_egos_samples_on_a_circle():
    points, s0 = centreline_from_ego(_circle_samples(0.8, 0.05))
    assert s0 == pytest.approx(40.0)
    np.testing.assert_allclose(np.hypot(points[:, 0], points[:, 1]), RADIUS_M, atol=1e-9)
    road = EgoRoad(RoadFrame(points), s0, "test")
    # a point 3.5 m left of the circle at 200 degrees: s = 40 + R * 200 deg
    phi = math.radians(200.0)
    s, d = road.project_path(np.array([[96.5 * math.cos(phi), 96.5 * math.sin(phi)]]))[0]
    assert s == pytest.approx(40.0 + RADIUS_M * phi, abs=0.05)
    assert d == pytest.approx(3.5, abs=0.01)


def test_an_ego_standing_still_gives_a_line_along_the_road_heading():
    samples = _circle_samples(0.0, 0.0).iloc[[0, 0, 0]]
    points, s0 = centreline_from_ego(samples)
    assert len(points) == 2 and s0 == pytest.approx(40.0)
    heading = math.atan2(*(points[1] - points[0])[::-1])
    assert heading == pytest.approx(math.pi / 2)


def _rows(
    vid, role, t, x, y=0.0, heading=0.0, speed=0.0, length=4.0, width=2.0, vclass="passenger"
):
    t = np.atleast_1d(np.asarray(t, dtype=float))
    n = len(t)
    return pd.DataFrame(
        {
            "time_s": t,
            "id": [vid] * n,
            "vclass": [vclass] * n,
            "role": [role] * n if isinstance(role, str) else role,
            "x_m": np.broadcast_to(x, n).astype(float),
            "y_m": np.broadcast_to(y, n).astype(float),
            "heading_rad": np.broadcast_to(heading, n).astype(float),
            "speed_mps": np.broadcast_to(speed, n).astype(float),
            "length_m": np.full(n, length),
            "width_m": np.full(n, width),
        }
    )


def test_the_closest_gap_is_the_box_gap_at_the_closest_time():
    t = np.arange(0.0, 2.0, 0.1)
    ego = _rows("ego", "ego", t, 10.0 * t)  # 4 m long: front at 10 t + 2
    aro = _rows("car", "aro", t, 30.0)  # rear at 28
    # an oncoming car in the next lane, 3.5 m left, passing the ego at t = 1.0
    onc = _rows("onc", "oncoming", t, 30.0 - 20.0 * t, 3.5, math.pi)
    traffic = pd.concat([ego, aro, onc], ignore_index=True)
    found = closest_approach(traffic, "aro")
    assert (found.vid, found.time_s) == ("car", pytest.approx(1.9))
    assert found.gap_m == pytest.approx(28.0 - (19.0 + 2.0))
    assert traffic.at[found.ego_row, "role"] == "ego"
    passing = closest_approach(traffic, "oncoming")
    assert passing.time_s == pytest.approx(1.0)
    assert passing.gap_m == pytest.approx(3.5 - 2.0)  # side by side: lane width - a width
    assert closest_approach(traffic, "parked") is None


def test_hard_braking_finds_the_spell_above_the_threshold_only():
    t = np.round(np.arange(0.0, 4.0, 0.01), 6)
    v_hard = np.clip(20.0 - 6.0 * np.clip(t - 1.0, 0.0, None), 8.0, None)  # 6 m/s^2, 1-3 s
    v_soft = 20.0 - 2.0 * t  # 2 m/s^2: not marked
    traffic = pd.concat(
        [
            _rows("ego", "ego", t, 0.0),
            _rows("hard", "aro", t, 50.0, speed=v_hard),
            _rows("soft", "other", t, 80.0, speed=v_soft),
            _rows("walker", "other", t, 60.0, speed=np.where(t < 2, 1.4, 0.0), vclass="pedestrian"),
        ],
        ignore_index=True,
    )
    spells = hard_braking(traffic)
    assert [s.vid for s in spells] == ["hard"]
    (spell,) = spells
    assert spell.peak_mps2 == pytest.approx(6.0, rel=1e-6)
    assert spell.t_start_s == pytest.approx(1.0, abs=0.1)  # within the window
    assert spell.t_end_s == pytest.approx(3.0, abs=0.1)  # within the window
    assert (spell.speed_from_mps, spell.speed_to_mps) == pytest.approx((20.0, 8.0), abs=0.7)
    assert 6.0 > HARD_BRAKING_MPS2 > 2.0


def test_a_road_user_leaving_the_log_is_not_braking():
    # seen at 10 m/s until 1 s, then again at 0 m/s from 3 s: no rows in between
    t = np.round(np.r_[np.arange(0.0, 1.0, 0.01), np.arange(3.0, 4.0, 0.01)], 6)
    traffic = pd.concat(
        [_rows("ego", "ego", t, 0.0), _rows("car", "other", t, 40.0, speed=(t < 2) * 10.0)],
        ignore_index=True,
    )
    assert hard_braking(traffic) == []


def test_projection_walks_each_road_user_and_roles_keep_the_most_telling():
    road = EgoRoad(RoadFrame([(0.0, 0.0), (100.0, 0.0), (100.0, 100.0)]), 10.0, "test")
    t = np.array([0.0, 1.0, 2.0])
    traffic = pd.concat(
        [
            _rows("ego", "ego", t, np.array([10.0, 20.0, 30.0])),
            _rows("car", ["aro", "aro", "other"], t, 98.0, np.array([10.0, 50.0, 90.0])),
        ],
        ignore_index=True,
    )
    out = project_traffic(traffic, road)
    np.testing.assert_allclose(out["s_m"], [20.0, 30.0, 40.0, 120.0, 160.0, 200.0])
    np.testing.assert_allclose(out["d_m"], [0.0, 0.0, 0.0, 2.0, 2.0, 2.0])
    assert telling_roles(traffic) == {"ego": "ego", "car": "aro"}
