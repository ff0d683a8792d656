"""Axle tyre forces: Fiala brush model, friction ellipse, locked-wheel sliding (no ABS).

References: H. B. Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed. (2012), sec. 3.2 (brush
model: pure and combined slip); R. Y. Hindiyeh & J. C. Gerdes, "A controller framework for
autonomous drifting", ASME J. Dyn. Sys. Meas. Control 136 (2014), tyre model (Fiala lateral
force with the peak derated by the longitudinal force). The friction limit scales every
force with the surface mu, which is the physical form of the paper's eqs. 35-37.

All functions take an ``ops`` object (``ops.py``) so they run on floats and on CasADi.
"""

from __future__ import annotations

from typing import NamedTuple

SLIP_SPEED_FLOOR_MPS = 1.0
"""Floor of the wheel's longitudinal speed |v_long| in the slip-angle quotient: keeps the
tyre's low-speed lateral stiffness C / (m v) bounded for the fixed-step integrator."""

CREEP_SPEED_MPS = 0.1
"""Speed over which brake and rolling-resistance forces ramp in from zero (they oppose motion
and vanish at rest, so a braked vehicle stops and stays stopped), and the regularisation of
the sliding direction of a locked wheel."""

FORCE_EPS_N = 1e-3
"""Lateral force capacity left when the longitudinal force uses the whole friction ellipse
(keeps the Fiala quotient finite and the model differentiable)."""


class AxleForce(NamedTuple):
    """Force of one axle's tyres on the body, in the BODY frame, and its slip state."""

    fx_n: float
    fy_n: float
    locked: object
    tan_slip: float


def fiala_lateral_force_n(tan_slip, cornering_stiffness_npr, peak_force_n, ops):
    """Fiala brush lateral force [N] (Pacejka 2012 sec. 3.2.2; Hindiyeh & Gerdes 2014).

    With ``z = C tan(alpha) / (3 F_peak)`` the classic cubic
    ``-C tan a + C^2 |tan a| tan a / (3 F) - C^3 tan^3 a / (27 F^2)`` equals
    ``-F sgn(z) (1 - (1 - |z|)^3)`` for ``|z| <= 1`` and ``-F sgn(z)`` beyond (full sliding),
    so the slope at zero slip is ``-C`` and the force saturates at ``F_peak``.
    """
    u = ops.fmin(cornering_stiffness_npr * ops.fabs(tan_slip) / (3.0 * peak_force_n), 1.0)
    w = 1.0 - u
    return -ops.sign(tan_slip) * peak_force_n * (1.0 - w * w * w)


def axle_force(
    vx_mps,
    vy_mps,
    cos_steer,
    sin_steer,
    brake_force_n,
    drive_force_n,
    fz_n,
    mu,
    cornering_stiffness_npr,
    rolling_resistance_coeff,
    sliding_friction_ratio,
    ops,
) -> AxleForce:
    """Tyre force of one axle whose contact patch moves at (vx, vy) in the body frame.

    Rolling axle (Pacejka 2012 sec. 3.2.3, friction ellipse with longitudinal priority): the
    wheel-frame longitudinal force is the drive minus the brake and rolling resistance, clipped
    to ``mu Fz``; the lateral force is Fiala with its peak derated to
    ``sqrt((mu Fz)^2 - Fx^2)`` (Hindiyeh & Gerdes 2014). A drive force above ``mu Fz`` (wheel
    spin) is clipped to it and so leaves no lateral force. Brake and rolling resistance oppose
    the wheel's rolling direction, so a wheel rolling backwards (in a spin) is handled too.

    No ABS: the brush tyre at slip angle alpha reaches full sliding when the longitudinal
    force reaches ``mu Fz cos(alpha)``; a brake force (net of drive) above that LOCKS the
    wheel. A locked wheel slides at ``sliding_friction_ratio * mu * Fz`` opposite the
    contact-patch velocity, whatever the steering angle: it gives no cornering force from
    steering and a locked front axle does not steer the vehicle.
    """
    v_long = vx_mps * cos_steer + vy_mps * sin_steer
    v_lat = -vx_mps * sin_steer + vy_mps * cos_steer
    tan_slip = v_lat / ops.fmax(ops.fabs(v_long), SLIP_SPEED_FLOOR_MPS)
    cos_slip = 1.0 / ops.sqrt(1.0 + tan_slip * tan_slip)
    capacity_n = mu * fz_n
    creep = ops.fmin(ops.fmax(v_long / CREEP_SPEED_MPS, -1.0), 1.0)

    fx_demand_n = drive_force_n - (brake_force_n + rolling_resistance_coeff * fz_n) * creep
    fx_n = ops.fmin(ops.fmax(fx_demand_n, -capacity_n), capacity_n)
    peak_n = ops.sqrt(
        ops.fmax(capacity_n * capacity_n - fx_n * fx_n, 0.0) + FORCE_EPS_N * FORCE_EPS_N
    )
    fy_n = fiala_lateral_force_n(tan_slip, cornering_stiffness_npr, peak_n, ops)
    fx_roll_n = fx_n * cos_steer - fy_n * sin_steer
    fy_roll_n = fx_n * sin_steer + fy_n * cos_steer

    locked = brake_force_n - drive_force_n > capacity_n * cos_slip
    slide = (
        sliding_friction_ratio
        * capacity_n
        / ops.sqrt(vx_mps * vx_mps + vy_mps * vy_mps + CREEP_SPEED_MPS * CREEP_SPEED_MPS)
    )
    return AxleForce(
        fx_n=ops.if_else(locked, -slide * vx_mps, fx_roll_n),
        fy_n=ops.if_else(locked, -slide * vy_mps, fy_roll_n),
        locked=locked,
        tan_slip=tan_slip,
    )
