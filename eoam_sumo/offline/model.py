"""Design model of the offline optimisation: the paper's planar single-track model.

Equations of motion in the road (global) frame, eqs. 15-20, with the linear-saturating tyre of
eq. 6 scaled by the surface friction (eq. 35), or the plant's Fiala tyre, or a blend of the
two (``tyre_blend``, 0 = the paper's, 1 = the plant's). One function serves both the CasADi
optimal control problem and the independent re-simulation: ``ops`` is the ``casadi`` or
``math`` module.

Additions the paper leaves open (stated in the README):

- the tyre's hard saturation at alpha* is smoothed for IPOPT, F = mu C alpha* sat(alpha/alpha*)
  with sat(u) = u / (1 + u^8)^(1/8) (slope C at 0, limit mu C alpha*, 8 % below the kink);
- the plant's tyre (``plant/tyres.py``): Fiala, F = F_p (3 z - 3 z |z| + z^3) with
  z = C tan(alpha) / (3 F_p), cornering stiffness C at any friction and the peak derated by the
  axle's longitudinal force, F_p = sqrt((mu Fz)^2 - Fx^2) (loads from the longitudinal tyre
  forces alone). The paper's tyre reaches the friction ellipse at a few degrees of slip, the
  plant's only at tan(alpha) = 3 F_p / C, with a falling slope: a plan made with the paper's
  tyre asks the plant for other slip angles, sideslip and steering than the plant needs, and a
  plan at the whole ellipse asks it for its peak slip, where no force is left to correct with.
  Lane changes are planned with the plant's tyre (``DesignSettings.plant_tyre``), reached by
  continuation from the paper's (``ocp.solve_chain``);
- one longitudinal force control u1 (eqs. 28-29): its negative part brakes both axles with the
  fixed front share ``VehicleParams.brake_front_share``, its positive part drives the rear
  axle; the split min(u1, 0) is smoothed, (u1 - sqrt(u1^2 + e^2)) / 2 with e = 100 N; the wheel
  forces are resolved through the steer angle;
- the friction ellipse (28) is applied to each axle with its load from the longitudinal load
  transfer (cg height), so no axle locks (the ego has no ABS) and |a| <= mu g overall;
- the steering angle is a state driven by its rate, bounded by the actuator's rate limit;
- no aerodynamic drag or rolling resistance (they would only help the manoeuvre).
"""

from __future__ import annotations

from dataclasses import dataclass

from eoam_sumo.params import G_MPS2, VehicleParams

STATE_NAMES = ("x_m", "x_speed_mps", "y_m", "y_speed_mps", "yaw_rad", "yaw_rate_radps", "steer_rad")
CONTROL_NAMES = ("steer_rate_radps", "long_force_n")
FORCE_SMOOTHING_N = 100.0
PEAK_FLOOR_N = 1.0  # keeps the derated Fiala peak > 0 (and its square root smooth)
N_STATES = len(STATE_NAMES)
N_CONTROLS = len(CONTROL_NAMES)


def smooth_sat(u):
    """Smooth unit saturation u / (1 + u^8)^(1/8) (works on floats and CasADi symbols)."""
    return u / (1.0 + u**8) ** 0.125


def split_force(long_force_n):
    """Smooth (brake part <= 0, drive part >= 0) of the longitudinal force control."""
    brake = 0.5 * (long_force_n - (long_force_n**2 + FORCE_SMOOTHING_N**2) ** 0.5)
    return brake, long_force_n - brake


def tyre_lateral_force(alpha_rad, cornering_npr: float, mu, alpha_sat_rad: float):
    """Axle lateral force of the linear-saturating tyre, eqs. 6 and 35 (smoothed)."""
    f_max = mu * cornering_npr * alpha_sat_rad
    return f_max * smooth_sat(alpha_rad / alpha_sat_rad)


def fiala_lateral_force(tan_alpha, cornering_npr: float, peak_n, ops):
    """Fiala brush lateral force F_p (3 z - 3 z |z| + z^3), z = C tan(alpha) / (3 F_p): the
    plant's tyre (``plant.tyres.fiala_lateral_force_n``) below its peak, |z| <= 1."""
    z = cornering_npr * tan_alpha / (3.0 * peak_n)
    return peak_n * z * (3.0 - 3.0 * ops.fabs(z) + z * z)


def _derated_peak(limit_n, fx_n):
    """sqrt(max((mu Fz)^2 - Fx^2, 0) + floor^2), the max smoothed (no NaN, smooth for IPOPT
    where an iterate asks an axle for more than its friction)."""
    q = limit_n**2 - fx_n**2
    f2 = PEAK_FLOOR_N**2
    return (0.5 * (q + (q * q + f2 * f2) ** 0.5) + f2) ** 0.5


def axle_loads(ax_mps2, params: VehicleParams):
    """Front and rear axle normal loads with longitudinal load transfer (N)."""
    p = params
    m, h, wb = p.mass_kg, p.cg_height_m, p.wheelbase_m
    fz_front = m * (G_MPS2 * p.cg_to_rear_m - ax_mps2 * h) / wb
    fz_rear = m * (G_MPS2 * p.cg_to_front_m + ax_mps2 * h) / wb
    return fz_front, fz_rear


@dataclass(frozen=True)
class ModelOutputs:
    """Quantities besides the state derivative (floats or CasADi expressions)."""

    ax_body_mps2: object  # body-frame longitudinal acceleration, eq. 1 / eq. 4
    ay_body_mps2: object  # body-frame lateral acceleration, eq. 2 / eq. 5
    vx_body_mps: object
    alpha_front_rad: object
    alpha_rear_rad: object
    fy_front_n: object
    fy_rear_n: object
    ellipse_front: object  # (Fx^2 + Fy^2) / (mu Fz)^2 of the front axle, <= 1 (eqs. 25, 28)
    ellipse_rear: object


def dynamics(x, u, mu, params: VehicleParams, ops, tyre_blend=0.0):
    """State derivative (list of 7) and ``ModelOutputs`` of the design model, eqs. 15-20.

    ``x`` in STATE_NAMES order, ``u`` in CONTROL_NAMES order, ``ops`` the module
    providing sin, cos, tan, atan2, fabs (``math`` or ``casadi``); ``tyre_blend`` weighs the
    plant's Fiala tyre against the paper's (0: the paper's eq. 6, 1: the plant's).
    """
    p = params
    _, x_speed, _, y_speed, yaw, yaw_rate, steer = (x[i] for i in range(N_STATES))
    steer_rate, long_force = u[0], u[1]
    c_yaw, s_yaw = ops.cos(yaw), ops.sin(yaw)
    vx = x_speed * c_yaw + y_speed * s_yaw
    vy = -x_speed * s_yaw + y_speed * c_yaw
    a, b = p.cg_to_front_m, p.cg_to_rear_m
    alpha_f = steer - ops.atan2(vy + a * yaw_rate, vx)
    alpha_r = -ops.atan2(vy - b * yaw_rate, vx)
    brake, drive = split_force(long_force)
    fx_f = p.brake_front_share * brake
    fx_r = drive + (1.0 - p.brake_front_share) * brake
    c_st, s_st = ops.cos(steer), ops.sin(steer)
    cf, cr = p.cornering_stiffness_front_npr, p.cornering_stiffness_rear_npr
    fy_f = tyre_lateral_force(alpha_f, cf, mu, p.slip_angle_sat_rad)
    fy_r = tyre_lateral_force(alpha_r, cr, mu, p.slip_angle_sat_rad)
    if not (isinstance(tyre_blend, float) and tyre_blend == 0.0):
        load_f, load_r = axle_loads((fx_r + fx_f * c_st) / p.mass_kg, p)
        peak_f = _derated_peak(mu * load_f, fx_f)
        peak_r = _derated_peak(mu * load_r, fx_r)
        fy_f += tyre_blend * (fiala_lateral_force(ops.tan(alpha_f), cf, peak_f, ops) - fy_f)
        fy_r += tyre_blend * (fiala_lateral_force(ops.tan(alpha_r), cr, peak_r, ops) - fy_r)
    force_x = fx_r + fx_f * c_st - fy_f * s_st  # eq. 1
    force_y = fy_r + fx_f * s_st + fy_f * c_st  # eq. 2
    moment = a * (fy_f * c_st + fx_f * s_st) - b * fy_r  # eq. 3
    m = p.mass_kg
    ax, ay = force_x / m, force_y / m
    fz_f, fz_r = axle_loads(ax, p)
    xdot = [
        x_speed,  # eq. 15
        ax * c_yaw - ay * s_yaw,  # eq. 16
        y_speed,  # eq. 17
        ax * s_yaw + ay * c_yaw,  # eq. 18
        yaw_rate,  # eq. 19
        moment / p.yaw_inertia_kgm2,  # eq. 20
        steer_rate,
    ]
    out = ModelOutputs(
        ax_body_mps2=ax,
        ay_body_mps2=ay,
        vx_body_mps=vx,
        alpha_front_rad=alpha_f,
        alpha_rear_rad=alpha_r,
        fy_front_n=fy_f,
        fy_rear_n=fy_r,
        ellipse_front=(fx_f**2 + fy_f**2) / (mu * fz_f) ** 2,
        ellipse_rear=(fx_r**2 + fy_r**2) / (mu * fz_r) ** 2,
    )
    return xdot, out
