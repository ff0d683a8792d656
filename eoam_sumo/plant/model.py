"""Nonlinear single-track plant of the ego, written ONCE for any arithmetic (``ops.py``).

Body-frame equations of the paper (Lowe & Guvenc 2022, eqs. 1-5), extended with the chassis
its offline model leaves out (docs/chassis.md has the equations and sources)::

    m (vx' - vy r) = Fx_f + Fx_r - F_drag          (eqs. 1, 4)
    m (vy' + vx r) = Fy_f + Fy_r                   (eqs. 2, 5)
    Iz r'          = a Fy_f - b Fy_r + M_lr        (eq. 3)
    J omega_i'     = T_drive_i - r_w Fx_i          (brake and rolling resistance: integrator)

Each axle's force is the sum of its two tyres' combined-slip Magic Formula forces
(``magic_formula.py``), each at its own load: quasi-static longitudinal and lateral load
transfer (roll stiffness shared by ``roll_stiffness_front_share``) from the accelerations
lagged by ``LOAD_TRANSFER_LAG_S``. ``M_lr`` is the moment of the left/right longitudinal
force difference (load transfer, ESC). Both tyres of an axle share its slips (single-track
kinematics): the longitudinal slip and the slip angle are relaxed states (relaxation lengths,
Pacejka 2012 sec. 7.2), with a low-speed damping so the car rests without ringing.

Brakes: line pressure per axle (build and dump rate limits, ABS per axle), a fixed
proportioning ``brake_front_share`` (front axle locks first, UN R13-H Annex 5); ESC brakes one
wheel; the drive force is wheel torque on the driven axle(s) (``drivetrain``).

``x``, ``u`` are sequences of scalars (floats, or CasADi SX/MX elements) in the order of
``STATE_NAMES`` and ``INPUT_NAMES``; ``mu`` is the peak surface friction under the vehicle.
"""

from __future__ import annotations

from typing import Any, NamedTuple

from eoam_sumo.params import AIR_DENSITY_KGPM3, G_MPS2, VehicleParams
from eoam_sumo.plant import chassis as ch_
from eoam_sumo.plant.chassis import Chassis, constants
from eoam_sumo.plant.magic_formula import axle_forces

STATE_NAMES = (
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "steer_rad",
    "drive_force_n",
    "brake_pressure_front_bar",
    "brake_pressure_rear_bar",
    "wheel_spin_front_radps",
    "wheel_spin_rear_radps",
    "slip_front",
    "slip_rear",
    "tan_slip_angle_front",
    "tan_slip_angle_rear",
    "ax_load_mps2",
    "ay_load_mps2",
    "esc_moment_nm",
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
    "wheel_speed_front_mps",
    "wheel_speed_rear_mps",
    "slip_front",
    "slip_rear",
    "brake_pressure_front_bar",
    "brake_pressure_rear_bar",
    "esc_moment_nm",
)
"""Body-frame accelerations (eqs. 4-5), lock flags (1.0: braking slip beyond ``LOCK_SLIP``),
body-frame axle tyre forces, axle loads, relaxed slip angles, the drive force after the power
limit and ESC, the aerodynamic drag, wheel speeds (omega r_w), longitudinal slips, line
pressures and the ESC's yaw moment."""

(X, Y, YAW, VX, VY, YAW_RATE, STEER, DRIVE, P_FRONT, P_REAR) = range(10)
(OMEGA_F, OMEGA_R, SLIP_F, SLIP_R, TAN_F, TAN_R, AX_LOAD, AY_LOAD, ESC) = range(10, 19)
BRAKE = P_FRONT  # the first brake state (kept for callers of the former single state)
STEER_CMD, DRIVE_CMD, BRAKE_CMD = range(len(INPUT_NAMES))

LOCK_SLIP = -0.5
"""An axle counts as locked while its braking slip is beyond this."""


class Axle(NamedTuple):
    """One axle: its force on the body (BODY frame), its tyres' longitudinal force (wheel
    frame, for the wheel spin), the moment of the left/right force difference, its load."""

    fx_n: Any
    fy_n: Any
    fx_wheel_n: Any
    moment_nm: Any
    fz_n: Any


class _Forces(NamedTuple):
    front: Axle
    rear: Axle
    drive_n: Any
    drag_n: Any
    esc_nm: Any


def tyre_loads_n(x, p: VehicleParams, ops):
    """``(FL, FR, RL, RR)`` normal loads [N]: static, plus the longitudinal transfer
    ``m ax h / L`` and the lateral ``m ay h / track`` shared by the roll stiffness."""
    m, h, wb = p.mass_kg, p.cg_height_m, p.wheelbase_m
    ax, ay = x[AX_LOAD], x[AY_LOAD]
    half_f = 0.5 * m * (G_MPS2 * p.cg_to_rear_m - h * ax) / wb
    half_r = 0.5 * m * (G_MPS2 * p.cg_to_front_m + h * ax) / wb
    lateral = m * ay * h / p.track_m
    d_f = lateral * p.roll_stiffness_front_share
    d_r = lateral - d_f
    return (
        ops.fmax(half_f - d_f, 0.0),  # a left turn (ay > 0) loads the right tyres
        ops.fmax(half_f + d_f, 0.0),
        ops.fmax(half_r - d_r, 0.0),
        ops.fmax(half_r + d_r, 0.0),
    )


def _esc_brake(force, fz, esc_n, mu, ops):
    """A tyre's wheel-frame ``(Fx, Fy)`` with ESC's braking force on it, capped by
    ``ESC_WHEEL_SHARE`` of its friction, its lateral force derated by the ellipse."""
    if esc_n is None:
        return force
    capacity = mu * ops.fmax(fz, 1.0)
    esc = ops.fmin(esc_n, ch_.ESC_WHEEL_SHARE * capacity)
    ratio = esc / capacity
    return force[0] - esc, force[1] * ops.sqrt(1.0 - ratio * ratio)


def _axle(x, slip_i, tan_i, loads, esc, steer_cs, mu, lky, p, ch: Chassis, ops) -> Axle:
    """The axle's two tyres (own loads, shared slips) summed; front ones rotated by the
    road-wheel angle ``steer_cs = (cos, sin)``."""
    alpha = x[tan_i]  # MF's slip-angle measure is tan(alpha) (Pacejka 2012 eq. 4.E3)
    left, right = axle_forces(x[slip_i], alpha, loads, mu, lky, ch.tyre, ops)
    fx0_l, fx0_r = left[0], right[0]
    fx_l, fy_l = _esc_brake(left, loads[0], esc[0], mu, ops)
    fx_r, fy_r = _esc_brake(right, loads[1], esc[1], mu, ops)
    fx, fy = fx_l + fx_r, fy_l + fy_r
    c, s = steer_cs
    return Axle(
        fx_n=fx * c - fy * s,
        fy_n=fx * s + fy * c,
        fx_wheel_n=fx0_l + fx0_r,
        moment_nm=0.5 * p.track_m * (fx_r - fx_l) * c,
        fz_n=loads[0] + loads[1],
    )


def _forces(x, mu, p: VehicleParams, ops) -> _Forces:
    ch = constants(p)
    vx, r = x[VX], x[YAW_RATE]
    loads = tyre_loads_n(x, p, ops)
    steer_cs = (ops.cos(x[STEER]), ops.sin(x[STEER]))
    none = (None, None, None, None)
    esc_nm = x[ESC] if p.esc_fitted else 0.0
    esc = ch_.esc_side_forces(esc_nm, r, p, ops) if p.esc_fitted else none
    front = _axle(x, SLIP_F, TAN_F, loads[:2], esc[:2], steer_cs, mu, ch.lky_front, p, ch, ops)
    rear = _axle(x, SLIP_R, TAN_R, loads[2:], esc[2:], (1.0, 0.0), mu, ch.lky_rear, p, ch, ops)
    drive_n = ops.fmin(x[DRIVE], p.max_drive_power_w / ops.fmax(vx, 1.0))
    if p.esc_fitted:
        drive_n = drive_n * ops.fmax(1.0 - ops.fabs(esc_nm) / ch_.ESC_TORQUE_CUT_NM, 0.0)
    drag_n = 0.5 * AIR_DENSITY_KGPM3 * p.drag_area_m2 * vx * ops.fabs(vx)
    return _Forces(front, rear, drive_n, drag_n, esc_nm)


def _body_accelerations(f: _Forces, p: VehicleParams):
    ax = (f.front.fx_n + f.rear.fx_n - f.drag_n) / p.mass_kg
    ay = (f.front.fy_n + f.rear.fy_n) / p.mass_kg
    return ax, ay


def wheel_velocities(x, p: VehicleParams, ops):
    """``((v_long, v_lat) front, (v_long, v_lat) rear)``: the contact patches' velocities in
    their wheel frames (single-track kinematics)."""
    vx, vy_f = x[VX], x[VY] + p.cg_to_front_m * x[YAW_RATE]
    c, s = ops.cos(x[STEER]), ops.sin(x[STEER])
    return (vx * c + vy_f * s, -vx * s + vy_f * c), (vx, x[VY] - p.cg_to_rear_m * x[YAW_RATE])


def _slip_rates(x, p: VehicleParams, ch: Chassis, ops) -> list:
    """Relaxation of the slips (Pacejka 2012 sec. 7.2.1): ``sigma kappa' = omega r_w - v_long
    - v_eff kappa`` and ``sigma tan(alpha)' = v_lat - v_eff tan(alpha)``, ``v_eff = |v_long|``
    plus the low-speed damping speed faded in below ``LOW_SPEED_MPS``."""
    rates = []
    wheels = wheel_velocities(x, p, ops)
    for (v_long, v_lat), omega_i, slip_i, tan_i in zip(
        wheels, (OMEGA_F, OMEGA_R), (SLIP_F, SLIP_R), (TAN_F, TAN_R)
    ):
        v_abs = ops.fabs(v_long)
        fade = ch_.low_speed_fade(v_abs, ops)
        v_long_eff = v_abs + ch.damping_speed_long_mps * fade
        v_lat_eff = v_abs + ch.damping_speed_lat_mps * fade
        rates.append(
            (x[omega_i] * p.wheel_radius_m - v_long - v_long_eff * x[slip_i])
            / p.relaxation_length_long_m
        )
        rates.append((v_lat - v_lat_eff * x[tan_i]) / p.relaxation_length_lat_m)
    return rates  # slip front, tan front, slip rear, tan rear


def _actuator_rates(x, u, mu, p: VehicleParams, ch: Chassis, ops) -> list:
    """Rates of steer (rate limited lag), drive force (lag) and the two line pressures."""
    steer_target = ops.fmin(ops.fmax(u[STEER_CMD], -p.max_steer_rad), p.max_steer_rad)
    steer_rate = ops.fmin(
        ops.fmax((steer_target - x[STEER]) / p.steer_lag_s, -p.max_steer_rate_radps),
        p.max_steer_rate_radps,
    )
    drive_target = ops.fmin(ops.fmax(u[DRIVE_CMD], 0.0), p.max_drive_force_n)
    brake_target = ops.fmin(ops.fmax(u[BRAKE_CMD], 0.0), p.max_brake_force_n)
    p_cmd = brake_target / ch.brake_n_per_bar
    r_w = p.wheel_radius_m
    wheels = wheel_velocities(x, p, ops)
    return [
        steer_rate,
        (drive_target - x[DRIVE]) / p.drive_lag_s,
        ch_.pressure_rate(p_cmd, x[P_FRONT], x[OMEGA_F] * r_w, wheels[0][0], mu, p, ch, ops),
        ch_.pressure_rate(p_cmd, x[P_REAR], x[OMEGA_R] * r_w, wheels[1][0], mu, p, ch, ops),
    ]


def _wheel_rates(x, f: _Forces, p: VehicleParams, ch: Chassis, ops) -> list:
    """Wheel spin rates without the brake and rolling-resistance torques (the integrator
    applies those as Coulomb friction, ``integrator.resist``)."""
    share = ch_.front_drive_share(x[SLIP_F], x[SLIP_R], p, ch, ops)
    torque_n = f.drive_n * p.wheel_radius_m
    j = ch.axle_inertia_kgm2
    return [
        (share * torque_n - p.wheel_radius_m * f.front.fx_wheel_n) / j,
        ((1.0 - share) * torque_n - p.wheel_radius_m * f.rear.fx_wheel_n) / j,
    ]


def rhs(x, u, mu, params: VehicleParams, ops) -> list:
    """State derivative dx/dt (list in ``STATE_NAMES`` order), for floats or CasADi, without
    the brake and rolling-resistance torques on the wheels (``integrator.resist``).
    Actuator commands are clipped to their ranges here; the lags must be > 0."""
    p = params
    ch = constants(p)
    f = _forces(x, mu, p, ops)
    vx, vy, yaw, r = x[VX], x[VY], x[YAW], x[YAW_RATE]
    ax, ay = _body_accelerations(f, p)
    cos_yaw, sin_yaw = ops.cos(yaw), ops.sin(yaw)
    moment = p.cg_to_front_m * f.front.fy_n - p.cg_to_rear_m * f.rear.fy_n
    moment = moment + f.front.moment_nm + f.rear.moment_nm
    slips = _slip_rates(x, p, ch, ops)
    esc_rate = 0.0
    if p.esc_fitted:
        target = ch_.esc_target_moment_nm(vx, vy, r, x[STEER], mu, p, ch, ops)
        esc_rate = (target - x[ESC]) / p.esc_lag_s
    lag = ch_.LOAD_TRANSFER_LAG_S
    fx_tyres = (f.front.fx_n + f.rear.fx_n) / p.mass_kg
    return [
        vx * cos_yaw - vy * sin_yaw,
        vx * sin_yaw + vy * cos_yaw,
        r,
        ax + vy * r,  # eq. 4
        ay - vx * r,  # eq. 5
        moment / p.yaw_inertia_kgm2,
        *_actuator_rates(x, u, mu, p, ch, ops),
        *_wheel_rates(x, f, p, ch, ops),
        slips[0],
        slips[2],
        slips[1],
        slips[3],
        (fx_tyres - x[AX_LOAD]) / lag,
        (ay - x[AY_LOAD]) / lag,
        esc_rate,
    ]


def outputs(x, mu, params: VehicleParams, ops) -> list:
    """Outputs in ``OUTPUT_NAMES`` order at state ``x`` (they depend on the actuator STATES,
    not on the commands, so no input is needed)."""
    f = _forces(x, mu, params, ops)
    ax, ay = _body_accelerations(f, params)
    r_w = params.wheel_radius_m
    return [
        ax,
        ay,
        ops.if_else(x[SLIP_F] < LOCK_SLIP, 1.0, 0.0),
        ops.if_else(x[SLIP_R] < LOCK_SLIP, 1.0, 0.0),
        f.front.fx_n,
        f.front.fy_n,
        f.rear.fx_n,
        f.rear.fy_n,
        f.front.fz_n,
        f.rear.fz_n,
        ops.atan(x[TAN_F]),
        ops.atan(x[TAN_R]),
        f.drive_n,
        f.drag_n,
        x[OMEGA_F] * r_w,
        x[OMEGA_R] * r_w,
        x[SLIP_F],
        x[SLIP_R],
        x[P_FRONT],
        x[P_REAR],
        f.esc_nm,
    ]
