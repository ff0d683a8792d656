"""An escape laid out in time keeps the duration predicted for it while the ego brakes.

Closed loop with the plant alone (no SUMO), straight road along x: the ego is in the next
lane's centre at 88 km/h on snow (mu 0.3), its lateral motion arrested, when mode 3 (abort)
shifts it back to its own lane within ``arrest_return_g`` (as after an arrest in Table 2's
onc-400_v120_mu0.3) and brakes with what the friction ellipse leaves. The commit/abort
prediction (``decision.oncoming``) times that shift as a ``MinTimeShift`` at the speed it
began with. Laid out in distance, the return took 0.2 s longer than predicted (back within
0.1 m of the lane centre at 2.76 s, predicted 2.56 s; the path's end at 3.31 s instead of
2.97 s) as the ego slowed from 24.4 to 19.4 m/s.
"""

import pytest

from eoam_sumo.decision.modes import ONCOMING_BRAKE
from eoam_sumo.eoam import EgoMeasurement, EoamController, EoamSettings, Perception
from eoam_sumo.eoam.transitions import enter, start_path
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import G_MPS2, ego_e_class_sedan
from eoam_sumo.plant import Plant, initial_state

P = ego_e_class_sedan()
ST = EoamSettings()
DT = 0.01
LANE = 3.5
MU = 0.3
SPEED = 24.4  # [m/s]


@pytest.fixture(scope="module")
def run():
    """Per step after the return began: (time since, offset, speed, the reference's offset
    at the step's measurement, ``DT`` earlier)."""
    tables = LookupTables.load(default_tables_dir(), params=P)
    plant = Plant(P, 1e-3, 10)
    ctrl = EoamController(P, tables)
    ctrl.reset(SPEED)
    x = initial_state(0.0, LANE, 0.0, SPEED)
    ax = ay = 0.0
    log = []
    for k in range(round(3.5 / DT)):
        t = k * DT
        X, Y, yaw, vx, vy, r = (float(x[i]) for i in range(6))
        meas = EgoMeasurement(t, vx, vy, r, ax, ay, X, Y, yaw, 0.0, MU, LANE)
        if k == 1:  # the perceive stage has set the friction: abort, the motion arrested
            enter(ctrl.parts, ctrl.state, ONCOMING_BRAKE, meas)
            back = ctrl.parts.escapes.shift(0.0, meas, ST.arrest_return_g)
            start_path(ctrl.parts, ctrl.state, meas, back, None)
        cmd = ctrl.step(meas, Perception(), DT)
        x, y = plant.step(x, (cmd.steer_cmd_rad, cmd.drive_force_cmd_n, cmd.brake_force_cmd_n), MU)
        ax, ay = float(y[0]), float(y[1])
        if k >= 1:
            log.append((t, float(x[1]), float(x[3]), cmd.y_target_m))
    return log


def predicted_shift():
    """The commit/abort prediction's shift back from rest in the next lane's centre."""
    budget = ST.arrest_return_g * MU * G_MPS2
    return MinTimeShift(LANE, 0.0, 0.0, 0.0, SPEED, budget, ST.escape_ramp_s)


def test_the_ego_brakes_during_the_return(run):
    assert run[-1][2] < SPEED - 4.0


@pytest.mark.parametrize("line_m", [1.67, 0.5, 0.1])
def test_back_within_a_line_when_predicted(run, line_m):
    """1.67 m: out of an oncoming car's path (``decision.oncoming``); 0.1 m: back in lane."""
    predicted = predicted_shift().time_within_s(line_m)
    executed = next(t for t, y, _, _ in run if y < line_m)
    assert executed == pytest.approx(predicted, abs=0.07)


def test_the_reference_ends_when_the_shift_does(run):
    ended = next(t - DT for t, _, _, y_ref in run if abs(y_ref) < 1e-6)
    assert ended == pytest.approx(predicted_shift().duration_s, abs=0.02)
