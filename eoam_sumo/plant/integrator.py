"""Fixed-step integration of the plant, for any arithmetic: the explicit midpoint rule (RK2)
for the smooth dynamics, then the wheels' Coulomb torques (brakes, rolling resistance) applied
exactly for the step (``resist``), a splitting that keeps the stiff stick-slip of a braked
wheel out of the explicit step."""

from __future__ import annotations

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.chassis import constants
from eoam_sumo.plant.model import (
    OMEGA_F,
    OMEGA_R,
    P_FRONT,
    P_REAR,
    outputs,
    rhs,
    tyre_loads_n,
)


def resist(x, params: VehicleParams, dt_s: float, ops) -> list:
    """The brake and rolling-resistance torques over ``dt_s`` as Coulomb friction on each
    axle's wheels: the spin falls by ``dt T / J`` and stops at zero (a wheel the brake can hold
    stays at rest: no reversal, no chatter); line pressures kept >= 0."""
    p = params
    ch = constants(p)
    fl, fr, rl, rr = tyre_loads_n(x, p, ops)
    r_w = p.wheel_radius_m
    step = dt_s * r_w / ch.axle_inertia_kgm2
    pf, pr = ops.fmax(x[P_FRONT], 0.0), ops.fmax(x[P_REAR], 0.0)
    brake_f = ch.brake_n_per_bar * p.brake_front_share * pf
    brake_r = ch.brake_n_per_bar * (1.0 - p.brake_front_share) * pr
    torque_f = brake_f + p.rolling_resistance_coeff * (fl + fr)
    torque_r = brake_r + p.rolling_resistance_coeff * (rl + rr)
    out = list(x)
    out[OMEGA_F] = ops.fmax(x[OMEGA_F] - step * torque_f, 0.0)
    out[OMEGA_R] = ops.fmax(x[OMEGA_R] - step * torque_r, 0.0)
    out[P_FRONT], out[P_REAR] = pf, pr
    return out


def sub_step(x, u, mu, params: VehicleParams, dt_s: float, ops) -> list:
    """One step of ``dt_s`` with inputs and friction held: the explicit midpoint rule, then
    ``resist``. The relaxed slips leave no mode fast against a 1 ms step (``MAX_DT_S``), so
    the second-order rule needs half the tyre evaluations of RK4."""
    k1 = rhs(x, u, mu, params, ops)
    k2 = rhs([xi + 0.5 * dt_s * ki for xi, ki in zip(x, k1)], u, mu, params, ops)
    x = [xi + dt_s * ki for xi, ki in zip(x, k2)]
    return resist(x, params, dt_s, ops)


def advance(x, u, mu, params: VehicleParams, dt_s: float, substeps: int, ops):
    """``substeps`` steps; returns ``(x_next, y)`` with ``y`` the outputs at ``x_next``."""
    for _ in range(substeps):
        x = sub_step(x, u, mu, params, dt_s, ops)
    return x, outputs(x, mu, params, ops)
