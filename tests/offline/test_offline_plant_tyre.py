"""The design model plans with the plant's tyre: its lateral dynamics are the plant's.

Independent truth: the plant's own tyre (``plant.tyres``) and right-hand side
(``plant.model.rhs``), which the optimiser never calls.
"""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.model import dynamics, fiala_lateral_force, split_force
from eoam_sumo.offline.ocp import LaneChangeOcp, quintic_guess
from eoam_sumo.offline.resim import resimulate
from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.plant import model as plant_model
from eoam_sumo.plant.ops import FloatOps
from eoam_sumo.plant.tyres import fiala_lateral_force_n

P = ego_e_class_sedan()
S = DesignSettings()


@given(z=st.floats(-1.0, 1.0), peak=st.floats(100.0, 12000.0))
def test_design_tyre_is_the_plant_fiala_tyre_below_its_peak(z, peak):
    c = P.cornering_stiffness_front_npr
    tan_alpha = 3.0 * peak * z / c
    ours = fiala_lateral_force(tan_alpha, c, peak, math)
    # the plant's sign convention: tan(slip) of the contact patch, force against it
    plant = fiala_lateral_force_n(-tan_alpha, c, peak, FloatOps())
    assert ours == pytest.approx(plant, rel=1e-9, abs=1e-6)


@pytest.mark.parametrize("speed_kmh, mu", [(55.0, 1.0), (150.0, 0.3)])
def test_plan_accelerations_are_the_plants_at_the_planned_state(speed_kmh, mu):
    """Along an optimal lane change, the plant at the planned state (body velocities, yaw
    rate, steering and longitudinal force) has the planned lateral and yaw accelerations:
    what the plan asks of the tyres is what the plant's tyres give."""
    v = speed_kmh / 3.6
    ocp = LaneChangeOcp(P, S)
    sol = ocp.solve(v, mu, quintic_guess(v, mu, P, S))
    assert sol.tyre_blend == 1.0
    resim = resimulate(sol, P, 0.5)
    ay_err, yaw_err, ay_scale = [], [], np.abs(resim.ay_body_mps2).max()
    for i in range(0, len(resim.t_s), 5):
        x, u = resim.states[i], resim.controls[i]
        xdot, out = dynamics(x, u, mu, P, math, 1.0)
        c, s = math.cos(x[4]), math.sin(x[4])
        brake, drive = split_force(u[1])
        state = [
            0.0,
            0.0,
            0.0,
            x[1] * c + x[3] * s,
            -x[1] * s + x[3] * c,
            x[5],
            x[6],
            float(drive),
            float(-brake),
        ]
        f = plant_model.rhs(state, [x[6], float(drive), float(-brake)], mu, P, FloatOps())
        ay_plant = f[4] + state[3] * x[5]  # eq. 5: vy' + vx r
        ay_err.append(abs(ay_plant - out.ay_body_mps2))
        yaw_err.append(abs(f[5] - xdot[5]))
    # the plant adds drag, rolling resistance and the lateral forces' share of the load
    # transfer, which the design model leaves out
    assert max(ay_err) < 0.05 * ay_scale
    assert max(yaw_err) < 0.1 * np.abs(np.gradient(resim.states[:, 5], resim.t_s)).max()


def test_plan_keeps_the_friction_reserve():
    v, mu = 100.0 / 3.6, 0.7
    sol = LaneChangeOcp(P, S).solve(v, mu, quintic_guess(v, mu, P, S))
    resim = resimulate(sol, P, 0.25)
    use = max(resim.ellipse_front.max(), resim.ellipse_rear.max())
    assert S.friction_use**2 - 0.05 < use <= S.friction_use**2 + S.verify_ellipse_tol


def test_settings_validate_the_friction_use():
    with pytest.raises(ValueError, match="friction_use"):
        DesignSettings(friction_use=1.2)
    with pytest.raises(ValueError, match="friction_use"):
        DesignSettings(friction_use=0.0)
