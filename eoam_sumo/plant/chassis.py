"""The chassis' constants and its control units: brakes and ABS, ESC, the drivetrain.

Written once for any arithmetic (``ops.py``), like ``model.py``; the constants are Python
floats derived from the ``VehicleParams`` once per parameter set (``constants``). Equations and
sources: docs/chassis.md.
"""

from __future__ import annotations

import dataclasses
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
ABS_SLIP_MIN_MPS = 0.1  # ... plus this wheel-speed difference (the speed estimate's error)
ABS_SLIP_BAND = 1.0  # ESC without ABS: its share cut fully at (1 + band) times the threshold
ABS_BUILD_BAND = 0.5  # ABS: pulsed build from (1 - band) times the threshold
ABS_BUILD_SHARE = 0.3  # share of the build rate ABS re-applies with (pulsed build)
ABS_VALVE_LAG_S = 0.01  # the ABS's phase reaches the wheel after this lag (assumed)
ABS_LEAD_S = ABS_VALVE_LAG_S  # the ABS judges the slip this far ahead (wheel acceleration)
ESC_MIN_SPEED_MPS = 5.0  # ESC acts above this speed
ESC_TORQUE_CUT_NM = 1500.0  # the drive force is cut fully at this corrective moment
ESC_YAW_LIMIT = 0.85  # yaw-rate reference limited to 0.85 mu g / v
EAWD_MAX_FRONT_SHARE = 0.5  # eAWD moves torque to the front up to this share
ESC_DEADBAND_ACCEL_MPS2 = 0.2  # the yaw dead band grows by this lateral acceleration / v
# What the control unit knows (wheel speeds, accelerometer, yaw rate, steering angle, brake
# pressure): its speed, friction and sideslip estimates (docs/chassis.md "Estimates").
SPEED_EST_PER_S = 20.0  # unbraked, the speed estimate is pulled to the fastest wheel at once
SPEED_EST_BRAKED_PER_S = 0.1  # braked, the accelerometer carries it (every wheel slips) ...
SPEED_EST_BRAKED_SHARE = 0.03  # ... pulled by at most this share of the measured deceleration
SPEED_EST_BRAKED_MIN_MPS2 = 0.02  # ... plus this (the accelerometer's offset), so never stuck
SPEED_EST_DRIVE_SHARE = 0.05  # AWD: from this drive force (share of the weight) the slowest wheel
BRAKE_ON_BAR = 2.0  # mean wheel pressure from which the car counts as braked
MU_EST_HIGH = 1.0  # the friction estimate starts at, and returns to, a dry road's
MU_EST_MIN = 0.05  # the ABS and ESC thresholds use at least this friction estimate
MU_EST_TAU_S = 0.1  # the estimate rises to an achieved |a| / g above it this fast
MU_EST_FALL_S = 0.5  # a wheel at its limit: it falls to the achieved |a| / g this slowly
MU_EST_ESC_FALL_S = 0.1  # ... the front axle at its limit (ESC sees understeer): this fast
MU_EST_RECOVER_S = 3.0  # no wheel at its limit: the estimate returns to MU_EST_HIGH this slowly
BETA_EST_LEAK_S = 2.0  # the kinematic sideslip estimate's integration leaks over this time


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

    # MF 5.2's nominal-load scaling (LFZO, Pacejka 2012 sec. 4.3.2): the set's curves about
    # the vehicle's own tyre's nominal load (the paper's sedans keep the set's 4850 N)
    tyre = dataclasses.replace(PAC2002_235_60R16.symmetric(), fz0=p.tyre_nominal_load_n)
    fz_f, fz_r = _static_tyre_loads_n(p)
    k_f = cornering_stiffness_npr(fz_f, tyre, FLOAT_OPS)
    k_r = cornering_stiffness_npr(fz_r, tyre, FLOAT_OPS)
    k_long = 2.0 * (fz_f + fz_r) * tyre.pkx1  # all four tyres' slip stiffness, about
    c_front = p.front_axle_stiffness_npr
    k_lat = c_front + p.cornering_stiffness_rear_npr
    zeta2 = 2.0 * LOW_SPEED_DAMPING_RATIO
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
        understeer_spmpm=p.understeer_gradient_rad_per_mps2,
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


def abs_threshold_slip(mu, ch: Chassis, ops):
    """The ABS's dump threshold on a wheel's braking slip: the tyre's peak slip at the
    friction estimate ``mu`` (at least ``MU_EST_MIN``) times ``ABS_SLIP_FACTOR``."""
    return ABS_SLIP_FACTOR * ch.peak_slip_per_mu * ops.fmax(mu, MU_EST_MIN)


def _slip_excess(wheel_mps, v_long, mu, ch: Chassis, ops):
    """``(excess, on)``: how far a wheel's braking slip ``(omega r_w - v) / v`` against its
    reference speed ``v_long`` (``estimated_wheel_speeds``) is past the tyre's peak slip at
    the friction estimate ``mu`` (``ABS_SLIP_FACTOR``), over ``ABS_SLIP_BAND``, in [0, 1];
    and the control's fade-in above ``ABS_MIN_SPEED_MPS`` (over 1 m/s)."""
    speed = ops.fmax(v_long, ABS_MIN_SPEED_MPS)
    slip = (wheel_mps - v_long) / speed
    threshold = abs_threshold_slip(mu, ch, ops) + ABS_SLIP_MIN_MPS / speed
    excess = ops.fmin(ops.fmax((-slip - threshold) / (ABS_SLIP_BAND * threshold), 0.0), 1.0)
    return excess, ops.fmin(ops.fmax(v_long - ABS_MIN_SPEED_MPS, 0.0), 1.0)


def slip_past(wheel_mps, v_long, mu, ch: Chassis, ops):
    """``(past, on)``: 1 while the wheel's braking slip is past its threshold
    (``_slip_excess``), else 0; and the control's fade-in."""
    excess, on = _slip_excess(wheel_mps, v_long, mu, ch, ops)
    return ops.if_else(excess > 0.0, 1.0, 0.0), on


def wheel_pressure_target(p_cmd_bar, esc_bar, wheel_mps, v_long, mu, p, ch: Chassis, ops):
    """A wheel's target pressure [bar]: the driver's line pressure plus the ESC's for this
    wheel, up to ``max_brake_pressure_bar``. ESC keeps its own wheel below the peak slip: its
    share is cut as the slip passes the peak (a slip-controlled intervention, with or without
    ABS; ``abs_weight``)."""
    excess, on = _slip_excess(wheel_mps, v_long, mu, ch, ops)
    esc_bar = esc_bar * (1.0 - excess * on)
    return ops.fmin(p_cmd_bar + esc_bar, p.max_brake_pressure_bar)


def abs_weight(p_cmd_bar, esc_bar, ops):
    """How much of the ABS's cut a wheel takes, in [0, 1]: all of it while the driver brakes
    (line pressure ``p_cmd_bar`` from ``BRAKE_ON_BAR``) or the ESC asks nothing of the wheel;
    none while only the ESC brakes it. The ESC's intervention limits its own slip
    (``wheel_pressure_target``): the ABS's dump-hold-build cycle, judging the slip against a
    reference speed that knows no lateral velocity, would throw away the corrective moment
    in a slide."""
    driver = ops.fmin(ops.fmax(p_cmd_bar / BRAKE_ON_BAR, 0.0), 1.0)
    esc_only = ops.fmin(ops.fmax(esc_bar / BRAKE_ON_BAR, 0.0), 1.0)
    return ops.fmax(driver, 1.0 - esc_only)


def pressure_rate(p_target_bar, p_bar, cut_barps, p: VehicleParams, ops):
    """One wheel's pressure rate [bar/s]: a first-order build to the target with the build and
    dump rate limits; with ABS, at most the build rate less the ABS's cut ``cut_barps`` (the
    lagged valve command, ``abs_cut_target``)."""
    rate = (p_target_bar - p_bar) / p.brake_lag_s
    rate = ops.fmin(ops.fmax(rate, -p.brake_dump_rate_barps), p.brake_build_rate_barps)
    if not p.abs_fitted:
        return rate
    return ops.fmin(rate, p.brake_build_rate_barps - cut_barps)


def abs_cut_target(wheel_mps, v_long, mu, accel, ax_meas, p: VehicleParams, ch, ops):
    """What one wheel's ABS asks of its valves, as a cut [bar/s] below the build rate: the
    phases of a three-phase controller from what it measures, the wheel's slip against its
    reference speed ``v_long`` and the friction estimate ``mu`` (``_slip_excess``) and the
    wheel's acceleration ``accel`` [m/s^2]. Past the threshold, dump while the wheel still
    decelerates (a locked wheel too) and hold once it spins up; below it, a pulsed build
    (``ABS_BUILD_SHARE``) within ``ABS_BUILD_BAND`` below the threshold; else no cut. The
    valves follow it with ``ABS_VALVE_LAG_S``, so the slip is judged ``ABS_LEAD_S`` ahead
    (a wheel-deceleration threshold in effect). Returns ``(cut, near)``: ``near`` 1 while the
    wheel is within the build band or past the threshold (at the friction limit:
    ``mu_estimate_rate``'s ``active``)."""
    build = p.brake_build_rate_barps
    wheel_ahead = wheel_mps + ABS_LEAD_S * accel
    v_ahead = v_long + ABS_LEAD_S * ax_meas
    excess, on = _slip_excess(wheel_ahead, v_ahead, mu, ch, ops)
    near, _ = _slip_excess(wheel_ahead, v_ahead, mu * (1.0 - ABS_BUILD_BAND), ch, ops)
    past = ops.if_else(accel < 0.0, -p.brake_dump_rate_barps, 0.0)
    limit = ops.if_else(excess > 0.0, past, ops.if_else(near > 0.0, ABS_BUILD_SHARE * build, build))
    return (build - limit) * on, ops.if_else(near > 0.0, 1.0, 0.0) * on


def front_drive_share(slip_front, slip_rear, p: VehicleParams, ch: Chassis, ops):
    """Share of the drive torque on the front axle: fixed (FWD 1, RWD 0, AWD the split), or
    for eAWD the split moved to the axle that slips less, by ``eawd_gain_per_slip``."""
    if p.drivetrain != "eawd":
        return ch.front_share
    moved = p.eawd_gain_per_slip * (slip_rear - slip_front)
    return ops.fmin(ops.fmax(ch.front_share + moved, 0.0), EAWD_MAX_FRONT_SHARE)


def estimated_wheel_speeds(v_est, r, steer, p: VehicleParams, ops):
    """Each wheel's contact-patch speed (FL, FR, RL, RR) as the control unit reckons it from
    its speed estimate, the yaw-rate sensor and the steering angle, with no lateral velocity
    (it has no measure of it): ``model.wheel_velocities`` at ``vy = 0``."""
    half = 0.5 * p.track_m * r
    c, s = ops.cos(steer), ops.sin(steer)
    lat_f = p.cg_to_front_m * r * s
    return ((v_est - half) * c + lat_f, (v_est + half) * c + lat_f, v_est - half, v_est + half)


def speed_estimate_rate(
    v_est, ax_meas, wheel_mps, r, steer, pressure_bar, drive_n, mu_est, p, ch, ops
):
    """Rate of the vehicle-speed estimate: the accelerometer's ``ax`` integrated; unbraked,
    pulled to the free-rolling wheels (``_unbraked_pull``; each wheel's speed
    referred to the centre of gravity, the inverse of ``estimated_wheel_speeds``). Braked
    (``pressure_bar`` the mean wheel pressure) every wheel runs at some slip, the fastest one
    (the ABS's recovered wheel) within the ABS's threshold slip at the friction estimate
    ``mu_est``: the estimate is pulled up while below the fastest wheel and down while even
    the fastest wheel is beyond that slip, slowly and by at most ``SPEED_EST_BRAKED_SHARE`` of
    the measured deceleration plus ``SPEED_EST_BRAKED_MIN_MPS2`` (the accelerometer's own
    error: gain, the body's pitch, its offset; a wheel spinning up past the car for a moment
    does not carry the estimate with it)."""
    half = 0.5 * p.track_m * r
    c, s = ops.cos(steer), ops.sin(steer)
    lat_f = p.cg_to_front_m * r * s
    fl, fr, rl, rr = wheel_mps
    refs = ((fl - lat_f) / c + half, (fr - lat_f) / c - half, rl + half, rr - half)
    fastest = ops.fmax(ops.fmax(refs[0], refs[1]), ops.fmax(refs[2], refs[3]))
    braked = ops.fmin(ops.fmax(pressure_bar / BRAKE_ON_BAR, 0.0), 1.0)
    slack = braked * abs_threshold_slip(mu_est, ch, ops) * ops.fmax(v_est, 0.0)
    gap = ops.fmax(fastest - v_est, 0.0) + ops.fmin(fastest + slack - v_est, 0.0)
    cap = SPEED_EST_BRAKED_SHARE * ops.fabs(ax_meas) + SPEED_EST_BRAKED_MIN_MPS2
    slow = ops.fmin(ops.fmax(SPEED_EST_BRAKED_PER_S * gap, -cap), cap)
    unbraked = _unbraked_pull(refs, v_est, cap, drive_n, p, ops)
    return ax_meas + braked * slow + (1.0 - braked) * unbraked


def _unbraked_pull(refs, v_est, cap, drive_n, p: VehicleParams, ops):
    """The unbraked speed estimate's pull [m/s^2] to the wheels that roll free (``refs``:
    each wheel's speed referred to the centre of gravity, FL, FR, RL, RR): at once
    (``SPEED_EST_PER_S``) to the faster undriven wheel of a front- or rear-driven car (the
    undriven wheels stand for the car's speed in traction control: Hori, Toyoda and
    Tsuruoka, IEEE Trans. Ind. Appl. 34(5), 1998). With every wheel driven (AWD, eAWD) to the
    fastest while coasting (a wheel the ESC brakes does not pull it down) and, under drive
    (blended by the drive force ``drive_n`` up to ``SPEED_EST_DRIVE_SHARE`` of the weight:
    the control unit knows the engine's torque), to the slowest, up by no more than the
    accelerometer's error ``cap`` over its reading, as while braked: four wheels spinning on
    ice do not carry it."""
    if p.drivetrain in ("fwd", "rwd"):
        undriven = (refs[2], refs[3]) if p.drivetrain == "fwd" else (refs[0], refs[1])
        return SPEED_EST_PER_S * (ops.fmax(undriven[0], undriven[1]) - v_est)
    fastest = ops.fmax(ops.fmax(refs[0], refs[1]), ops.fmax(refs[2], refs[3]))
    slowest = ops.fmin(ops.fmin(refs[0], refs[1]), ops.fmin(refs[2], refs[3]))
    driving = ops.fmin(ops.fmax(drive_n / (SPEED_EST_DRIVE_SHARE * p.mass_kg * G_MPS2), 0.0), 1.0)
    coasting_pull = SPEED_EST_PER_S * (fastest - v_est)
    driving_pull = ops.fmin(SPEED_EST_PER_S * (slowest - v_est), cap)
    return coasting_pull + driving * (driving_pull - coasting_pull)


def mu_estimate_rate(mu_est, accel_g, active, understeer, ops):
    """Rate of the friction estimate: while a tyre is at its limit (``active``: ABS slip past
    its threshold, or ESC seeing understeer) it falls to the acceleration the car achieves,
    ``|a| / g`` from the accelerometer (at least ``MU_EST_MIN``), averaging over the ABS's
    cycles (``MU_EST_FALL_S``); with the front axle at its limit (``understeer``: a steady
    lateral acceleration, no cycles to average) within ``MU_EST_ESC_FALL_S``, before the ESC
    brakes a rear wheel for a yaw rate the road cannot give; otherwise it returns slowly to
    a dry road's; it rises at once to any acceleration achieved above it."""
    rise = ops.fmax(accel_g - mu_est, 0.0) / MU_EST_TAU_S
    fall_s = MU_EST_FALL_S + understeer * (MU_EST_ESC_FALL_S - MU_EST_FALL_S)
    follow = active * ops.fmin(ops.fmax(accel_g, MU_EST_MIN) - mu_est, 0.0) / fall_s
    return follow + (1.0 - active) * (MU_EST_HIGH - mu_est) / MU_EST_RECOVER_S + rise


def sideslip_estimate_rate(beta_est, ay_meas, r, v_est, ops):
    """Rate of the kinematic sideslip estimate ``beta' = ay / v - r`` (the accelerometer and
    the yaw-rate sensor), its integration drift leaked over ``BETA_EST_LEAK_S``."""
    v = ops.fmax(v_est, ESC_MIN_SPEED_MPS)
    return ay_meas / v - r - beta_est / BETA_EST_LEAK_S


def esc_deadband_radps(v_est, p: VehicleParams, ops):
    """The ESC's yaw-rate dead band at the speed estimate: ``esc_yaw_deadband_radps`` plus a
    lateral-acceleration error of ``ESC_DEADBAND_ACCEL_MPS2`` over v (wider at low speed)."""
    return p.esc_yaw_deadband_radps + ESC_DEADBAND_ACCEL_MPS2 / ops.fmax(v_est, ESC_MIN_SPEED_MPS)


def esc_understeer(v_est, r, r_ref, p: VehicleParams, ops):
    """1 while the yaw rate falls short of the reference by more than the dead band (the
    front tyres at their limit), else 0."""
    error = r_ref - r
    short = ops.if_else(r_ref * error > 0.0, 1.0, 0.0)
    beyond = ops.if_else(ops.fabs(error) > esc_deadband_radps(v_est, p, ops), 1.0, 0.0)
    return short * beyond * ops.fmin(ops.fmax(v_est - ESC_MIN_SPEED_MPS, 0.0), 1.0)


def esc_reference_rate(v_est, steer, r_ref, mu_est, p: VehicleParams, ch: Chassis, ops):
    """Rate of the ESC's yaw-rate reference: the linear single-track steady state
    ``v delta / (L + K v^2)``, limited to ``0.85 mu g / v`` at the friction estimate, through
    a first-order lag of the car's own yaw time constant ``Iz v / (a^2 C_f + b^2 C_r)``
    (Rajamani 2012 ch. 8: the desired yaw rate of a yaw-dynamics reference model), so a car
    that follows its steering as a linear car would is never corrected."""
    v = ops.fmax(v_est, ESC_MIN_SPEED_MPS)
    r_lin = v * steer / (p.wheelbase_m + ch.understeer_spmpm * v * v)
    r_max = ESC_YAW_LIMIT * ops.fmax(mu_est, MU_EST_MIN) * G_MPS2 / v
    tau = p.yaw_inertia_kgm2 * v / ch.yaw_damping_nmspr
    return (ops.fmin(ops.fmax(r_lin, -r_max), r_max) - r_ref) / tau


def esc_target_moment_nm(v_est, beta_est, r, r_ref, p: VehicleParams, ops):
    """The ESC's corrective yaw moment [N m]: the yaw-rate error to the reference
    (``esc_reference_rate``) past the speed-dependent dead band (``esc_deadband_radps``),
    times ``Iz * esc_yaw_gain``; plus ``esc_sideslip_gain`` times the sideslip estimate past
    its threshold."""
    error = r_ref - r
    band = esc_deadband_radps(v_est, p, ops)
    yaw_part = ops.sign(error) * ops.fmax(ops.fabs(error) - band, 0.0)
    beta = beta_est
    beta_part = ops.sign(beta) * ops.fmax(ops.fabs(beta) - p.esc_sideslip_threshold_rad, 0.0)
    on = ops.fmin(ops.fmax(v_est - ESC_MIN_SPEED_MPS, 0.0), 1.0)
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
