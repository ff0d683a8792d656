"""Quintic single-lane-change path and its arc-length parameterisation (paper eqs. 7-13).

The lateral position is the fifth-order polynomial y(t) = h (10 tau^3 - 15 tau^4 + 6 tau^5),
tau = t / T, with zero lateral speed and acceleration at both ends (sec. 4.2), driven at the
constant entry speed v, so x(t) = v t. Its peak lateral acceleration is 5.77 h / T^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# Gauss-Legendre 3-point nodes and weights on [0, 1] (exact for polynomials of degree 5).
_GL_NODES = np.array([0.5 - math.sqrt(0.15), 0.5, 0.5 + math.sqrt(0.15)])
_GL_WEIGHTS = np.array([5.0, 8.0, 5.0]) / 18.0


def quintic_lateral(t_s, duration_s: float, height_m: float):
    """Lateral position and its first three time derivatives of the quintic lane change.

    ``t_s`` is clipped to [0, T]; returns (y, y', y'', y''') as numpy arrays (eq. 7, y part).
    """
    if not (duration_s > 0.0 and math.isfinite(duration_s)):
        raise ValueError(f"duration_s={duration_s!r} must be finite and > 0")
    tau = np.clip(np.asarray(t_s, dtype=float) / duration_s, 0.0, 1.0)
    t2, t3 = tau * tau, tau * tau * tau
    y = height_m * t3 * (10.0 - 15.0 * tau + 6.0 * t2)
    dy = height_m / duration_s * 30.0 * t2 * (1.0 - tau) ** 2
    ddy = height_m / duration_s**2 * 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau)
    dddy = height_m / duration_s**3 * 60.0 * (1.0 - 6.0 * tau + 6.0 * t2)
    return y, dy, ddy, dddy


@dataclass(frozen=True)
class ArcLengthPath:
    """The quintic sampled in time with its arc length, yaw and curvature (eqs. 8-13).

    Arrays share one index: ``t_s`` time, ``s_m`` arc length (eq. 8), ``x_m``/``y_m`` position
    (eqs. 11-12), ``theta_rad`` path yaw (eq. 10), ``curvature_1pm`` signed curvature K(s),
    positive to the left (eq. 9 without the absolute value, K = 1/R eq. 13),
    ``dcurvature_1pm2`` its arc-length derivative dK/ds.
    """

    speed_mps: float
    duration_s: float
    height_m: float
    t_s: np.ndarray
    s_m: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    theta_rad: np.ndarray
    curvature_1pm: np.ndarray
    dcurvature_1pm2: np.ndarray

    @property
    def length_m(self) -> float:
        return float(self.s_m[-1])


def quintic_path(
    speed_mps: float, duration_s: float, height_m: float, samples: int = 1001
) -> ArcLengthPath:
    """Quintic lane change at constant speed, parameterised in arc length (eqs. 7-13)."""
    if not (speed_mps > 0.0 and math.isfinite(speed_mps)):
        raise ValueError(f"speed_mps={speed_mps!r} must be finite and > 0")
    if samples < 3:
        raise ValueError(f"samples={samples} must be >= 3")
    t = np.linspace(0.0, duration_s, samples)
    y, dy, ddy, dddy = quintic_lateral(t, duration_s, height_m)
    v = float(speed_mps)
    # eq. 8: s(t) = int |(x', y')| dt, per sample interval by 3-point Gauss-Legendre.
    h = np.diff(t)
    tq = t[:-1, None] + h[:, None] * _GL_NODES[None, :]
    dyq = quintic_lateral(tq, duration_s, height_m)[1]
    seg = h * (np.sqrt(v * v + dyq * dyq) @ _GL_WEIGHTS)
    s = np.concatenate(([0.0], np.cumsum(seg)))
    speed2 = v * v + dy * dy
    # eq. 9 (signed): K = (x' y'' - y' x'') / (x'^2 + y'^2)^(3/2) with x' = v, x'' = 0.
    curvature = v * ddy / speed2**1.5
    dk_dt = v * dddy / speed2**1.5 - 3.0 * v * ddy * ddy * dy / speed2**2.5
    return ArcLengthPath(
        speed_mps=v,
        duration_s=float(duration_s),
        height_m=float(height_m),
        t_s=t,
        s_m=s,
        x_m=v * t,
        y_m=y,
        theta_rad=np.arctan2(dy, v),
        curvature_1pm=curvature,
        dcurvature_1pm2=dk_dt / np.sqrt(speed2),
    )
