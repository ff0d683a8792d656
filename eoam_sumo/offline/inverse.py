"""Inverse dynamics along a lane-change path (paper sec. 4.4, Figures 6-7).

Given the path (curvature K(s) and its derivative) driven with its own speed profile, the
single-track model (eqs. 1-3) is solved for the axle lateral forces, the slip angles through
the friction-scaled linear-saturating tyre (eqs. 6, 35), the body sideslip beta and the
steering road-wheel angle. Quasi-steady: the sideslip rate is neglected, so the yaw rate is
r = V K and the heading Psi = theta - beta (a few fixed-point passes resolve the coupling
through beta and the steer angle). From the lateral
forces, the friction ellipse of each axle (with longitudinal load transfer), the brake split,
the brake force limit and the engine limit (eq. 29) give the least and the largest
longitudinal acceleration available at each point (Figure 7).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from eoam_sumo.offline.model import axle_loads
from eoam_sumo.offline.quintic import ArcLengthPath
from eoam_sumo.params import VehicleParams

_FIXED_POINT_ITERATIONS = 40


@dataclass(frozen=True)
class InverseDynamics:
    """Per-sample results along the path (arrays on the path's index)."""

    steer_rad: np.ndarray
    alpha_front_rad: np.ndarray
    alpha_rear_rad: np.ndarray
    fy_front_n: np.ndarray
    fy_rear_n: np.ndarray
    sideslip_rad: np.ndarray
    yaw_rad: np.ndarray  # vehicle heading Psi = theta - beta
    yaw_rate_radps: np.ndarray
    ax_min_mps2: np.ndarray  # NaN where the lateral demand alone exceeds the friction
    ax_max_mps2: np.ndarray
    feasible: np.ndarray  # bool: lateral forces within the tyre and the friction ellipse


def _inverse_tyre(force_n, cornering_npr: float, mu: float, alpha_sat_rad: float):
    """Slip angle giving ``force_n`` on the smoothed linear-saturating tyre; |q| clipped < 1."""
    q = np.clip(force_n / (mu * cornering_npr * alpha_sat_rad), -0.999, 0.999)
    return alpha_sat_rad * q / (1.0 - q**8) ** 0.125


def inverse_dynamics(path: ArcLengthPath, params: VehicleParams, mu: float) -> InverseDynamics:
    """Steering, slip angles, lateral forces and longitudinal-acceleration limits (Figs. 6-7)."""
    if not (0.0 < mu <= 1.5):
        raise ValueError(f"mu={mu!r} must be in (0, 1.5]")
    p = params
    m, iz, a, b, wb = p.mass_kg, p.yaw_inertia_kgm2, p.cg_to_front_m, p.cg_to_rear_m, p.wheelbase_m
    share = p.brake_front_share
    speed = np.gradient(path.s_m, path.t_s)
    accel_t = np.gradient(speed, path.t_s)
    accel_n = speed**2 * path.curvature_1pm
    yaw_rate = speed * path.curvature_1pm
    yaw_acc = accel_t * path.curvature_1pm + speed**2 * path.dcurvature_1pm2
    beta = np.zeros_like(speed)
    steer = np.zeros_like(speed)
    fy_f = np.zeros_like(speed)
    for _ in range(4):
        ax_b = accel_t * np.cos(beta) + accel_n * np.sin(beta)
        ay_b = -accel_t * np.sin(beta) + accel_n * np.cos(beta)
        f_long = m * ax_b + fy_f * np.sin(steer)
        brake = np.where(f_long < 0.0, -f_long / ((1.0 - share) + share * np.cos(steer)), 0.0)
        fx_f = -share * brake
        front_lat = (m * ay_b * b + iz * yaw_acc) / wb
        fy_r = (m * ay_b * a - iz * yaw_acc) / wb
        fy_f = (front_lat - fx_f * np.sin(steer)) / np.cos(steer)
        alpha_f = _inverse_tyre(fy_f, p.cornering_stiffness_front_npr, mu, p.slip_angle_sat_rad)
        alpha_r = _inverse_tyre(fy_r, p.cornering_stiffness_rear_npr, mu, p.slip_angle_sat_rad)
        beta = np.arcsin(np.clip(b * yaw_rate * np.cos(alpha_r) / speed, -1.0, 1.0)) - alpha_r
        steer = alpha_f + np.arctan2(speed * np.sin(beta) + a * yaw_rate, speed * np.cos(beta))
    peak = 0.999 * mu * p.slip_angle_sat_rad  # of the tyre force per unit cornering stiffness
    tyre_ok = (np.abs(fy_f) < peak * p.cornering_stiffness_front_npr) & (
        np.abs(fy_r) < peak * p.cornering_stiffness_rear_npr
    )
    ax_min, ax_max, ellipse_ok = _accel_limits(fy_f, fy_r, steer, speed, p, mu)
    feasible = tyre_ok & ellipse_ok
    return InverseDynamics(
        steer_rad=steer,
        alpha_front_rad=alpha_f,
        alpha_rear_rad=alpha_r,
        fy_front_n=fy_f,
        fy_rear_n=fy_r,
        sideslip_rad=beta,
        yaw_rad=path.theta_rad - beta,
        yaw_rate_radps=yaw_rate,
        ax_min_mps2=np.where(feasible, ax_min, np.nan),
        ax_max_mps2=np.where(feasible, ax_max, np.nan),
        feasible=feasible,
    )


def _accel_limits(fy_f, fy_r, steer, speed, p: VehicleParams, mu: float):
    """Least and largest body longitudinal acceleration with these lateral forces (Figure 7).

    Braking: the largest brake force (front share fixed) keeping both axles inside their
    friction ellipse and under the brake limit; drive: rear axle ellipse and engine limit.
    The loads depend on the acceleration (load transfer): solved by fixed-point iteration.
    """
    m, share = p.mass_kg, p.brake_front_share
    drag_lat = fy_f * np.sin(steer)
    c_st = np.cos(steer)

    def spare(fz, fy):
        return np.sqrt(np.maximum((mu * fz) ** 2 - fy**2, 0.0))

    ax_min = -drag_lat / m
    for _ in range(_FIXED_POINT_ITERATIONS):
        fz_f, fz_r = axle_loads(ax_min, p)
        brake = np.minimum.reduce(
            [
                spare(fz_f, fy_f) / share,
                spare(fz_r, fy_r) / (1.0 - share),
                np.full_like(fy_f, p.max_brake_force_n),
            ]
        )
        ax_min = (-(1.0 - share) * brake - share * brake * c_st - drag_lat) / m
    engine = np.minimum(p.max_drive_force_n, p.max_drive_power_w / np.maximum(speed, 1e-3))
    ax_max = -drag_lat / m
    for _ in range(_FIXED_POINT_ITERATIONS):
        fz_f, fz_r = axle_loads(ax_max, p)
        ax_max = (np.minimum(spare(fz_r, fy_r), engine) - drag_lat) / m
    fz_f0, fz_r0 = axle_loads(-drag_lat / m, p)  # no longitudinal tyre force
    ellipse_ok = (np.abs(fy_f) <= mu * fz_f0) & (np.abs(fy_r) <= mu * fz_r0)
    return ax_min, ax_max, ellipse_ok
