"""Automotive radar and tracker against ground truth (no SUMO): noise, timing, occlusion,
misses, seeding."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.sensing.automotive import (
    AutomotiveRadar,
    AutomotiveRadarSettings,
    make_radar,
    parse_radar_model,
)
from eoam_sumo.sensing.radar import Radar
from eoam_sumo.sensing.tracker import Measurement, Tracker, TrackerSettings
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.world.bodies import Body

LANE_M = 3.5
CAR = (4.70, 1.82)
ROAD = RoadFrame([(-1000.0, 0.0), (5000.0, 0.0)])
EXACT = AutomotiveRadarSettings(
    range_sd_m=0.0, azimuth_sd_deg=0.0, range_rate_sd_mps=0.0, detection_probability=1.0
)


def _car(rear_x_m, y_m=0.0, speed_mps=0.0, dims=CAR, vid="car"):
    return Body(vid, "passenger", rear_x_m + 0.5 * dims[0], y_m, 0.0, speed_mps, *dims)


def _drive(radar, targets_at, seconds, ego_speed=30.0, dt=0.01):
    """Scan every step, the ego at x = v t; ``targets_at(t)`` gives the world."""
    out = []
    for k in range(round(seconds / dt)):
        t = k * dt
        out.append(
            (t, radar.scan((ego_speed * t, 0.0), 0.0, ego_speed, ROAD, targets_at(t), LANE_M, t))
        )
    return out


def test_exact_model_reports_the_truth_of_the_scan_it_last_saw():
    """Without noise or misses: the first report comes after the latency plus one more cycle
    (two hits confirm a track), and the reported range is the true range at that scan."""
    radar = AutomotiveRadar(model=EXACT)
    stopped = [_car(80.0)]
    trace = _drive(radar, lambda t: stopped, 1.0)
    first = next(t for t, rep in trace if rep.in_path_range_m is not None)
    # scans at the first steps at or after 0 and 0.072 s (0.08, the confirming one),
    # delivered 0.072 s later: at the first step at or after 0.152 s
    assert first == pytest.approx(0.16, abs=1e-9)
    for t, rep in trace:
        if rep.in_path_range_m is None:
            continue
        seen_at = max(s for s in _scan_times(1.0) if s + 0.072 <= t + 1e-9)
        assert rep.in_path_range_m == pytest.approx(80.0 - 30.0 * seen_at, abs=1e-3)
        assert rep.in_path_range_rate_mps == pytest.approx(-30.0, abs=1e-3)


def _scan_times(seconds, cycle=0.072, dt=0.01):
    """The steps at which a 72 ms radar scans when called every 10 ms from t = 0."""
    times, due = [], 0.0
    for k in range(round(seconds / dt)):
        t = k * dt
        if t + 1e-9 >= due:
            times.append(t)
            due += cycle * max(1, math.floor((t + 1e-9 - due) / cycle) + 1)
    return times


def test_same_seed_same_reports_other_seed_other_noise():
    world = [_car(60.0, 0.2, 10.0), _car(90.0, LANE_M, -20.0)]
    a = _drive(AutomotiveRadar(seed=3), lambda t: world, 1.5)
    b = _drive(AutomotiveRadar(seed=3), lambda t: world, 1.5)
    c = _drive(AutomotiveRadar(seed=4), lambda t: world, 1.5)
    assert a == b
    assert a != c


def test_noise_is_that_of_the_data_sheet():
    """Range errors of single detections have the set standard deviation (0.40 m)."""
    radar = AutomotiveRadar(seed=1)
    errors = []
    for _ in range(2000):
        scan = radar._measure(0.0, (0.0, 0.0), 0.0, 30.0, ROAD, [_car(50.0)])
        errors += [m.range_m - 50.0 for m in scan.measurements]
    errors = np.array(errors)
    assert len(errors) == pytest.approx(0.9 * 2000, rel=0.05)  # detection probability
    assert abs(errors.mean()) < 0.05 and errors.std() == pytest.approx(0.40, rel=0.08)


def test_a_car_hidden_behind_a_nearer_one_is_not_seen():
    radar = AutomotiveRadar(model=EXACT)
    near, hidden = _car(40.0), _car(70.0)
    visible = radar._visible(0.0, 0.0, 0.0, 1.0, 0.0, [hidden, near])
    assert [v[0] for v in visible] == [near]
    # a car half a lane to the left behind it shows a corner: seen at that corner
    offset = _car(70.0, 1.5)
    visible = radar._visible(0.0, 0.0, 0.0, 1.0, 0.0, [offset, near])
    assert [v[0] for v in visible] == [near, offset]
    x, y = visible[1][2:]
    assert (x, y) == pytest.approx((70.0, 1.5 + 0.5 * CAR[1]))
    # the ideal radar sees through
    assert len(Radar().scan((0.0, 0.0), 0.0, 30.0, ROAD, [hidden, near], LANE_M).detections) == 2


def test_tracks_are_confirmed_by_two_hits_and_deleted_after_three_misses():
    tracker = Tracker(TrackerSettings())
    m = Measurement(50.0, 0.0, -30.0, 0.4, 0.002, 0.1, 2.35, 0.0, *CAR)
    tracker.update(0.0, [m], (0.0, 0.0), (30.0, 0.0))
    assert tracker.confirmed() == []
    tracker.update(0.1, [m._replace(range_m=47.0)], (3.0, 0.0), (30.0, 0.0))  # ego moved
    (track,) = tracker.confirmed()
    assert track.vx_mps == pytest.approx(0.0, abs=1.0)
    for k in range(2):
        tracker.update(0.2 + 0.1 * k, [], (0.0, 0.0), (30.0, 0.0))
        assert len(tracker.confirmed()) == 1
    tracker.update(0.4, [], (0.0, 0.0), (30.0, 0.0))
    assert tracker.confirmed() == []


def test_tracker_follows_a_braking_car_and_gates_out_a_far_detection():
    """An obstacle stopping at 8 m/s^2 from 16.7 m/s, measured with the data sheet's noise
    every 72 ms: the speed estimate stays within 1.5 m/s of the truth; a detection 30 m away
    opens a second track rather than pulling the first."""
    rng = np.random.default_rng(0)
    tracker = Tracker()
    worst = 0.0
    for k in range(60):
        t = 0.072 * k
        v = max(16.7 - 8.0 * max(t - 1.0, 0.0), 0.0)
        x = (
            60.0
            + 16.7 * min(t, 1.0)
            + (16.7 * (t - 1) - 4.0 * (t - 1) ** 2 if 1.0 < t <= 1.0 + 16.7 / 8 else 0.0)
        )
        if t > 1.0 + 16.7 / 8:
            x = 60.0 + 16.7 + 16.7**2 / 16.0
        r = x + 0.4 * rng.standard_normal()
        az = math.radians(0.1) * rng.standard_normal()
        rr = v + 0.1 * rng.standard_normal()  # the radar stands still
        tracker.update(
            t,
            [Measurement(r, az, rr, 0.4, math.radians(0.1), 0.1, 2.35, 0, *CAR)],
            (0.0, 0.0),
            (0.0, 0.0),
        )
        if k >= 5:
            (track,) = tracker.confirmed()
            worst = max(worst, abs(track.vx_mps - v))
    assert worst < 1.5
    far = Measurement(r + 30.0, 0.0, 0.0, 0.4, math.radians(0.1), 0.1, 2.35, 0, *CAR)
    tracker.update(t + 0.072, [far], (0.0, 0.0), (0.0, 0.0))
    tracker.update(t + 0.144, [far], (0.0, 0.0), (0.0, 0.0))
    assert len(tracker.confirmed()) == 2


@pytest.mark.parametrize("bad", ["perfect", "", 3])
def test_bad_radar_model_is_an_input_error(bad):
    with pytest.raises(InputError, match="radar_model"):
        parse_radar_model(bad)


def test_make_radar_and_settings_checks():
    assert isinstance(make_radar("ideal", Radar().settings), Radar)
    assert isinstance(make_radar("Automotive", Radar().settings), AutomotiveRadar)
    with pytest.raises(InputError, match="detection_probability"):
        replace(EXACT, detection_probability=0.0)
    with pytest.raises(InputError, match="confirm_hits"):
        TrackerSettings(confirm_hits=4, confirm_window=3)


@pytest.mark.parametrize(
    ("option", "value", "named"),
    [
        ("--radar-model", "sonar", "radar_model 'sonar'"),
        ("--seed", "-1", "seed = -1"),
        ("--seed", "x", "seed 'x'"),
    ],
)
def test_run_refuses_a_bad_radar_model_or_seed_with_one_line(
    option, value, named, capsys, tmp_path
):
    from pathlib import Path

    from eoam_sumo.cli import main

    cfg = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.sumocfg"
    assert main(["run", str(cfg), option, value, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0]


def test_a_tracked_wrong_way_car_in_the_lane_is_the_in_path_obstacle():
    """The automotive radar classifies its tracks as the ideal radar does: a wrong-way car
    half an ego width off the lane centre is reported in path, at the closing speed (ego +
    target, exact model), and as oncoming traffic."""
    ego_mps, tgt_mps = 80 / 3.6, 50 / 3.6
    radar = AutomotiveRadar(model=EXACT)

    def world(t):
        centre = 90.0 + 0.5 * CAR[0] - tgt_mps * t
        return [Body("wrong_way", "passenger", centre, 0.925, math.pi, tgt_mps, *CAR)]

    reports = [rep for _, rep in _drive(radar, world, 1.0, ego_speed=ego_mps)]
    seen = [rep for rep in reports if rep.in_path is not None]
    assert seen, "never in path"
    for rep in seen:
        assert rep.oncoming_detected and rep.in_path.head_on
        assert rep.in_path.category == "oncoming"
        assert rep.in_path_range_rate_mps == pytest.approx(-(ego_mps + tgt_mps), abs=0.05)
