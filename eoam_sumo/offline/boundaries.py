"""DMM phase-diagram boundaries: stopping and minimum clearing distances, buffers (eqs. 30-34).

Clearing distance (eqs. 30-32): the longitudinal distance, from the ego's centre of gravity at
the trigger, at which the ego's front right body corner first reaches the lateral position of
the rear left corner of an obstacle of width ``obstacle_width_m`` centred in the ego's lane
(left lane change). As in eq. 32 it is measured from the CG: compared with the bumper-to-bumper
radar range it therefore carries the CG-to-front-bumper distance d_f as an implicit margin.
d_f is ``VehicleParams.cg_to_front_bumper_m`` (the body corner, not the axle).

Stopping distance (eq. 33): v^2 / (2 a) with a the largest straight-line deceleration without
locking an axle (no ABS); no reaction or actuator-delay term (the braking buffer carries it).
"""

from __future__ import annotations

import math

import numpy as np

from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.inverse import inverse_dynamics
from eoam_sumo.offline.quintic import quintic_path
from eoam_sumo.params import G_MPS2, VehicleParams


def max_decel_no_lock_mps2(params: VehicleParams, mu: float) -> float:
    """Largest straight-line deceleration without locking an axle (eq. 33's x''_max decel).

    With the fixed front brake share phi and the load transfer m a h / L, the front axle
    locks when phi m a > mu m (g b + a h) / L and the rear when (1 - phi) m a >
    mu m (g a_f - a h) / L; the brake force limit caps both. The result is below mu g unless
    the split happens to be ideal for this mu.
    """
    if not (math.isfinite(mu) and mu > 0.0):
        raise ValueError(f"mu={mu!r} must be finite and > 0")
    p = params
    phi, h, wb = p.brake_front_share, p.cg_height_m, p.wheelbase_m
    limits = [p.max_brake_force_n / p.mass_kg]
    rear = mu * G_MPS2 * p.cg_to_front_m / ((1.0 - phi) * wb + mu * h)
    limits.append(rear)
    if phi * wb > mu * h:  # otherwise the front axle can never lock
        limits.append(mu * G_MPS2 * p.cg_to_rear_m / (phi * wb - mu * h))
    return min(limits)


def stop_distance_m(speed_mps: float, decel_mps2: float) -> float:
    """Straight-line stopping distance v^2 / (2 a) (eq. 33)."""
    if not decel_mps2 > 0.0:
        raise ValueError(f"decel_mps2={decel_mps2!r} must be > 0")
    return speed_mps * speed_mps / (2.0 * decel_mps2)


def clearing_distance_m(x_m, y_m, yaw_rad, params: VehicleParams, obstacle_width_m: float) -> float:
    """Minimum clearing distance of a sampled trajectory (eqs. 30-32).

    ``x_m``, ``y_m`` (CG, from the CG at the trigger) and ``yaw_rad`` (body heading Psi) are
    time-ordered samples. The clearance of eq. 30, y + d_f sin Psi - (w_ego / 2) cos Psi -
    w_obj / 2, is zero at t_c (eq. 31), found by linear interpolation between samples;
    x_clearance = x + d_f cos Psi + (w_ego / 2) sin Psi at t_c (eq. 32).
    """
    x, y, yaw = (np.asarray(a, dtype=float) for a in (x_m, y_m, yaw_rad))
    d_f, half_w = params.cg_to_front_bumper_m, 0.5 * params.width_m
    clearance = y + d_f * np.sin(yaw) - half_w * np.cos(yaw) - 0.5 * obstacle_width_m
    corner_x = x + d_f * np.cos(yaw) + half_w * np.sin(yaw)
    hits = np.flatnonzero(clearance >= 0.0)
    if hits.size == 0:
        raise ValueError("the trajectory never clears the obstacle's corner")
    i = int(hits[0])
    if i == 0:
        return float(corner_x[0])
    w = -clearance[i - 1] / (clearance[i] - clearance[i - 1])
    return float(corner_x[i - 1] + w * (corner_x[i] - corner_x[i - 1]))


def constant_speed_clearing_distance_m(
    speed_mps: float, mu: float, params: VehicleParams, settings: DesignSettings
) -> float:
    """Clearing distance of the quintic lane change at constant speed (Figure 11's curve).

    The body heading is the path yaw less the sideslip from the inverse dynamics.
    """
    path = quintic_path(
        speed_mps, settings.quintic_time_s(mu), settings.lane_change_m, samples=2001
    )
    inv = inverse_dynamics(path, params, mu)
    return clearing_distance_m(path.x_m, path.y_m, inv.yaw_rad, params, settings.obstacle_width_m)


def steer_buffered_m(clear_m: float, speed_mps: float, settings: DesignSettings) -> float:
    """Buffered steering boundary Sb = S + t_s v + c_s (sec. 6.2)."""
    return clear_m + settings.steer_buffer_time_s * speed_mps + settings.steer_buffer_m


def stop_buffered_m(stop_m: float, speed_mps: float, settings: DesignSettings) -> float:
    """Buffered braking boundary Bb = B0 + t_b v + c_b (sec. 6.2)."""
    return stop_m + settings.brake_buffer_time_s * speed_mps + settings.brake_buffer_m
