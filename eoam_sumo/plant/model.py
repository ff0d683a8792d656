"""Nonlinear single-track plant of the ego, written ONCE for any arithmetic (``ops.py``).

Body-frame equations of the paper (Lowe & Guvenc 2022, eqs. 1-5), extended with the chassis
its offline model leaves out (docs/chassis.md has the equations and sources)::

    m (vx' - vy r) = Fx_f + Fx_r - F_drag          (eqs. 1, 4)
    m (vy' + vx r) = Fy_f + Fy_r                   (eqs. 2, 5)
    Iz r'          = a Fy_f - b Fy_r + M_lr        (eq. 3)
    J omega_i'     = T_drive_i - r_w Fx_i          (brake and rolling resistance: integrator)

Each axle's force is the sum of its two tyres' combined-slip Magic Formula forces
(``magic_formula.py``), each at its own load and its own longitudinal slip (wheel spin per
wheel, contact-patch speeds -/+ r track / 2), the axle sharing the slip angle: quasi-static
longitudinal and lateral load transfer (roll stiffness shared by ``roll_stiffness_front_share``)
from the accelerations lagged by ``LOAD_TRANSFER_LAG_S``. ``M_lr`` is the moment of the
left/right longitudinal force difference (load transfer, brakes, ESC). The slips are relaxed
states (relaxation lengths, Pacejka 2012 sec. 7.2), with a low-speed damping so the car rests
without ringing. Steering compliance turns the road wheels back by ``Fy_f / k_s``.

Brakes: a pressure per wheel (build and dump rate limits, ABS per wheel), the driver's line
pressure equal on both sides of an axle, a fixed proportioning ``brake_front_share`` (front
axle locks first, UN R13-H Annex 5); ESC adds pressure on one wheel, so its force comes
through that tyre's slip and friction ellipse; the drive force is wheel torque on the driven
axle(s) (``drivetrain``), half to each wheel.

``x``, ``u`` are sequences of scalars (floats, or CasADi SX/MX elements) in the order of
``STATE_NAMES`` and ``INPUT_NAMES``; ``mu`` is the peak surface friction under the vehicle.
"""

from __future__ import annotations

from typing import Any, NamedTuple

from eoam_sumo.params import AIR_DENSITY_KGPM3, G_MPS2, VehicleParams
from eoam_sumo.plant import chassis as ch_
from eoam_sumo.plant.chassis import Chassis, constants
from eoam_sumo.plant.magic_formula import FZ_MIN_N, axle_forces

WHEELS = ("fl", "fr", "rl", "rr")
"""The wheels, in the order of every per-wheel state and output (``tyre_loads_n``'s)."""

STATE_NAMES = (
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "steer_rad",
    "drive_force_n",
    *(f"brake_pressure_{w}_bar" for w in WHEELS),
    *(f"wheel_spin_{w}_radps" for w in WHEELS),
    *(f"slip_{w}" for w in WHEELS),
    "tan_slip_angle_front",
    "tan_slip_angle_rear",
    "ax_load_mps2",
    "ay_load_mps2",
    "esc_moment_nm",
    "esc_reference_radps",
    "speed_estimate_mps",
    "mu_estimate",
    "sideslip_estimate_rad",
    *(f"abs_cut_{w}_barps" for w in WHEELS),
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
    "road_wheel_angle_rad",
    *(f"wheel_speed_{w}_mps" for w in WHEELS),
    *(f"fz_{w}_n" for w in WHEELS),
    *(f"friction_use_{w}" for w in WHEELS),
    *(f"friction_ellipse_{w}" for w in WHEELS),
)
"""Body-frame accelerations (eqs. 4-5), lock flags (1.0: an axle's mean braking slip beyond
``LOCK_SLIP``), body-frame axle tyre forces, axle loads, relaxed slip angles, the drive force
after the power limit and ESC, the aerodynamic drag, the axles' mean wheel speeds (omega r_w),
longitudinal slips and line pressures, the ESC's yaw moment, the road-wheel angle after the
steering compliance; per wheel: its speed, load, ``|F| / (mu Fz)`` against the road's mu and
``sqrt((Fx/Dx)^2 + (Fy/Dy)^2)`` against its own friction ellipse."""

(X, Y, YAW, VX, VY, YAW_RATE, STEER, DRIVE) = range(8)
PRESSURES = (8, 9, 10, 11)
OMEGAS = (12, 13, 14, 15)
SLIPS = (16, 17, 18, 19)
(TAN_F, TAN_R, AX_LOAD, AY_LOAD, ESC, ESC_REF) = range(20, 26)
(V_EST, MU_EST, BETA_EST) = range(26, 29)
ABS_CUTS = (29, 30, 31, 32)
STEER_CMD, DRIVE_CMD, BRAKE_CMD = range(len(INPUT_NAMES))

LOCK_SLIP = -0.5
"""An axle counts as locked while its mean braking slip is beyond this."""


class Axle(NamedTuple):
    """One axle: its force on the body (BODY frame), its tyres' wheel-frame forces (for the
    wheel spins and the friction use), the moment of the left/right force difference, its
    load."""

    fx_n: Any
    fy_n: Any
    tyres: tuple
    moment_nm: Any
    fz_n: Any


class _Forces(NamedTuple):
    front: Axle
    rear: Axle
    drive_n: Any
    drag_n: Any
    esc_nm: Any
    steer_rad: Any  # the road-wheel angle after the steering compliance
    loads: tuple


def tyre_loads_n(x, p: VehicleParams, ops):
    """``(FL, FR, RL, RR)`` normal loads [N]: static, plus the longitudinal transfer
    ``m ax h / L`` and the lateral ``m ay h / track`` shared by the roll stiffness. The loads
    always add up to the weight: an axle's load lies in [0, m g] (the other axle carries the
    rest), an axle's lateral transfer at most lifts its inner wheel, the excess passing to the
    other axle (``_lateral_transfer``)."""
    m, h, wb = p.mass_kg, p.cg_height_m, p.wheelbase_m
    ax, ay = x[AX_LOAD], x[AY_LOAD]
    weight = m * G_MPS2
    half_f = 0.5 * ops.fmin(ops.fmax(m * (G_MPS2 * p.cg_to_rear_m - h * ax) / wb, 0.0), weight)
    half_r = 0.5 * ops.fmin(ops.fmax(m * (G_MPS2 * p.cg_to_front_m + h * ax) / wb, 0.0), weight)
    d_f, d_r = _lateral_transfer(m * ay * h / p.track_m, half_f, half_r, p, ops)
    return (half_f - d_f, half_f + d_f, half_r - d_r, half_r + d_r)  # ay > 0 loads the right


def _lateral_transfer(lateral_n, half_f, half_r, p: VehicleParams, ops):
    """Each axle's lateral load transfer ``(d_f, d_r)`` [N] from the total ``lateral_n``:
    shared by the roll stiffness (``roll_stiffness_front_share``), each at most its axle's
    half load (the inner wheel lifted); what the front axle cannot take passes to the rear,
    what neither can is lost (the car on its two outer wheels, rolling over)."""
    wanted_f = lateral_n * p.roll_stiffness_front_share
    d_f = ops.fmin(ops.fmax(wanted_f, -half_f), half_f)
    d_r = ops.fmin(ops.fmax(lateral_n - wanted_f + (wanted_f - d_f), -half_r), half_r)
    return d_f, d_r


def _axle(kappas, alpha, loads, steer_cs, mu, lky, p: VehicleParams, ch: Chassis, ops) -> Axle:
    """The axle's two tyres (own loads, own longitudinal slips, the axle's slip angle) summed;
    front ones rotated by the road-wheel angle ``steer_cs = (cos, sin)``."""
    left, right = axle_forces(kappas, alpha, loads, mu, lky, ch.tyre, ops)
    fx, fy = left.fx_n + right.fx_n, left.fy_n + right.fy_n
    c, s = steer_cs
    return Axle(
        fx_n=fx * c - fy * s,
        fy_n=fx * s + fy * c,
        tyres=(left, right),
        moment_nm=0.5 * p.track_m * (right.fx_n - left.fx_n) * c,
        fz_n=loads[0] + loads[1],
    )


def _forces(x, mu, p: VehicleParams, ops) -> _Forces:
    """The tyres' forces at state ``x``: the rear axle's, the front one's, whose lateral
    force turns the road wheels back by the steering compliance (``compliant_steer``)."""
    ch = constants(p)
    loads = tyre_loads_n(x, p, ops)
    k = [x[i] for i in SLIPS]
    rear = _axle(k[2:], x[TAN_R], loads[2:], (1.0, 0.0), mu, ch.lky_rear, p, ch, ops)
    front_wheel = _axle(k[:2], x[TAN_F], loads[:2], (1.0, 0.0), mu, ch.lky_front, p, ch, ops)
    steer = compliant_steer(x[STEER], front_wheel.fy_n, ch)
    c, s = ops.cos(steer), ops.sin(steer)
    fx_w, fy_w = front_wheel.fx_n, front_wheel.fy_n
    front = front_wheel._replace(
        fx_n=fx_w * c - fy_w * s, fy_n=fx_w * s + fy_w * c, moment_nm=front_wheel.moment_nm * c
    )
    vx = x[VX]
    esc_nm = x[ESC] if p.esc_fitted else 0.0
    drive_n = ops.fmin(x[DRIVE], p.max_drive_power_w / ops.fmax(driven_speed_mps(x, p, ops), 1.0))
    if p.esc_fitted:
        drive_n = drive_n * ops.fmax(1.0 - ops.fabs(esc_nm) / ch_.ESC_TORQUE_CUT_NM, 0.0)
    drag_n = 0.5 * AIR_DENSITY_KGPM3 * p.drag_area_m2 * vx * ops.fabs(vx)
    return _Forces(front, rear, drive_n, drag_n, esc_nm, steer, loads)


def driven_speed_mps(x, p: VehicleParams, ops):
    """The driven wheels' speed ``omega r_w`` [m/s], each axle's mean weighted by its share of
    the drive torque: the drive force delivers ``F v`` of the engine's power at the wheels, so
    a spinning wheel takes its share of the power and cannot spin up without bound."""
    ch = constants(p)
    front = 0.5 * (x[OMEGAS[0]] + x[OMEGAS[1]])
    rear = 0.5 * (x[OMEGAS[2]] + x[OMEGAS[3]])
    share = ch_.front_drive_share(
        0.5 * (x[SLIPS[0]] + x[SLIPS[1]]), 0.5 * (x[SLIPS[2]] + x[SLIPS[3]]), p, ch, ops
    )
    return (share * front + (1.0 - share) * rear) * p.wheel_radius_m


def compliant_steer(steer_rad, fy_front_n, ch: Chassis):
    """The road-wheel angle ``delta - Fy_f / k_s`` (Gillespie 1992 ch. 6, steering system
    compliance): the front tyres' lateral force (wheel frame) turns the wheels back against
    the steering's stiffness ``k_s``; the tyres' own curve is unchanged."""
    return steer_rad - fy_front_n * ch.steer_compliance_rad_per_n


def _body_accelerations(f: _Forces, p: VehicleParams):
    ax = (f.front.fx_n + f.rear.fx_n - f.drag_n) / p.mass_kg
    ay = (f.front.fy_n + f.rear.fy_n) / p.mass_kg
    return ax, ay


def wheel_velocities(x, steer, p: VehicleParams, ops):
    """``(v_long per wheel, (v_lat front, v_lat rear))``: the contact patches' longitudinal
    velocities in their wheel frames (FL, FR, RL, RR: each side ``-/+ r track / 2``), and the
    lateral velocity of each axle's centre, at road-wheel angle ``steer``."""
    vx, half = x[VX], 0.5 * p.track_m * x[YAW_RATE]
    vy_f = x[VY] + p.cg_to_front_m * x[YAW_RATE]
    c, s = ops.cos(steer), ops.sin(steer)
    v_long = ((vx - half) * c + vy_f * s, (vx + half) * c + vy_f * s, vx - half, vx + half)
    return v_long, (-vx * s + vy_f * c, x[VY] - p.cg_to_rear_m * x[YAW_RATE])


def _slip_rates(x, steer, p: VehicleParams, ch: Chassis, ops) -> list:
    """Relaxation of the slips (Pacejka 2012 sec. 7.2.1): per wheel ``sigma kappa' = omega
    r_w - v_long - v_eff kappa``; per axle ``sigma tan(alpha)' = v_lat - v_eff tan(alpha)``;
    ``v_eff = |v_long|`` plus the low-speed damping speed faded in below ``LOW_SPEED_MPS``."""
    v_long, v_lat = wheel_velocities(x, steer, p, ops)
    rates = []
    for v, omega_i, slip_i in zip(v_long, OMEGAS, SLIPS):
        v_abs = ops.fabs(v)
        v_eff = v_abs + ch.damping_speed_long_mps * ch_.low_speed_fade(v_abs, ops)
        rates.append(
            (x[omega_i] * p.wheel_radius_m - v - v_eff * x[slip_i]) / p.relaxation_length_long_m
        )
    for axle, tan_i in enumerate((TAN_F, TAN_R)):
        v_abs = ops.fabs(0.5 * (v_long[2 * axle] + v_long[2 * axle + 1]))
        v_eff = v_abs + ch.damping_speed_lat_mps * ch_.low_speed_fade(v_abs, ops)
        rates.append((v_lat[axle] - v_eff * x[tan_i]) / p.relaxation_length_lat_m)
    return rates  # slips FL, FR, RL, RR, tan front, tan rear


def _actuator_rates(x, u, f: _Forces, spins, p: VehicleParams, ch: Chassis, ops):
    """Rates of steer (rate limited lag), drive force (lag) and the four wheels' pressures:
    the driver's line pressure on each (equal on the two sides of an axle), plus the ESC's on
    one wheel (``chassis.esc_side_forces``), each through that wheel's ABS; and of the ABS's
    lagged valve cuts (``ABS_CUTS``): each wheel's ABS judges its slip against the speed and
    friction estimates (``V_EST``, ``MU_EST``) and its acceleration: ``spins``
    (``_wheel_rates``) less the brake's and the rolling resistance's torques
    (``integrator.resist``; a locked wheel's is negative, not 0)."""
    steer_target = ops.fmin(ops.fmax(u[STEER_CMD], -p.max_steer_rad), p.max_steer_rad)
    steer_rate = ops.fmin(
        ops.fmax((steer_target - x[STEER]) / p.steer_lag_s, -p.max_steer_rate_radps),
        p.max_steer_rate_radps,
    )
    drive_target = ops.fmin(ops.fmax(u[DRIVE_CMD], 0.0), p.max_drive_force_n)
    brake_target = ops.fmin(ops.fmax(u[BRAKE_CMD], 0.0), p.max_brake_force_n)
    p_cmd = brake_target / ch.brake_n_per_bar
    esc = ch_.esc_side_forces(x[ESC], x[YAW_RATE], p, ops) if p.esc_fitted else (0.0,) * 4
    v_refs = ch_.estimated_wheel_speeds(x[V_EST], x[YAW_RATE], f.steer_rad, p, ops)
    mu_est = x[MU_EST]
    ax, _ = _body_accelerations(f, p)
    pressures, cuts, active = [], [], 0.0
    for i, (p_i, omega_i) in enumerate(zip(PRESSURES, OMEGAS)):
        wheel_mps = x[omega_i] * p.wheel_radius_m
        esc_bar = esc[i] / ch.wheel_brake_n_per_bar[i] if p.esc_fitted else 0.0
        target = ch_.wheel_pressure_target(p_cmd, esc_bar, wheel_mps, v_refs[i], mu_est, p, ch, ops)
        pressures.append(ch_.pressure_rate(target, x[p_i], x[ABS_CUTS[i]], p, ops))
        if not p.abs_fitted:
            cuts.append(0.0)
            past, on = ch_.slip_past(wheel_mps, v_refs[i], mu_est, ch, ops)
            active = ops.fmax(active, past * on)
            continue
        resisting = ch.wheel_brake_n_per_bar[i] * x[p_i] + p.rolling_resistance_coeff * f.loads[i]
        accel = (spins[i] - resisting * p.wheel_radius_m / p.wheel_inertia_kgm2) * p.wheel_radius_m
        cut, past = ch_.abs_cut_target(wheel_mps, v_refs[i], mu_est, accel, ax, p, ch, ops)
        if p.esc_fitted:
            cut = cut * ch_.abs_weight(p_cmd, esc_bar, ops)
        cuts.append((cut - x[ABS_CUTS[i]]) / ch_.ABS_VALVE_LAG_S)
        active = ops.fmax(active, past)
    return [steer_rate, (drive_target - x[DRIVE]) / p.drive_lag_s, *pressures], cuts, active


def _estimate_rates(x, u, accel, steer, abs_active, p: VehicleParams, ops) -> list:
    """Rates of the control unit's estimates (speed, friction, sideslip) from what it
    measures: wheel speeds, accelerometer ``accel = (ax, ay)``, yaw rate, steering angle,
    the driver's line pressure (``chassis.speed_estimate_rate`` and after); ``abs_active``: a
    wheel at its limit (``_actuator_rates``). Zero without ABS and ESC."""
    if not (p.abs_fitted or p.esc_fitted):
        return [0.0, 0.0, 0.0]
    ch = constants(p)
    ax, ay = accel
    r, v_est, mu_est = x[YAW_RATE], x[V_EST], x[MU_EST]
    wheel_mps = [x[i] * p.wheel_radius_m for i in OMEGAS]
    pressure = ops.fmin(ops.fmax(u[BRAKE_CMD], 0.0), p.max_brake_force_n) / ch.brake_n_per_bar
    drive_n = x[DRIVE]
    v_rate = ch_.speed_estimate_rate(
        v_est, ax, wheel_mps, r, steer, pressure, drive_n, mu_est, p, ch, ops
    )
    understeer = 0.0
    if p.esc_fitted:
        understeer = ch_.esc_understeer(v_est, r, x[ESC_REF], p, ops)
    active = ops.fmax(abs_active, understeer)
    accel_g = ops.sqrt(ax * ax + ay * ay) / G_MPS2
    return [
        v_rate,
        ch_.mu_estimate_rate(mu_est, accel_g, active, understeer, ops),
        ch_.sideslip_estimate_rate(x[BETA_EST], ay, r, v_est, ops),
    ]


def _wheel_rates(x, f: _Forces, p: VehicleParams, ch: Chassis, ops) -> list:
    """Wheel spin rates without the brake and rolling-resistance torques (the integrator
    applies those as Coulomb friction, ``integrator.resist``); an open differential gives
    each wheel of an axle half its drive torque."""
    slip_f = 0.5 * (x[SLIPS[0]] + x[SLIPS[1]])
    slip_r = 0.5 * (x[SLIPS[2]] + x[SLIPS[3]])
    share = ch_.front_drive_share(slip_f, slip_r, p, ch, ops)
    half_torque = 0.5 * f.drive_n * p.wheel_radius_m
    tyres = (*f.front.tyres, *f.rear.tyres)
    shares = (share, share, 1.0 - share, 1.0 - share)
    j = p.wheel_inertia_kgm2
    return [(s * half_torque - p.wheel_radius_m * t.fx_n) / j for s, t in zip(shares, tyres)]


def rhs(x, u, mu, params: VehicleParams, ops) -> list:
    """State derivative dx/dt (list in ``STATE_NAMES`` order), for floats or CasADi, without
    the brake and rolling-resistance torques on the wheels (``integrator.resist``).
    Actuator commands are clipped to their ranges here; the lags must be > 0."""
    p = params
    ch = constants(p)
    f = _forces(x, mu, p, ops)
    vx, vy, yaw, r = x[VX], x[VY], x[YAW], x[YAW_RATE]
    ax, ay = _body_accelerations(f, p)  # also what the accelerometer reads
    cos_yaw, sin_yaw = ops.cos(yaw), ops.sin(yaw)
    moment = p.cg_to_front_m * f.front.fy_n - p.cg_to_rear_m * f.rear.fy_n
    moment = moment + f.front.moment_nm + f.rear.moment_nm
    slips = _slip_rates(x, f.steer_rad, p, ch, ops)
    esc_rate = ref_rate = 0.0
    if p.esc_fitted:
        target = ch_.esc_target_moment_nm(x[V_EST], x[BETA_EST], r, x[ESC_REF], p, ops)
        esc_rate = (target - x[ESC]) / p.esc_lag_s
        ref_rate = ch_.esc_reference_rate(x[V_EST], x[STEER], x[ESC_REF], x[MU_EST], p, ch, ops)
    lag = ch_.LOAD_TRANSFER_LAG_S
    fx_tyres = (f.front.fx_n + f.rear.fx_n) / p.mass_kg
    spins = _wheel_rates(x, f, p, ch, ops)
    actuators, cuts, abs_active = _actuator_rates(x, u, f, spins, p, ch, ops)
    return [
        vx * cos_yaw - vy * sin_yaw,
        vx * sin_yaw + vy * cos_yaw,
        r,
        ax + vy * r,  # eq. 4
        ay - vx * r,  # eq. 5
        moment / p.yaw_inertia_kgm2,
        *actuators,
        *spins,
        *slips,
        (fx_tyres - x[AX_LOAD]) / lag,
        (ay - x[AY_LOAD]) / lag,
        esc_rate,
        ref_rate,
        *_estimate_rates(x, u, (ax, ay), f.steer_rad, abs_active, p, ops),
        *cuts,
    ]


def _tyre_use(f: _Forces, mu, ops) -> tuple[list, list]:
    """Per wheel ``|F| / (mu Fz)`` (the road's mu) and ``sqrt((Fx/Dx)^2 + (Fy/Dy)^2)`` (the
    tyre's own ellipse, at most 1)."""
    use, ellipse = [], []
    for t, fz in zip((*f.front.tyres, *f.rear.tyres), f.loads):
        use.append(ops.sqrt(t.fx_n * t.fx_n + t.fy_n * t.fy_n) / (mu * ops.fmax(fz, FZ_MIN_N)))
        ex, ey = t.fx_n / t.dx_n, t.fy_n / t.dy_n
        ellipse.append(ops.sqrt(ex * ex + ey * ey))
    return use, ellipse


def outputs(x, mu, params: VehicleParams, ops) -> list:
    """Outputs in ``OUTPUT_NAMES`` order at state ``x`` (they depend on the actuator STATES,
    not on the commands, so no input is needed)."""
    f = _forces(x, mu, params, ops)
    ax, ay = _body_accelerations(f, params)
    r_w = params.wheel_radius_m
    speeds = [x[i] * r_w for i in OMEGAS]
    slip_f, slip_r = 0.5 * (x[SLIPS[0]] + x[SLIPS[1]]), 0.5 * (x[SLIPS[2]] + x[SLIPS[3]])
    use, ellipse = _tyre_use(f, mu, ops)
    return [
        ax,
        ay,
        ops.if_else(slip_f < LOCK_SLIP, 1.0, 0.0),
        ops.if_else(slip_r < LOCK_SLIP, 1.0, 0.0),
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
        0.5 * (speeds[0] + speeds[1]),
        0.5 * (speeds[2] + speeds[3]),
        slip_f,
        slip_r,
        0.5 * (x[PRESSURES[0]] + x[PRESSURES[1]]),
        0.5 * (x[PRESSURES[2]] + x[PRESSURES[3]]),
        f.esc_nm,
        f.steer_rad,
        *speeds,
        *f.loads,
        *use,
        *ellipse,
    ]
