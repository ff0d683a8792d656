"""The chassis' constants and its control units: brakes and ABS, ESC, the drivetrain.

Written once for any arithmetic (``ops.py``), like ``model.py``; the constants are Python
floats derived from the ``VehicleParams`` once per parameter set (``constants``). Equations and
sources: docs/chassis.md.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

from eoam_sumo.params import G_MPS2, VehicleParams
from eoam_sumo.plant.magic_formula import (
    PAC2002_235_60R16,
    MfCoefficients,
    cornering_stiffness_npr,
    peak_slip,
)

LOW_SPEED_MPS = 3.0
"""Below this wheel speed the slip relaxation gets its low-speed damping (Pacejka 2012
sec. 8.6.5's VXLOW idea): it fades in as (1 - |v| / LOW_SPEED_MPS)^2."""

LOW_SPEED_DAMPING_RATIO = 0.8
"""Damping ratio of the body on its tyres' relaxation springs at rest (no ringing at rest)."""

LOAD_TRANSFER_LAG_S = 0.05
"""First-order lag of the accelerations that set the quasi-static load transfer: the body's
pitch and roll response, and no algebraic loop between loads and tyre forces."""

ABS_MIN_SPEED_MPS = 2.0  # ABS control ends below this speed (the wheel may then stop)
ABS_SLIP_FACTOR = 1.0  # ABS dump threshold as a multiple of the tyre's peak slip
ABS_SLIP_BAND = 1.0  # full dump at (1 + band) times the threshold
ABS_BUILD_SHARE = 0.3  # share of the build rate ABS re-applies with (pulsed build)
ESC_MIN_SPEED_MPS = 5.0  # ESC acts above this speed
ESC_TORQUE_CUT_NM = 1500.0  # the drive force is cut fully at this corrective moment
ESC_YAW_LIMIT = 0.85  # yaw-rate reference limited to 0.85 mu g / v
EAWD_MAX_FRONT_SHARE = 0.5  # eAWD moves torque to the front up to this share


class Chassis(NamedTuple):
    """Constants of the model, derived from the parameters (floats)."""

    tyre: MfCoefficients  # the symmetric MF set both axles use
    lky_front: float  # LKY of the front tyres: their axle stiffness at static load
    lky_rear: float
    brake_n_per_bar: float  # road brake force of both axles per bar of line pressure
    wheel_brake_n_per_bar: tuple[float, float, float, float]  # each wheel's, FL, FR, RL, RR
    steer_compliance_rad_per_n: float  # road-wheel angle lost per N of front lateral force
    damping_speed_long_mps: float  # low-speed damping speed of the longitudinal relaxation
    damping_speed_lat_mps: float
    peak_slip_per_mu: float  # the tyre's braking peak slip per unit road mu (ABS reference)
    understeer_spmpm: float  # K of r = v delta / (L + K v^2), the ESC's reference [s^2/m]
    yaw_damping_nmspr: float  # a^2 C_f + b^2 C_r: the yaw time constant is Iz v / this
    front_share: float  # drive torque share of the front axle (fixed drivetrains)


def _static_tyre_loads_n(p: VehicleParams) -> tuple[float, float]:
    weight_n = p.mass_kg * G_MPS2
    return 0.5 * weight_n * p.cg_to_rear_m / p.wheelbase_m, (
        0.5 * weight_n * p.cg_to_front_m / p.wheelbase_m
    )


@functools.lru_cache(maxsize=32)
def constants(p: VehicleParams) -> Chassis:
    """The ``Chassis`` of a parameter set."""
    from eoam_sumo.plant.ops import FLOAT_OPS

    tyre = PAC2002_235_60R16.symmetric()
    fz_f, fz_r = _static_tyre_loads_n(p)
    k_f = cornering_stiffness_npr(fz_f, tyre, FLOAT_OPS)
    k_r = cornering_stiffness_npr(fz_r, tyre, FLOAT_OPS)
    k_long = 2.0 * (fz_f + fz_r) * tyre.pkx1  # all four tyres' slip stiffness, about
    c_front = p.front_axle_stiffness_npr
    k_lat = c_front + p.cornering_stiffness_rear_npr
    zeta2 = 2.0 * LOW_SPEED_DAMPING_RATIO
    understeer = p.mass_kg * (
        p.cg_to_rear_m / c_front - p.cg_to_front_m / p.cornering_stiffness_rear_npr
    )
    share = {"fwd": 1.0, "rwd": 0.0}.get(p.drivetrain, p.awd_front_share)
    per_bar = p.max_brake_force_n / p.max_brake_pressure_bar
    front = 0.5 * per_bar * p.brake_front_share
    rear = 0.5 * per_bar * (1.0 - p.brake_front_share)
    return Chassis(
        tyre=tyre,
        lky_front=p.cornering_stiffness_front_npr / (2.0 * k_f),
        lky_rear=p.cornering_stiffness_rear_npr / (2.0 * k_r),
        brake_n_per_bar=per_bar,
        wheel_brake_n_per_bar=(front, front, rear, rear),
        steer_compliance_rad_per_n=steer_compliance_rad_per_n(p),
        damping_speed_long_mps=zeta2 * math.sqrt(k_long * p.relaxation_length_long_m / p.mass_kg),
        damping_speed_lat_mps=zeta2 * math.sqrt(k_lat * p.relaxation_length_lat_m / p.mass_kg),
        peak_slip_per_mu=peak_slip(PAC2002_235_60R16) / tyre.pdx1,
        understeer_spmpm=understeer / p.wheelbase_m,
        yaw_damping_nmspr=p.cg_to_front_m**2 * c_front
        + p.cg_to_rear_m**2 * p.cornering_stiffness_rear_npr,
        front_share=share,
    )


def low_speed_fade(v_abs, ops):
    """(1 - |v| / LOW_SPEED_MPS)^2 below LOW_SPEED_MPS, else 0."""
    w = ops.fmax(1.0 - v_abs / LOW_SPEED_MPS, 0.0)
    return w * w


def steer_compliance_rad_per_n(p: VehicleParams) -> float:
    """``1 / k_s`` [rad/N] of the steering's compliance: the front axle's effective cornering
    stiffness ``c C_f`` (``front_steer_compliance`` c) is its tyres' ``C_f`` in series with
    ``k_s``, ``1 / (c C_f) = 1 / C_f + 1 / k_s``, so ``1 / k_s = (1 / c - 1) / C_f`` (zero: a
    stiff steering, c >= 1)."""
    c = p.front_steer_compliance
    if c >= 1.0:
        return 0.0
    return (1.0 / c - 1.0) / p.cornering_stiffness_front_npr


def _slip_excess(wheel_mps, v_long, mu, ch: Chassis, ops):
    """``(excess, on)``: how far a wheel's braking slip ``(omega r_w - v) / v`` is past the
    tyre's peak slip on this road (``ABS_SLIP_FACTOR``), over ``ABS_SLIP_BAND``, in [0, 1];
    and the control's fade-in above ``ABS_MIN_SPEED_MPS`` (over 1 m/s)."""
    slip = (wheel_mps - v_long) / ops.fmax(v_long, ABS_MIN_SPEED_MPS)
    threshold = ABS_SLIP_FACTOR * ch.peak_slip_per_mu * mu
    excess = ops.fmin(ops.fmax((-slip - threshold) / (ABS_SLIP_BAND * threshold), 0.0), 1.0)
    return excess, ops.fmin(ops.fmax(v_long - ABS_MIN_SPEED_MPS, 0.0), 1.0)


def wheel_pressure_target(p_cmd_bar, esc_bar, wheel_mps, v_long, mu, p, ch: Chassis, ops):
    """A wheel's target pressure [bar]: the driver's line pressure plus the ESC's for this
    wheel, up to ``max_brake_pressure_bar``. ESC keeps its own wheel below the peak slip (its
    hydraulic unit is the ABS's): without ABS its share is cut as the slip passes the peak."""
    if not p.abs_fitted:
        excess, on = _slip_excess(wheel_mps, v_long, mu, ch, ops)
        esc_bar = esc_bar * (1.0 - excess * on)
    return ops.fmin(p_cmd_bar + esc_bar, p.max_brake_pressure_bar)


def pressure_rate(p_target_bar, p_bar, wheel_mps, v_long, mu, p: VehicleParams, ch: Chassis, ops):
    """One wheel's pressure rate [bar/s]: a first-order build to the target with the build and
    dump rate limits; with ABS, the rate is cut from a slower build towards a dump as the
    wheel's braking slip passes the tyre's peak slip on this road (``_slip_excess``,
    ``ABS_BUILD_SHARE``)."""
    rate = (p_target_bar - p_bar) / p.brake_lag_s
    rate = ops.fmin(ops.fmax(rate, -p.brake_dump_rate_barps), p.brake_build_rate_barps)
    if not p.abs_fitted:
        return rate
    excess, on = _slip_excess(wheel_mps, v_long, mu, ch, ops)
    build = ABS_BUILD_SHARE * p.brake_build_rate_barps
    limit = build - (build + p.brake_dump_rate_barps) * excess
    return ops.fmin(rate, ops.if_else(excess > 0.0, limit, rate) * on + rate * (1.0 - on))


def front_drive_share(slip_front, slip_rear, p: VehicleParams, ch: Chassis, ops):
    """Share of the drive torque on the front axle: fixed (FWD 1, RWD 0, AWD the split), or
    for eAWD the split moved to the axle that slips less, by ``eawd_gain_per_slip``."""
    if p.drivetrain != "eawd":
        return ch.front_share
    moved = p.eawd_gain_per_slip * (slip_rear - slip_front)
    return ops.fmin(ops.fmax(ch.front_share + moved, 0.0), EAWD_MAX_FRONT_SHARE)


def esc_reference_rate(vx, steer, r_ref, mu, p: VehicleParams, ch: Chassis, ops):
    """Rate of the ESC's yaw-rate reference: the linear single-track steady state
    ``v delta / (L + K v^2)``, limited to ``0.85 mu g / v``, through a first-order lag of the
    car's own yaw time constant ``Iz v / (a^2 C_f + b^2 C_r)`` (Rajamani 2012 ch. 8: the
    desired yaw rate of a yaw-dynamics reference model), so a car that follows its steering
    as a linear car would is never corrected."""
    v = ops.fmax(vx, ESC_MIN_SPEED_MPS)
    r_lin = v * steer / (p.wheelbase_m + ch.understeer_spmpm * v * v)
    r_max = ESC_YAW_LIMIT * mu * G_MPS2 / v
    tau = p.yaw_inertia_kgm2 * v / ch.yaw_damping_nmspr
    return (ops.fmin(ops.fmax(r_lin, -r_max), r_max) - r_ref) / tau


def esc_target_moment_nm(vx, vy, r, r_ref, p: VehicleParams, ops):
    """The ESC's corrective yaw moment [N m]: the yaw-rate error to the reference
    (``esc_reference_rate``) past a dead band, times ``Iz * esc_yaw_gain``; plus
    ``esc_sideslip_gain`` times the sideslip past its threshold."""
    v = ops.fmax(vx, ESC_MIN_SPEED_MPS)
    error = r_ref - r
    yaw_part = ops.sign(error) * ops.fmax(ops.fabs(error) - p.esc_yaw_deadband_radps, 0.0)
    beta = ops.atan(vy / v)
    beta_part = ops.sign(beta) * ops.fmax(ops.fabs(beta) - p.esc_sideslip_threshold_rad, 0.0)
    on = ops.fmin(ops.fmax(vx - ESC_MIN_SPEED_MPS, 0.0), 1.0)
    moment = p.yaw_inertia_kgm2 * p.esc_yaw_gain * yaw_part + p.esc_sideslip_gain_nmprad * beta_part
    return moment * on


def esc_side_forces(moment_nm, r, p: VehicleParams, ops):
    """The braking force [N] ESC asks of each wheel, ``(front_left, front_right, rear_left,
    rear_right)``: ``|M| / (track / 2)`` on the side that turns the car the way of ``M``
    (left for M > 0); on the front axle against oversteer (M opposing the yaw rate), on the
    rear against understeer."""
    half_track = 0.5 * p.track_m
    left = ops.fmax(moment_nm, 0.0) / half_track
    right = ops.fmax(-moment_nm, 0.0) / half_track
    front = ops.if_else(moment_nm * r < 0.0, 1.0, 0.0)
    return left * front, right * front, left * (1.0 - front), right * (1.0 - front)
