"""Fixed-step integration of the plant, for any arithmetic: the explicit midpoint rule (RK2)
for the smooth dynamics, then the four wheels' Coulomb torques (brakes, rolling resistance) applied
exactly for the step (``resist``), a splitting that keeps the stiff stick-slip of a braked
wheel out of the explicit step."""

from __future__ import annotations

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.chassis import constants
from eoam_sumo.plant.model import OMEGAS, PRESSURES, outputs, rhs, tyre_loads_n


def resist(x, params: VehicleParams, dt_s: float, ops) -> list:
    """The brake and rolling-resistance torques over ``dt_s`` as Coulomb friction on each
    wheel: the spin falls by ``dt T / J`` and stops at zero (a wheel the brake can hold stays
    at rest: no reversal, no chatter); pressures kept >= 0."""
    p = params
    ch = constants(p)
    loads = tyre_loads_n(x, p, ops)
    step = dt_s * p.wheel_radius_m / p.wheel_inertia_kgm2
    out = list(x)
    for p_i, omega_i, gain, fz in zip(PRESSURES, OMEGAS, ch.wheel_brake_n_per_bar, loads):
        pressure = ops.fmax(x[p_i], 0.0)
        torque = gain * pressure + p.rolling_resistance_coeff * fz
        out[omega_i] = ops.fmax(x[omega_i] - step * torque, 0.0)
        out[p_i] = pressure
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
