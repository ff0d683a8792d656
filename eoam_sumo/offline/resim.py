"""Independent check of each optimal lane change: re-simulation and constraint audit.

The optimal piecewise-constant controls are re-applied to the design model
(``model.dynamics`` with the ``math`` module) and integrated by an adaptive explicit
Runge-Kutta method of order 8 (scipy DOP853), independent of the collocation used by the
optimiser. The dense result is audited against the constraints of eqs. 23-29 and the
imposed final conditions; any breach raises ``OcpError`` naming the speed and friction.
The audited re-simulation is also what the lookup tables and the clearing distances use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.model import dynamics, split_force
from eoam_sumo.offline.ocp import OcpError, OcpSolution
from eoam_sumo.params import VehicleParams

_RTOL = 1e-9
_ATOL = 1e-9


@dataclass(frozen=True)
class Resimulation:
    """Dense re-simulated lane change: arrays on one time index."""

    speed_mps: float
    mu: float
    t_s: np.ndarray
    states: np.ndarray  # (M, 7) in model.STATE_NAMES order
    controls: np.ndarray  # (M, 2) the control acting at each sample (the later one at a step)
    ax_body_mps2: np.ndarray
    ay_body_mps2: np.ndarray
    vx_body_mps: np.ndarray
    ellipse_front: np.ndarray
    ellipse_rear: np.ndarray

    @property
    def distance_m(self) -> float:
        return float(self.states[-1, 0])


def resimulate(solution: OcpSolution, params: VehicleParams, max_spacing_m: float) -> Resimulation:
    """Integrate the optimal controls interval by interval; samples at most ``max_spacing_m``
    apart in x (and at least 8 per interval)."""
    n = solution.controls.shape[0]
    h = solution.duration_s / n
    per = max(8, math.ceil(solution.distance_m / (n * max_spacing_m)))
    mu, blend = solution.mu, solution.tyre_blend
    x = solution.states[0].astype(float)
    times, states, controls = [np.array([0.0])], [x[None, :]], [solution.controls[:1]]
    for k in range(n):
        u = solution.controls[k]
        t_eval = np.linspace(k * h, (k + 1) * h, per + 1)

        def rhs(_t, y, u=u):
            return dynamics(y, u, mu, params, math, blend)[0]

        res = solve_ivp(
            rhs, (k * h, (k + 1) * h), x, method="DOP853", t_eval=t_eval, rtol=_RTOL, atol=_ATOL
        )
        if not res.success:
            raise OcpError(
                f"re-simulation at mu={mu:g}, {solution.speed_mps * 3.6:g} km/h "
                f"failed in interval {k}: {res.message}"
            )
        x = res.y[:, -1]
        times.append(res.t[1:])
        states.append(res.y[:, 1:].T)
        controls.append(np.repeat(u[None, :], per, axis=0))
    t = np.concatenate(times)
    xs = np.vstack(states)
    us = np.vstack(controls)
    # at each interval start the state belongs to both intervals: audit it with the new control
    outs = [dynamics(xs[i], us[i], mu, params, math, blend)[1] for i in range(len(t))]
    starts = [
        dynamics(xs[k * per], solution.controls[k], mu, params, math, blend)[1] for k in range(n)
    ]
    ef = np.array([o.ellipse_front for o in outs])
    er = np.array([o.ellipse_rear for o in outs])
    ef[::per][:n] = np.maximum(ef[::per][:n], [o.ellipse_front for o in starts])
    er[::per][:n] = np.maximum(er[::per][:n], [o.ellipse_rear for o in starts])
    return Resimulation(
        speed_mps=solution.speed_mps,
        mu=mu,
        t_s=t,
        states=xs,
        controls=us,
        ax_body_mps2=np.array([o.ax_body_mps2 for o in outs]),
        ay_body_mps2=np.array([o.ay_body_mps2 for o in outs]),
        vx_body_mps=np.array([o.vx_body_mps for o in outs]),
        ellipse_front=ef,
        ellipse_rear=er,
    )


def audit(
    solution: OcpSolution, resim: Resimulation, params: VehicleParams, settings: DesignSettings
) -> None:
    """Check the re-simulation against every constraint; raise ``OcpError`` listing breaches."""
    checks = _final_checks(solution, resim, settings) + _limit_checks(
        solution, resim, params, settings
    )
    breaches = [
        f"{name} off by {value:.4g} {unit} (tolerance {tol:g})"
        for name, value, tol, unit in checks
        if not value <= tol
    ]
    if breaches:
        raise OcpError(
            f"optimal lane change at mu={solution.mu:g}, {solution.speed_mps * 3.6:g} km/h "
            "fails its re-simulation check: " + "; ".join(breaches)
        )


def _final_checks(solution: OcpSolution, resim: Resimulation, s: DesignSettings) -> list[tuple]:
    """(name, excess, tolerance, unit) of the imposed final conditions (eq. 23, settled in the
    next lane) and of the distance against the optimiser's."""
    end = resim.states[-1]
    return [
        ("final y (eq. 23)", abs(end[2] - s.lane_change_m), s.verify_lateral_tol_m, "m"),
        ("x(t_f) vs optimiser", abs(end[0] - solution.distance_m), s.verify_distance_tol_m, "m"),
        ("final lateral speed", abs(end[3]), s.verify_lat_speed_tol_mps, "m/s"),
        ("final yaw", abs(end[4]), s.verify_yaw_tol_rad, "rad"),
        ("final yaw rate", abs(end[5]), s.verify_yaw_rate_tol_radps, "rad/s"),
    ]


def _limit_checks(
    solution: OcpSolution, resim: Resimulation, p: VehicleParams, s: DesignSettings
) -> list[tuple]:
    """(name, excess, tolerance, unit) of the path constraints over the whole manoeuvre:
    friction ellipses (eqs. 25, 28), steering (eqs. 26-27), forces and power (eq. 29), and
    the speed floor."""
    brake, drive = split_force(resim.controls[:, 1])
    return [
        (
            "front friction ellipse (eqs. 25, 28)",
            resim.ellipse_front.max() - s.friction_use**2,
            s.verify_ellipse_tol,
            "-",
        ),
        (
            "rear friction ellipse (eq. 28)",
            resim.ellipse_rear.max() - s.friction_use**2,
            s.verify_ellipse_tol,
            "-",
        ),
        (
            "steering angle (eqs. 26-27)",
            np.abs(resim.states[:, 6]).max() - p.max_steer_rad,
            1e-6,
            "rad",
        ),
        (
            "steering rate",
            np.abs(resim.controls[:, 0]).max() - p.max_steer_rate_radps,
            1e-6,
            "rad/s",
        ),
        (
            "brake force",
            -brake.min() - p.max_brake_force_n,
            s.verify_ellipse_tol * p.max_brake_force_n,
            "N",
        ),
        (
            "drive force (eq. 29)",
            drive.max() - p.max_drive_force_n,
            s.verify_ellipse_tol * p.max_drive_force_n,
            "N",
        ),
        (
            "drive power (eq. 29)",
            (drive * resim.vx_body_mps).max() - p.max_drive_power_w,
            s.verify_ellipse_tol * p.max_drive_power_w,
            "W",
        ),
        (
            "speed floor",
            s.min_speed_fraction * solution.speed_mps - resim.vx_body_mps.min(),
            s.verify_lat_speed_tol_mps,
            "m/s",
        ),
    ]
