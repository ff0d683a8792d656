"""Closed loop with the plant alone (no SUMO): straight road along x, a stationary obstacle.

The road frame is the network frame (s = x, d = y, e_yaw = yaw). The obstacle (the paper's
D-class minivan) stands on the ego lane centre; a simple in-path radar reports the range from
the ego's front bumper to its rear while the two overlap laterally and it is within the
detection range. Contact is checked on oriented boxes (separating axes) at every step.
"""

import math

import pytest

from eoam_sumo.eoam import EgoMeasurement, EoamController, EoamSettings, Perception
from eoam_sumo.eoam.parts import build_parts
from eoam_sumo.eoam.perceive import friction_at
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import AIR_DENSITY_KGPM3, aro_d_class_minivan, ego_e_class_sedan
from eoam_sumo.plant import OUTPUT_NAMES, Plant, initial_state

P = ego_e_class_sedan()
ARO = aro_d_class_minivan()
DT = 0.01
LANE = 3.5
LOCK = (OUTPUT_NAMES.index("front_locked"), OUTPUT_NAMES.index("rear_locked"))


@pytest.fixture(scope="module")
def tables():
    return LookupTables.load(default_tables_dir(), params=P)


@pytest.fixture(scope="module")
def plant():
    return Plant(P, 1e-3, 10)


def corners(x, y, yaw, length, width):
    c, s = math.cos(yaw), math.sin(yaw)
    return [
        (x + c * u - s * w, y + s * u + c * w)
        for u, w in (
            (length / 2, width / 2),
            (length / 2, -width / 2),
            (-length / 2, -width / 2),
            (-length / 2, width / 2),
        )
    ]


def overlap(a, b):
    """Separating-axis test of two convex quadrilaterals given by their corners."""
    for poly in (a, b):
        for i in range(4):
            (x1, y1), (x2, y2) = poly[i], poly[(i + 1) % 4]
            nx, ny = y1 - y2, x2 - x1
            pa = [nx * px + ny * py for px, py in a]
            pb = [nx * px + ny * py for px, py in b]
            if max(pa) < min(pb) or max(pb) < min(pa):
                return False
    return True


def simulate(tables, plant, speed_mps, mu, obstacle_rear_m, detect_m, seconds):
    """Run the EOAM on the plant; returns the per-step log and the controller."""
    ctrl = EoamController(P, tables)
    ctrl.reset(speed_mps)
    x = initial_state(0.0, 0.0, 0.0, speed_mps)
    obstacle = corners(obstacle_rear_m + ARO.length_m / 2, 0.0, 0.0, ARO.length_m, ARO.width_m)
    half_widths = 0.5 * (P.width_m + ARO.width_m)
    ax = ay = 0.0
    log = []
    for k in range(round(seconds / DT)):
        t = k * DT
        X, Y, yaw, vx, vy, r = (float(x[i]) for i in range(6))
        rng = obstacle_rear_m - (X + P.cg_to_front_bumper_m * math.cos(yaw))
        seen = abs(Y) < half_widths and 0.0 < rng <= detect_m
        perception = Perception(rng if seen else None, -vx if seen else None, False)
        meas = EgoMeasurement(t, vx, vy, r, ax, ay, X, Y, yaw, 0.0, mu, LANE)
        cmd = ctrl.step(meas, perception, DT)
        x, y = plant.step(x, (cmd.steer_cmd_rad, cmd.drive_force_cmd_n, cmd.brake_force_cmd_n), mu)
        ax, ay = float(y[0]), float(y[1])
        X, Y, yaw, vx = float(x[0]), float(x[1]), float(x[2]), float(x[3])
        drag = 0.5 * AIR_DENSITY_KGPM3 * P.drag_area_m2 * vx * abs(vx) / P.mass_kg
        off = P.cg_to_front_bumper_m - P.length_m / 2  # CG to the footprint centre
        ego = corners(X + off * math.cos(yaw), Y + off * math.sin(yaw), yaw, P.length_m, P.width_m)
        hit = overlap(ego, obstacle)
        log.append(
            {
                "t": t + DT,
                "x": X,
                "y": Y,
                "yaw": yaw,
                "vx": vx,
                "ax": ax,
                "ay": ay,
                "mode": cmd.mode,
                "tyre_accel": math.hypot(ax + drag, ay),
                "locked": y[LOCK[0]] + y[LOCK[1]],
                "hit": hit,
                "cmd": cmd,
            }
        )
        if hit:
            break
    return log, ctrl


def steer_detection_range(tables, mu, speed_mps):
    """A first-detection range just inside the buffered steering boundary (sector F or B), as
    when the phase point crosses Sb: the obstacle appears (cut-in, or radar pick-up late)."""
    b = tables.boundaries.at(mu, speed_mps)
    assert b.clear_buffered_m - b.clear_opt_m > 1.0
    return b.clear_buffered_m - 0.5


def lane_change_case(tables, plant, speed_mps, mu):
    detect = steer_detection_range(tables, mu, speed_mps)
    log, ctrl = simulate(
        tables, plant, speed_mps, mu, P.cg_to_front_bumper_m + detect + 0.3, detect, seconds=30.0
    )
    return log, ctrl


def check_lane_change(log, ctrl, mu, *, lane_tol_m, overshoot_m, ellipse, return_tol_m):
    assert not any(r["hit"] for r in log), "the ego touched the obstacle"
    assert ctrl.modes_visited == [0, 2, 5] and ctrl.mode == 0, ctrl.modes_visited
    steer = [r for r in log if r["mode"] == 2]
    # lane change: settled in the next lane when the manoeuvre timer ends, small overshoot
    assert abs(steer[-1]["y"] - LANE) <= lane_tol_m
    assert max(r["y"] for r in steer) <= LANE + overshoot_m
    # inside the friction ellipse (tyre forces: the measured acceleration less aero drag)
    assert max(r["tyre_accel"] for r in log) <= ellipse * mu * 9.81
    assert not any(r["locked"] for r in log), "a wheel locked"
    # handed back in the original lane, and it stays there
    back = next(i for i, r in enumerate(log) if r["mode"] == 0 and r["t"] > steer[-1]["t"])
    assert all(abs(r["y"]) <= return_tol_m for r in log[back:])
    assert abs(log[-1]["yaw"]) < 0.01


def test_lane_change_120kmh_dry(tables, plant):
    """120 km/h, mu 1.0: 3.5 +/- 0.3 m, overshoot < 0.5 m, |a| <= 1.05 mu g, back within 0.2 m."""
    log, ctrl = lane_change_case(tables, plant, 120 / 3.6, 1.0)
    check_lane_change(
        log, ctrl, 1.0, lane_tol_m=0.3, overshoot_m=0.5, ellipse=1.05, return_tol_m=0.2
    )


def test_lane_change_120kmh_snow(tables, plant):
    """120 km/h, mu 0.3: the same bounds (the slower, longer manoeuvre still fits the timer)."""
    log, ctrl = lane_change_case(tables, plant, 120 / 3.6, 0.3)
    check_lane_change(
        log, ctrl, 0.3, lane_tol_m=0.3, overshoot_m=0.5, ellipse=1.05, return_tol_m=0.2
    )


def test_braking_stops_behind_the_obstacle(tables, plant):
    """80 km/h on snow (mu 0.3), seen 2 m inside the DMM's buffered braking boundary Bb (at
    the braking the EOAM commands, 110 m): sector D brakes; steering sectors met later while
    braking still stops short (d > B0) do not start a lane change: a stop behind it. (Seen
    at 100 m, inside B0 = 104 m, limit braking stops 0.06 m short, without its buffer: the
    DMM then rightly steers.)"""
    speed, mu, rear = 80 / 3.6, 0.3, 150.0
    curve = friction_at(build_parts(P, tables, EoamSettings()), mu).curve
    detect = curve.at(speed).stop_buffered_m - 2.0
    assert curve.at(speed).clear_buffered_m < detect < 112.0
    log, ctrl = simulate(tables, plant, speed, mu, rear, detect, seconds=15.0)
    assert not any(r["hit"] for r in log), "the ego hit the obstacle"
    assert ctrl.modes_visited == [0, 1] and ctrl.fcw_raised
    sectors = {r["cmd"].sector for r in log}
    assert "D" in sectors and "A" not in sectors
    assert log[-1]["vx"] < 0.05
    gap = rear - (log[-1]["x"] + P.cg_to_front_bumper_m)
    assert 0.0 < gap < 15.0
    assert abs(log[-1]["y"]) < 0.05
    # no wheel locked while moving (a held brake at rest counts as locked in the plant)
    assert not any(r["locked"] for r in log if r["vx"] > 0.5)
    # limit braking: the share of the no-lock deceleration (plus drag), never beyond it
    a_lim = tables.max_decel_mps2(mu)
    share = tables.limit_brake_fraction
    braking = [r["ax"] for r in log if r["mode"] == 1 and r["vx"] > 3.0]
    assert min(braking) >= -(a_lim + 0.1)
    assert sorted(braking)[len(braking) // 2] == pytest.approx(-share * a_lim, abs=0.15)
