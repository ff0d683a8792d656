"""Nonlinear single-track plant of the ego, written ONCE for any arithmetic (``ops.py``).

Body-frame equations of the paper (Lowe & Guvenc 2022, eqs. 1-5), extended with the forces
its offline model leaves out::

    m (vx' - vy r) = Fx_f + Fx_r - F_drag          (eqs. 1, 4)
    m (vy' + vx r) = Fy_f + Fy_r                   (eqs. 2, 5)
    Iz r'          = a Fy_f - b Fy_r               (eq. 3)

``Fx_*``, ``Fy_*`` are the axle tyre forces in the body frame (front ones rotated by the
road-wheel angle, ``tyres.py``): Fiala brush tyres with a friction ellipse, friction limit
``mu Fz`` (the physical form of eqs. 35-37), wheel lock without ABS. Normal loads carry the
quasi-static longitudinal load transfer ``Fz_f = (m g b - h (Fx_f + Fx_r)) / L`` (drag taken
to act at CG height, so the pitch moment is the tyre forces'), solved by fixed-point
iteration. Drag ``0.5 rho CdA vx |vx|``; drive on the rear axle only, limited by the maximum
force and by power / speed; brake split front/rear by ``brake_front_share``; first-order lags
for the steering (rate limited), drive and brake actuators.

Low speed: brake and rolling-resistance forces ramp in over ``CREEP_SPEED_MPS`` and slip
quotients use ``max(|v_long|, SLIP_SPEED_FLOOR_MPS)``, so there is no singularity at rest and
a braked vehicle comes to rest and stays there without reversing. ``vx`` is NOT clamped: it
turns negative only when the body yaws more than 90 deg from its path (a spin), which the
tyres handle as a wheel rolling backwards; clamping it would delete momentum mid-spin.

``x``, ``u`` are sequences of scalars (floats, or CasADi SX/MX elements) in the order of
``STATE_NAMES`` and ``INPUT_NAMES``; ``mu`` is the peak surface friction under the vehicle.
"""

from __future__ import annotations

from typing import Any, NamedTuple

from eoam_sumo.params import AIR_DENSITY_KGPM3, G_MPS2, VehicleParams
from eoam_sumo.plant.tyres import CREEP_SPEED_MPS, SLIP_SPEED_FLOOR_MPS, AxleForce, axle_force

STATE_NAMES = (
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "steer_rad",
    "drive_force_n",
    "brake_force_n",
)
INPUT_NAMES = ("steer_cmd_rad", "drive_force_cmd_n", "brake_force_cmd_n")
OUTPUT_NAMES = (
    "ax_mps2",
    "ay_mps2",
    "front_locked",
    "rear_locked",
    "fx_front_n",
    "fy_front_n",
    "fx_rear_n",
    "fy_rear_n",
    "fz_front_n",
    "fz_rear_n",
    "slip_angle_front_rad",
    "slip_angle_rear_rad",
    "drive_force_delivered_n",
    "drag_force_n",
)
"""Body-frame accelerations (eqs. 4-5), lock flags (1.0 locked), body-frame axle tyre forces,
normal loads, slip angles, the drive force after the power limit, and the aerodynamic drag."""

X, Y, YAW, VX, VY, YAW_RATE, STEER, DRIVE, BRAKE = range(len(STATE_NAMES))
STEER_CMD, DRIVE_CMD, BRAKE_CMD = range(len(INPUT_NAMES))

LOAD_TRANSFER_ITERATIONS = 2
"""Fixed-point updates of the tyre-force sum that sets the load transfer. The loop gain is at
most about ``sliding_friction_ratio * mu * h / L`` (~0.16 on dry road; zero while both axles
roll in a straight line, where the brake forces do not depend on the loads), so two updates
leave a residual below 1 % of the load transfer."""


class _Forces(NamedTuple):
    front: AxleForce
    rear: AxleForce
    fz_front_n: Any  # a float or a CasADi expression, as the arithmetic in use gives
    fz_rear_n: Any
    drive_n: Any
    drag_n: Any


def _forces(x, mu, p: VehicleParams, ops) -> _Forces:
    vx, vy, r, steer = x[VX], x[VY], x[YAW_RATE], x[STEER]
    a, b, h = p.cg_to_front_m, p.cg_to_rear_m, p.cg_height_m
    wheelbase = a + b
    weight_n = p.mass_kg * G_MPS2
    cos_steer, sin_steer = ops.cos(steer), ops.sin(steer)
    drive_n = ops.fmin(x[DRIVE], p.max_drive_power_w / ops.fmax(vx, SLIP_SPEED_FLOOR_MPS))
    brake_front_n = p.brake_front_share * x[BRAKE]
    brake_rear_n = (1.0 - p.brake_front_share) * x[BRAKE]
    drag_n = 0.5 * AIR_DENSITY_KGPM3 * p.drag_area_m2 * vx * ops.fabs(vx)

    def axles(fx_tyres_n):
        fz_front = ops.fmax((weight_n * b - h * fx_tyres_n) / wheelbase, 0.0)
        fz_rear = ops.fmax((weight_n * a + h * fx_tyres_n) / wheelbase, 0.0)
        front = axle_force(
            vx, vy + a * r, cos_steer, sin_steer, brake_front_n, 0.0, fz_front, mu,
            p.cornering_stiffness_front_npr, p.rolling_resistance_coeff,
            p.sliding_friction_ratio, ops,
        )  # fmt: skip
        rear = axle_force(
            vx, vy - b * r, 1.0, 0.0, brake_rear_n, drive_n, fz_rear, mu,
            p.cornering_stiffness_rear_npr, p.rolling_resistance_coeff,
            p.sliding_friction_ratio, ops,
        )  # fmt: skip
        return front, rear, fz_front, fz_rear

    creep = ops.fmin(ops.fmax(vx / CREEP_SPEED_MPS, -1.0), 1.0)
    limit_n = mu * weight_n
    fx_tyres_n = ops.fmin(ops.fmax(drive_n - x[BRAKE] * creep, -limit_n), limit_n)
    for _ in range(LOAD_TRANSFER_ITERATIONS):
        front, rear, _, _ = axles(fx_tyres_n)
        fx_tyres_n = front.fx_n + rear.fx_n
    front, rear, fz_front, fz_rear = axles(fx_tyres_n)
    return _Forces(front, rear, fz_front, fz_rear, drive_n, drag_n)


def _body_accelerations(f: _Forces, p: VehicleParams):
    ax = (f.front.fx_n + f.rear.fx_n - f.drag_n) / p.mass_kg
    ay = (f.front.fy_n + f.rear.fy_n) / p.mass_kg
    return ax, ay


def rhs(x, u, mu, params: VehicleParams, ops) -> list:
    """State derivative dx/dt (list in ``STATE_NAMES`` order), for floats or CasADi.

    This is the function the offline optimiser may use with ``ops = CASADI_OPS`` (SX or MX
    arguments). Actuator commands are clipped to their ranges here; the lags must be > 0.
    """
    p = params
    f = _forces(x, mu, p, ops)
    vx, vy, yaw, r = x[VX], x[VY], x[YAW], x[YAW_RATE]
    ax, ay = _body_accelerations(f, p)
    cos_yaw, sin_yaw = ops.cos(yaw), ops.sin(yaw)
    steer_target = ops.fmin(ops.fmax(u[STEER_CMD], -p.max_steer_rad), p.max_steer_rad)
    steer_rate = ops.fmin(
        ops.fmax((steer_target - x[STEER]) / p.steer_lag_s, -p.max_steer_rate_radps),
        p.max_steer_rate_radps,
    )
    drive_target = ops.fmin(ops.fmax(u[DRIVE_CMD], 0.0), p.max_drive_force_n)
    brake_target = ops.fmin(ops.fmax(u[BRAKE_CMD], 0.0), p.max_brake_force_n)
    return [
        vx * cos_yaw - vy * sin_yaw,
        vx * sin_yaw + vy * cos_yaw,
        r,
        ax + vy * r,  # eq. 4
        ay - vx * r,  # eq. 5
        (p.cg_to_front_m * f.front.fy_n - p.cg_to_rear_m * f.rear.fy_n) / p.yaw_inertia_kgm2,
        steer_rate,
        (drive_target - x[DRIVE]) / p.drive_lag_s,
        (brake_target - x[BRAKE]) / p.brake_lag_s,
    ]


def outputs(x, mu, params: VehicleParams, ops) -> list:
    """Outputs in ``OUTPUT_NAMES`` order at state ``x`` (they depend on the actuator STATES,
    not on the commands, so no input is needed)."""
    f = _forces(x, mu, params, ops)
    ax, ay = _body_accelerations(f, params)
    return [
        ax,
        ay,
        ops.if_else(f.front.locked, 1.0, 0.0),
        ops.if_else(f.rear.locked, 1.0, 0.0),
        f.front.fx_n,
        f.front.fy_n,
        f.rear.fx_n,
        f.rear.fy_n,
        f.fz_front_n,
        f.fz_rear_n,
        ops.atan(f.front.tan_slip),
        ops.atan(f.rear.tan_slip),
        f.drive_n,
        f.drag_n,
    ]
