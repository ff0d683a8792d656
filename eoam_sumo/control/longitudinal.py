"""Longitudinal control: acceleration PID during the EOAM, speed PID otherwise (paper sec. 9).

During the lane change the reference is the optimised longitudinal acceleration of the lookup
table at the current differential x-position (eqs. 14-29 offline); outside it a speed PID
holds the set speed, standing in for the high-level ARV system. Both act on a net longitudinal
force ``m_eq a + F_res(v)`` that is split into a drive force (>= 0) and a brake force (>= 0),
never both. ``m_eq = m + sum(J_w) / r_w^2`` (``equivalent_mass_kg``): the plant's wheels spin up
and down with the car, so a brake (or drive) force referred to the road moves the body by
``m a`` only after ``J_w a / r_w^2`` per wheel has decelerated (accelerated) the wheel itself.

Force limits (``limits``): the ego has no ABS and no traction control, so the controller itself
must never ask for a force that locks or spins a wheel. The brake force is at most the largest
straight-line force that locks no axle (eq. 33's deceleration times m), as a command: the
wheels' inertia takes its share of it, which leaves the tyres a margin against the front
axle's load-sensitive peak on low friction, where eq. 33's margin is thin; the drive force at
most eq. 37 (mu times the engine limit) and a share of the rear axle's static friction. Both shrink
with the friction ellipse sqrt(1 - q^2), q = margin |a_y| / (mu g), so that the lateral
acceleration in use keeps its tyre force: a locked or spinning axle has none, and a saturated
rear axle spins the car.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from mypy_extensions import mypyc_attr

from eoam_sumo.control.brake_split import BrakeSplit
from eoam_sumo.params import (
    AIR_DENSITY_KGPM3,
    G_MPS2,
    VehicleParams,
    equivalent_mass_kg,
)


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class LongitudinalGains:
    """PID gains and limits of the two longitudinal loops (acceleration in m/s^2 units)."""

    accel_kp: float = 0.6  # [-] per m/s^2 of acceleration error
    accel_ki_per_s: float = 3.0  # [1/s]
    accel_kd_s: float = 0.01  # [s]
    accel_integral_limit_mps2: float = 3.0  # integrator clamp [m/s^2]
    speed_kp_per_s: float = 1.5  # [1/s] acceleration demand per m/s of speed error
    speed_ki_per_s2: float = 0.1  # [1/s^2]
    speed_kd: float = 0.05  # [-] per m/s^2 of speed-error rate
    speed_integral_limit_mps2: float = 1.0  # integrator clamp [m/s^2]
    speed_accel_limit_g: float = 0.25  # |demand| <= this * mu * g (comfort, traction) [-]
    ellipse_margin: float = 1.1  # |a_y| inflated by this in the friction-ellipse caps [-]
    traction_fraction: float = 0.8  # drive <= this * mu * static rear axle load [-]
    wheel_lock_fraction: float = 0.95  # brake <= this * the split's wheel-lock force, no ABS [-]

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"longitudinal gain {f.name}={v!r} must be finite and >= 0")
        for name in (
            "speed_accel_limit_g",
            "ellipse_margin",
            "traction_fraction",
            "wheel_lock_fraction",
        ):
            if getattr(self, name) <= 0.0:
                raise ValueError(f"longitudinal gain {name} must be > 0")


class Pid:
    """Discrete PID on an error, derivative on the error, clamped conditional integration."""

    __slots__ = ("i_limit", "integral", "kd", "ki", "kp", "prev_error")

    def __init__(self, kp: float, ki: float, kd: float, i_limit: float):
        self.kp, self.ki, self.kd, self.i_limit = kp, ki, kd, i_limit
        self.prev_error: float | None = None
        self.reset()

    def reset(self) -> None:
        self.integral = 0.0
        self.prev_error = None

    def update(self, error: float, dt_s: float, lo: float, hi: float) -> float:
        """Output clipped to [lo, hi]; the integrator does not wind up against the clip."""
        deriv = 0.0 if self.prev_error is None or dt_s <= 0.0 else (error - self.prev_error) / dt_s
        self.prev_error = error
        trial = self.integral + self.ki * error * dt_s
        trial = min(max(trial, -self.i_limit), self.i_limit)
        out = self.kp * error + trial + self.kd * deriv
        if out > hi:
            if error < 0.0:
                self.integral = trial
            return hi
        if out < lo:
            if error > 0.0:
                self.integral = trial
            return lo
        self.integral = trial
        return out


class LongitudinalController:
    """Acceleration and speed PIDs producing (drive_force_n, brake_force_n)."""

    __slots__ = (
        "_abs",
        "_accel",
        "_alim_g",
        "_brake_split",
        "_drag",
        "_fmax",
        "_lock",
        "_m",
        "_margin",
        "_pmax",
        "_rear_n",
        "_res0",
        "_speed",
    )

    def __init__(self, params: VehicleParams, gains: LongitudinalGains = LongitudinalGains()):
        g = gains
        self._m = equivalent_mass_kg(params)
        self._res0 = params.mass_kg * G_MPS2 * params.rolling_resistance_coeff
        self._drag = 0.5 * AIR_DENSITY_KGPM3 * params.drag_area_m2
        self._fmax = params.max_drive_force_n
        self._pmax = params.max_drive_power_w
        self._rear_n = (
            g.traction_fraction
            * params.mass_kg
            * G_MPS2
            * params.cg_to_front_m
            / params.wheelbase_m
        )
        self._margin = g.ellipse_margin / G_MPS2
        self._accel = Pid(g.accel_kp, g.accel_ki_per_s, g.accel_kd_s, g.accel_integral_limit_mps2)
        self._speed = Pid(
            g.speed_kp_per_s, g.speed_ki_per_s2, g.speed_kd, g.speed_integral_limit_mps2
        )
        self._alim_g = g.speed_accel_limit_g * G_MPS2
        self._abs, self._lock = params.abs_fitted, g.wheel_lock_fraction
        self._brake_split = BrakeSplit(params)

    def reset(self) -> None:
        """Clear both integrators (called at every switch of longitudinal loop)."""
        self._accel.reset()
        self._speed.reset()

    def resistance_n(self, speed_mps: float) -> float:
        """Rolling resistance plus aerodynamic drag at a forward speed [N] (feedforward)."""
        v = speed_mps
        return self._res0 + self._drag * v * v if v > 0.0 else 0.0

    def wheel_lock_limit_n(self, speed_mps: float, mu: float, lateral_accel_mps2: float) -> float:
        """``wheel_lock_fraction`` of the brake command that locks an axle's inner wheel on
        the fixed brake split at this lateral acceleration (``brake_split``); ``math.inf``
        with ABS, which modulates a wheel's pressure at its peak slip itself."""
        if self._abs:
            return math.inf
        q = self._margin * abs(lateral_accel_mps2) / mu
        res = self.resistance_n(speed_mps)
        lock = self._brake_split.limit_n(mu, lateral_accel_mps2, res, q, self._m)
        return self._lock * lock

    def limits(
        self, speed_mps: float, mu: float, lateral_accel_mps2: float, no_lock_brake_n: float
    ) -> tuple[float, float]:
        """(drive, brake) force limits at this speed, friction and lateral acceleration: the
        brake within the friction ellipse and below ``wheel_lock_limit_n``."""
        q = self._margin * abs(lateral_accel_mps2) / mu
        ellipse = math.sqrt(1.0 - q * q) if q < 1.0 else 0.0
        drive = self._fmax
        if speed_mps > 1.0:
            drive = min(drive, self._pmax / speed_mps)  # power-limited
        drive = min(drive, self._rear_n)  # traction-limited
        drive = mu * drive
        lock = self.wheel_lock_limit_n(speed_mps, mu, lateral_accel_mps2)
        return drive * ellipse, min(no_lock_brake_n * ellipse, lock)

    @staticmethod
    def split(net_force_n: float, drive_limit_n: float, brake_limit_n: float):
        """(drive, brake) realising a net force within the limits; never both."""
        if net_force_n > 0.0:
            return min(net_force_n, drive_limit_n), 0.0
        return 0.0, min(-net_force_n, brake_limit_n)

    def track_accel(
        self,
        ax_ref: float,
        ax_mps2: float,
        speed_mps: float,
        drive_limit_n: float,
        brake_limit_n: float,
        dt_s: float,
    ):
        """Acceleration PID with feedforward m_eq ax_ref + F_res: (drive, brake)."""
        m = self._m
        res = self.resistance_n(speed_mps)
        lo = -(brake_limit_n + res) / m - ax_ref
        hi = (drive_limit_n - res) / m - ax_ref
        corr = self._accel.update(ax_ref - ax_mps2, dt_s, lo, max(hi, lo))
        return self.split(m * (ax_ref + corr) + res, drive_limit_n, brake_limit_n)

    def track_speed(
        self,
        speed_ref_mps: float,
        speed_mps: float,
        mu: float,
        drive_limit_n: float,
        brake_limit_n: float,
        dt_s: float,
    ):
        """Speed PID giving an acceleration demand (|a| <= limit * mu * g): (drive, brake, a)."""
        lim = self._alim_g * mu
        a = self._speed.update(speed_ref_mps - speed_mps, dt_s, -lim, lim)
        drive, brake = self.split(
            self._m * a + self.resistance_n(speed_mps), drive_limit_n, brake_limit_n
        )
        return drive, brake, a
