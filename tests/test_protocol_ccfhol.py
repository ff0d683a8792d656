"""CCFhol: the oncoming target's lane change along Vector's catalogue path (independent truth:
the clothoid segments of ``TrajectoryCatalog.xosc`` copied by hand, the protocol's lateral
distance 3.5 m and TTC 1.5 s), and one SUMO run of the 50/50 km/h point at 50 %."""

from __future__ import annotations

import math
import subprocess
import sys

import pandas as pd
import pytest

from eoam_sumo.protocols import lane_change
from eoam_sumo.protocols.points import PROTOCOLS, protocol_points

SEDAN_WIDTH_M = 1.85


def test_vector_paths_shift_about_the_protocols_lateral_distance():
    # GVT_CCFhol_50: 15 m at 0.008 1/m, 1 m at 0.006, 1 m at 0.001, 10 m straight, 1 m at
    # -0.006, 15 m at -0.008 (43 m; the protocol's L is 44 m); GVT_CCFhol_70: 60 m
    assert lane_change.path_length_m(50) == 43.0 and lane_change.path_length_m(70) == 60.0
    for speed in (50, 70):
        raw = lane_change._integrate(lane_change.segments(speed))[-1]
        assert raw[1] == pytest.approx(3.5, rel=0.02)  # O = 3.5 m, as integrated
        assert lane_change.path_points(speed, 3.5)[-1][1] == pytest.approx(3.5)
    # small angles: the extent along the road is the length times cos(<= 0.12 rad)
    assert 42.6 < lane_change.path_extent_m(50) < 43.0


def test_faster_paths_keep_the_lateral_acceleration_and_the_shift():
    def peak_lateral_accel(speed_kmh):
        return max(abs(c) for c, _ in lane_change.segments(speed_kmh)) * (speed_kmh / 3.6) ** 2

    assert peak_lateral_accel(100) == pytest.approx(peak_lateral_accel(70))
    raw70 = lane_change._integrate(lane_change.segments(70))[-1][1]
    raw100 = lane_change._integrate(lane_change.segments(100))[-1][1]
    assert raw100 == pytest.approx(raw70, rel=1e-3)
    with pytest.raises(ValueError, match="60"):
        lane_change.segments(60)


def test_every_point_lines_up_with_the_ttc_at_the_lane_changes_end():
    """Both at their test speeds, the fronts are 1.5 s of closing apart when the lane change
    ends: 8 s of closing, then the lane change's duration at the target's speed."""
    for p in protocol_points(PROTOCOLS[1], SEDAN_WIDTH_M):
        if p.test != "CCFhol":
            continue
        ve, vt = p.ego_speed_kmh / 3.6, p.target_speed_kmh / 3.6
        duration = lane_change.path_length_m(p.target_speed_kmh) / vt
        ego_x = (8.0 + duration) * ve
        target_x = p.gap_m - 8.0 * vt - lane_change.path_extent_m(p.target_speed_kmh)
        assert (target_x - ego_x) / (ve + vt) == pytest.approx(1.5, abs=2e-3), p.point_id


@pytest.mark.sumo
def test_the_target_changes_lanes_into_the_aeb_that_brakes(tmp_path):
    out = tmp_path / "hol"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "eoam_sumo",
            "protocol",
            PROTOCOLS[1],
            "--out",
            str(out),
            "--points",
            "^CCFhol_v50_t50_o50_",
            "--no-progress",
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    row = pd.read_csv(out / "results.csv").iloc[0]
    traffic = pd.read_csv(out / row["case_dir"] / "traffic.csv")
    target = traffic[traffic["id"] == "target"]
    ego_lane_y = -1.75
    assert target["y_m"].iloc[0] == pytest.approx(ego_lane_y + 3.5, abs=0.01)
    assert target["y_m"].min() == pytest.approx(ego_lane_y, abs=0.01)
    # halfway through the lane change (its front 1.75 m over, 21.5 m of 43 m along its path)
    # the fronts are (L / 2 v + 1.5 s) of closing apart; the ego still at its test speed
    half = 4.023 / 2  # traffic.csv gives the footprint's centre; the path is the front's
    front_x = target["x_m"] + half * target["heading_rad"].map(math.cos)
    front_y = target["y_m"] + half * target["heading_rad"].map(math.sin)
    mid = front_y <= ego_lane_y + 3.5 / 2
    t_mid = float(target.loc[mid, "time_s"].iloc[0])
    ego = traffic[(traffic["id"] == "ego") & (traffic["time_s"] == t_mid)].iloc[0]
    ego_run = pd.read_csv(out / row["case_dir"] / "timeseries.csv")
    assert (ego_run.loc[ego_run["time_s"] <= t_mid, "mode"] == 0).all()
    gap = float(front_x[mid].iloc[0]) - (ego["x_m"] + ego["length_m"] / 2)
    closing = 2 * 50 / 3.6
    assert gap / closing == pytest.approx(21.5 / (50 / 3.6) + 1.5, abs=0.05)
    # the obstruction vehicle drives the opposite lane, 1 s of the target's speed ahead
    sov = traffic[traffic["id"] == "obstruction"].set_index("time_s")
    first = target.iloc[0]
    assert sov["y_m"].iloc[0] == pytest.approx(1.75, abs=0.01)
    ahead = first["x_m"] - sov.loc[first["time_s"], "x_m"] - (4.023 + 4.418) / 2
    assert ahead == pytest.approx(50 / 3.6, abs=0.2)
    # aeb: braked in lane, no lane change, hit by the target well below its test speed
    assert row["manoeuvre"] == "B" and row["time_in_next_lane_s"] == 0.0
    assert row["collision_with_id"] == "target"
    assert row["speed_reduction_kmh"] > 30 and row["colour"] == "green"
    assert not math.isnan(row["warning_lead_s"])
