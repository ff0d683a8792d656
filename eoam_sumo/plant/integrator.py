"""Fixed-step classical Runge-Kutta (RK4) integration of the plant, for any arithmetic."""

from __future__ import annotations

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant.model import outputs, rhs


def rk4_step(x, u, mu, params: VehicleParams, dt_s: float, ops) -> list:
    """One RK4 step of ``dt_s`` with inputs and friction held."""
    k1 = rhs(x, u, mu, params, ops)
    k2 = rhs([xi + 0.5 * dt_s * ki for xi, ki in zip(x, k1)], u, mu, params, ops)
    k3 = rhs([xi + 0.5 * dt_s * ki for xi, ki in zip(x, k2)], u, mu, params, ops)
    k4 = rhs([xi + dt_s * ki for xi, ki in zip(x, k3)], u, mu, params, ops)
    sixth = dt_s / 6.0
    return [xi + sixth * (a + 2.0 * b + 2.0 * c + d) for xi, a, b, c, d in zip(x, k1, k2, k3, k4)]


def advance(x, u, mu, params: VehicleParams, dt_s: float, substeps: int, ops):
    """``substeps`` RK4 steps; returns ``(x_next, y)`` with ``y`` the outputs at ``x_next``."""
    for _ in range(substeps):
        x = rk4_step(x, u, mu, params, dt_s, ops)
    return x, outputs(x, mu, params, ops)
