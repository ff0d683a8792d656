"""Design settings of the offline EOAM build: grids, buffers, TTC per friction, solver options.

Every field carries its unit and its source or reason (``dataclasses.fields(s)[i].metadata``).

DMM phase-diagram sectors (paper sec. 5-6, Figures 11, 14, 15), with, at the relative speed v,
S = clear_opt (eq. 32 with the optimised profile), Sb = clear_buffered, B0 = stop (eq. 33),
Bb = stop_buffered and T = ttc * v (eq. 34), for a relative distance d:

- A: d <= S and d <= B0                      imminent: limit braking
- C: d <= S and d > B0                       braking only
- F: S < d <= Sb and d <= Bb                 steer
- B: S < d <= Sb and d > Bb                  steer
- D: d > Sb and d <= Bb                      brake
- E: d > Sb, d > Bb and d <= T               forward-collision warning only
- G: otherwise                               do nothing

Buffers (sec. 6.2 leaves them to the designer): Sb = S + steer_buffer_time_s * v +
steer_buffer_m and Bb = B0 + brake_buffer_time_s * v + brake_buffer_m.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from eoam_sumo.params import G_MPS2, LANE_CHANGE_HEIGHT_M, MU_MAX, aro_d_class_minivan

PAPER = "Lowe & Guvenc 2022 (the paper)"
DESIGN = "design choice"


def _p(default, unit: str, source: str):
    return field(default=default, metadata={"unit": unit, "source": source})


@dataclass(frozen=True)
class DesignSettings:
    """Settings of the offline design (paths, optimal control, phase boundaries, tables)."""

    lane_change_m: float = _p(
        LANE_CHANGE_HEIGHT_M, "m", PAPER + ", sec. 4.2 (y_f = 3.5 m, one lane)"
    )
    obstacle_width_m: float = _p(
        aro_d_class_minivan().width_m, "m", "eoam_sumo.params.aro_d_class_minivan (sec. 10.1)"
    )
    speeds_kmh: tuple = _p(
        tuple(float(v) for v in range(20, 180, 5)),
        "km/h",
        PAPER + ", sec. 2 (55-165 km/h), widened to 20-175 km/h so the runs' relative speeds fit",
    )
    mus: tuple = _p((1.0, 0.7, 0.3, 0.1), "-", PAPER + ", sec. 10.1 (surface friction values)")
    dx_step_m: float = _p(0.5, "m", DESIGN + ": uniform differential-x grid of the tables")
    lat_accel_fraction: float = _p(
        0.8,
        "-",
        DESIGN + ": quintic peak lateral acceleration 5.77 h/T^2 = k mu g; 20 % of the "
        "friction is left for the tracking controller and the longitudinal profile",
    )
    max_quintic_time_s: float = _p(
        6.0,
        "s",
        DESIGN + ": upper bound of T; binds only below mu 0.07 and keeps the lane "
        "change well inside the 8 s manoeuvre timer",
    )
    plant_tyre: bool = _p(
        True,
        "-",
        DESIGN + ": the lane change is planned with the plant's Fiala tyre (cornering "
        "stiffness C at any friction, peak derated by the longitudinal force), not the paper's "
        "eq. 6 tyre (stiffness mu C, the ellipse reached at a few degrees of slip): the plan's "
        "steering and sideslip are then the ones the plant needs (False: the paper's tyre)",
    )
    friction_use: float = _p(
        0.8,
        "-",
        DESIGN + ": each axle's planned tyre force stays within this share of its "
        "friction limit mu Fz (eqs. 25, 28: ellipse <= share^2); the rest is the tracking loop's: "
        "at the whole ellipse the plant's tyre is at its peak slip, where no force is left to "
        "correct with (measured: 0.92 m of tracking error at 55 km/h, mu 1.0; at 0.9 on the "
        "per-wheel chassis plant, whose inner wheels lose load and whose front slip envelope "
        "keeps ~0.88 of the peak, 0.78 m; at 0.8, 0.15 m)",
    )
    continuation_steps: int = _p(
        4,
        "-",
        DESIGN + ": steps from the paper's tyre and the whole ellipse to the plant's tyre "
        "and friction_use, each warm-started from the last, where a direct solve fails",
    )
    ocp_intervals: int = _p(40, "-", DESIGN + ": collocation intervals (speed vs. accuracy)")
    collocation_degree: int = _p(3, "-", DESIGN + ": Radau collocation points per interval")
    min_speed_fraction: float = _p(
        0.5,
        "-",
        DESIGN + ": the body speed stays above this fraction of the entry speed: the "
        "EOAM is a lane change, a manoeuvre shedding more speed is braking (the stopping "
        "boundary covers it); also keeps the slip angles defined",
    )
    max_yaw_rad: float = _p(math.radians(45.0), "rad", DESIGN + ": bound keeping the OCP regular")
    regularisation: float = _p(
        0.3,
        "m",
        DESIGN + ": weight of the squared steps between intervals of the controls "
        "(scaled by mu m g and the steer-rate limit) added to the cost x(t_f): removes the chatter "
        "of the bang-bang optimum along the friction limit (a smooth, trackable, slightly "
        "suboptimal profile, cf. the paper's 'suboptimal' profiles) and makes it unique",
    )
    ipopt_tol: float = _p(1e-8, "-", "IPOPT default (tight, so warm starts reach the same optimum)")
    ipopt_max_iter: int = _p(1000, "-", DESIGN + ": the last resort's iteration limit")
    ipopt_mu_init: float = _p(
        1e-4,
        "-",
        DESIGN + ": IPOPT's initial barrier parameter in the speed chain, whose every solve "
        "starts from a neighbouring optimum (IPOPT's default 0.1 pushes such a start off its "
        "active constraints, and the low-friction, low-speed solves then fail)",
    )
    attempt_max_iter: int = _p(
        200,
        "-",
        DESIGN + ": iteration limit of a solve in the speed chain (converging ones take "
        "fewer); a solve that reaches it is retried from a nearer speed",
    )
    chain_step_kmh: float = _p(
        2.5,
        "km/h",
        DESIGN + ": the largest speed step of the chain (intermediate speeds are solved and "
        "not tabulated): small enough that every warm-started solve converges far below "
        "attempt_max_iter (the sedan's chains: at most 60 iterations after the first), so "
        "which local optimum a chain reaches never hangs on an iteration limit, which a "
        "last-bit difference between machines could cross",
    )
    speed_halvings: int = _p(
        3,
        "-",
        DESIGN + ": a failed step of the speed chain is split into two half steps, nested "
        "at most this many times, before the last resort (IPOPT's defaults, then continuation "
        "in the tyre and the ellipse)",
    )
    verify_lateral_tol_m: float = _p(0.03, "m", DESIGN + ": re-simulated final y vs y_f")
    verify_distance_tol_m: float = _p(0.10, "m", DESIGN + ": re-simulated vs optimised x(t_f)")
    verify_lat_speed_tol_mps: float = _p(0.05, "m/s", DESIGN + ": final lateral speed")
    verify_yaw_tol_rad: float = _p(0.005, "rad", DESIGN + ": final yaw angle")
    verify_yaw_rate_tol_radps: float = _p(0.02, "rad/s", DESIGN + ": final yaw rate")
    verify_ellipse_tol: float = _p(
        0.03, "-", DESIGN + ": allowed excess of the friction-ellipse use between the nodes"
    )
    steer_buffer_time_s: float = _p(
        0.6,
        "s",
        DESIGN + ": DMM step 10 ms + steering lag 0.05 s + closed-loop lateral lag "
        "~0.25 s (measured) + the ARO still braking during the steer (~0.5 a t_c^2)",
    )
    steer_buffer_m: float = _p(2.0, "m", DESIGN + ": visual-comfort margin (sec. 6.2)")
    brake_buffer_time_s: float = _p(
        0.3, "s", DESIGN + ": DMM step + brake build-up (lag 0.1 s, about 3 time constants)"
    )
    brake_buffer_m: float = _p(2.0, "m", DESIGN + ": stop about 2 m short of the obstacle")
    limit_brake_fraction: float = _p(
        0.95,
        "-",
        DESIGN + ": limit braking's deceleration as a share of eq. 33's (its tyre force 5 % "
        "below the no-lock limit or the ABS's mean deceleration); the EOAM commands it "
        "(m_eq times it, the wheels spinning down with the car) and B0 (eq. 33) is its "
        "stopping distance",
    )
    ttc_mus: tuple = _p((0.1, 0.3, 0.7, 1.0), "-", PAPER + ", sec. 6.2")
    ttc_values_s: tuple = _p(
        (20.0, 5.0, 2.5, 2.5), "s", PAPER + ", sec. 6.2 (linear in mu between, clamped outside)"
    )

    def __post_init__(self) -> None:
        self._check_numbers()
        self._check_counts()
        if self.friction_use > 1.0:
            raise ValueError(f"friction_use={self.friction_use} must be <= 1")
        if not isinstance(self.plant_tyre, bool):
            raise ValueError(f"design setting plant_tyre={self.plant_tyre!r} must be true or false")
        if self.min_speed_fraction >= 1.0:
            raise ValueError(f"min_speed_fraction={self.min_speed_fraction} must be < 1")
        if self.lat_accel_fraction > 1.0:
            raise ValueError(f"lat_accel_fraction={self.lat_accel_fraction} must be <= 1")
        # the lane-change optimisation is posed for highway manoeuvres: below 20 km/h or
        # mu 0.1 IPOPT finds no solution (measured: 1 km/h, mu 0.001)
        _check_grid("speeds_kmh", self.speeds_kmh, MIN_SPEED_KMH, 400.0, inclusive=True)
        _check_grid("mus", self.mus, MIN_MU, MU_MAX, inclusive=True)
        _check_grid("ttc_mus", self.ttc_mus, 0.0, MU_MAX)
        if list(self.ttc_mus) != sorted(self.ttc_mus):
            raise ValueError(f"ttc_mus={self.ttc_mus} must be in increasing order")
        if len(self.ttc_values_s) != len(self.ttc_mus) or not all(
            isinstance(v, (int, float)) and math.isfinite(v) and v > 0 for v in self.ttc_values_s
        ):
            raise ValueError("ttc_values_s must hold one finite TTC > 0 per entry of ttc_mus")

    def _check_numbers(self) -> None:
        """The real-valued settings: finite, positive (or non-negative)."""
        positive = (
            "lane_change_m",
            "obstacle_width_m",
            "dx_step_m",
            "lat_accel_fraction",
            "max_quintic_time_s",
            "min_speed_fraction",
            "max_yaw_rad",
            "ipopt_tol",
            "ipopt_mu_init",
            "friction_use",
            "verify_lateral_tol_m",
            "verify_distance_tol_m",
            "verify_lat_speed_tol_mps",
            "verify_yaw_tol_rad",
            "verify_yaw_rate_tol_radps",
            "verify_ellipse_tol",
        )
        for name in positive:
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
                raise ValueError(f"design setting {name}={v!r} must be a finite number > 0")
        for name in (
            "regularisation",
            "steer_buffer_time_s",
            "steer_buffer_m",
            "brake_buffer_time_s",
            "brake_buffer_m",
        ):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0.0):
                raise ValueError(f"design setting {name}={v!r} must be a finite number >= 0")

    def _check_counts(self) -> None:
        """The integer settings."""
        for name in (
            "ocp_intervals",
            "collocation_degree",
            "ipopt_max_iter",
            "attempt_max_iter",
            "continuation_steps",
        ):
            v = getattr(self, name)
            if not (isinstance(v, int) and v >= 1):
                raise ValueError(f"design setting {name}={v!r} must be an integer >= 1")
        if not 0.0 < self.limit_brake_fraction <= 1.0:
            raise ValueError(
                f"limit_brake_fraction={self.limit_brake_fraction!r} must be in (0, 1]"
            )
        if not (math.isfinite(self.chain_step_kmh) and self.chain_step_kmh > 0.0):
            raise ValueError(f"chain_step_kmh={self.chain_step_kmh!r} must be finite and > 0")
        if not (isinstance(self.speed_halvings, int) and self.speed_halvings >= 0):
            raise ValueError(f"speed_halvings={self.speed_halvings!r} must be an integer >= 0")
        if self.ocp_intervals < 10:
            raise ValueError(f"ocp_intervals={self.ocp_intervals} must be >= 10")

    def ttc_s(self, mu: float) -> float:
        """TTC of the do-nothing boundary (eq. 34): linear in mu between the table, clamped."""
        mus, ttcs = self.ttc_mus, self.ttc_values_s
        if mu <= mus[0]:
            return float(ttcs[0])
        for i in range(1, len(mus)):
            if mu <= mus[i]:
                w = (mu - mus[i - 1]) / (mus[i] - mus[i - 1])
                return float(ttcs[i - 1] + w * (ttcs[i] - ttcs[i - 1]))
        return float(ttcs[-1])

    @property
    def tyre_blend(self) -> float:
        """Weight of the plant's tyre in the design model (``model.dynamics``)."""
        return 1.0 if self.plant_tyre else 0.0

    def quintic_time_s(self, mu: float) -> float:
        """Lane-change time T of the quintic: 5.77 h / T^2 = k mu g, capped (sec. 4.2)."""
        if not (math.isfinite(mu) and mu > 0.0):
            raise ValueError(f"mu={mu!r} must be > 0")
        t = math.sqrt(
            QUINTIC_PEAK_COEFF * self.lane_change_m / (self.lat_accel_fraction * mu * G_MPS2)
        )
        return min(t, self.max_quintic_time_s)

    def as_dict(self) -> dict:
        """Every setting as {name: {value, unit, source}} (for metadata.json)."""
        return {
            f.name: {
                "value": list(getattr(self, f.name))
                if isinstance(getattr(self, f.name), tuple)
                else getattr(self, f.name),
                "unit": f.metadata["unit"],
                "source": f.metadata["source"],
            }
            for f in dataclasses.fields(self)
        }


# Peak |y''| of the quintic 10 t^3 - 15 t^4 + 6 t^5 (t in [0, 1]) is 10 sqrt(3)/3 = 5.7735.
QUINTIC_PEAK_COEFF = 10.0 * math.sqrt(3.0) / 3.0


MIN_SPEED_KMH = 20.0  # lowest entry speed of a lookup table the optimisation solves [km/h]
MIN_MU = 0.1  # lowest friction of a lookup table the optimisation solves [-]


def _check_grid(name: str, values, low: float, high: float, inclusive: bool = False) -> None:
    if not isinstance(values, tuple) or len(values) < 1:
        raise ValueError(f"design setting {name} holds no values")
    for v in values:
        above = low <= v if inclusive else low < v
        if not (isinstance(v, (int, float)) and math.isfinite(v) and above and v <= high):
            bounds = f"[{low:g}, {high:g}]" if inclusive else f"({low:g}, {high:g}]"
            raise ValueError(f"design setting {name} holds {v!r}: must be in {bounds}")
    if len(set(values)) != len(values):
        raise ValueError(f"design setting {name} holds duplicates: {values}")
