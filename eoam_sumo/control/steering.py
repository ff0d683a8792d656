"""Steering control: feedforward + state feedback on the single-track model (paper eq. 38).

* Feedforward from the reference curvature kappa (path plus road, taken a preview distance
  ahead) with the steady-state understeer of the single-track model:
  delta_ff = (L + K_us v^2) kappa, K_us = m (b / C_f - a / C_r) / L [rad per m/s^2]
  (Gillespie 1992, eq. 6-29).
* Feedback on the deviation from steady cornering on the reference (Rajamani 2012, sec. 3.2):
  lateral error e, heading error psi~ = psi - (theta_ref - beta_ss), lateral-velocity error
  vy - v beta_ss and yaw-rate error r - v kappa, with beta_ss the body sideslip of steady
  cornering on kappa. The body heading of a car following a path is its course less its
  sideslip; comparing the course (direction of travel) with the path's course, not the body
  heading, removes the apparent error the sideslip (0.04 rad at 120 km/h on a dry lane
  change) would make at the look-ahead distance. The equivalent look-ahead error
  e + (k_psi / k_e) psi~ is logged.

On a planned manoeuvre (the lookup tables' lane change, planned with the plant's tyre) the
feedforward is the plan's own road-wheel angle taken a little ahead and the reference sideslip
is the plan's (``command``'s ``planned_steer_rad``, ``sideslip_rad``); the curvature it is given
is then the plan's body yaw per metre (``PathReference``), so v kappa is the plan's body yaw
rate, its course rate less its sideslip's rate.

Gains by pole placement (Ackermann's formula) on the linear single-track model with states
(vy, r, psi, e) at each speed: the path-following pair at s^2 + 2 zeta omega s + omega^2 with
omega = omega_0 mu^p min(1, v / v_full) (the friction factor keeps the feedback inside what
the tyres give, the speed factor keeps the spatial bandwidth omega / v bounded at low speed),
the body (sideslip and yaw) pair where the car has it, its damping raised to at least
``body_damping_ratio``. Gains are tabulated once per friction on a speed grid and blended
linearly in between.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np
from mypy_extensions import mypyc_attr

from eoam_sumo.params import VehicleParams


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class SteeringGains:
    """Design values of the steering schedule."""

    natural_freq_radps: float = 6  # omega_0, path pair at mu = 1 and v >= v_full [rad/s]
    damping_ratio: float = 1.0  # zeta of the path pair [-]
    body_damping_ratio: float = 0.8  # least damping of the body pair [-]
    schedule_min_speed_mps: float = 3.0  # gains below this speed are this speed's [m/s]
    full_bandwidth_speed_mps: float = 25  # v_full: omega falls linearly below it [m/s]
    friction_exponent: float = 0.5  # p: omega scales with mu^p [-]
    front_slip_fraction: float = 0.5  # front slip kept below this share of its peak [-]
    schedule_step_mps: float = 0.5  # speed step of the gain table [m/s]
    schedule_max_speed_mps: float = 80.0  # top of the gain table (held above) [m/s]

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"steering gain {f.name}={v!r} must be finite and >= 0")
        for name in (
            "natural_freq_radps",
            "damping_ratio",
            "body_damping_ratio",
            "schedule_min_speed_mps",
            "full_bandwidth_speed_mps",
            "schedule_step_mps",
        ):
            if getattr(self, name) <= 0.0:
                raise ValueError(f"steering gain {name} must be > 0")
        if self.schedule_max_speed_mps <= self.schedule_min_speed_mps:
            raise ValueError("schedule_max_speed_mps must exceed schedule_min_speed_mps")


class SteeringCommand(NamedTuple):
    """The road-wheel angle of eq. 38 and its parts (left positive)."""

    steer_rad: float  # feedforward + both feedbacks, clipped to the lock
    feedforward_rad: float  # (L + K_us v^2) kappa ahead
    feedback_rad: float  # on the lateral and heading errors
    body_feedback_rad: float  # on the lateral-velocity and yaw-rate errors (damping)
    lookahead_error_m: float  # the position feedback's error e + (k_psi / k_e) psi~


def axle_cornering_stiffness_npr(params: VehicleParams) -> tuple[float, float]:
    """(C_f, C_r) [N/rad]: the plant's linear axle cornering stiffnesses at the static axle
    loads. Its Magic Formula tyre's K_y alpha (Pacejka 2012 eq. 4.E25) at the static load is
    scaled (LKY) to the tyres' stiffness of the parameters, and the front axle's is that times
    the steering compliance (Gillespie 1992 ch. 6; ``VehicleParams.front_axle_stiffness_npr``),
    so the steering law sees the understeer the plant has."""
    return params.front_axle_stiffness_npr, params.cornering_stiffness_rear_npr


def understeer_gradient(params: VehicleParams) -> float:
    """K_us = m (b / C_f - a / C_r) / L [rad per m/s^2] (``axle_cornering_stiffness_npr``:
    ``VehicleParams.understeer_gradient_rad_per_mps2``)."""
    return params.understeer_gradient_rad_per_mps2


def single_track_matrices(params: VehicleParams, speed_mps: float):
    """(A, B) of the linear single-track model with states (vy, r, psi, e) about a straight
    path at ``speed_mps`` and input the road-wheel angle (``axle_cornering_stiffness_npr``)."""
    m, iz = params.mass_kg, params.yaw_inertia_kgm2
    a, b = params.cg_to_front_m, params.cg_to_rear_m
    (cf, cr), v = axle_cornering_stiffness_npr(params), speed_mps
    A = np.array(
        [
            [-(cf + cr) / (m * v), -(a * cf - b * cr) / (m * v) - v, 0.0, 0.0],
            [-(a * cf - b * cr) / (iz * v), -(a * a * cf + b * b * cr) / (iz * v), 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [1.0, 0.0, v, 0.0],
        ]
    )
    B = np.array([cf / m, a * cf / iz, 0.0, 0.0])
    return A, B


def place_poles(A: np.ndarray, B: np.ndarray, poles) -> np.ndarray:
    """State-feedback gains K (u = -K x) giving A - B K the ``poles`` (Ackermann's formula)."""
    powers = matrix_powers(A)
    return ackermann(powers, controllability(powers, B), poles)


def matrix_powers(A: np.ndarray) -> list[np.ndarray]:
    """A^0, A^1, ..., A^n of an n x n matrix."""
    return [np.linalg.matrix_power(A, k) for k in range(A.shape[0] + 1)]


def controllability(powers: list[np.ndarray], B: np.ndarray) -> np.ndarray:
    """The controllability matrix [B, A B, ..., A^(n-1) B] (``powers``: A^0 ... A^n)."""
    return np.column_stack([powers[k] @ B for k in range(len(powers) - 1)])


def ackermann(powers: list[np.ndarray], ctrb: np.ndarray, poles) -> np.ndarray:
    """Ackermann's formula: K = [0 ... 0 1] C^-1 phi(A), C the controllability matrix and phi
    the monic polynomial with roots ``poles`` (``powers``: A^0 ... A^n)."""
    n = len(powers) - 1
    coeffs = np.real(np.poly(poles))
    phi = sum(c * powers[n - i] for i, c in enumerate(coeffs))
    last = np.zeros(n)
    last[-1] = 1.0
    return last @ np.linalg.solve(ctrb, phi)


_Gains = tuple[float, float, float, float]
#: Gain tables by (vehicle parameters, gains, friction), shared by the runs of a process; a
#: row (one speed) is placed when first needed: an estimated friction takes many values a run.
_GAIN_TABLES: dict[tuple, list[_Gains | None]] = {}
_MAX_GAIN_TABLES = 512  # beyond this many frictions the tables are dropped (memory)
#: What a gain-table row needs that does not depend on the friction, by (vehicle parameters,
#: gains) and speed index: A's powers, the controllability matrix and the body poles. A new
#: friction (an estimate moves every update) then costs Ackermann's formula alone.
_SPEED_ROWS: dict[tuple, list[tuple | None]] = {}


class SteeringController:
    """Eq. 38 steering law; ``command`` returns the clipped road-wheel angle and its parts."""

    __slots__ = (
        "_L",
        "_a",
        "_b",
        "_gains",
        "_kus",
        "_max",
        "_params",
        "_preview_s",
        "_rows",
        "_slip_frac",
        "_slip_k",
        "_speeds",
        "_table",
        "_table_mu",
        "_vmin",
    )

    def __init__(
        self,
        params: VehicleParams,
        gains: SteeringGains = SteeringGains(),
        preview_time_s: float = 0.0,
    ):
        """``preview_time_s``: how far ahead ``command``'s preview curvature is taken (0:
        the yaw-rate reference leaves out the steady sideslip's rate)."""
        self._params = params
        self._preview_s = preview_time_s
        self._gains = gains
        self._L = params.wheelbase_m
        self._kus = understeer_gradient(params)
        self._b = params.cg_to_rear_m
        self._a = params.cg_to_front_m
        # Fiala: the front force peaks at tan(alpha) = 3 mu Fz_f / C_f (the plant's Magic
        # Formula at 2.34 PCY1 mu Fz_f / C_f, 5 % further); keep to a share of it
        fz_front = params.mass_kg * 9.81 * params.cg_to_rear_m / params.wheelbase_m
        c_f, c_r = axle_cornering_stiffness_npr(params)
        self._slip_frac = gains.front_slip_fraction * 3.0 * fz_front / c_f
        self._slip_k = params.mass_kg * params.cg_to_front_m / (params.wheelbase_m * c_r)
        self._max = params.max_steer_rad
        self._vmin = gains.schedule_min_speed_mps
        n = math.ceil((gains.schedule_max_speed_mps - self._vmin) / gains.schedule_step_mps)
        self._speeds = [self._vmin + i * gains.schedule_step_mps for i in range(n + 1)]
        self._table_mu = math.nan
        self._table: list[_Gains | None] = []
        key = (params, gains)
        if key not in _SPEED_ROWS:
            if len(_SPEED_ROWS) >= _MAX_GAIN_TABLES:
                _SPEED_ROWS.clear()
            _SPEED_ROWS[key] = [None] * len(self._speeds)
        self._rows = _SPEED_ROWS[key]

    def natural_freq(self, speed_mps: float, mu: float) -> float:
        """omega = omega_0 mu^p min(1, v / v_full) [rad/s], v floored."""
        g = self._gains
        v = max(self._vmin, speed_mps)
        return (
            g.natural_freq_radps
            * mu**g.friction_exponent
            * min(1.0, v / g.full_bandwidth_speed_mps)
        )

    def design_poles(self, speed_mps: float, mu: float) -> np.ndarray:
        """The closed-loop poles the gains place at this speed and friction."""
        v = max(speed_mps, self._vmin)
        A, _ = single_track_matrices(self._params, v)
        return np.array(self._path_poles(v, mu) + self._body_poles(A))

    def _path_poles(self, v: float, mu: float) -> list:
        """The path-following pair at s^2 + 2 zeta omega s + omega^2 (``natural_freq``)."""
        w = self.natural_freq(v, mu)
        z = self._gains.damping_ratio
        root = math.sqrt(abs(z * z - 1.0))
        if z < 1.0:
            return [complex(-z * w, w * root), complex(-z * w, -w * root)]
        return [-w * (z - root), -w * (z + root)]

    def _body_poles(self, A: np.ndarray) -> list:
        """The car's own sideslip and yaw modes (of A's upper 2 x 2), their damping raised to
        at least ``body_damping_ratio``."""
        body = []
        for p in np.linalg.eigvals(A[:2, :2]):
            mag = abs(p)
            re = min(p.real, -self._gains.body_damping_ratio * mag)
            body.append(
                complex(re, math.copysign(math.sqrt(max(mag * mag - re * re, 0.0)), p.imag))
            )
        return body

    def gains_at(self, speed_mps: float, mu: float) -> _Gains:
        """(k_vy [rad s/m], k_r [rad s/rad], k_psi [rad/rad], k_e [rad/m]) at this speed and
        friction, blended from the gain table."""
        if mu != self._table_mu:
            key = (self._params, self._gains, mu)
            if key not in _GAIN_TABLES:
                if len(_GAIN_TABLES) >= _MAX_GAIN_TABLES:
                    _GAIN_TABLES.clear()
                _GAIN_TABLES[key] = [None] * len(self._speeds)
            self._table = _GAIN_TABLES[key]
            self._table_mu = mu
        speeds, table = self._speeds, self._table
        j = bisect_right(speeds, speed_mps)
        if j <= 0 or j >= len(speeds):  # below or above the table: its end row
            i = 0 if j <= 0 else len(speeds) - 1
            end = table[i]
            return end if end is not None else self._place(i)
        a, b = table[j - 1], table[j]
        if a is None:
            a = self._place(j - 1)
        if b is None:
            b = self._place(j)
        w = (speed_mps - speeds[j - 1]) / (speeds[j] - speeds[j - 1])
        return (
            a[0] + w * (b[0] - a[0]),
            a[1] + w * (b[1] - a[1]),
            a[2] + w * (b[2] - a[2]),
            a[3] + w * (b[3] - a[3]),
        )

    def _place(self, i: int) -> _Gains:
        """Row ``i`` of the gain table at the table's friction (pole placement: the same
        arithmetic as ``place_poles(A, B, design_poles(v, mu))``, its friction-free part kept
        per speed in ``_SPEED_ROWS``)."""
        v = self._speeds[i]
        known = self._rows[i]
        if known is None:
            A, B = single_track_matrices(self._params, v)
            powers = matrix_powers(A)
            known = self._rows[i] = (powers, controllability(powers, B), self._body_poles(A))
        powers, ctrb, body = known
        k = ackermann(powers, ctrb, np.array(self._path_poles(v, self._table_mu) + body))
        row = (float(k[0]), float(k[1]), float(k[2]), float(k[3]))
        self._table[i] = row
        return row

    def steady_sideslip(self, speed_mps: float, curvature_1pm: float) -> float:
        """Body sideslip angle [rad] of steady cornering on a curvature (linear bicycle model):
        kappa (b - m a v^2 / (L C_r)), a and b the CG's distances to the axles; its negative is
        the heading the body keeps off the path tangent."""
        return curvature_1pm * (self._b - self._slip_k * speed_mps * speed_mps)

    def lateral_accel(self, speed_mps: float, steer_rad: float) -> float:
        """Steady-state lateral acceleration v^2 delta / (L + K_us v^2) a steer angle asks for."""
        return speed_mps * speed_mps * steer_rad / (self._L + self._kus * speed_mps * speed_mps)

    def steer_for_lateral_accel(self, speed_mps: float, lateral_accel_mps2: float) -> float:
        """The steady-state steer angle asking for ``lateral_accel_mps2`` (the inverse of
        :meth:`lateral_accel`; the lock when standing)."""
        v2 = speed_mps * speed_mps
        if v2 <= 1e-9:
            return self._max
        return lateral_accel_mps2 * (self._L + self._kus * v2) / v2

    def command(
        self,
        speed_mps: float,
        yaw_rate_radps: float,
        lateral_speed_mps: float,
        lateral_error_m: float,
        heading_error_rad: float,
        curvature_1pm: float,
        preview_curvature_1pm: float,
        mu: float,
        planned_steer_rad: float = 0.0,
        sideslip_rad: float | None = None,
    ) -> SteeringCommand:
        """The steering command; delta clipped to the lock.

        ``lateral_error_m`` is the ego's offset minus the reference's, ``heading_error_rad``
        the body heading minus the path's course (left positive), ``lateral_speed_mps`` the
        body's lateral velocity; ``curvature_1pm`` the reference curvature here (path plus
        road), ``preview_curvature_1pm`` the one a preview distance ahead, used by the
        feedforward to make up for the steering and tyre lags. A planned manoeuvre (the
        tables' lane change) adds its own road-wheel angle ``planned_steer_rad`` to the
        feedforward (its path's curvature then left out of ``preview_curvature_1pm``) and
        gives its body sideslip ``sideslip_rad`` in place of the steady-state one. The
        yaw-rate reference is the body's: v kappa less the sideslip's rate (the plan's is in
        its curvature; the steady one's is taken from the preview curvature).
        """
        v = max(0.0, speed_mps)  # 0 for -0.0 and NaN too
        k_vy, k_r, k_psi, k_e = self.gains_at(v, mu)
        yaw_kappa = curvature_1pm  # the body's yaw per metre the reference asks for
        if sideslip_rad is None:
            beta = self.steady_sideslip(v, curvature_1pm)
            if self._preview_s > 0.0 and v > 1.0:  # less the steady sideslip's rate
                ahead = self.steady_sideslip(v, preview_curvature_1pm)
                yaw_kappa -= (ahead - beta) / (v * self._preview_s)
        else:
            beta = sideslip_rad
        psi = heading_error_rad + beta
        ff = (self._L + self._kus * v * v) * preview_curvature_1pm + planned_steer_rad
        fb = -(k_e * lateral_error_m + k_psi * psi)
        yd = -(k_vy * (lateral_speed_mps - v * beta) + k_r * (yaw_rate_radps - v * yaw_kappa))
        delta = ff + fb + yd
        # front slip envelope: the front tyre's slip stays short of where its force peaks
        if v > 1.0:
            course_f = (lateral_speed_mps + self._a * yaw_rate_radps) / v
            slip = self._slip_frac * mu
            delta = max(delta, course_f - slip)
            delta = min(delta, course_f + slip)
        delta = max(delta, -self._max)
        delta = min(delta, self._max)
        return SteeringCommand(delta, ff, fb, yd, -fb / k_e)

    def share_edges(
        self,
        speed_mps: float,
        yaw_rate_radps: float,
        lateral_speed_mps: float,
        mu: float,
        share: float,
    ) -> tuple[float, float]:
        """(right, left) road-wheel angles at which the front tyres' lateral force is
        ``share`` of its peak, about the body's own motion as :meth:`envelope_edge` takes it,
        never past that edge: a Fiala tyre gives 1 - (1 - x)^3 of its peak force at x of its
        peak slip, so ``share`` at x = 1 - (1 - share)^(1/3)."""
        x = 1.0 - (1.0 - min(max(share, 0.0), 1.0)) ** (1.0 / 3.0)
        scale = mu * min(x / self._gains.front_slip_fraction, 1.0)
        return (
            self.envelope_edge(speed_mps, yaw_rate_radps, lateral_speed_mps, scale, -1.0),
            self.envelope_edge(speed_mps, yaw_rate_radps, lateral_speed_mps, scale, 1.0),
        )

    def envelope_edge(
        self,
        speed_mps: float,
        yaw_rate_radps: float,
        lateral_speed_mps: float,
        mu: float,
        towards: float,
    ) -> float:
        """The road-wheel angle at the edge of ``command``'s front slip envelope on the side
        ``towards`` (+1 left, -1 right), clipped to the lock: the most lateral force towards
        that side the steering law allows (front slip at ``front_slip_fraction`` of its
        peak's, where the Fiala force is 7/8 of the peak)."""
        v = max(1.0, speed_mps)  # 1 for NaN too
        delta = (lateral_speed_mps + self._a * yaw_rate_radps) / v + towards * self._slip_frac * mu
        return max(-self._max, min(self._max, delta))
