"""What both plant implementations share: step-size checks and initial states."""

from __future__ import annotations

import math

import numpy as np

from eoam_sumo.params import (
    AIR_DENSITY_KGPM3,
    G_MPS2,
    TYRE_LOAD_RANGE,
    VehicleParams,
    ego_e_class_sedan,
)
from eoam_sumo.plant.chassis import MU_EST_HIGH, constants
from eoam_sumo.plant.model import (
    AY_LOAD,
    BETA_EST,
    DRIVE,
    ESC_REF,
    MU_EST,
    OMEGAS,
    PRESSURES,
    STATE_NAMES,
    STEER,
    TAN_F,
    TAN_R,
    V_EST,
    VX,
    VY,
    YAW,
    YAW_RATE,
    X,
    Y,
)

MAX_DT_S = 0.002
"""Largest sub-step accepted: keeps the sedan's wheel-and-tyre mode (about 160 rad/s; a faster
one splits the sub-step: ``stable_substeps``) and the slip relaxation at speed
(``|v| / sigma``, under 200 1/s) well inside the midpoint rule's stability region
(|lambda dt| < 0.35)."""


def validate_step(params: VehicleParams, dt_s: float, substeps: int) -> None:
    """Raise ``ValueError`` unless ``0 < dt_s <= MAX_DT_S``, ``substeps >= 1`` and every
    actuator lag is at least ``dt_s`` (a shorter lag would make the fixed step unstable)."""
    if isinstance(substeps, bool) or not isinstance(substeps, int) or substeps < 1:
        raise ValueError(f"substeps={substeps!r} must be an int >= 1")
    if not (isinstance(dt_s, (int, float)) and 0.0 < dt_s <= MAX_DT_S):
        raise ValueError(f"dt_s={dt_s!r} must be in (0, {MAX_DT_S}] s")
    for name in ("steer_lag_s", "drive_lag_s", "brake_lag_s"):
        if getattr(params, name) < dt_s:
            raise ValueError(
                f"vehicle parameter {name}={getattr(params, name)} must be >= dt_s={dt_s}"
            )


WHEEL_MODE_STEP_BOUND = 0.35
"""Largest ``omega_n dt`` of the wheel-and-tyre mode a sub-step may have (``MAX_DT_S``'s bound
on |lambda dt|: the midpoint rule's stability region barely reaches along the imaginary axis,
so a lightly damped mode must stay well inside it)."""


def wheel_mode_radps(params: VehicleParams) -> float:
    """Natural frequency [rad/s] of the stiffest wheel on its tyre's longitudinal relaxation
    spring: ``I omega' = -r K kappa`` and ``sigma kappa' = omega r - ...`` (Pacejka 2012
    sec. 7.2.1) give ``omega_n^2 = r^2 K / (I sigma)``, K the slip stiffness ``PKX1 Fz`` at
    the most load a tyre is meant to carry (``TYRE_LOAD_RANGE``'s top multiple of the heavier
    axle's static tyre load)."""
    p = params
    ch = constants(p)
    axle_n = p.mass_kg * G_MPS2 * max(p.cg_to_front_m, p.cg_to_rear_m) / p.wheelbase_m
    k_n = ch.tyre.pkx1 * TYRE_LOAD_RANGE[1] * 0.5 * axle_n
    return math.sqrt(
        p.wheel_radius_m**2 * k_n / (p.wheel_inertia_kgm2 * p.relaxation_length_long_m)
    )


def stable_substeps(params: VehicleParams, dt_s: float, substeps: int) -> tuple[float, int]:
    """The sub-step and count the plant integrates ``dt_s * substeps`` with: ``dt_s`` split
    into the fewest equal parts that keep the wheel-and-tyre mode within
    ``WHEEL_MODE_STEP_BOUND`` (a light wheel on a stiff, short-relaxation tyre), so the step's
    length is unchanged; ``(dt_s, substeps)`` itself for every catalogue vehicle."""
    parts = math.ceil(dt_s * wheel_mode_radps(params) / WHEEL_MODE_STEP_BOUND - 1e-9)
    if parts <= 1:
        return dt_s, substeps
    return dt_s / parts, substeps * parts


def check_mu(mu: float) -> float:
    """The surface friction as a float; ``ValueError`` unless finite and > 0."""
    mu = float(mu)
    if not (0.0 < mu < math.inf):
        raise ValueError(f"mu={mu!r} must be finite and > 0")
    return mu


def initial_state(
    x_m: float,
    y_m: float,
    yaw_rad: float,
    speed_mps: float,
    *,
    steer_rad: float = 0.0,
    drive_force_n: float = 0.0,
    brake_force_n: float = 0.0,
    params: VehicleParams | None = None,
    curvature_per_m: float = 0.0,
) -> np.ndarray:
    """State vector (``STATE_NAMES`` order) of a vehicle at ``(x_m, y_m)`` heading ``yaw_rad``
    moving straight at ``speed_mps >= 0``, its wheels rolling (``params``: default the
    paper's sedan); actuator states zero unless given (``brake_force_n`` as line pressure);
    the speed estimate the speed, the friction estimate a dry road's. ``curvature_per_m``
    not 0 (left positive): turning steadily on that curve instead (``_steady_turn``)."""
    if not speed_mps >= 0.0:
        raise ValueError(f"speed_mps={speed_mps!r} must be >= 0")
    p = params or ego_e_class_sedan()
    x = np.zeros(len(STATE_NAMES))
    x[X], x[Y], x[YAW], x[VX] = x_m, y_m, yaw_rad, speed_mps
    x[STEER], x[DRIVE] = steer_rad, drive_force_n
    for i in PRESSURES:
        x[i] = brake_force_n / constants(p).brake_n_per_bar
    for i in OMEGAS:
        x[i] = speed_mps / p.wheel_radius_m
    x[V_EST], x[MU_EST] = speed_mps, MU_EST_HIGH  # the control unit's estimates: a dry road
    if curvature_per_m:
        _steady_turn(x, speed_mps, curvature_per_m, p)
    return x


def _steady_turn(x: np.ndarray, v: float, kappa: float, p: VehicleParams) -> None:
    """``x`` turning steadily at ``v`` on a curve of curvature ``kappa`` by the linear
    single-track model (Gillespie 1992 ch. 6): the steer ``L kappa + K_us v^2 kappa``, the
    yaw rate ``v kappa``, the sideslip ``kappa (b - m a v^2 / (L C_r))``, the axles' slips
    and the lagged lateral acceleration, the ESC's reference and sideslip estimate, at their
    steady values (a car entering the run on a curve was started straight: it had to build
    its turn up and drifted off near the friction's limit)."""
    ay = v * v * kappa
    steer = p.wheelbase_m * kappa + p.understeer_gradient_rad_per_mps2 * ay
    beta = kappa * (
        p.cg_to_rear_m
        - p.mass_kg * p.cg_to_front_m * v * v / (p.wheelbase_m * p.cornering_stiffness_rear_npr)
    )
    r, vy = v * kappa, v * beta
    x[STEER], x[YAW_RATE], x[VY] = steer, r, vy
    vy_f, vy_r = vy + p.cg_to_front_m * r, vy - p.cg_to_rear_m * r
    lat_f = -v * math.sin(steer) + vy_f * math.cos(steer)
    long_f = v * math.cos(steer) + vy_f * math.sin(steer)
    if v > 0.0:
        x[TAN_F], x[TAN_R] = lat_f / long_f, vy_r / v
    x[AY_LOAD], x[ESC_REF], x[BETA_EST] = ay, r, beta


def brake_gains_n_per_bar(params: VehicleParams) -> tuple[float, float, float, float]:
    """Road brake force [N] per bar of each wheel's pressure (``model.PRESSURES``: FL, FR, RL,
    RR; the plant's fixed front/rear split, as ``integrator`` applies it)."""
    return constants(params).wheel_brake_n_per_bar


def brake_force_n(x, params: VehicleParams) -> float:
    """The road brake force [N] the four wheels' pressures of state ``x`` apply."""
    gains = constants(params).wheel_brake_n_per_bar
    return sum(g * float(x[i]) for g, i in zip(gains, PRESSURES))


def cruise_drive_force_n(params: VehicleParams, speed_mps: float) -> float:
    """Drive force [N] that holds ``speed_mps`` on a straight level road: aerodynamic drag plus
    rolling resistance, as in ``model.rhs``."""
    drag_n = 0.5 * AIR_DENSITY_KGPM3 * params.drag_area_m2 * speed_mps * speed_mps
    return drag_n + params.rolling_resistance_coeff * params.mass_kg * G_MPS2
