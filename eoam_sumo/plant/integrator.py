"""Fixed-step integration of the plant, for any arithmetic: the explicit midpoint rule (RK2)
for the smooth dynamics, then the four wheels' Coulomb torques (brakes, rolling resistance) applied
exactly for the step (``resist``), a splitting that keeps the stiff stick-slip of a braked
wheel out of the explicit step."""

from __future__ import annotations

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.chassis import constants
from eoam_sumo.plant.model import (
    OMEGAS,
    PRESSURES,
    VX,
    YAW_RATE,
    outputs,
    rhs,
    tyre_loads_n,
)


def resist(x, params: VehicleParams, dt_s: float, ops) -> list:
    """The brake and rolling-resistance torques over ``dt_s`` as Coulomb friction on each
    wheel: the spin's magnitude falls by ``dt T / J`` and stops at zero (a wheel the brake can
    hold stays at rest: no reversal, no chatter); a wheel turning backwards (a car sliding or
    rolling backwards, or spun round) is slowed the same way. No drive turns a wheel
    backwards, so it turns backwards no faster than the ground under it (its side's speed
    along the body, ``vx -/+ r t / 2``): the tyre's spring cannot wind it back past it.
    Pressures kept >= 0."""
    p = params
    ch = constants(p)
    loads = tyre_loads_n(x, p, ops)
    step = dt_s * p.wheel_radius_m / p.wheel_inertia_kgm2
    out = list(x)
    half = 0.5 * p.track_m * x[YAW_RATE]
    grounds = (x[VX] - half, x[VX] + half, x[VX] - half, x[VX] + half)
    wheels = zip(PRESSURES, OMEGAS, ch.wheel_brake_n_per_bar, loads, grounds)
    for p_i, omega_i, gain, fz, ground_mps in wheels:
        pressure = ops.fmax(x[p_i], 0.0)
        torque = gain * pressure + p.rolling_resistance_coeff * fz
        spin = x[omega_i]
        coulomb = ops.fmax(spin - step * torque, ops.fmin(spin + step * torque, 0.0))
        out[omega_i] = ops.fmax(coulomb, ops.fmin(ground_mps / p.wheel_radius_m, 0.0))
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
