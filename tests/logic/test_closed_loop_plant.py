"""Closed loop with the plant alone (no SUMO): straight road along x, a stationary obstacle.

The road frame is the network frame (s = x, d = y, e_yaw = yaw). The obstacle (the paper's
D-class minivan) stands on the ego lane centre; a simple in-path radar reports the range from
the ego's front bumper to its rear while the two overlap laterally and it is within the
detection range. Contact is checked on oriented boxes (separating axes) at every step.
"""

import math

import pytest

from eoam_sumo.eoam import EgoMeasurement, EoamController, Perception
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import AIR_DENSITY_KGPM3, G_MPS2, aro_d_class_minivan, ego_e_class_sedan
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
    return [(x + c * u - s * w, y + s * u + c * w)
            for u, w in ((length / 2, width / 2), (length / 2, -width / 2),
                         (-length / 2, -width / 2), (-length / 2, width / 2))]


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
    for k in range(int(round(seconds / DT))):
        t = k * DT
        X, Y, yaw, vx, vy, r = (float(x[i]) for i in range(6))
        rng = obstacle_rear_m - (X + P.cg_to_front_bumper_m * math.cos(yaw))
        seen = abs(Y) < half_widths and 0.0 < rng <= detect_m
        perception = Perception(rng if seen else None, -vx if seen else None, False)
        meas = EgoMeasurement(t, vx, vy, r, ax, ay, X, Y, yaw, 0.0, mu, LANE)
        cmd = ctrl.step(meas, perception, DT)
        x, y = plant.step(x, (cmd.steer_cmd_rad, cmd.drive_force_cmd_n, cmd.brake_force_cmd_n),
                          mu)
        ax, ay = float(y[0]), float(y[1])
        X, Y, yaw, vx = float(x[0]), float(x[1]), float(x[2]), float(x[3])
        drag = 0.5 * AIR_DENSITY_KGPM3 * P.drag_area_m2 * vx * abs(vx) / P.mass_kg
        off = P.cg_to_front_bumper_m - P.length_m / 2  # CG to the footprint centre
        ego = corners(X + off * math.cos(yaw), Y + off * math.sin(yaw), yaw, P.length_m,
                      P.width_m)
        hit = overlap(ego, obstacle)
        log.append(dict(t=t + DT, x=X, y=Y, yaw=yaw, vx=vx, ax=ax, ay=ay, mode=cmd.mode,
                        tyre_accel=math.hypot(ax + drag, ay), locked=y[LOCK[0]] + y[LOCK[1]],
                        hit=hit, cmd=cmd))
        if hit:
            break
    return log, ctrl
