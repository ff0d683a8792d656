"""Steering control: feedforward + lookahead feedback + yaw damping (paper eq. 38).

* Feedforward from the reference curvature kappa (path plus road) with the steady-state
  understeer of the single-track model: delta_ff = (L + K_us v^2) kappa, where
  K_us = m (b / C_f - a / C_r) / L [rad per m/s^2] (Gillespie 1992, eq. 6-29).
* Feedback on the lookahead error e_la = e + x_la sin(e_psi) (lateral error plus lookahead
  distance times heading error), the potential-field lane keeping of Rossetter & Gerdes (2006)
  and Talvala & Gerdes (2008): delta_fb = -k_la e_la.
* Yaw damping on the yaw-rate error against the path: delta_yd = -k_r (r - v kappa).

Gain schedule. With the kinematic lateral response e'' = v^2 delta / (L + K_us v^2), the
feedback alone gives e'' + (v k_la x_la / L_eff) e' + (v^2 k_la / L_eff) e = 0; choosing
k_la = omega^2 L_eff / v^2 and x_la = 2 zeta v / omega makes the error dynamics a second-order
system of natural frequency omega and damping ratio zeta. omega is scheduled on friction and
speed: omega = omega_0 mu^p min(1, v / v_full). The friction factor keeps the loop inside what
the tyres give (the friction-limited path is itself slower); the speed factor
keeps the spatial bandwidth omega / v bounded at low speed, where a fixed omega would ask for
heading angles of tens of degrees. The schedule speed is floored to keep the gains finite.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import NamedTuple

from eoam_sumo.params import VehicleParams


@dataclass(frozen=True)
class SteeringGains:
    """Design values of the steering schedule."""

    natural_freq_radps: float = 2.2  # omega_0, at mu = 1 and v >= v_full [rad/s]
    damping_ratio: float = 1.5  # zeta [-]
    min_lookahead_m: float = 4.0  # floor of x_la [m]
    schedule_min_speed_mps: float = 5.0  # speed floor used in the schedule [m/s]
    full_bandwidth_speed_mps: float = 15.0  # v_full: omega falls linearly below it [m/s]
    yaw_damping_s: float = 0.22  # k_r [rad per rad/s]
    friction_exponent: float = 0.25  # p: omega scales with mu^p [-]

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"steering gain {f.name}={v!r} must be finite and >= 0")
        for name in (
            "natural_freq_radps",
            "damping_ratio",
            "schedule_min_speed_mps",
            "full_bandwidth_speed_mps",
        ):
            if getattr(self, name) <= 0.0:
                raise ValueError(f"steering gain {name} must be > 0")


class SteeringCommand(NamedTuple):
    """The road-wheel angle of eq. 38 and its parts (left positive)."""

    steer_rad: float  # feedforward + feedback + yaw damping, clipped to the lock
    feedforward_rad: float
    feedback_rad: float
    yaw_damping_rad: float
    lookahead_error_m: float  # the feedback's error e_la


_new = tuple.__new__  # builds the per-step SteeringCommand in half its constructor's time


def understeer_gradient(params: VehicleParams) -> float:
    """K_us = m (b / C_f - a / C_r) / L [rad per m/s^2] (axle cornering stiffnesses)."""
    return (
        params.mass_kg
        * (
            params.cg_to_rear_m / params.cornering_stiffness_front_npr
            - params.cg_to_front_m / params.cornering_stiffness_rear_npr
        )
        / params.wheelbase_m
    )


class SteeringController:
    """Eq. 38 steering law; ``command`` returns the clipped road-wheel angle and its parts."""

    __slots__ = (
        "_L",
        "_b",
        "_fexp",
        "_kr",
        "_kus",
        "_max",
        "_mu",
        "_slip_k",
        "_vfull",
        "_vmin",
        "_w",
        "_wmu",
        "_xmin",
        "_z",
    )

    def __init__(self, params: VehicleParams, gains: SteeringGains = SteeringGains()):
        self._L = params.wheelbase_m
        self._kus = understeer_gradient(params)
        self._b = params.cg_to_rear_m
        self._slip_k = params.mass_kg * params.cg_to_front_m / (
            params.wheelbase_m * params.cornering_stiffness_rear_npr
        )
        self._max = params.max_steer_rad
        self._w = gains.natural_freq_radps
        self._z = gains.damping_ratio
        self._xmin = gains.min_lookahead_m
        self._vmin = gains.schedule_min_speed_mps
        self._vfull = gains.full_bandwidth_speed_mps
        self._kr = gains.yaw_damping_s
        self._fexp = gains.friction_exponent
        self._mu = -1.0
        self._wmu = self._w

    def natural_freq(self, speed_mps: float, mu: float) -> float:
        """omega = omega_0 mu^p min(1, v / v_full) [rad/s], v floored."""
        if mu != self._mu:
            self._mu = mu
            self._wmu = self._w * mu**self._fexp
        v = speed_mps if speed_mps > self._vmin else self._vmin
        return self._wmu * v / self._vfull if v < self._vfull else self._wmu

    def schedule(self, speed_mps: float, mu: float) -> tuple[float, float]:
        """(k_la [rad/m], x_la [m]) at this speed and friction."""
        w = self.natural_freq(speed_mps, mu)
        v = speed_mps if speed_mps > self._vmin else self._vmin
        x_la = 2.0 * self._z * v / w
        if x_la < self._xmin:
            x_la = self._xmin
        return w * w * (self._L + self._kus * v * v) / (v * v), x_la

    def steady_sideslip(self, speed_mps: float, curvature_1pm: float) -> float:
        """Body sideslip angle [rad] of steady cornering on a curvature (linear bicycle model):
        kappa (b - m a v^2 / (L C_r)), a and b the CG's distances to the axles; its negative is
        the heading the body keeps off the path tangent."""
        return curvature_1pm * (self._b - self._slip_k * speed_mps * speed_mps)

    def lateral_accel(self, speed_mps: float, steer_rad: float) -> float:
        """Steady-state lateral acceleration v^2 delta / (L + K_us v^2) a steer angle asks for."""
        return speed_mps * speed_mps * steer_rad / (self._L + self._kus * speed_mps * speed_mps)

    def command(
        self,
        speed_mps: float,
        yaw_rate_radps: float,
        lateral_error_m: float,
        heading_error_rad: float,
        curvature_1pm: float,
        preview_curvature_1pm: float,
        mu: float,
    ) -> SteeringCommand:
        """The steering command; delta clipped to the lock.

        ``lateral_error_m`` and ``heading_error_rad`` are ego minus reference (left positive);
        ``curvature_1pm`` is the reference curvature here (path plus road, left positive), the
        yaw-rate reference; ``preview_curvature_1pm`` the one a preview distance ahead, used by
        the feedforward to make up for the steering and tyre lags.
        """
        v = speed_mps if speed_mps > 0.0 else 0.0
        k_la, x_la = self.schedule(v, mu)
        e_la = lateral_error_m + x_la * math.sin(heading_error_rad)
        ff = (self._L + self._kus * v * v) * preview_curvature_1pm
        fb = -k_la * e_la
        yd = -self._kr * (yaw_rate_radps - v * curvature_1pm)
        delta = ff + fb + yd
        lim = self._max
        if delta > lim:
            delta = lim
        elif delta < -lim:
            delta = -lim
        return _new(SteeringCommand, (delta, ff, fb, yd, e_la))
